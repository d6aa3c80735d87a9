/*
 * route_package.c: route 1 of the C example: the pass from the kernel package alone.
 * Pipelines, descriptor-set layouts, the pass's own buffers and every descriptor write are
 * made from manifest.json (read with Jansson): no binding number, buffer size or entry
 * point is written in this file. strata_frame.h computes each frame's uniforms and
 * dispatch sizes.
 *
 * Part of strata (MIT OR Apache-2.0).
 */
#include <jansson.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "routes.h"

#define MAX_BINDINGS 16
#define MAX_BUFFERS 16

/* A buffer of the manifest's `buffers`, made here or handed over by the engine. */
typedef struct NamedBuffer {
    const char *name;
    Buffer buffer;
    int owned;
} NamedBuffer;

/* One kernel's pipeline and descriptor set. */
typedef struct Kernel {
    json_t *entry;
    VkShaderModule module;
    VkDescriptorSetLayout set_layout;
    VkPipelineLayout layout;
    VkPipeline pipeline;
    VkDescriptorSet set;
} Kernel;

/* `object[key]` as a string, or exits naming the key. */
static const char *text_of(json_t *object, const char *key) {
    json_t *value = json_object_get(object, key);
    if (!json_is_string(value)) {
        fail("manifest.json: `%s` is not a string", key);
    }
    return json_string_value(value);
}

/* `object[key]` as a whole number, or exits naming the key. */
static uint64_t number_of(json_t *object, const char *key) {
    json_t *value = json_object_get(object, key);
    if (!json_is_integer(value) || json_integer_value(value) < 0) {
        fail("manifest.json: `%s` is not a whole number", key);
    }
    return (uint64_t)json_integer_value(value);
}

/* The kernel entry named `name`. */
static json_t *kernel_named(json_t *manifest, const char *name) {
    size_t index;
    json_t *kernel;
    json_array_foreach(json_object_get(manifest, "kernels"), index, kernel) {
        if (strcmp(text_of(kernel, "name"), name) == 0) {
            return kernel;
        }
    }
    fail("manifest.json: no kernel named `%s`", name);
    return NULL;
}

static NamedBuffer *buffer_named(NamedBuffer *buffers, size_t count, const char *name) {
    for (size_t i = 0; i < count; i++) {
        if (strcmp(buffers[i].name, name) == 0) {
            return &buffers[i];
        }
    }
    fail("manifest.json: a binding names buffer `%s`, which `buffers` lacks", name);
    return NULL;
}

static VkDescriptorType descriptor_type(json_t *binding) {
    const char *type = text_of(binding, "descriptor_type");
    if (strcmp(type, "uniform_buffer") == 0) {
        return VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER;
    }
    if (strcmp(type, "storage_buffer") == 0) {
        return VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
    }
    fail("manifest.json: descriptor_type `%s` is not one this engine knows", type);
    return VK_DESCRIPTOR_TYPE_MAX_ENUM;
}

/* Exits naming the kernel unless the device has every feature it requires. */
static void check_features(Engine *engine, const Kernel *kernel) {
    size_t index;
    json_t *feature;
    json_array_foreach(json_object_get(kernel->entry, "required_features"), index, feature) {
        const char *name = json_string_value(feature);
        if (name != NULL && strcmp(name, "subgroups") == 0) {
            VkPhysicalDeviceSubgroupProperties subgroup = {0};
            subgroup.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_SUBGROUP_PROPERTIES;
            VkPhysicalDeviceProperties2 properties = {0};
            properties.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2;
            properties.pNext = &subgroup;
            vkGetPhysicalDeviceProperties2(engine->physical_device, &properties);
            VkSubgroupFeatureFlags needed = VK_SUBGROUP_FEATURE_BASIC_BIT | VK_SUBGROUP_FEATURE_SHUFFLE_BIT;
            if (!(subgroup.supportedStages & VK_SHADER_STAGE_COMPUTE_BIT) ||
                (subgroup.supportedOperations & needed) != needed) {
                fail("kernel `%s` needs subgroup shuffles in compute shaders, which this device lacks: run "
                     "block_histogram or block_histogram_rank",
                     text_of(kernel->entry, "name"));
            }
        } else {
            fail("kernel `%s` requires feature `%s`, which this engine does not know",
                 text_of(kernel->entry, "name"), name != NULL ? name : "?");
        }
    }
}

