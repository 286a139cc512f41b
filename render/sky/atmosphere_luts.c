#include "atmosphere_luts.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "ground_transfer.h"
#include "sky_photometry.h"
#include "sky_shared.h"
#include "sky_uniforms.h"

enum phase { PHASE_IDLE, PHASE_BUILDING, PHASE_BLENDING };

/* Starting guesses of GPU ms per slice on lavapipe (2 cores): the measured times replace them
 * after the first slice. */
#define INITIAL_MS_PER_TRANSMITTANCE_BLOCK 0.15 /* 64 texels */
#define INITIAL_MS_PER_MULTISCATTERING_TEXEL 0.04
#define IRRADIANCE_MS 0.2

struct atmosphere_luts {
    uint64_t display_generation; /* counts changes of what the displayed LUTs hold */
    bool built;
    enum phase phase;
    double budget_ms, budget_fraction;
    int blend_frames;
    /* GPU time of the rest of the frame (smoothed; 0 before the first), and this frame's LUT
     * work so far. */
    double frame_ms, lut_ms_this_frame;
    double usable_idle_ms; /* of the idle time before this frame, what LUT work may take */
    /* What frames are shaded with now, and the two ends of a rebuild. */
    struct sky_render_atmosphere displayed, previous, target;
    struct sky_atmosphere_uniforms displayed_u, previous_u, target_u;
    double zenith_displayed[3], zenith_previous[3], zenith_target[3];
    /* Progress of the rebuild. */
    enum sky_build_step step;
    uint32_t next_slice, transmittance_slices, multiscattering_slices;
    int blend_frame;
    /* Slice costs (ms per transmittance block of 64 texels, per multiple-scattering texel), and
     * the slices recorded this frame to turn a measured time into one. */
    double ms_per_slice[2];
    uint32_t slices_this_frame[2];
};

struct atmosphere_luts *atmosphere_luts_create(void)
{
    struct atmosphere_luts *luts = calloc(1, sizeof *luts);
    if (!luts)
        return NULL;
    luts->blend_frames = 4;
    luts->ms_per_slice[SKY_BUILD_TRANSMITTANCE] = INITIAL_MS_PER_TRANSMITTANCE_BLOCK;
    luts->ms_per_slice[SKY_BUILD_MULTISCATTERING] = INITIAL_MS_PER_MULTISCATTERING_TEXEL;
    return luts;
}

void atmosphere_luts_destroy(struct atmosphere_luts **luts)
{
    free(*luts);
    *luts = NULL;
}

void atmosphere_luts_set_amortization(struct atmosphere_luts *luts, double budget_ms,
                                      double budget_fraction, int blend_frames)
{
    luts->budget_ms = budget_ms;
    luts->budget_fraction = budget_fraction > 0.0 ? budget_fraction : 0.0;
    luts->blend_frames = blend_frames < 1 ? 1 : blend_frames;
}

void atmosphere_luts_invalidate(struct atmosphere_luts *luts)
{
    luts->built = false;
    luts->phase = PHASE_IDLE;
}

static bool same_atmosphere(const struct sky_render_atmosphere *a,
                            const struct sky_render_atmosphere *b)
{
    return memcmp(a, b, sizeof *a) == 0;
}

/* Element-wise mix of two structs made only of doubles (or only of floats). */
static void mix_doubles(const double *a, const double *b, size_t n, double w, double *out)
{
    for (size_t i = 0; i < n; i++)
        out[i] = a[i] + (b[i] - a[i]) * w;
}

static void mix_floats(const float *a, const float *b, size_t n, double w, float *out)
{
    for (size_t i = 0; i < n; i++)
        out[i] = (float)(a[i] + (b[i] - a[i]) * w);
}

static void show(struct atmosphere_luts *luts, struct sky_passes *passes, double weight)
{
    luts->display_generation++;
    mix_doubles((const double *)&luts->previous, (const double *)&luts->target,
                sizeof luts->target / sizeof(double), weight, (double *)&luts->displayed);
    mix_floats((const float *)&luts->previous_u, (const float *)&luts->target_u,
               sizeof luts->target_u / sizeof(float), weight, (float *)&luts->displayed_u);
    mix_doubles(luts->zenith_previous, luts->zenith_target, 3, weight, luts->zenith_displayed);
    sky_passes_upload_atmosphere(passes, &luts->displayed_u);
}

