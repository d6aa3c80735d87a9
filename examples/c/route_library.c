/*
 * route_library.c: route 2 of the C example: the pass through the strata_vk library's C
 * ABI (strata_vk.h) on this engine's device, buffers and command buffers.
 *
 * Part of strata (MIT OR Apache-2.0).
 */
#include <stdio.h>

#include "routes.h"
#include "strata_vk.h"

/* Exits with the library's message unless `status` is STRATA_STATUS_OK. */
static void check_strata(StrataStatus status, const StrataError *error, const char *call) {
    if (status != STRATA_STATUS_OK) {
        fail("%s: status %d: %s", call, (int)status, error->message);
    }
}

static StrataVkBufferSlice slice_of(const Buffer *buffer) {
    StrataVkBufferSlice slice = {buffer->buffer, 0, buffer->size};
    return slice;
}

void route_library(Engine *engine, const Run *run) {
    StrataError error = {0};
    StrataVkDevice device = {0};
    device.get_instance_proc_addr = vkGetInstanceProcAddr;
    device.instance = engine->instance;
    device.physical_device = engine->physical_device;
    device.device = engine->device;
    device.shader_zero_initialize_workgroup_memory = 0;
    StrataVkPass *pass = NULL;
    check_strata(strata_vk_create(STRATA_VERSION, &device, &run->settings, run->width, run->height, &pass, &error), &error,
                 "strata_vk_create");
    check_strata(strata_vk_set_seed(pass, run->seed, &error), &error, "strata_vk_set_seed");

    EngineBuffers buffers = engine_buffers_create(engine, run);
    StrataVkBuffers bound = {0};
    bound.candidates = slice_of(&buffers.candidates);
    if (buffers.payloads.buffer != VK_NULL_HANDLE) {
        bound.payloads = slice_of(&buffers.payloads);
    }
    bound.selections = slice_of(&buffers.selections);
    bound.resample_inputs = slice_of(&buffers.resample_inputs);
    bound.resampled = slice_of(&buffers.resampled);
    StrataVkBindings *bindings = NULL;
    check_strata(strata_vk_bind(pass, &bound, &bindings, &error), &error, "strata_vk_bind");

    for (uint32_t frame = 0; frame < run->frames; frame++) {
        VkCommandBuffer commands = commands_begin(engine);
        check_strata(strata_vk_record_selection(pass, bindings, commands, frame, &error), &error,
                     "strata_vk_record_selection");
        check_strata(strata_vk_record_resampling(pass, bindings, commands, &error), &error,
                     "strata_vk_record_resampling");
        commands_submit(engine, commands);
        engine_buffers_write(&buffers, run, frame);
    }

    check_strata(strata_vk_destroy_bindings(pass, bindings, &error), &error, "strata_vk_destroy_bindings");
    check_strata(strata_vk_destroy(pass, &error), &error, "strata_vk_destroy");
    engine_buffers_destroy(engine, &buffers);
}
