/* What the sky passes' files share inside render/sky: the passes, their state, and the two
 * helpers the recording (sky_pass_record.c) takes from the setup (sky_passes.c). */
#ifndef SKYD_SKY_PASSES_INTERNAL_H
#define SKYD_SKY_PASSES_INTERNAL_H

#include "composite_variants.h"
#include "ms_refine.h"
#include "compute_pass.h"
#include "sky_passes.h"
#include "view_outputs.h"
#include "vk_resources.h"

#define LUT_FORMAT VK_FORMAT_R32G32B32A32_SFLOAT
#define IRRADIANCE_SIZE 64
#define METER_MAX_GRID 256

/* Shading passes come in pairs: the camera inside the atmosphere, then above it (the same
 * SPIR-V specialized with FROM_SPACE, so each pipeline holds only its own path). */
enum pass_id {
    PASS_TRANSMITTANCE,
    PASS_MULTISCATTERING,
    PASS_IRRADIANCE,
    PASS_SKYVIEW,
    PASS_SKYVIEW_MOON, /* the same LUT lit by the moon (night sky) */
    PASS_AERIAL_PERSPECTIVE,
    PASS_EXPOSURE_RESOLVE,
    PASS_METER,
    PASS_METER_SPACE,
    PASS_PROBE,
    PASS_PROBE_SPACE,
    /* display = mix(previous, build, weight), one per atmosphere LUT; then the same shader
     * saving the display into previous (weight 0). */
    PASS_BLEND_TRANSMITTANCE,
    PASS_BLEND_MULTISCATTERING,
    PASS_BLEND_IRRADIANCE,
    PASS_SAVE_TRANSMITTANCE,
    PASS_SAVE_MULTISCATTERING,
    PASS_SAVE_IRRADIANCE,
    /* Inside the atmosphere without the night sky (NIGHT_SKY, constant_id 2, false): frames
     * where it adds nothing visible (night_sky_visible) skip its cost. */
    PASS_METER_DAY,
    PASS_COUNT
};

struct sky_passes {
    VkSampler sampler;
    struct compute_pass pass[PASS_COUNT];
    struct composite_variants *composite;
    /* The atmosphere LUTs exist three times: what frames read (display), what a rebuild
     * writes (build, from build_atmosphere_params), and the display saved when a rebuild starts
     * (previous), which the display blends away from when the build completes. */
    struct gpu_image transmittance, multiscattering, irradiance, skyview;
    struct gpu_image build_transmittance, build_multiscattering, build_irradiance;
    struct gpu_image previous_transmittance, previous_multiscattering, previous_irradiance;
    struct gpu_image ap_inscatter, ap_transmittance;
    struct gpu_image ap_shafts; /* in-scattering the clouds' shadows take away (light shafts) */
    struct sky_cloud_bindings ap_clouds; /* the clouds (shadow map, block) the AP pass reads */
    struct gpu_image moon_skyview;
    struct gpu_buffer stars; /* night_shared.h layout */
    double brightest_star_lux;
    struct gpu_buffer atmosphere_params, build_atmosphere_params, frame_params;
    struct gpu_buffer exposure, meter_partials;
    struct view_outputs outputs;
    struct view_output *out; /* the output image and readback buffer of the view being drawn */
    struct gpu_buffer probe_in, probe_out;
    size_t probe_capacity;
    struct sky_meter_push meter;
    double metered_ev100;
    struct sky_cloud_bindings clouds;
    struct ms_refine *ms; /* the converged multiple scattering the sky-view may read */
};

/* The pass of a shading pair for the camera's situation. */
static inline enum pass_id sky_pass_variant(enum pass_id inside, bool from_space)
{
    return from_space ? (enum pass_id)(inside + 1) : inside;
}

/* Points the aerial-perspective pass at p->ap_clouds' shadow map and cloud block. */
void sky_passes_bind_aerial_perspective(struct vk_context *ctx, struct sky_passes *p);
/* Points the composite passes at the current output and clouds. */
void sky_passes_bind_composite(struct sky_passes *p);

#endif