/* The pipeline of `kernel` from its SPIR-V file and bindings. */
static void kernel_create(Engine *engine, const char *package, Kernel *kernel) {
    check_features(engine, kernel);
    char path[4096];
    json_t *files = json_object_get(kernel->entry, "files");
    snprintf(path, sizeof path, "%s/%s", package, text_of(files, "spirv"));
    size_t size = 0;
    uint32_t *words = file_read(path, &size);
    if (size < 20 || size % 4 != 0 || words[0] != 0x07230203u) {
        fail("%s: not a SPIR-V module", path);
    }
    VkShaderModuleCreateInfo module_info = {0};
    module_info.sType = VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO;
    module_info.codeSize = size;
    module_info.pCode = words;
    check_vk(vkCreateShaderModule(engine->device, &module_info, NULL, &kernel->module), "vkCreateShaderModule");
    free(words);

    VkDescriptorSetLayoutBinding layout_bindings[MAX_BINDINGS];
    json_t *bindings = json_object_get(kernel->entry, "bindings");
    size_t count = json_array_size(bindings);
    if (count > MAX_BINDINGS) {
        fail("manifest.json: %zu bindings, more than this engine's %d", count, MAX_BINDINGS);
    }
    for (size_t i = 0; i < count; i++) {
        json_t *binding = json_array_get(bindings, i);
        if (number_of(binding, "set") != 0) {
            fail("manifest.json: binding `%s` is in set %llu; this engine makes set 0 only",
                 text_of(binding, "name"), (unsigned long long)number_of(binding, "set"));
        }
        VkDescriptorSetLayoutBinding layout_binding = {0};
        layout_binding.binding = (uint32_t)number_of(binding, "binding");
        layout_binding.descriptorType = descriptor_type(binding);
        layout_binding.descriptorCount = 1;
        layout_binding.stageFlags = VK_SHADER_STAGE_COMPUTE_BIT;
        layout_bindings[i] = layout_binding;
    }
    VkDescriptorSetLayoutCreateInfo set_info = {0};
    set_info.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO;
    set_info.bindingCount = (uint32_t)count;
    set_info.pBindings = layout_bindings;
    check_vk(vkCreateDescriptorSetLayout(engine->device, &set_info, NULL, &kernel->set_layout),
             "vkCreateDescriptorSetLayout");
    VkPipelineLayoutCreateInfo layout_info = {0};
    layout_info.sType = VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO;
    layout_info.setLayoutCount = 1;
    layout_info.pSetLayouts = &kernel->set_layout;
    check_vk(vkCreatePipelineLayout(engine->device, &layout_info, NULL, &kernel->layout), "vkCreatePipelineLayout");
    VkComputePipelineCreateInfo pipeline_info = {0};
    pipeline_info.sType = VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO;
    pipeline_info.stage.sType = VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO;
    pipeline_info.stage.stage = VK_SHADER_STAGE_COMPUTE_BIT;
    pipeline_info.stage.module = kernel->module;
    pipeline_info.stage.pName = text_of(json_object_get(kernel->entry, "entry_point"), "spirv");
    pipeline_info.layout = kernel->layout;
    check_vk(vkCreateComputePipelines(engine->device, VK_NULL_HANDLE, 1, &pipeline_info, NULL, &kernel->pipeline),
             "vkCreateComputePipelines");
}

/* Writes `kernel`'s descriptor set: each binding gets the buffer its manifest entry names. */
static void kernel_bind(Engine *engine, Kernel *kernel, NamedBuffer *buffers, size_t buffer_count) {
    json_t *bindings = json_object_get(kernel->entry, "bindings");
    size_t count = json_array_size(bindings);
    VkDescriptorBufferInfo infos[MAX_BINDINGS];
    VkWriteDescriptorSet writes[MAX_BINDINGS];
    for (size_t i = 0; i < count; i++) {
        json_t *binding = json_array_get(bindings, i);
        NamedBuffer *named = buffer_named(buffers, buffer_count, text_of(binding, "buffer"));
        VkDescriptorBufferInfo info = {named->buffer.buffer, 0, named->buffer.size};
        infos[i] = info;
        VkWriteDescriptorSet write = {0};
        write.sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET;
        write.dstSet = kernel->set;
        write.dstBinding = (uint32_t)number_of(binding, "binding");
        write.descriptorCount = 1;
        write.descriptorType = descriptor_type(binding);
        write.pBufferInfo = &infos[i];
        writes[i] = write;
    }
    vkUpdateDescriptorSets(engine->device, (uint32_t)count, writes, 0, NULL);
}

static void kernel_destroy(Engine *engine, Kernel *kernel) {
    vkDestroyPipeline(engine->device, kernel->pipeline, NULL);
    vkDestroyPipelineLayout(engine->device, kernel->layout, NULL);
    vkDestroyDescriptorSetLayout(engine->device, kernel->set_layout, NULL);
    vkDestroyShaderModule(engine->device, kernel->module, NULL);
}

