/*
 * route_package.c: route 1 of the C example: the pass from the kernel package alone.
 * Pipelines, descriptor-set layouts, the pass's own buffers and every descriptor write are
 * made from manifest.json (read with Jansson): no binding number, buffer size, usage flag,
 * entry point, barrier, dispatch formula or kernel-choice rule is written in this file. The
 * buffers' sizes and the dispatches come from the manifest's expressions (`variables`,
 * `size.expr`, `dispatch`), the barriers and the order of the commands from
 * `frame.sequence`, the histogram kernel (`--histogram auto`) from `histogram_choice`.
 * strata_frame.h computes each frame's uniforms (and its dispatch sizes, which must agree).
 *
 * Part of strata (MIT OR Apache-2.0).
 */
#include <jansson.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "routes.h"
#include "strata_vk.h"

#define MAX_BINDINGS 16
#define MAX_BUFFERS 16
#define MAX_VARIABLES 64

/* The manifest's schema version this engine was written for. */
#define SCHEMA_VERSION 2

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

/* Named values of the manifest's `variables` for one frame. */
typedef struct Variables {
    const char *names[MAX_VARIABLES];
    uint64_t values[MAX_VARIABLES];
    size_t count;
} Variables;

static void variable_set(Variables *variables, const char *name, uint64_t value) {
    for (size_t i = 0; i < variables->count; i++) {
        if (strcmp(variables->names[i], name) == 0) {
            variables->values[i] = value;
            return;
        }
    }
    if (variables->count == MAX_VARIABLES) {
        fail("manifest.json: more variables than this engine's %d", MAX_VARIABLES);
    }
    variables->names[variables->count] = name;
    variables->values[variables->count++] = value;
}

static uint64_t variable_get(const Variables *variables, const char *name) {
    for (size_t i = 0; i < variables->count; i++) {
        if (strcmp(variables->names[i], name) == 0) {
            return variables->values[i];
        }
    }
    fail("manifest.json: an expression uses variable `%s`, which has no value", name);
    return 0;
}

/* The value of a manifest expression: a number, a variable's name or {"op", "args"}. */
static uint64_t evaluate(json_t *expr, const Variables *variables) {
    if (json_is_integer(expr) && json_integer_value(expr) >= 0) {
        return (uint64_t)json_integer_value(expr);
    }
    if (json_is_string(expr)) {
        return variable_get(variables, json_string_value(expr));
    }
    const char *op = text_of(expr, "op");
    json_t *args = json_object_get(expr, "args");
    size_t count = json_array_size(args);
    if (count == 0) {
        fail("manifest.json: operation `%s` without arguments", op);
    }
    uint64_t result = evaluate(json_array_get(args, 0), variables);
    for (size_t i = 1; i < count; i++) {
        uint64_t value = evaluate(json_array_get(args, i), variables);
        if (strcmp(op, "add") == 0) {
            result += value;
        } else if (strcmp(op, "mul") == 0) {
            result *= value;
        } else if (strcmp(op, "sub") == 0 && value <= result) {
            result -= value;
        } else if (strcmp(op, "div") == 0 && value != 0) {
            result /= value;
        } else if (strcmp(op, "ceil_div") == 0 && value != 0) {
            result = result / value + (result % value != 0);
        } else if (strcmp(op, "min") == 0) {
            result = value < result ? value : result;
        } else if (strcmp(op, "max") == 0) {
            result = value > result ? value : result;
        } else {
            fail("manifest.json: operation `%s` of %llu and %llu is not one this engine can do", op,
                 (unsigned long long)result, (unsigned long long)value);
        }
    }
    return result;
}

/* The manifest constant `name`'s value. */
static uint64_t constant_of(json_t *manifest, const char *name) {
    size_t index;
    json_t *constant;
    json_array_foreach(json_object_get(manifest, "constants"), index, constant) {
        if (strcmp(text_of(constant, "name"), name) == 0) {
            return number_of(constant, "value");
        }
    }
    fail("manifest.json: no constant named `%s`", name);
    return 0;
}

/* Every variable of the manifest for frame `frame`: the inputs from the run, the settings,
 * strata_grid_shift and the device, the constants and the derived values in order. */
