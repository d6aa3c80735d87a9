/*
 * routes.h: what both routes of the C example are given and what they write.
 *
 * A run: a width x height image, the selection settings, a seed, a number of frames; the
 * engine's inputs read from files (`candidates.bin`: StrataCandidate per pixel;
 * `payloads.bin`, optional: uint32_t per pixel; `resample_inputs.bin`: StrataResampleInput
 * per pixel); per frame f the pass's outputs written as `selections_F.bin` and
 * `resampled_F.bin` (F = f, in decimal) into the output folder.
 *
 * Part of strata (MIT OR Apache-2.0).
 */
#ifndef STRATA_EXAMPLE_ROUTES_H
#define STRATA_EXAMPLE_ROUTES_H

#include <stdint.h>

#include "engine.h"
#include "strata_frame.h"

typedef struct Run {
    uint32_t width;
    uint32_t height;
    StrataSelectionSettings settings;
    uint32_t seed;
    uint32_t frames;
    /* Folder of the engine's input files and of the outputs. */
    const char *inputs;
    const char *outputs;
    /* Route 1: the package's folder and the histogram kernel to run (its manifest name). */
    const char *package;
    const char *histogram;
} Run;

/* The engine's buffers, made from the input files. */
typedef struct EngineBuffers {
    Buffer candidates;
    /* .buffer is VK_NULL_HANDLE without payloads.bin. */
    Buffer payloads;
    Buffer selections;
    Buffer resample_inputs;
    Buffer resampled;
} EngineBuffers;

EngineBuffers engine_buffers_create(Engine *engine, const Run *run);
void engine_buffers_destroy(Engine *engine, EngineBuffers *buffers);
/* Writes frame `frame`'s selections and resampled records into the output folder. */
void engine_buffers_write(const EngineBuffers *buffers, const Run *run, uint32_t frame);

/* Route 1: reads only the package (manifest.json, SPIR-V, the headers' formulas, the
 * blue-noise file) and makes its pipelines and descriptor sets from the manifest. */
void route_package(Engine *engine, const Run *run);

/* Route 2: the strata_vk library's C ABI (strata_vk.h). */
void route_library(Engine *engine, const Run *run);

#endif
