/*
 * engine.h: the small Vulkan engine both routes of the C example run on, as an engine in C
 * would have it: an instance and a device with a compute queue, host-visible buffers, one
 * command buffer submitted and waited for, and files read and written whole.
 *
 * Part of strata (MIT OR Apache-2.0). Written for strata's examples and tests.
 */
#ifndef STRATA_EXAMPLE_ENGINE_H
#define STRATA_EXAMPLE_ENGINE_H

#include <stddef.h>
#include <stdint.h>
#include <vulkan/vulkan.h>

typedef struct Engine {
    VkInstance instance;
    VkPhysicalDevice physical_device;
    VkDevice device;
    VkQueue queue;
    uint32_t queue_family;
    VkCommandPool command_pool;
    VkPhysicalDeviceMemoryProperties memory;
    VkPhysicalDeviceLimits limits;
} Engine;

/* A buffer in host-visible, coherent memory, mapped for its whole life. */
typedef struct Buffer {
    VkBuffer buffer;
    VkDeviceMemory memory;
    VkDeviceSize size;
    void *mapped;
} Buffer;

/* Prints "error: WHAT" (printf-style) and exits with status 1. */
#if defined(__GNUC__)
__attribute__((format(printf, 1, 2)))
#endif
_Noreturn void fail(const char *what, ...);

/* Exits with a message naming `call` unless `result` is VK_SUCCESS. */
void check_vk(VkResult result, const char *call);

/* An instance (Vulkan 1.1), the first physical device with a compute queue, a device. */
void engine_open(Engine *engine);
void engine_close(Engine *engine);

/* A storage (and transfer) buffer of `size` bytes, filled with `contents` if not NULL and
 * with zeros otherwise; `usage` is added to STORAGE | TRANSFER_SRC | TRANSFER_DST. */
Buffer buffer_create(Engine *engine, VkDeviceSize size, VkBufferUsageFlags usage, const void *contents);
void buffer_destroy(Engine *engine, Buffer *buffer);

/* A primary command buffer in the recording state. */
VkCommandBuffer commands_begin(Engine *engine);
/* Ends, submits and waits for `commands`, then frees it. */
void commands_submit(Engine *engine, VkCommandBuffer commands);

/* The whole file; exits naming it if it cannot be read. `size` gets its length. */
void *file_read(const char *path, size_t *size);
/* Writes `size` bytes; exits naming the file on failure. */
void file_write(const char *path, const void *bytes, size_t size);

#endif