static Variables variables_of(json_t *manifest, const Engine *engine, const Run *run, uint32_t frame) {
    Variables variables = {0};
    uint32_t shift_x = 0, shift_y = 0;
    strata_grid_shift(&run->settings, frame, run->seed, &shift_x, &shift_y);
    const struct {
        const char *name;
        uint64_t value;
    } inputs[] = {{"width", run->width},
                  {"height", run->height},
                  {"B", run->settings.block_size},
                  {"block_shift", run->settings.block_shift},
                  {"shift_x", shift_x},
                  {"shift_y", shift_y},
                  {"max_compute_work_group_count_x", engine->limits.maxComputeWorkGroupCount[0]},
                  {"max_compute_work_group_count_y", engine->limits.maxComputeWorkGroupCount[1]},
                  {"max_compute_work_group_count_z", engine->limits.maxComputeWorkGroupCount[2]}};
    size_t index;
    json_t *variable;
    json_array_foreach(json_object_get(manifest, "variables"), index, variable) {
        const char *name = text_of(variable, "name");
        json_t *expr = json_object_get(variable, "expr");
        json_t *constant = json_object_get(variable, "constant");
        if (expr != NULL) {
            variable_set(&variables, name, evaluate(expr, &variables));
        } else if (constant != NULL) {
            variable_set(&variables, name, constant_of(manifest, json_string_value(constant)));
        } else {
            int found = 0;
            for (size_t i = 0; i < sizeof inputs / sizeof inputs[0]; i++) {
                if (strcmp(inputs[i].name, name) == 0) {
                    variable_set(&variables, name, inputs[i].value);
                    found = 1;
                }
            }
            if (!found) {
                fail("manifest.json: input `%s` (%s) is not one this engine supplies", name,
                     text_of(variable, "input"));
            }
        }
    }
    return variables;
}

/* A Vulkan flag by its name, from the names a manifest of this schema uses. */
static uint32_t flag_named(const char *name) {
    static const struct {
        const char *name;
        uint32_t bit;
    } flags[] = {{"VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT", VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT},
                 {"VK_PIPELINE_STAGE_TRANSFER_BIT", VK_PIPELINE_STAGE_TRANSFER_BIT},
                 {"VK_PIPELINE_STAGE_ALL_COMMANDS_BIT", VK_PIPELINE_STAGE_ALL_COMMANDS_BIT},
                 {"VK_ACCESS_UNIFORM_READ_BIT", VK_ACCESS_UNIFORM_READ_BIT},
                 {"VK_ACCESS_SHADER_READ_BIT", VK_ACCESS_SHADER_READ_BIT},
                 {"VK_ACCESS_SHADER_WRITE_BIT", VK_ACCESS_SHADER_WRITE_BIT},
                 {"VK_ACCESS_TRANSFER_READ_BIT", VK_ACCESS_TRANSFER_READ_BIT},
                 {"VK_ACCESS_TRANSFER_WRITE_BIT", VK_ACCESS_TRANSFER_WRITE_BIT},
                 {"VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT", VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT},
                 {"VK_BUFFER_USAGE_STORAGE_BUFFER_BIT", VK_BUFFER_USAGE_STORAGE_BUFFER_BIT},
                 {"VK_BUFFER_USAGE_TRANSFER_DST_BIT", VK_BUFFER_USAGE_TRANSFER_DST_BIT}};
    for (size_t i = 0; i < sizeof flags / sizeof flags[0]; i++) {
        if (strcmp(flags[i].name, name) == 0) {
            return flags[i].bit;
        }
    }
    fail("manifest.json: flag `%s` is not one this engine knows", name);
    return 0;
}

/* The flags an array of names of the manifest sets. */
static uint32_t flags_of(json_t *object, const char *key) {
    uint32_t flags = 0;
    size_t index;
    json_t *name;
    json_array_foreach(json_object_get(object, key), index, name) {
        if (!json_is_string(name)) {
            fail("manifest.json: `%s` holds a flag that is not a string", key);
        }
        flags |= flag_named(json_string_value(name));
    }
    return flags;
}

/* A barrier step of `frame.sequence`: stages and access masks as the manifest gives them. */
static void barrier(VkCommandBuffer commands, json_t *step) {
    VkMemoryBarrier memory = {0};
    memory.sType = VK_STRUCTURE_TYPE_MEMORY_BARRIER;
    memory.srcAccessMask = flags_of(step, "src_access");
    memory.dstAccessMask = flags_of(step, "dst_access");
    vkCmdPipelineBarrier(commands, flags_of(step, "src_stages"), flags_of(step, "dst_stages"), 0, 1, &memory, 0,
                         NULL, 0, NULL);
}