bool atmosphere_luts_record_exact(struct atmosphere_luts *luts, struct sky_passes *passes,
                                  VkCommandBuffer cmd, struct gpu_timer *timer,
                                  const struct sky_render_atmosphere *a)
{
    if (luts->built && luts->phase == PHASE_IDLE && same_atmosphere(a, &luts->displayed))
        return false;
    luts->target = luts->previous = *a;
    sky_uniforms_fill_atmosphere(a, &luts->target_u);
    luts->previous_u = luts->target_u;
    sky_zenith_transmittance(a, luts->zenith_target);
    memcpy(luts->zenith_previous, luts->zenith_target, sizeof luts->zenith_target);
    sky_passes_upload_build_atmosphere(passes, &luts->target_u);
    sky_passes_record_atmosphere(passes, cmd, timer);
    show(luts, passes, 1.0);
    luts->built = true;
    luts->phase = PHASE_IDLE;
    return true;
}

/* A new target: the display as it stands becomes the start of the blend. During a build the
 * display has not moved since it was saved, so a restart (a parameter being dragged) costs no
 * copy; nor does it pay for the ground transfer integral until the build gets that far. */
static void start_rebuild(struct atmosphere_luts *luts, struct sky_passes *passes,
                          VkCommandBuffer cmd, struct gpu_timer *timer,
                          const struct sky_render_atmosphere *a)
{
    if (luts->phase != PHASE_BUILDING) {
        luts->previous = luts->displayed;
        luts->previous_u = luts->displayed_u;
        memcpy(luts->zenith_previous, luts->zenith_displayed, sizeof luts->zenith_previous);
        sky_passes_record_save_display(passes, cmd, timer);
    }
    luts->target = *a;
    sky_uniforms_fill_atmosphere_media(a, &luts->target_u);
    sky_passes_upload_build_atmosphere(passes, &luts->target_u);
    sky_passes_atmosphere_slices(passes, &luts->transmittance_slices,
                                 &luts->multiscattering_slices);
    luts->step = SKY_BUILD_TRANSMITTANCE;
    luts->next_slice = 0;
    luts->phase = PHASE_BUILDING;
}

/* Records slices until the budget is spent (at least one slice per frame, so a rebuild always
 * ends). Returns true when the build is complete. */
static bool record_slices(struct atmosphere_luts *luts, struct sky_passes *passes,
                          VkCommandBuffer cmd, struct gpu_timer *timer)
{
    double remaining = atmosphere_luts_frame_budget(luts);
    bool first = true;
    while (luts->step != SKY_BUILD_IRRADIANCE) {
        uint32_t total = luts->step == SKY_BUILD_TRANSMITTANCE ? luts->transmittance_slices
                                                               : luts->multiscattering_slices;
        double cost = luts->ms_per_slice[luts->step];
        uint32_t slices = (uint32_t)fmax(0.0, floor(remaining / cost));
        if (slices == 0 && !first)
            return false;
        if (slices == 0)
            slices = 1;
        if (slices > total - luts->next_slice)
            slices = total - luts->next_slice;
        sky_passes_record_build(passes, cmd, timer, luts->step, luts->next_slice, slices);
        luts->slices_this_frame[luts->step] += slices;
        remaining -= slices * cost;
        first = false;
        luts->next_slice += slices;
        if (luts->next_slice < total)
            return false;
        if (luts->step == SKY_BUILD_TRANSMITTANCE) {
            /* Multiple scattering reads the ground transfer: now it is worth computing. */
            double transfer[3];
            sky_ground_transfer(&luts->target, transfer);
            luts->target_u.ground_transfer = (sky_vec4){ (float)transfer[0], (float)transfer[1],
                                                         (float)transfer[2], 0.0f };
            sky_passes_upload_build_atmosphere(passes, &luts->target_u);
        }
        luts->step = luts->step == SKY_BUILD_TRANSMITTANCE ? SKY_BUILD_MULTISCATTERING
                                                           : SKY_BUILD_IRRADIANCE;
        luts->next_slice = 0;
    }
    if (!first && remaining < IRRADIANCE_MS)
        return false;
    sky_passes_record_build(passes, cmd, timer, SKY_BUILD_IRRADIANCE, 0, 1);
    /* Only now, once per completed rebuild: this integral costs CPU time. */
    sky_zenith_transmittance(&luts->target, luts->zenith_target);
    return true;
}

double atmosphere_luts_frame_budget(const struct atmosphere_luts *luts)
{
    double budget = luts->budget_ms;
    if (luts->budget_fraction > 0.0 && luts->frame_ms > 0.0) {
        double share = luts->budget_fraction * luts->frame_ms;
        budget = fmin(budget, fmax(share, luts->usable_idle_ms));
    }
    return budget;
}

