/*
 * main.c: the C example of strata's kernel package: an engine in C11 runs the stratified
 * selection pass over several frames, by route 1 (the package alone: manifest.json and
 * SPIR-V, no binding number in this code) or route 2 (the strata_vk library), and writes
 * the pass's outputs for comparison.
 *
 *   strata_c ROUTE INPUTS OUTPUTS [--package DIR] [--histogram NAME] [--width W]
 *            [--height H] [--block-size B] [--candidates K] [--sampler ID] [--masking 0|1]
 *            [--block-shift 0|1] [--seed S] [--frames N]
 *
 * ROUTE is `package` or `library`; INPUTS a folder of the engine's input files (routes.h),
 * or `-` for generated demo inputs. Build (after `cargo xtask export --out PKG` and
 * `cargo build -p strata-vk`):
 *
 *   cc -std=c11 -Wall -Wextra -Werror -I PKG/include examples/c/main.c examples/c/engine.c \
 *      examples/c/route_package.c examples/c/route_library.c -o strata_c \
 *      -lvulkan -ljansson -L target/debug -lstrata_vk
 *
 * Part of strata (MIT OR Apache-2.0).
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "routes.h"

/* The value of a numeric option, or exits naming it. */
static uint32_t number(const char *option, const char *text) {
    char *end = NULL;
    unsigned long value = strtoul(text, &end, 10);
    if (end == text || *end != 0 || value > 0xffffffffUL) {
        fail("%s %s: expected a whole number from 0 to 4294967295", option, text);
    }
    return (uint32_t)value;
}

int main(int argc, char **argv) {
    if (argc < 4) {
        fail("usage: %s package|library INPUTS OUTPUTS [options] (see main.c)", argv[0]);
    }
    Run run = {0};
    run.width = 50;
    run.height = 27;
    run.settings = strata_default_settings();
    run.frames = 4;
    run.inputs = argv[2];
    run.outputs = argv[3];
    run.histogram = "block_histogram";
    for (int i = 4; i < argc; i += 2) {
        if (i + 1 >= argc) {
            fail("%s: needs a value", argv[i]);
        }
        const char *option = argv[i], *value = argv[i + 1];
        if (strcmp(option, "--package") == 0) {
            run.package = value;
        } else if (strcmp(option, "--histogram") == 0) {
            run.histogram = value;
        } else if (strcmp(option, "--width") == 0) {
            run.width = number(option, value);
        } else if (strcmp(option, "--height") == 0) {
            run.height = number(option, value);
        } else if (strcmp(option, "--block-size") == 0) {
            run.settings.block_size = number(option, value);
        } else if (strcmp(option, "--candidates") == 0) {
            run.settings.candidates = number(option, value);
        } else if (strcmp(option, "--sampler") == 0) {
            run.settings.sampler = number(option, value);
        } else if (strcmp(option, "--masking") == 0) {
            run.settings.masking = number(option, value);
        } else if (strcmp(option, "--block-shift") == 0) {
            run.settings.block_shift = number(option, value);
        } else if (strcmp(option, "--seed") == 0) {
            run.seed = number(option, value);
        } else if (strcmp(option, "--frames") == 0) {
            run.frames = number(option, value);
        } else {
            fail("unknown option %s", option);
        }
    }
    char message[256];
    if (strata_check_settings(&run.settings, message, sizeof message)) {
        fail("settings: %s", message);
    }
    if (run.width == 0 || run.height == 0) {
        fail("--width %u --height %u: the image needs at least one pixel", run.width, run.height);
    }
    Engine engine;
    engine_open(&engine);
    if (strcmp(argv[1], "package") == 0) {
        if (run.package == NULL) {
            fail("route package needs --package DIR (a folder written by cargo xtask export)");
        }
        route_package(&engine, &run);
    } else if (strcmp(argv[1], "library") == 0) {
        route_library(&engine, &run);
    } else {
        fail("route `%s`: expected package or library", argv[1]);
    }
    engine_close(&engine);
    printf("%s: %u frames of %ux%u written to %s\n", argv[1], run.frames, run.width, run.height, run.outputs);
    return 0;
}

/* Demo inputs (INPUTS is `-`): candidates of a few objects in vertical bands with
 * luminance keys from a hash, payloads = pixel index (no payloads buffer), weights 1. */