/* The histogram kernel `histogram_choice` gives for this device and settings. */
static const char *chosen_histogram(json_t *manifest, const Engine *engine, const Run *run) {
    VkPhysicalDeviceSubgroupProperties subgroup = {0};
    subgroup.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_SUBGROUP_PROPERTIES;
    VkPhysicalDeviceProperties2 properties = {0};
    properties.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2;
    properties.pNext = &subgroup;
    vkGetPhysicalDeviceProperties2(engine->physical_device, &properties);
    VkSubgroupFeatureFlags needed = VK_SUBGROUP_FEATURE_BASIC_BIT | VK_SUBGROUP_FEATURE_SHUFFLE_BIT;
    int shuffles = (subgroup.supportedStages & VK_SHADER_STAGE_COMPUTE_BIT) &&
                   (subgroup.supportedOperations & needed) == needed;
    const char *types[] = {"VK_PHYSICAL_DEVICE_TYPE_OTHER", "VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU",
                           "VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU", "VK_PHYSICAL_DEVICE_TYPE_VIRTUAL_GPU",
                           "VK_PHYSICAL_DEVICE_TYPE_CPU"};
    uint32_t type = (uint32_t)properties.properties.deviceType;
    const char *device_type = type < 5 ? types[type] : "unknown";
    json_t *inputs = json_pack("{s:s, s:b, s:I}", "device_type", device_type, "subgroup_shuffles", shuffles, "B",
                               (json_int_t)run->settings.block_size);
    size_t index, c;
    json_t *rule, *condition;
    const char *kernel = NULL;
    json_array_foreach(json_object_get(json_object_get(manifest, "histogram_choice"), "rules"), index, rule) {
        int holds = 1;
        json_array_foreach(json_object_get(rule, "when"), c, condition) {
            json_t *value = json_object_get(inputs, text_of(condition, "input"));
            json_t *wanted = json_object_get(condition, "value");
            const char *test = text_of(condition, "test");
            if (value == NULL) {
                fail("manifest.json: histogram_choice tests input `%s`, which this engine does not supply",
                     text_of(condition, "input"));
            }
            if (strcmp(test, "equals") == 0) {
                holds &= json_equal(value, wanted);
            } else if (strcmp(test, "at_most") == 0) {
                holds &= json_is_integer(value) && json_is_integer(wanted) &&
                         json_integer_value(value) <= json_integer_value(wanted);
            } else {
                fail("manifest.json: histogram_choice test `%s` is not one this engine knows", test);
            }
        }
        if (holds) {
            kernel = text_of(rule, "kernel");
            break;
        }
    }
    json_decref(inputs);
    if (kernel == NULL) {
        fail("manifest.json: no rule of histogram_choice holds");
    }
    return kernel;
}

/* The workgroups of `kernel`'s dispatch from its `dispatch` expressions. */
static void workgroups_of(const Kernel *kernel, const Variables *variables, uint32_t workgroups[3]) {
    json_t *dispatch = json_object_get(kernel->entry, "dispatch");
    if (json_array_size(dispatch) != 3) {
        fail("manifest.json: kernel `%s`: dispatch is not three expressions", text_of(kernel->entry, "name"));
    }
    for (int axis = 0; axis < 3; axis++) {
        workgroups[axis] = (uint32_t)evaluate(json_array_get(dispatch, (size_t)axis), variables);
    }
}

