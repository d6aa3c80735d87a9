/*
 * engine.c: the small Vulkan engine of the C example (engine.h).
 *
 * Part of strata (MIT OR Apache-2.0).
 */
#include "engine.h"

#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

_Noreturn void fail(const char *what, ...) {
    va_list arguments;
    va_start(arguments, what);
    fprintf(stderr, "error: ");
    vfprintf(stderr, what, arguments);
    fprintf(stderr, "\n");
    va_end(arguments);
    exit(1);
}

void check_vk(VkResult result, const char *call) {
    if (result != VK_SUCCESS) {
        fail("%s failed: VkResult %d", call, (int)result);
    }
}

void engine_open(Engine *engine) {
    memset(engine, 0, sizeof *engine);
    VkApplicationInfo application = {0};
    application.sType = VK_STRUCTURE_TYPE_APPLICATION_INFO;
    application.pApplicationName = "strata C example";
    application.apiVersion = VK_API_VERSION_1_1;
    VkInstanceCreateInfo instance_info = {0};
    instance_info.sType = VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO;
    instance_info.pApplicationInfo = &application;
    check_vk(vkCreateInstance(&instance_info, NULL, &engine->instance), "vkCreateInstance");

    uint32_t count = 0;
    check_vk(vkEnumeratePhysicalDevices(engine->instance, &count, NULL), "vkEnumeratePhysicalDevices");
    if (count == 0) {
        fail("no Vulkan device (install a driver, e.g. Mesa's lavapipe: mesa-vulkan-drivers)");
    }
    VkPhysicalDevice *devices = calloc(count, sizeof *devices);
    if (devices == NULL) {
        fail("out of memory listing %u Vulkan devices", count);
    }
    check_vk(vkEnumeratePhysicalDevices(engine->instance, &count, devices), "vkEnumeratePhysicalDevices");
    for (uint32_t d = 0; d < count && engine->physical_device == VK_NULL_HANDLE; d++) {
        VkPhysicalDeviceProperties device_properties;
        vkGetPhysicalDeviceProperties(devices[d], &device_properties);
        if (device_properties.apiVersion < VK_API_VERSION_1_1) {
            continue; /* the kernels' SPIR-V 1.3 needs Vulkan 1.1 */
        }
        uint32_t families = 0;
        vkGetPhysicalDeviceQueueFamilyProperties(devices[d], &families, NULL);
        VkQueueFamilyProperties *properties = calloc(families, sizeof *properties);
        if (properties == NULL) {
            fail("out of memory listing %u queue families", families);
        }
        vkGetPhysicalDeviceQueueFamilyProperties(devices[d], &families, properties);
        for (uint32_t f = 0; f < families; f++) {
            if (properties[f].queueFlags & VK_QUEUE_COMPUTE_BIT) {
                engine->physical_device = devices[d];
                engine->queue_family = f;
                break;
            }
        }
        free(properties);
    }
    free(devices);
    if (engine->physical_device == VK_NULL_HANDLE) {
        fail("no Vulkan 1.1 device with a compute queue");
    }
    VkPhysicalDeviceProperties properties;
    vkGetPhysicalDeviceProperties(engine->physical_device, &properties);
    engine->limits = properties.limits;
    vkGetPhysicalDeviceMemoryProperties(engine->physical_device, &engine->memory);

    float priority = 1.0f;
    VkDeviceQueueCreateInfo queue_info = {0};
    queue_info.sType = VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO;
    queue_info.queueFamilyIndex = engine->queue_family;
    queue_info.queueCount = 1;
    queue_info.pQueuePriorities = &priority;
    VkDeviceCreateInfo device_info = {0};
    device_info.sType = VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO;
    device_info.queueCreateInfoCount = 1;
    device_info.pQueueCreateInfos = &queue_info;
    check_vk(vkCreateDevice(engine->physical_device, &device_info, NULL, &engine->device), "vkCreateDevice");
    vkGetDeviceQueue(engine->device, engine->queue_family, 0, &engine->queue);
    VkCommandPoolCreateInfo pool_info = {0};
    pool_info.sType = VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO;
    pool_info.queueFamilyIndex = engine->queue_family;
    check_vk(vkCreateCommandPool(engine->device, &pool_info, NULL, &engine->command_pool), "vkCreateCommandPool");
}

void engine_close(Engine *engine) {
    vkDestroyCommandPool(engine->device, engine->command_pool, NULL);
    vkDestroyDevice(engine->device, NULL);
    vkDestroyInstance(engine->instance, NULL);
}

