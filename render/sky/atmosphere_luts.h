/* Which atmosphere the transmittance, multiple-scattering and irradiance LUTs show, and the
 * amortized rebuild that moves them to a new one (seed 001, 3.5.1): the rebuild is recorded a
 * few slices per frame under a GPU-time budget while frames keep reading the last complete
 * LUTs; when it completes, the displayed LUTs (and the atmosphere the frame is shaded with)
 * blend to the new ones over a few frames. A change during a rebuild restarts it from the
 * display as it stands. */
#ifndef SKYD_ATMOSPHERE_LUTS_H
#define SKYD_ATMOSPHERE_LUTS_H

#include <stdbool.h>
#include <stdint.h>

#include <vulkan/vulkan.h>

#include "sky_passes.h"
#include "sky_renderer.h"

struct gpu_timer;
struct atmosphere_luts;

struct atmosphere_luts *atmosphere_luts_create(void);
void atmosphere_luts_destroy(struct atmosphere_luts **luts);

/* budget_ms <= 0: every change is rebuilt at once. budget_fraction > 0 caps a frame's share at
 * that fraction of the rest of the frame (atmosphere_luts_observe_frame), or at the usable
 * part of the time the renderer sat idle before it (atmosphere_luts_observe_idle) when that
 * is more. */
void atmosphere_luts_set_amortization(struct atmosphere_luts *luts, double budget_ms,
                                      double budget_fraction, int blend_frames);
/* The LUT images were recreated or a submission failed: the next frame rebuilds at once. */
void atmosphere_luts_invalidate(struct atmosphere_luts *luts);

/* Makes the display exactly `a` in this command buffer (a whole rebuild when it is not). */
bool atmosphere_luts_record_exact(struct atmosphere_luts *luts, struct sky_passes *passes,
                                  VkCommandBuffer cmd, struct gpu_timer *timer,
                                  const struct sky_render_atmosphere *a);
/* Records this frame's share of the work toward `a`; true when any LUT work was recorded. */
bool atmosphere_luts_record_frame(struct atmosphere_luts *luts, struct sky_passes *passes,
                                  VkCommandBuffer cmd, struct gpu_timer *timer,
                                  const struct sky_render_atmosphere *a);

/* This frame's GPU-time budget for LUT work (ms): budget_ms, or less by budget_fraction
 * unless the idle time before the frame leaves more; <= 0 when amortization is off. */
double atmosphere_luts_frame_budget(const struct atmosphere_luts *luts);
/* The part of the wall time since the renderer's previous call ended (a frame period's idle
 * part) that LUT work may take without delaying the next frame; sky_renderer.c decides the
 * share. 0 when frames come back to back. */
void atmosphere_luts_observe_idle(struct atmosphere_luts *luts, double usable_idle_ms);

/* Changes whenever the displayed LUTs do (an exact build, a blend step); slices of a rebuild
 * under way leave it, as they leave the display. */
uint64_t atmosphere_luts_display_generation(const struct atmosphere_luts *luts);
/* The atmosphere frames are shaded with now, and its zenith transmittance. */
const struct sky_render_atmosphere *atmosphere_luts_displayed(const struct atmosphere_luts *luts);
const double *atmosphere_luts_zenith_transmittance(const struct atmosphere_luts *luts);
/* True when the display is exactly the last atmosphere asked for (no build or blend left). */
bool atmosphere_luts_settled(const struct atmosphere_luts *luts);
/* Of the rebuild under way, in [0, 1]; 1 when none is. */
double atmosphere_luts_progress(const struct atmosphere_luts *luts);
/* GPU time of a recorded pass (from the timestamps), to size the next slices. */
void atmosphere_luts_observe(struct atmosphere_luts *luts, const char *pass_name, double ms);
/* A frame's whole GPU time, after its passes were observed: the rest of the frame (without the
 * atmosphere LUT work) sets the relative budget. NAN for a call that is not a frame (a whole
 * rebuild): its LUT work is forgotten. */
void atmosphere_luts_observe_frame(struct atmosphere_luts *luts, double total_ms);

#endif
