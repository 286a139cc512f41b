/* The interfaces of the atmosphere, sky and composite passes (render/sky/), declared once for
 * their shaders and for render/sky/sky_passes.c and composite_variants.c: binding indices,
 * specialization-constant ids, workgroup sizes and each pass's layout (pass_layout.h). */
#ifndef SKY_LAYOUTS_H
#define SKY_LAYOUTS_H

#include "pass_layout.h"

/* ---- atmosphere LUTs ---- */

/* transmittance.comp: a workgroup covers a block of SKY_TRANSMITTANCE_LOCAL texels. */
#define SKY_TRANSMITTANCE_LOCAL 64
#define SKY_TRANSMITTANCE_ATMOSPHERE 0
#define SKY_TRANSMITTANCE_OUT 1
#define SKY_LAYOUT_TRANSMITTANCE(X) X(SKY_TRANSMITTANCE_ATMOSPHERE, BLOCK) X(SKY_TRANSMITTANCE_OUT, IMAGE)

/* multiscattering.comp: a workgroup is one texel, SKY_MULTISCATTERING_LOCAL sphere directions. */
#define SKY_MULTISCATTERING_LOCAL 32
#define SKY_MULTISCATTERING_ATMOSPHERE 0
#define SKY_MULTISCATTERING_TRANSMITTANCE 1
#define SKY_MULTISCATTERING_OUT 2
#define SKY_LAYOUT_MULTISCATTERING(X)                                                     \
    X(SKY_MULTISCATTERING_ATMOSPHERE, BLOCK) X(SKY_MULTISCATTERING_TRANSMITTANCE, SAMPLED)  \
    X(SKY_MULTISCATTERING_OUT, IMAGE)

/* irradiance.comp: a workgroup is one texel, SKY_IRRADIANCE_DIRECTIONS directions of the upper
 * hemisphere (8 zenith angles x 8 azimuths, the sun's side mirrored). */
#define SKY_IRRADIANCE_DIRECTIONS 64
#define SKY_IRRADIANCE_ATMOSPHERE 0
#define SKY_IRRADIANCE_TRANSMITTANCE 1
#define SKY_IRRADIANCE_MULTISCATTERING 2
#define SKY_IRRADIANCE_OUT 3
#define SKY_LAYOUT_IRRADIANCE(X)                                                          \
    X(SKY_IRRADIANCE_ATMOSPHERE, BLOCK) X(SKY_IRRADIANCE_TRANSMITTANCE, SAMPLED)            \
    X(SKY_IRRADIANCE_MULTISCATTERING, SAMPLED) X(SKY_IRRADIANCE_OUT, IMAGE)

/* lut_blend.comp: out = mix(from, to, weight), per texel. */
#define SKY_LUT_BLEND_LOCAL 8
#define SKY_LUT_BLEND_FROM 0
#define SKY_LUT_BLEND_TO 1
#define SKY_LUT_BLEND_OUT 2
#define SKY_LAYOUT_LUT_BLEND(X)                                                           \
    X(SKY_LUT_BLEND_FROM, IMAGE) X(SKY_LUT_BLEND_TO, IMAGE) X(SKY_LUT_BLEND_OUT, IMAGE)

/* ---- converged multiple scattering (render/sky/ms_refine.h, ms_table.glsl) ---- */

/* The 4D tables: SKY_MS_NU x SKY_MS_MU_S texels across, SKY_MS_MU rows (ground rays, then sky
 * rays), SKY_MS_R slices; the ground irradiance over SKY_MS_GROUND cosines. No side a power of
 * two (lut_extent in sky_passes.c says why). */
#define SKY_MS_NU 8
#define SKY_MS_MU_S 31
#define SKY_MS_MU 30
#define SKY_MS_R 8
#define SKY_MS_GROUND SKY_MS_MU_S
#define SKY_MS_MU_S_MIN (-0.2) /* the sun 11.5 deg below the horizon: darker is zero */
#define SKY_MS_LOCAL 8 /* texels per workgroup: the slice of the amortized build */
#define SKY_MS_CONST_HIGHER 0 /* ms_radiance: orders >= 2; ms_density: orders >= 3 */

