/* What every cloud pass records with, whichever file owns it (cloud_renderer.c: the shared
 * maps; cloud_view.c: a view's trace, reconstruction and resolve; cloud_reference.c: the path
 * tracer): the shorthands of their descriptors, their 2D workgroup, the constructors of their
 * bindings and the marching passes' shared ones. */
#ifndef SKYD_CLOUD_PASSES_H
#define SKYD_CLOUD_PASSES_H

#include <stdbool.h>
#include <stdint.h>

#include "cloud_frame.h"
#include "cloud_layouts.h"
#include "cloud_shared.h"
#include "compute_pass.h"
#include "sky_passes.h"
#include "vk_resources.h"

/* 1 when the moon lights this frame's clouds (the frame uniforms' flag), else 0. */
static inline int moonlit(const struct cloud_frame *f)
{
    return f->frame->moon_illuminance.w > 0.5f ? 1 : 0;
}

#define SPIRV(name) .spirv = name, .spirv_bytes = sizeof(name)
/* clang-format off */
#define MARCH_SPEC(moonlit, towering)                                                      \
    .spec_count = SKY_CLOUD_CONST_TOWERING + 1,                                            \
    .spec_values = { [SKY_CLOUD_CONST_MOONLIT] = moonlit, [SKY_CLOUD_CONST_TOWERING] = towering }
/* clang-format on */
#define ROWS_PUSH .push_constant_bytes = sizeof(struct sky_cloud_rows_push)

/* The workgroup of the 2D passes. */
static const uint32_t local_2d[3] = { SKY_CLOUD_LOCAL, SKY_CLOUD_LOCAL, 1 };

static inline struct compute_resource tex(const struct gpu_image *image, VkSampler sampler)
{
    return (struct compute_resource){ .image = image, .sampler = sampler };
}

static inline struct compute_resource img(const struct gpu_image *image)
{
    return (struct compute_resource){ .image = image };
}

static inline struct compute_resource buf(const struct gpu_buffer *buffer)
{
    return (struct compute_resource){ .buffer = buffer };
}

/* The bindings the marching passes share (SKY_LAYOUT_CLOUD_MARCH) come first in each of their
 * layouts, at indices 0 to CLOUD_MARCH_BINDINGS - 1. */
#define CLOUD_MARCH_BINDINGS SKY_LAYOUT_COUNT(SKY_LAYOUT_CLOUD_MARCH)
_Static_assert(SKY_CLOUD_MARCH_SUN_COLUMNS == CLOUD_MARCH_BINDINGS - 1,
               "the march bindings are indices 0 to count - 1");

/* Copies them into the front of a marching pass's bindings. */
static inline void cloud_march_copy(const struct compute_resource *march,
                                    struct compute_resource *r)
{
    for (int i = 0; i < CLOUD_MARCH_BINDINGS; i++)
        r[i] = march[i];
}

#endif