static void dispatch(VkCommandBuffer commands, const Kernel *kernel, const uint32_t workgroups[3]) {
    vkCmdBindPipeline(commands, VK_PIPELINE_BIND_POINT_COMPUTE, kernel->pipeline);
    vkCmdBindDescriptorSets(commands, VK_PIPELINE_BIND_POINT_COMPUTE, kernel->layout, 0, 1, &kernel->set, 0, NULL);
    vkCmdDispatch(commands, workgroups[0], workgroups[1], workgroups[2]);
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
    if (number_of(manifest, "schema_version") != SCHEMA_VERSION) {
        fail("%s: schema_version %llu; this engine reads version %d", path,
             (unsigned long long)number_of(manifest, "schema_version"), SCHEMA_VERSION);
    }
    Kernel kernels[3] = {{0}};
    const char *histogram =
        strcmp(run->histogram, "auto") == 0 ? chosen_histogram(manifest, engine, run) : run->histogram;
    if (strcmp(run->histogram, "auto") == 0) {
        fprintf(stderr, "histogram_choice: %s\n", histogram);
    }
    const char *names[3] = {histogram, "strata_select", "strata_resample"};
    for (int k = 0; k < 3; k++) {
        kernels[k].entry = kernel_named(manifest, names[k]);
        kernel_create(engine, run->package, &kernels[k]);
    }

    /* The buffers: the engine's from its files, the pass's own by the manifest's sizes. */
    EngineBuffers engine_buffers = engine_buffers_create(engine, run);
    uint32_t identity_payload = engine_buffers.payloads.buffer == VK_NULL_HANDLE;
    NamedBuffer buffers[MAX_BUFFERS];
    memset(buffers, 0, sizeof buffers);
    /* Sizes are the same for every frame (they use the largest grid, not the frame's). */
    Variables sizes = variables_of(manifest, engine, run, 0);
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
        uint64_t size = evaluate(json_object_get(json_object_get(entry, "size"), "expr"), &sizes);
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
            named->buffer = buffer_create(engine, size, flags_of(entry, "vulkan_usage"), contents);
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
    const char *stages[3] = {"histogram", "select", "resample"};
    for (uint32_t frame = 0; frame < run->frames; frame++) {
        StrataFrameParams params;
        char message[256];
        if (strata_frame_params(&run->settings, run->width, run->height, frame, run->seed, identity_payload,
                                max_workgroups, &params, message, sizeof message)) {
            fail("strata_frame_params: %s", message);
        }
        Variables variables = variables_of(manifest, engine, run, frame);
        /* The library's validation of what this engine is about to record (route 1 records
         * the kernels itself: nothing else checks its dispatches and buffer sizes). */
        StrataFrameCheck check;
        memset(&check, 0, sizeof check);
        check.settings = run->settings;
        check.width = run->width;
        check.height = run->height;
        check.frame = frame;
        check.previous_frame = frame == 0 ? STRATA_NO_FRAME : frame - 1;
        check.seed = run->seed;
        check.max_workgroups = max_workgroups;
        workgroups_of(&kernels[0], &variables, check.histogram_workgroups);
        workgroups_of(&kernels[1], &variables, check.pixel_workgroups);
        const struct {
            const char *name;
            uint64_t *bytes;
        } sized[] = {{"candidates", &check.buffer_bytes.candidates},
                     {"payloads", &check.buffer_bytes.payloads},
                     {"selections", &check.buffer_bytes.selections},
                     {"resample_inputs", &check.buffer_bytes.resample_inputs},
                     {"resampled", &check.buffer_bytes.resampled},
                     {"sorted_pixels", &check.buffer_bytes.sorted_pixels},
                     {"spans", &check.buffer_bytes.spans},
                     {"block_stats", &check.buffer_bytes.block_stats},
                     {"blue_noise", &check.buffer_bytes.blue_noise},
                     {"histogram_params", &check.buffer_bytes.histogram_params},
                     {"selection_params", &check.buffer_bytes.selection_params}};
        for (size_t b = 0; b < sizeof sized / sizeof sized[0]; b++) {
            *sized[b].bytes = buffer_named(buffers, buffer_count, sized[b].name)->buffer.size;
        }
        if (identity_payload) {
            check.buffer_bytes.payloads = 0;
        }
        StrataError check_error;
        if (strata_vk_check_frame(&check, &check_error) != STRATA_STATUS_OK) {
            fail("strata_vk_check_frame: %s", check_error.message);
        }
        VkCommandBuffer commands = commands_begin(engine);
        /* frame.sequence, step by step (the engine's own writes and reads are its files,
         * written and read between submissions). */
        json_t *step;
        json_array_foreach(json_object_get(json_object_get(manifest, "frame"), "sequence"), index, step) {
            const char *op = text_of(step, "op");
            if (strcmp(op, "barrier") == 0) {
                barrier(commands, step);
            } else if (strcmp(op, "update_uniform") == 0) {
                NamedBuffer *uniform = buffer_named(buffers, buffer_count, text_of(step, "buffer"));
                const char *value = text_of(step, "value");
                if (strcmp(value, "histogram") == 0 && uniform->buffer.size == sizeof params.histogram) {
                    vkCmdUpdateBuffer(commands, uniform->buffer.buffer, 0, sizeof params.histogram, &params.histogram);
                } else if (strcmp(value, "selection") == 0 && uniform->buffer.size == sizeof params.selection) {
                    vkCmdUpdateBuffer(commands, uniform->buffer.buffer, 0, sizeof params.selection, &params.selection);
                } else {
                    fail("manifest.json: update_uniform of `%s` with `%s`, which StrataFrameParams does not fit",
                         uniform->name, value);
                }
            } else if (strcmp(op, "dispatch") == 0) {
                const char *stage = text_of(step, "stage");
                int k = 0;
                while (k < 3 && strcmp(stages[k], stage) != 0) {
                    k++;
                }
                if (k == 3) {
                    fail("manifest.json: dispatch of stage `%s`, which this engine does not know", stage);
                }
                uint32_t workgroups[3];
                workgroups_of(&kernels[k], &variables, workgroups);
                const uint32_t *want = k == 0 ? params.histogram_workgroups : params.pixel_workgroups;
                if (memcmp(workgroups, want, sizeof workgroups) != 0) {
                    fail("frame %u: the manifest's dispatch of `%s` is %ux%ux%u, strata_frame_params's %ux%ux%u", frame,
                         stage, workgroups[0], workgroups[1], workgroups[2], want[0], want[1], want[2]);
                }
                dispatch(commands, &kernels[k], workgroups);
            } else if (strcmp(op, "engine_writes") != 0 && strcmp(op, "engine_reads") != 0) {
                fail("manifest.json: frame.sequence step `%s` is not one this engine knows", op);
            }
        }
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
