/*
 * strata_frame.h: the per-frame parameters of strata's stratified selection (Salaün et
 * al., SIGGRAPH 2025, §4 and §5.3) in plain C11, header-only.
 *
 * What a frame needs before its dispatches: the two uniforms (StrataHistogramParams for
 * the histogram kernel, StrataSelectionParams for strata_select and strata_resample), the
 * workgroup counts of the three dispatches, and the sizes of the pass's buffers. Each
 * function here computes exactly what the pass plan of strata's kernels crate
 * (`pass_plan/frame.rs`, `pass_plan/buffers.rs`) computes, which strata's renderer and
 * strata-embed run (a test of the strata repository runs both on the same inputs and
 * compares the bytes); manifest.json says the same as formulas.
 *
 * Written by hand for the strata project (MIT OR Apache-2.0); strata.h, which it
 * includes, is generated from the Rust twins of the kernels' structs.
 */
#ifndef STRATA_FRAME_H
#define STRATA_FRAME_H

#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include "strata.h"

#ifdef __cplusplus
extern "C" {
#endif

/* The selection's settings (strata_kernels::selection::SelectionSettings). */
typedef struct StrataSelectionSettings {
    /* B: candidates are sorted per B x B block (4, 8, 16 or 32; the paper's 16). */
    uint32_t block_size;
    /* K: candidates selected per pixel besides its own (1 to 4; the paper's 4). */
    uint32_t candidates;
    /* A StrataSampler (the paper's STRATA_SAMPLER_ANTITHETIC). */
    uint32_t sampler;
    /* 1: candidates cluster by object id within a block (§4.3); 0: one cluster per block. */
    uint32_t masking;
    /* 1: the block grid moves by a new offset every frame (§5.3 limitations); 0: fixed. */
    uint32_t block_shift;
} StrataSelectionSettings;

/* The paper's settings: 16 x 16 blocks, 4 antithetic candidates with temporal blue noise,
 * object masking, no block shifting. */
static inline StrataSelectionSettings strata_default_settings(void) {
    StrataSelectionSettings settings = {16u, 4u, STRATA_SAMPLER_ANTITHETIC, 1u, 0u};
    return settings;
}

/* 0 if every field is in range; else 1 with a one-line message naming the field, its
 * value and what it may be (at most `size` bytes, NUL-terminated) in `message`, which may
 * be NULL. */
static inline int strata_check_settings(const StrataSelectionSettings *settings, char *message, size_t size) {
    const char *expected = NULL;
    const char *field = NULL;
    uint32_t value = 0;
    if (settings->block_size != 4u && settings->block_size != 8u && settings->block_size != 16u &&
        settings->block_size != 32u) {
        field = "block_size", value = settings->block_size, expected = "4, 8, 16 or 32";
    } else if (settings->candidates < 1u || settings->candidates > STRATA_MAX_SELECTED) {
        field = "candidates", value = settings->candidates, expected = "1 to 4";
    } else if (settings->sampler >= STRATA_SAMPLER_COUNT) {
        field = "sampler", value = settings->sampler, expected = "a StrataSampler (" STRATA_SAMPLER_RANGE ")";
    } else if (settings->masking > 1u) {
        field = "masking", value = settings->masking, expected = "0 or 1";
    } else if (settings->block_shift > 1u) {
        field = "block_shift", value = settings->block_shift, expected = "0 or 1";
    }
    if (field == NULL) {
        return 0;
    }
    if (message != NULL && size > 0) {
        snprintf(message, size, "%s = %u: must be %s", field, (unsigned)value, expected);
    }
    return 1;
}

/* The PCG hash of Jarzynski and Olano 2020 (WGSL `selection_hash`). */
static inline uint32_t strata_selection_hash(uint32_t v) {
    uint32_t state = v * 747796405u + 2891336453u;
    uint32_t word = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u;
    return (word >> 22u) ^ word;
}

/* The block-grid shift (sx, sy), each in 0..B, of frame `frame` of the render `seed`:
 * (0, 0) without block shifting, else a hash of the frame and the seed. */
static inline void strata_grid_shift(const StrataSelectionSettings *settings, uint32_t frame, uint32_t seed,
                                     uint32_t *shift_x, uint32_t *shift_y) {
    if (!settings->block_shift) {
        *shift_x = 0u;
        *shift_y = 0u;
        return;
    }
    uint32_t h = strata_selection_hash(frame ^ strata_selection_hash(seed ^ 0xb10cu));
    *shift_x = h % settings->block_size;
    *shift_y = (h >> 16u) % settings->block_size;
}

static inline uint32_t strata_div_ceil(uint32_t a, uint32_t b) { return a / b + (a % b != 0u ? 1u : 0u); }

/* Blocks of the largest grid any frame has: with block shifting one more row and column
 * (what the block_stats buffer must hold, sizeof(StrataBlockStats) each); 0 for settings
 * or an image strata_frame_params refuses. */
static inline uint64_t strata_max_blocks(const StrataSelectionSettings *settings, uint32_t width, uint32_t height) {
    if (strata_check_settings(settings, NULL, 0) || width == 0u || height == 0u ||
        (uint64_t)width * (uint64_t)height > 0xffffffffull) {
        return 0u;
    }
    uint64_t b = settings->block_size;
    uint64_t extra = settings->block_shift ? b - 1u : 0u;
    return ((width + extra + b - 1u) / b) * ((height + extra + b - 1u) / b);
}

/* Everything one frame's dispatches need. */
typedef struct StrataFrameParams {
    /* The histogram kernel's uniform (binding `params` of block_histogram*). */
    StrataHistogramParams histogram;
    /* strata_select's and strata_resample's uniform (their binding `params`). */
    StrataSelectionParams selection;
    /* Workgroups of the histogram dispatch (x, y, z). */
    uint32_t histogram_workgroups[3];
    /* Workgroups of the strata_select and strata_resample dispatches (x, y, z). */
    uint32_t pixel_workgroups[3];
} StrataFrameParams;

/* The parameters of frame `frame` of the render `seed` over a width x height image.
 * `identity_payload`: 1 when the engine binds no payloads buffer (a pixel's payload is its
 * index). `max_workgroups`: the device's smallest maxComputeWorkGroupCount component.
 * Returns 0, or 1 with a one-line message (as strata_check_settings) for bad settings or
 * an image of 0 pixels or more than 2^32 - 1. */
static inline int strata_frame_params(const StrataSelectionSettings *settings, uint32_t width, uint32_t height,
                                      uint32_t frame, uint32_t seed, uint32_t identity_payload,
                                      uint32_t max_workgroups, StrataFrameParams *out, char *message, size_t size) {
    if (strata_check_settings(settings, message, size)) {
        return 1;
    }
    if (width == 0u || height == 0u || (uint64_t)width * (uint64_t)height > 0xffffffffull) {
        if (message != NULL && size > 0) {
            snprintf(message, size, "image size %ux%u: each side at least 1, at most 2^32 - 1 pixels in all",
                     (unsigned)width, (unsigned)height);
        }
        return 1;
    }
    uint32_t b = settings->block_size;
    uint32_t shift_x, shift_y;
    strata_grid_shift(settings, frame, seed, &shift_x, &shift_y);
    uint32_t blocks_x = strata_div_ceil(width + shift_x, b);
    uint32_t blocks_y = strata_div_ceil(height + shift_y, b);
    uint32_t blocks_per_workgroup = STRATA_HISTOGRAM_SLOTS_PER_WORKGROUP / (b * b);
    uint32_t total = strata_div_ceil(blocks_x * blocks_y, blocks_per_workgroup);
    uint32_t x = total < (max_workgroups > 0u ? max_workgroups : 1u) ? total : (max_workgroups > 0u ? max_workgroups : 1u);
    uint32_t log2_b = 0u;
    while ((1u << log2_b) < b) {
        log2_b++;
    }
    StrataFrameParams params;
    memset(&params, 0, sizeof params);
    params.histogram.width = width;
    params.histogram.height = height;
    params.histogram.block_size = b;
    params.histogram.log2_block_size = log2_b;
    params.histogram.blocks_x = blocks_x;
    params.histogram.blocks_y = blocks_y;
    params.histogram.workgroups_x = x;
    params.histogram.shift_x = shift_x;
    params.histogram.shift_y = shift_y;
    params.histogram.masking = settings->masking ? 1u : 0u;
    params.selection.width = width;
    params.selection.height = height;
    params.selection.frame = frame;
    params.selection.seed = seed;
    params.selection.candidates = settings->candidates;
    params.selection.sampler = settings->sampler;
    params.selection.identity_payload = identity_payload ? 1u : 0u;
    params.histogram_workgroups[0] = x;
    params.histogram_workgroups[1] = strata_div_ceil(total, x);
    params.histogram_workgroups[2] = 1u;
    params.pixel_workgroups[0] = strata_div_ceil(width, STRATA_SELECT_WORKGROUP_SIZE_X);
    params.pixel_workgroups[1] = strata_div_ceil(height, STRATA_SELECT_WORKGROUP_SIZE_Y);
    params.pixel_workgroups[2] = 1u;
    *out = params;
    return 0;
}

#ifdef __cplusplus
}
#endif

#endif /* STRATA_FRAME_H */
