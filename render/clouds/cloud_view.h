/* A view's clouds (seed 001 section 5): the trace at block resolution and its temporal
 * reconstruction in the view's history (cloud_history.h), or the path-traced reference
 * (cloud_reference.h) in their place, then the resolve into what the composite blends over
 * the sky and the ground. The shared maps (weather, shadow, hemisphere averages) come in as
 * bindings: how they are built is cloud_renderer.c's. */
#ifndef SKYD_CLOUD_VIEW_H
#define SKYD_CLOUD_VIEW_H

#include <stdint.h>
#include <vulkan/vulkan.h>

#include "sky_passes.h"
#include "sky_renderer.h"

struct vk_context;
struct gpu_timer;
struct gpu_buffer;
struct gpu_image;
struct compute_resource;
struct cloud_frame;
struct cloud_views;

/* The views' passes, their histories and the reference (made with its first frame). */
struct cloud_views *cloud_views_create(struct vk_context *ctx);
void cloud_views_destroy(struct vk_context *ctx, struct cloud_views **views);

/* What a view's passes read of the frame's clouds and shared maps. */
struct cloud_view_inputs {
    const struct sky_render_clouds *clouds;
    /* The bindings the marching passes share (SKY_LAYOUT_CLOUD_MARCH), and the variant of the
     * trace that reads them: 1 when the moon lights the frame, plus 2 when the shown weather
     * map may hold towering clouds. */
    const struct compute_resource *march;
    int march_variant;
    const struct gpu_buffer *params, *env; /* the cloud block and the hemisphere averages */
    const struct gpu_image *shadow;        /* the shown shadow map */
    VkSampler repeat;
    /* Changes whenever the clouds other than the wind's drift or a shown map change: a
     * history that shows other clouds than a one-off view would now starts over. */
    uint32_t look;
    float precipitation_ceiling; /* the largest precipitation of the weather maps */
};

/* Records the view's trace, reconstruction and resolve (or the reference and the resolve)
 * and sets out->over_sky, out->over_ground and out->over_filled. Returns 0 or -1. */
int cloud_views_record(struct vk_context *ctx, struct cloud_views *views, VkCommandBuffer cmd,
                       struct gpu_timer *timer, const struct cloud_frame *f,
                       const struct cloud_view_inputs *in, struct sky_cloud_bindings *out);

/* The last reference frame's counters; -1 when there was none. */
int cloud_views_reference_stats(const struct cloud_views *views,
                                struct sky_render_reference_stats *out);

#endif
