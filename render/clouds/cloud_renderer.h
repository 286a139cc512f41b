/* The cloud passes of a frame (seed 001 section 5): noise volumes, the amortized weather map,
 * cloud shadow map and hemisphere averages, the per-view trace at block resolution and its
 * temporal reconstruction. Produces what the composite needs (sky_passes_bind_clouds). */
#ifndef SKYD_CLOUD_RENDERER_H
#define SKYD_CLOUD_RENDERER_H

#include <stdbool.h>
#include <stdint.h>
#include <vulkan/vulkan.h>

#include "cloud_frame.h"
#include "sky_passes.h"
#include "sky_renderer.h"

struct vk_context;
struct gpu_timer;
struct cloud_renderer;

/* cache_dir: where the noise volumes are kept between runs (cloud_noise_cache.h); NULL: not
 * kept. */
struct cloud_renderer *cloud_renderer_create(struct vk_context *ctx, bool quiet,
                                             const char *cache_dir);
void cloud_renderer_destroy(struct vk_context *ctx, struct cloud_renderer **cr);

/* Generates the noise volumes for `seed` now unless they exist already: a service calls it at
 * start-up so that the first cloudy frame does not pay for it. */
int cloud_renderer_prepare_noise(struct vk_context *ctx, struct cloud_renderer *cr, uint32_t seed);
/* The clouds of the next frames; generates the noise when first needed or reseeded. */
int cloud_renderer_set(struct vk_context *ctx, struct cloud_renderer *cr,
                       const struct sky_render_clouds *clouds);
int cloud_renderer_set_weather_map(struct vk_context *ctx, struct cloud_renderer *cr,
                                   const uint8_t *rgba8, uint32_t width, uint32_t height);
/* GPU ms per frame for weather and shadow map rebuilds; <= 0 rebuilds at once. Frames back to
 * back give them at most 2 ms of it (or a tenth of the frame, when more); idle time before a
 * frame (cloud_renderer_observe_idle) up to all of it. */
void cloud_renderer_set_budget(struct cloud_renderer *cr, double budget_ms);
/* The part of the wall time since the renderer's previous frame returned that map builds may
 * take (sky_renderer.c decides the share; 0 back to back). */
void cloud_renderer_observe_idle(struct cloud_renderer *cr, double usable_idle_ms);
/* GPU ms a whole frame may take, which quality AUTO fits (cloud_quality.h); <= 0 none. */
void cloud_renderer_set_frame_budget(struct cloud_renderer *cr, double frame_budget_ms);
/* The resolution frames trace at now: the clouds' own, or the rung AUTO chose. */
enum sky_render_cloud_resolution cloud_renderer_resolution(const struct cloud_renderer *cr);
/* The low layer's march steps frames take now: the clouds' own, or the rung AUTO chose. */
int cloud_renderer_primary_steps(const struct cloud_renderer *cr);

/* The cloud work of a frame, in two parts around the view's aerial-perspective volume (which
 * takes the shadow map and is read by the trace). First the shared maps (weather, shadow,
 * hemisphere averages; nothing when no layer is on), filling the bindings (no clouds when
 * off); then the view's trace, reconstruction and resolve, which set out->over_sky and
 * out->over_ground. Return 0 or -1. */
int cloud_renderer_record_maps(struct vk_context *ctx, struct cloud_renderer *cr,
                               VkCommandBuffer cmd, struct gpu_timer *timer,
                               const struct cloud_frame *f, struct sky_cloud_bindings *out);
int cloud_renderer_record_view(struct vk_context *ctx, struct cloud_renderer *cr,
                               VkCommandBuffer cmd, struct gpu_timer *timer,
                               const struct cloud_frame *f, struct sky_cloud_bindings *out);
/* True when frames show clouds (a layer has coverage and the noise is ready). */
bool cloud_renderer_active(const struct cloud_renderer *cr);
/* The composite's bindings with no clouds. */
void cloud_renderer_no_clouds(const struct cloud_renderer *cr, struct sky_cloud_bindings *out);
/* GPU time of a recorded pass, to size the next map slices. */
void cloud_renderer_observe(struct cloud_renderer *cr, const char *pass_name, double ms);
/* Of the map rebuild under way, in [0, 1]; 1 when settled. */
/* The last frame's GPU time: map builds may take a tenth of it when that exceeds the budget. */
void cloud_renderer_observe_frame(struct cloud_renderer *cr, double gpu_ms);
double cloud_renderer_progress(const struct cloud_renderer *cr);
/* The largest low-layer type whose procedural weather map holds no towering clouds. */
double cloud_renderer_plain_type(void);
/* The last reference frame's counters; -1 when there was none. */
int cloud_renderer_reference_stats(const struct cloud_renderer *cr,
                                   struct sky_render_reference_stats *out);

#endif