static EngineBuffers demo_buffers(Engine *engine, const Run *run) {
    EngineBuffers buffers = {0};
    uint64_t pixels = (uint64_t)run->width * run->height;
    StrataCandidate *candidates = malloc(pixels * sizeof *candidates);
    StrataResampleInput *weights = calloc(pixels, sizeof *weights);
    if (candidates == NULL || weights == NULL) {
        fail("out of memory for %llu pixels", (unsigned long long)pixels);
    }
    for (uint64_t p = 0; p < pixels; p++) {
        candidates[p].key = (float)(strata_selection_hash((uint32_t)p) % 1000u) / 100.0f;
        candidates[p].object_id = (uint32_t)(p % run->width) / 8u;
        for (int slot = 0; slot < 4; slot++) {
            weights[p].weights[slot] = 1.0f;
            weights[p].targets[slot] = 1.0f;
        }
        weights[p].canonical_weight = 1.0f;
        weights[p].canonical_target = 1.0f;
        weights[p].canonical_payload = (uint32_t)p;
    }
    buffers.candidates = buffer_create(engine, pixels * sizeof *candidates, 0, candidates);
    buffers.resample_inputs = buffer_create(engine, pixels * sizeof *weights, 0, weights);
    buffers.selections = buffer_create(engine, pixels * sizeof(StrataSelectedCandidates), 0, NULL);
    buffers.resampled = buffer_create(engine, pixels * sizeof(StrataResampleOutput), 0, NULL);
    free(candidates);
    free(weights);
    return buffers;
}

EngineBuffers engine_buffers_create(Engine *engine, const Run *run) {
    if (strcmp(run->inputs, "-") == 0) {
        return demo_buffers(engine, run);
    }
    EngineBuffers buffers = {0};
    uint64_t pixels = (uint64_t)run->width * run->height;
    char path[4096];
    size_t size = 0;
    snprintf(path, sizeof path, "%s/candidates.bin", run->inputs);
    void *bytes = file_read(path, &size);
    if (size != pixels * sizeof(StrataCandidate)) {
        fail("%s: %zu bytes, expected %llu (StrataCandidate per pixel)", path, size,
             (unsigned long long)(pixels * sizeof(StrataCandidate)));
    }
    buffers.candidates = buffer_create(engine, size, 0, bytes);
    free(bytes);
    snprintf(path, sizeof path, "%s/payloads.bin", run->inputs);
    FILE *probe = fopen(path, "rb");
    if (probe != NULL) {
        fclose(probe);
        bytes = file_read(path, &size);
        if (size != pixels * sizeof(uint32_t)) {
            fail("%s: %zu bytes, expected a uint32_t per pixel", path, size);
        }
        buffers.payloads = buffer_create(engine, size, 0, bytes);
        free(bytes);
    }
    snprintf(path, sizeof path, "%s/resample_inputs.bin", run->inputs);
    bytes = file_read(path, &size);
    if (size != pixels * sizeof(StrataResampleInput)) {
        fail("%s: %zu bytes, expected a StrataResampleInput per pixel", path, size);
    }
    buffers.resample_inputs = buffer_create(engine, size, 0, bytes);
    free(bytes);
    buffers.selections = buffer_create(engine, pixels * sizeof(StrataSelectedCandidates), 0, NULL);
    buffers.resampled = buffer_create(engine, pixels * sizeof(StrataResampleOutput), 0, NULL);
    return buffers;
}

void engine_buffers_destroy(Engine *engine, EngineBuffers *buffers) {
    buffer_destroy(engine, &buffers->candidates);
    if (buffers->payloads.buffer != VK_NULL_HANDLE) {
        buffer_destroy(engine, &buffers->payloads);
    }
    buffer_destroy(engine, &buffers->selections);
    buffer_destroy(engine, &buffers->resample_inputs);
    buffer_destroy(engine, &buffers->resampled);
}

void engine_buffers_write(const EngineBuffers *buffers, const Run *run, uint32_t frame) {
    char path[4096];
    snprintf(path, sizeof path, "%s/selections_%u.bin", run->outputs, (unsigned)frame);
    file_write(path, buffers->selections.mapped, (size_t)buffers->selections.size);
    snprintf(path, sizeof path, "%s/resampled_%u.bin", run->outputs, (unsigned)frame);
    file_write(path, buffers->resampled.mapped, (size_t)buffers->resampled.size);
}