/* ms_radiance.comp: one order's radiance; orders >= 2 add into the sum. */
#define SKY_MS_RADIANCE_ATMOSPHERE 0
#define SKY_MS_RADIANCE_TRANSMITTANCE 1
#define SKY_MS_RADIANCE_DENSITY 2
#define SKY_MS_RADIANCE_GROUND 3
#define SKY_MS_RADIANCE_PREVIOUS 4
#define SKY_MS_RADIANCE_OUT 5
#define SKY_MS_RADIANCE_SUM 6
#define SKY_LAYOUT_MS_RADIANCE(X)                                                          \
    X(SKY_MS_RADIANCE_ATMOSPHERE, BLOCK) X(SKY_MS_RADIANCE_TRANSMITTANCE, SAMPLED)           \
    X(SKY_MS_RADIANCE_DENSITY, SAMPLED) X(SKY_MS_RADIANCE_GROUND, SAMPLED)                   \
    X(SKY_MS_RADIANCE_PREVIOUS, SAMPLED) X(SKY_MS_RADIANCE_OUT, IMAGE)                       \
    X(SKY_MS_RADIANCE_SUM, IMAGE)

/* ms_moments.comp: an order's second moments per (mu_s, r), 4 texels each, for Rayleigh. */
#define SKY_MS_MOMENTS 4
#define SKY_MS_MOMENTS_ATMOSPHERE 0
#define SKY_MS_MOMENTS_RADIANCE 1
#define SKY_MS_MOMENTS_OUT 2
#define SKY_LAYOUT_MS_MOMENTS(X)                                                           \
    X(SKY_MS_MOMENTS_ATMOSPHERE, BLOCK) X(SKY_MS_MOMENTS_RADIANCE, SAMPLED)                  \
    X(SKY_MS_MOMENTS_OUT, IMAGE)

/* ms_density.comp: the next order's scattering density from an order's radiance (Mie) and its
 * moments (Rayleigh). */
#define SKY_MS_DENSITY_ATMOSPHERE 0
#define SKY_MS_DENSITY_RADIANCE 1
#define SKY_MS_DENSITY_OUT 2
#define SKY_MS_DENSITY_MOMENTS 3
#define SKY_LAYOUT_MS_DENSITY(X)                                                           \
    X(SKY_MS_DENSITY_ATMOSPHERE, BLOCK) X(SKY_MS_DENSITY_RADIANCE, SAMPLED)                  \
    X(SKY_MS_DENSITY_OUT, IMAGE) X(SKY_MS_DENSITY_MOMENTS, SAMPLED)

/* ms_ground.comp: an order's ground irradiance. */
#define SKY_MS_GROUND_ATMOSPHERE 0
#define SKY_MS_GROUND_RADIANCE 1
#define SKY_MS_GROUND_OUT 2
#define SKY_LAYOUT_MS_GROUND(X)                                                            \
    X(SKY_MS_GROUND_ATMOSPHERE, BLOCK) X(SKY_MS_GROUND_RADIANCE, SAMPLED)                    \
    X(SKY_MS_GROUND_OUT, IMAGE)

/* ---- per-view LUTs ---- */

/* skyview.comp; MOON_LIGHT: the same LUT lit by the moon. */
#define SKY_SKYVIEW_LOCAL 8
#define SKY_SKYVIEW_ATMOSPHERE 0
#define SKY_SKYVIEW_FRAME 1
#define SKY_SKYVIEW_TRANSMITTANCE 2
#define SKY_SKYVIEW_MULTISCATTERING 3
#define SKY_SKYVIEW_IRRADIANCE 4
#define SKY_SKYVIEW_OUT 5
#define SKY_SKYVIEW_MS_SUM 6 /* the converged multiple scattering (ms_table.glsl) */
#define SKY_SKYVIEW_CONST_MOON_LIGHT 0
#define SKY_LAYOUT_SKYVIEW(X)                                                             \
    X(SKY_SKYVIEW_ATMOSPHERE, BLOCK) X(SKY_SKYVIEW_FRAME, BLOCK)                            \
    X(SKY_SKYVIEW_TRANSMITTANCE, SAMPLED) X(SKY_SKYVIEW_MULTISCATTERING, SAMPLED)           \
    X(SKY_SKYVIEW_IRRADIANCE, SAMPLED) X(SKY_SKYVIEW_OUT, IMAGE)                            \
    X(SKY_SKYVIEW_MS_SUM, SAMPLED)

