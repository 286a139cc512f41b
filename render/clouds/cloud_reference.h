/* The clouds' path-traced reference (shaders/cloud_pathtrace.comp): in place of the trace and
 * the reconstruction, every pixel of a view's cloud image is path traced through the same
 * density and phase, sky_render_clouds.reference_spp samples summed over dispatches of a few
 * samples each, into the image the resolve composites. */
#ifndef SKYD_CLOUD_REFERENCE_H
#define SKYD_CLOUD_REFERENCE_H

#include <vulkan/vulkan.h>

#include "sky_renderer.h"

struct vk_context;
struct compute_resource;
struct cloud_frame;
struct cloud_history_entry;
struct cloud_reference;

struct cloud_reference *cloud_reference_create(struct vk_context *ctx);
void cloud_reference_destroy(struct vk_context *ctx, struct cloud_reference **ref);

/* Records the dispatches that path trace `spp` samples per pixel of the view into e's latest
 * colour image (e's trace images hold the sums: e is a history entry of the output's size
 * with a block of 1). `march`: the bindings the marching passes share (SKY_LAYOUT_CLOUD_MARCH).
 * `precipitation_ceiling`: the largest precipitation of the weather map. Returns 0 or -1. */
int cloud_reference_record(struct vk_context *ctx, struct cloud_reference *ref,
                           const struct compute_resource *march, VkCommandBuffer cmd,
                           const struct cloud_frame *f, struct cloud_history_entry *e, uint32_t spp,
                           uint32_t seed, float precipitation_ceiling);

/* The counters of the last recorded reference, once its frame has completed. */
void cloud_reference_stats(const struct cloud_reference *ref,
                           struct sky_render_reference_stats *out);

#endif