/* The bytes the manifest's size rule gives a buffer for this run. */
static uint64_t size_of_buffer(json_t *buffer, const Run *run) {
    json_t *size = json_object_get(buffer, "size");
    const char *rule = text_of(size, "rule");
    uint64_t bytes = number_of(size, "bytes");
    if (strcmp(rule, "fixed") == 0) {
        return bytes;
    }
    if (strcmp(rule, "per_pixel") == 0) {
        return bytes * run->width * run->height;
    }
    if (strcmp(rule, "per_block") == 0) {
        return bytes * strata_max_blocks(&run->settings, run->width, run->height);
    }
    fail("manifest.json: size rule `%s` of buffer `%s` is not one this engine knows", rule, text_of(buffer, "name"));
    return 0;
}

/* A barrier from `source` writes to every read and write of compute and transfer. */
static void barrier(VkCommandBuffer commands, VkPipelineStageFlags source, VkAccessFlags writes) {
    VkMemoryBarrier memory = {0};
    memory.sType = VK_STRUCTURE_TYPE_MEMORY_BARRIER;
    memory.srcAccessMask = writes;
    memory.dstAccessMask = VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_UNIFORM_READ_BIT |
                           VK_ACCESS_TRANSFER_READ_BIT | VK_ACCESS_TRANSFER_WRITE_BIT;
    vkCmdPipelineBarrier(commands, source, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT, 0,
                         1, &memory, 0, NULL, 0, NULL);
}

static void dispatch(VkCommandBuffer commands, const Kernel *kernel, const uint32_t workgroups[3]) {
    vkCmdBindPipeline(commands, VK_PIPELINE_BIND_POINT_COMPUTE, kernel->pipeline);
    vkCmdBindDescriptorSets(commands, VK_PIPELINE_BIND_POINT_COMPUTE, kernel->layout, 0, 1, &kernel->set, 0, NULL);
    vkCmdDispatch(commands, workgroups[0], workgroups[1], workgroups[2]);
    barrier(commands, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_WRITE_BIT);
}

/* The buffer a kernel's uniform binding names. */
static NamedBuffer *uniform_of(const Kernel *kernel, NamedBuffer *buffers, size_t count) {
    size_t index;
    json_t *binding;
    json_array_foreach(json_object_get(kernel->entry, "bindings"), index, binding) {
        if (descriptor_type(binding) == VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER) {
            return buffer_named(buffers, count, text_of(binding, "buffer"));
        }
    }
    fail("manifest.json: kernel `%s` has no uniform binding", text_of(kernel->entry, "name"));
    return NULL;
}