Buffer buffer_create(Engine *engine, VkDeviceSize size, VkBufferUsageFlags usage, const void *contents) {
    Buffer buffer = {0};
    buffer.size = size;
    VkBufferCreateInfo info = {0};
    info.sType = VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO;
    info.size = size;
    info.usage = usage | VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT |
                 VK_BUFFER_USAGE_TRANSFER_DST_BIT;
    info.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
    check_vk(vkCreateBuffer(engine->device, &info, NULL, &buffer.buffer), "vkCreateBuffer");
    VkMemoryRequirements requirements;
    vkGetBufferMemoryRequirements(engine->device, buffer.buffer, &requirements);
    VkMemoryPropertyFlags wanted = VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;
    uint32_t type = UINT32_MAX;
    for (uint32_t t = 0; t < engine->memory.memoryTypeCount; t++) {
        if ((requirements.memoryTypeBits & (1u << t)) &&
            (engine->memory.memoryTypes[t].propertyFlags & wanted) == wanted) {
            type = t;
            break;
        }
    }
    if (type == UINT32_MAX) {
        fail("no host-visible, coherent memory type for a buffer");
    }
    VkMemoryAllocateInfo allocate = {0};
    allocate.sType = VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO;
    allocate.allocationSize = requirements.size;
    allocate.memoryTypeIndex = type;
    check_vk(vkAllocateMemory(engine->device, &allocate, NULL, &buffer.memory), "vkAllocateMemory");
    check_vk(vkBindBufferMemory(engine->device, buffer.buffer, buffer.memory, 0), "vkBindBufferMemory");
    check_vk(vkMapMemory(engine->device, buffer.memory, 0, VK_WHOLE_SIZE, 0, &buffer.mapped), "vkMapMemory");
    if (contents != NULL) {
        memcpy(buffer.mapped, contents, (size_t)size);
    } else {
        memset(buffer.mapped, 0, (size_t)size);
    }
    return buffer;
}

void buffer_destroy(Engine *engine, Buffer *buffer) {
    vkUnmapMemory(engine->device, buffer->memory);
    vkDestroyBuffer(engine->device, buffer->buffer, NULL);
    vkFreeMemory(engine->device, buffer->memory, NULL);
    memset(buffer, 0, sizeof *buffer);
}

VkCommandBuffer commands_begin(Engine *engine) {
    VkCommandBufferAllocateInfo allocate = {0};
    allocate.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO;
    allocate.commandPool = engine->command_pool;
    allocate.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
    allocate.commandBufferCount = 1;
    VkCommandBuffer commands;
    check_vk(vkAllocateCommandBuffers(engine->device, &allocate, &commands), "vkAllocateCommandBuffers");
    VkCommandBufferBeginInfo begin = {0};
    begin.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO;
    begin.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
    check_vk(vkBeginCommandBuffer(commands, &begin), "vkBeginCommandBuffer");
    return commands;
}

void commands_submit(Engine *engine, VkCommandBuffer commands) {
    /* The host reads the results after the queue is idle: make the device's writes
     * visible to it. */
    VkMemoryBarrier to_host = {0};
    to_host.sType = VK_STRUCTURE_TYPE_MEMORY_BARRIER;
    to_host.srcAccessMask = VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_WRITE_BIT;
    to_host.dstAccessMask = VK_ACCESS_HOST_READ_BIT;
    vkCmdPipelineBarrier(commands, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, VK_PIPELINE_STAGE_HOST_BIT, 0, 1, &to_host, 0,
                         NULL, 0, NULL);
    check_vk(vkEndCommandBuffer(commands), "vkEndCommandBuffer");
    VkSubmitInfo submit = {0};
    submit.sType = VK_STRUCTURE_TYPE_SUBMIT_INFO;
    submit.commandBufferCount = 1;
    submit.pCommandBuffers = &commands;
    check_vk(vkQueueSubmit(engine->queue, 1, &submit, VK_NULL_HANDLE), "vkQueueSubmit");
    check_vk(vkQueueWaitIdle(engine->queue), "vkQueueWaitIdle");
    vkFreeCommandBuffers(engine->device, engine->command_pool, 1, &commands);
}

void *file_read(const char *path, size_t *size) {
    FILE *file = fopen(path, "rb");
    if (file == NULL) {
        fail("%s: cannot open", path);
    }
    if (fseek(file, 0, SEEK_END) != 0) {
        fail("%s: cannot seek", path);
    }
    long length = ftell(file);
    if (length < 0 || fseek(file, 0, SEEK_SET) != 0) {
        fail("%s: cannot tell its size", path);
    }
    void *bytes = malloc((size_t)length + 1);
    if (bytes == NULL) {
        fail("%s: out of memory for %ld bytes", path, length);
    }
    if (fread(bytes, 1, (size_t)length, file) != (size_t)length) {
        fail("%s: cannot read", path);
    }
    fclose(file);
    ((char *)bytes)[length] = 0;
    *size = (size_t)length;
    return bytes;
}

void file_write(const char *path, const void *bytes, size_t size) {
    FILE *file = fopen(path, "wb");
    if (file == NULL || fwrite(bytes, 1, size, file) != size || fclose(file) != 0) {
        fail("%s: cannot write", path);
    }
}
