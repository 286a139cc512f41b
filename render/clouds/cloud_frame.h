/* What one view's frame gives the cloud passes: the sky's resources and uniforms, the view's
 * size, history and whether it is a stream (sky_renderer.c fills it). */
#ifndef SKYD_CLOUD_FRAME_H
#define SKYD_CLOUD_FRAME_H

#include <stdbool.h>
#include <stdint.h>

#include "sky_passes.h"

struct cloud_frame {
    struct sky_pass_resources sky;
    const struct sky_frame_uniforms *frame;
    double bottom_radius_km;
    uint32_t width, height;
    uint64_t history_key;
    double now_s; /* monotonic: histories idle for CLOUD_HISTORY_IDLE_S are released */
    bool live;    /* a stream: a new history starts converging from its first frame */
    /* Output rows [first, end) that may see the ground, or NULL: none (sky_uniforms.h). */
    const uint32_t *ground_rows;
};

#endif