void route_package(Engine *engine, const Run *run) {
    char path[4096];
    snprintf(path, sizeof path, "%s/manifest.json", run->package);
    json_error_t parse_error;
    json_t *manifest = json_load_file(path, 0, &parse_error);
    if (manifest == NULL) {
        fail("%s: line %d: %s", path, parse_error.line, parse_error.text);
    }
    if (number_of(manifest, "schema_version") != 1) {
        fail("%s: schema_version %llu; this engine reads version 1", path,
             (unsigned long long)number_of(manifest, "schema_version"));
    }
    Kernel kernels[3] = {{0}};
    const char *names[3] = {run->histogram, "strata_select", "strata_resample"};
    for (int k = 0; k < 3; k++) {
        kernels[k].entry = kernel_named(manifest, names[k]);
        kernel_create(engine, run->package, &kernels[k]);
    }

    /* The buffers: the engine's from its files, the pass's own by the manifest's sizes. */
    EngineBuffers engine_buffers = engine_buffers_create(engine, run);
    uint32_t identity_payload = engine_buffers.payloads.buffer == VK_NULL_HANDLE;
    NamedBuffer buffers[MAX_BUFFERS];
    memset(buffers, 0, sizeof buffers);
    size_t buffer_count = 0;
    size_t index;
    json_t *entry;
    json_array_foreach(json_object_get(manifest, "buffers"), index, entry) {
        if (buffer_count == MAX_BUFFERS) {
            fail("manifest.json: more buffers than this engine's %d", MAX_BUFFERS);
        }
        NamedBuffer *named = &buffers[buffer_count++];
        named->name = text_of(entry, "name");
        named->owned = strcmp(text_of(entry, "owner"), "pass") == 0;
        uint64_t size = size_of_buffer(entry, run);
        const struct {
            const char *name;
            Buffer *buffer;
        } engine_owned[] = {{"candidates", &engine_buffers.candidates},
                            {"payloads", &engine_buffers.payloads},
                            {"selections", &engine_buffers.selections},
                            {"resample_inputs", &engine_buffers.resample_inputs},
                            {"resampled", &engine_buffers.resampled}};
        if (named->owned) {
            void *contents = NULL;
            if (strcmp(text_of(entry, "written_by"), "host_once") == 0) {
                json_t *blue_noise = json_object_get(manifest, "blue_noise");
                char file[4096];
                snprintf(file, sizeof file, "%s/%s", run->package, text_of(blue_noise, "file"));
                size_t bytes = 0;
                contents = file_read(file, &bytes);
                if (bytes != size) {
                    fail("%s: %zu bytes, the manifest says %llu", file, bytes, (unsigned long long)size);
                }
            }
            named->buffer = buffer_create(engine, size, VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT, contents);
            free(contents);
            continue;
        }
        for (size_t e = 0; e < sizeof engine_owned / sizeof engine_owned[0]; e++) {
            if (strcmp(engine_owned[e].name, named->name) != 0) {
                continue;
            }
            if (engine_owned[e].buffer->buffer == VK_NULL_HANDLE) {
                /* An optional buffer the engine does not have: any 4 bytes stand in. */
                if (!json_is_true(json_object_get(entry, "optional"))) {
                    fail("manifest.json: the engine lacks buffer `%s`, which is not optional", named->name);
                }
                named->buffer = buffer_create(engine, 4, 0, NULL);
                named->owned = 1;
            } else {
                if (engine_owned[e].buffer->size < size) {
                    fail("buffer `%s`: %llu bytes, the manifest asks for %llu", named->name,
                         (unsigned long long)engine_owned[e].buffer->size, (unsigned long long)size);
                }
                named->buffer = *engine_owned[e].buffer;
            }
        }
        if (named->buffer.buffer == VK_NULL_HANDLE) {
            fail("manifest.json: buffer `%s` is the engine's, and this engine has no such buffer", named->name);
        }
    }

    /* One descriptor set per kernel, every binding written from the manifest. */
    VkDescriptorPoolSize pool_sizes[2] = {{VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER, 3 * MAX_BINDINGS},
                                          {VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 3 * MAX_BINDINGS}};
    VkDescriptorPoolCreateInfo pool_info = {0};
    pool_info.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO;
    pool_info.maxSets = 3;
    pool_info.poolSizeCount = 2;
    pool_info.pPoolSizes = pool_sizes;
    VkDescriptorPool pool;
    check_vk(vkCreateDescriptorPool(engine->device, &pool_info, NULL, &pool), "vkCreateDescriptorPool");
    for (int k = 0; k < 3; k++) {
        VkDescriptorSetAllocateInfo allocate = {0};
        allocate.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO;
        allocate.descriptorPool = pool;
        allocate.descriptorSetCount = 1;
        allocate.pSetLayouts = &kernels[k].set_layout;
        check_vk(vkAllocateDescriptorSets(engine->device, &allocate, &kernels[k].set), "vkAllocateDescriptorSets");
        kernel_bind(engine, &kernels[k], buffers, buffer_count);
    }
    NamedBuffer *histogram_uniform = uniform_of(&kernels[0], buffers, buffer_count);
    NamedBuffer *selection_uniform = uniform_of(&kernels[1], buffers, buffer_count);
    if (histogram_uniform->buffer.size != sizeof(StrataHistogramParams) ||
        selection_uniform->buffer.size != sizeof(StrataSelectionParams)) {
        fail("manifest.json: the uniforms' sizes are not those of strata.h's structs");
    }

    uint32_t max_workgroups = engine->limits.maxComputeWorkGroupCount[0];
    for (int axis = 1; axis < 3; axis++) {
        if (engine->limits.maxComputeWorkGroupCount[axis] < max_workgroups) {
            max_workgroups = engine->limits.maxComputeWorkGroupCount[axis];
        }
    }
    for (uint32_t frame = 0; frame < run->frames; frame++) {
        StrataFrameParams params;
        char message[256];
        if (strata_frame_params(&run->settings, run->width, run->height, frame, run->seed, identity_payload,
                                max_workgroups, &params, message, sizeof message)) {
            fail("strata_frame_params: %s", message);
        }
        VkCommandBuffer commands = commands_begin(engine);
        barrier(commands, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_WRITE_BIT);
        vkCmdUpdateBuffer(commands, histogram_uniform->buffer.buffer, 0, sizeof params.histogram, &params.histogram);
        vkCmdUpdateBuffer(commands, selection_uniform->buffer.buffer, 0, sizeof params.selection, &params.selection);
        barrier(commands, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT);
        dispatch(commands, &kernels[0], params.histogram_workgroups);
        dispatch(commands, &kernels[1], params.pixel_workgroups);
        dispatch(commands, &kernels[2], params.pixel_workgroups);
        commands_submit(engine, commands);
        engine_buffers_write(&engine_buffers, run, frame);
    }

    vkDestroyDescriptorPool(engine->device, pool, NULL);
    for (int k = 0; k < 3; k++) {
        kernel_destroy(engine, &kernels[k]);
    }
    for (size_t b = 0; b < buffer_count; b++) {
        if (buffers[b].owned) {
            buffer_destroy(engine, &buffers[b].buffer);
        }
    }
    engine_buffers_destroy(engine, &engine_buffers);
    json_decref(manifest);
}
