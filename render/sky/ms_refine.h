/* Converged multiple scattering: while the atmosphere stands still, the orders of scattering
 * are gathered one by one into a 4D table of (altitude, view zenith, sun zenith, view-sun
 * angle) (Bruneton & Neyret 2008, section 4) a few slices per frame under the LUT budget; once
 * complete, the sky-view fades from Hillaire's isotropic multiple-scattering LUT to the table
 * over MS_REFINE_FADE_S. The table holds every order >= 2 for any sun and camera altitude, so
 * the sun and the camera may move freely: "standing still" means the atmosphere's parameters
 * (media, radii, ground albedo) stay the same. Any change fades the table out and, once the
 * new atmosphere's LUTs are displayed, starts it again from order 1. */
#ifndef SKYD_MS_REFINE_H
#define SKYD_MS_REFINE_H

#include <stdbool.h>
#include <stdint.h>

#include <vulkan/vulkan.h>

#include "sky_renderer.h"

struct vk_context;
struct gpu_timer;
struct gpu_image;
struct gpu_buffer;
struct ms_refine;

#define MS_REFINE_FADE_S 0.5 /* the table fades in (and out) over this much wall time */
#define MS_REFINE_ORDERS 4   /* orders computed; the rest of the series as a geometric tail */

struct ms_refine *ms_refine_create(struct vk_context *ctx);
void ms_refine_destroy(struct vk_context *ctx, struct ms_refine **refine);

/* Points the passes at the displayed atmosphere's parameters and transmittance LUT. */
void ms_refine_bind(struct vk_context *ctx, struct ms_refine *refine,
                    const struct gpu_buffer *atmosphere_params,
                    const struct gpu_image *transmittance, VkSampler sampler);
/* The table the sky-view reads: all orders >= 2 of radiance per unit sun illuminance. */
const struct gpu_image *ms_refine_table(const struct ms_refine *refine);
/* One of its images by name, for tests: "ms_sum" (the table), "ms_density", "ms_ground",
 * "ms_moments", "ms_radiance_even" and "ms_radiance_odd" (the last two orders' radiance); NULL
 * for another. */
const struct gpu_image *ms_refine_image(const struct ms_refine *refine, const char *name);

/* One frame's step. `displayed` is the atmosphere the frame is shaded with and `settled` whether
 * the atmosphere LUTs show exactly the one asked for; records work worth about budget_ms (at
 * least one slice) while the table is being built, and moves the fade by the wall time since
 * the last call (now_s, a monotonic clock). Returns true when any work was recorded. */
bool ms_refine_record_frame(struct ms_refine *refine, VkCommandBuffer cmd, struct gpu_timer *timer,
                            const struct sky_render_atmosphere *displayed, bool settled,
                            double budget_ms, double now_s);
/* Builds the whole table for `displayed` now (unless it holds it) and shows it fully. */
bool ms_refine_record_all(struct ms_refine *refine, VkCommandBuffer cmd, struct gpu_timer *timer,
                          const struct sky_render_atmosphere *displayed);
/* Runs every pass once over nothing, the first time only: lavapipe compiles a pipeline at its
 * first dispatch, which is better paid by a frame that rebuilds the LUTs at once anyway than
 * by one under the budget. */
void ms_refine_record_warm_up(struct ms_refine *refine, VkCommandBuffer cmd);
/* Forget the table (images recreated, a failed submission). */
void ms_refine_invalidate(struct ms_refine *refine);

/* The weight of the table in the sky-view now, [0, 1]; 0 for an atmosphere other than its own
 * once the fade-out is over (a probe of another atmosphere). */
double ms_refine_weight_for(const struct ms_refine *refine,
                            const struct sky_render_atmosphere *displayed);
/* Of the build under way or done, [0, 1] (1: complete for the displayed atmosphere). */
double ms_refine_progress(const struct ms_refine *refine);
/* The order being computed (0 when none is). */
int ms_refine_order(const struct ms_refine *refine);
/* Wall time from the build's start to its completion (NAN before one completes). */
double ms_refine_build_seconds(const struct ms_refine *refine);
/* GPU time of a recorded pass, to size the next slices. */
void ms_refine_observe(struct ms_refine *refine, const char *pass_name, double ms);

#endif