/* aerial_perspective.comp: the froxel volumes, with the clouds' shadow map and block. */
#define SKY_AP_LOCAL 8
#define SKY_AP_ATMOSPHERE 0
#define SKY_AP_FRAME 1
#define SKY_AP_TRANSMITTANCE 2
#define SKY_AP_MULTISCATTERING 3
#define SKY_AP_INSCATTER_OUT 4
#define SKY_AP_TRANSMITTANCE_OUT 5
#define SKY_AP_SHAFTS_OUT 6
#define SKY_AP_CLOUD_SHADOW 7
#define SKY_AP_CLOUD 8
#define SKY_AP_CLOUD_ENV 9
#define SKY_LAYOUT_AERIAL_PERSPECTIVE(X)                                                  \
    X(SKY_AP_ATMOSPHERE, BLOCK) X(SKY_AP_FRAME, BLOCK) X(SKY_AP_TRANSMITTANCE, SAMPLED)     \
    X(SKY_AP_MULTISCATTERING, SAMPLED) X(SKY_AP_INSCATTER_OUT, IMAGE)                       \
    X(SKY_AP_TRANSMITTANCE_OUT, IMAGE) X(SKY_AP_SHAFTS_OUT, IMAGE)                          \
    X(SKY_AP_CLOUD_SHADOW, SAMPLED) X(SKY_AP_CLOUD, BLOCK) X(SKY_AP_CLOUD_ENV, BUFFER)

/* ---- passes that shade view directions (shading_bindings.glsl) ---- */

/* Bindings 0-7 of the composite, meter and probe passes. */
#define SKY_SHADING_ATMOSPHERE 0
#define SKY_SHADING_FRAME 1
#define SKY_SHADING_TRANSMITTANCE 2
#define SKY_SHADING_MULTISCATTERING 3
#define SKY_SHADING_SKYVIEW 4
#define SKY_SHADING_IRRADIANCE 5
#define SKY_SHADING_STARS 6
#define SKY_SHADING_MOON_SKYVIEW 7
#define SKY_LAYOUT_SHADING(X)                                                             \
    X(SKY_SHADING_ATMOSPHERE, BLOCK) X(SKY_SHADING_FRAME, BLOCK)                            \
    X(SKY_SHADING_TRANSMITTANCE, SAMPLED) X(SKY_SHADING_MULTISCATTERING, SAMPLED)           \
    X(SKY_SHADING_SKYVIEW, SAMPLED) X(SKY_SHADING_IRRADIANCE, SAMPLED)                      \
    X(SKY_SHADING_STARS, BUFFER) X(SKY_SHADING_MOON_SKYVIEW, SAMPLED)
/* Their specialization: the camera above the atmosphere, the composite's sun-disk region, the
 * night sky, and the composite's clouds and ground. */
#define SKY_CONST_FROM_SPACE 0
#define SKY_CONST_SUN_REGION 1
#define SKY_CONST_NIGHT_SKY 2
#define SKY_CONST_CLOUDS 3
#define SKY_CONST_GROUND 4

/* meter.comp: auto-exposure partial sums over a grid (SKY_METER_LOCAL in sky_shared.h). */
#define SKY_METER_PARTIALS 8
#define SKY_LAYOUT_METER(X) SKY_LAYOUT_SHADING(X) X(SKY_METER_PARTIALS, BUFFER)

/* exposure_resolve.comp */
#define SKY_EXPOSURE_LOCAL 64
#define SKY_EXPOSURE_FRAME 0
#define SKY_EXPOSURE_PARTIALS 1
#define SKY_EXPOSURE_OUT 2
#define SKY_LAYOUT_EXPOSURE_RESOLVE(X)                                                    \
    X(SKY_EXPOSURE_FRAME, BLOCK) X(SKY_EXPOSURE_PARTIALS, BUFFER) X(SKY_EXPOSURE_OUT, BUFFER)

/* probe.comp: one direction (or transmittance query) per invocation. */
#define SKY_PROBE_LOCAL 64
#define SKY_PROBE_IN 8
#define SKY_PROBE_OUT 9
#define SKY_LAYOUT_PROBE(X) SKY_LAYOUT_SHADING(X) X(SKY_PROBE_IN, BUFFER) X(SKY_PROBE_OUT, BUFFER)

/* composite.comp: the frame from the LUTs, the exposure and the clouds' reconstruction. */
#define SKY_COMPOSITE_LOCAL 8
#define SKY_COMPOSITE_EXPOSURE 8
#define SKY_COMPOSITE_OUT 9
#define SKY_COMPOSITE_CLOUDS_OVER_SKY 10
#define SKY_COMPOSITE_CLOUDS_OVER_GROUND 11
#define SKY_LAYOUT_COMPOSITE(X)                                                           \
    SKY_LAYOUT_SHADING(X) X(SKY_COMPOSITE_EXPOSURE, BUFFER) X(SKY_COMPOSITE_OUT, IMAGE)     \
    X(SKY_COMPOSITE_CLOUDS_OVER_SKY, SAMPLED) X(SKY_COMPOSITE_CLOUDS_OVER_GROUND, SAMPLED)

#endif