void atmosphere_luts_observe_idle(struct atmosphere_luts *luts, double usable_idle_ms)
{
    luts->usable_idle_ms = usable_idle_ms > 0.0 && isfinite(usable_idle_ms) ? usable_idle_ms : 0.0;
}

bool atmosphere_luts_record_frame(struct atmosphere_luts *luts, struct sky_passes *passes,
                                  VkCommandBuffer cmd, struct gpu_timer *timer,
                                  const struct sky_render_atmosphere *a)
{
    luts->slices_this_frame[0] = luts->slices_this_frame[1] = 0;
    if (!luts->built || luts->budget_ms <= 0.0)
        return atmosphere_luts_record_exact(luts, passes, cmd, timer, a);
    bool recorded = false;
    if (!same_atmosphere(a, &luts->target)) {
        start_rebuild(luts, passes, cmd, timer, a);
        recorded = true;
    }
    switch (luts->phase) {
    case PHASE_IDLE:
        break;
    case PHASE_BUILDING:
        recorded = true;
        if (record_slices(luts, passes, cmd, timer)) {
            luts->phase = PHASE_BLENDING;
            luts->blend_frame = 0;
        }
        break;
    case PHASE_BLENDING: {
        recorded = true;
        luts->blend_frame++;
        double weight = (double)luts->blend_frame / luts->blend_frames;
        if (weight >= 1.0)
            weight = 1.0;
        sky_passes_record_blend(passes, cmd, timer, (float)weight);
        show(luts, passes, weight);
        if (weight >= 1.0)
            luts->phase = PHASE_IDLE;
        break;
    }
    }
    return recorded;
}

uint64_t atmosphere_luts_display_generation(const struct atmosphere_luts *luts)
{
    return luts->display_generation;
}

const struct sky_render_atmosphere *atmosphere_luts_displayed(const struct atmosphere_luts *luts)
{
    return &luts->displayed;
}

const double *atmosphere_luts_zenith_transmittance(const struct atmosphere_luts *luts)
{
    return luts->zenith_displayed;
}

bool atmosphere_luts_settled(const struct atmosphere_luts *luts)
{
    return luts->built && luts->phase == PHASE_IDLE;
}

double atmosphere_luts_progress(const struct atmosphere_luts *luts)
{
    if (luts->phase != PHASE_BUILDING)
        return 1.0;
    uint32_t total = luts->transmittance_slices + luts->multiscattering_slices + 1;
    uint32_t done = luts->next_slice;
    if (luts->step >= SKY_BUILD_MULTISCATTERING)
        done += luts->transmittance_slices;
    if (luts->step == SKY_BUILD_IRRADIANCE)
        done = luts->transmittance_slices + luts->multiscattering_slices;
    return (double)done / total;
}

bool sky_render_pass_is_atmosphere_lut(const char *name)
{
    static const char *const names[] = { "transmittance", "multiscattering", "irradiance",
                                         "lut_blend",     "lut_save",        "ms_moments",
                                         "ms_density",    "ms_radiance",     "ms_ground" };
    for (size_t i = 0; i < sizeof names / sizeof names[0]; i++)
        if (strcmp(name, names[i]) == 0)
            return true;
    return false;
}

void atmosphere_luts_observe_frame(struct atmosphere_luts *luts, double total_ms)
{
    double rest = total_ms - luts->lut_ms_this_frame;
    luts->lut_ms_this_frame = 0.0;
    if (!(rest > 0.0))
        return;
    /* Smoothed, but quick to follow a frame that got cheaper (a smaller view). */
    luts->frame_ms = luts->frame_ms > 0.0 && rest > luts->frame_ms
                         ? 0.9 * luts->frame_ms + 0.1 * rest
                         : rest;
}

void atmosphere_luts_observe(struct atmosphere_luts *luts, const char *pass_name, double ms)
{
    if (sky_render_pass_is_atmosphere_lut(pass_name) && ms > 0.0)
        luts->lut_ms_this_frame += ms;
    int step = strcmp(pass_name, "transmittance") == 0     ? SKY_BUILD_TRANSMITTANCE
               : strcmp(pass_name, "multiscattering") == 0 ? SKY_BUILD_MULTISCATTERING
                                                           : -1;
    if (step < 0 || luts->slices_this_frame[step] == 0 || !(ms > 0.0))
        return;
    double per_slice = ms / luts->slices_this_frame[step];
    /* Smoothed: lavapipe's timings jitter from frame to frame. */
    luts->ms_per_slice[step] = 0.7 * luts->ms_per_slice[step] + 0.3 * per_slice;
    luts->slices_this_frame[step] = 0;
}
