/* The interfaces of the cloud passes (render/clouds/), declared once for their shaders and for
 * cloud_renderer.c and cloud_noise.c: binding indices, specialization-constant ids, workgroup
 * sizes and each pass's layout (pass_layout.h). */
#ifndef CLOUD_LAYOUTS_H
#define CLOUD_LAYOUTS_H

#include "pass_layout.h"

/* Workgroup side of the 2D cloud passes (weather, shadow, trace, reconstruct, resolve, curl
 * noise). The hemisphere pass is one workgroup of CLOUD_HEMISPHERE_RAYS (cloud_shared.h). */
#define SKY_CLOUD_LOCAL 8

/* ---- maps ---- */

/* cloud_weather.comp */
#define SKY_CLOUD_WEATHER_CLIENT_MAP 0
#define SKY_CLOUD_WEATHER_OUT 1
#define SKY_LAYOUT_CLOUD_WEATHER(X)                                                       \
    X(SKY_CLOUD_WEATHER_CLIENT_MAP, SAMPLED) X(SKY_CLOUD_WEATHER_OUT, IMAGE)

/* cloud_shadow.comp */
#define SKY_CLOUD_SHADOW_ATMOSPHERE 0
#define SKY_CLOUD_SHADOW_CLOUD 1
#define SKY_CLOUD_SHADOW_BASE_NOISE 2
#define SKY_CLOUD_SHADOW_DETAIL_NOISE 3
#define SKY_CLOUD_SHADOW_CURL_NOISE 4
#define SKY_CLOUD_SHADOW_WEATHER 5
#define SKY_CLOUD_SHADOW_OUT 6
#define SKY_CLOUD_SHADOW_SUN_DEPTH_OUT 7
#define SKY_LAYOUT_CLOUD_SHADOW(X)                                                        \
    X(SKY_CLOUD_SHADOW_ATMOSPHERE, BLOCK) X(SKY_CLOUD_SHADOW_CLOUD, BLOCK)                  \
    X(SKY_CLOUD_SHADOW_BASE_NOISE, SAMPLED) X(SKY_CLOUD_SHADOW_DETAIL_NOISE, SAMPLED)       \
    X(SKY_CLOUD_SHADOW_CURL_NOISE, SAMPLED) X(SKY_CLOUD_SHADOW_WEATHER, SAMPLED)            \
    X(SKY_CLOUD_SHADOW_OUT, IMAGE) X(SKY_CLOUD_SHADOW_SUN_DEPTH_OUT, IMAGE)

/* cloud_sun_columns.comp: after a shadow map's last slice, each sun column's support (how much
 * of the cloud around it is still cloud to its sides) beside its transmittance and optical
 * depth, from the finished volume. */
#define SKY_CLOUD_COLUMNS_CLOUD 0
#define SKY_CLOUD_COLUMNS_SUN_DEPTH 1
#define SKY_CLOUD_COLUMNS_SHADOW 2
#define SKY_LAYOUT_CLOUD_SUN_COLUMNS(X)                                                   \
    X(SKY_CLOUD_COLUMNS_CLOUD, BLOCK) X(SKY_CLOUD_COLUMNS_SUN_DEPTH, SAMPLED)               \
    X(SKY_CLOUD_COLUMNS_SHADOW, IMAGE)

/* Altitude levels of the sun-space optical-depth volume (cloud_shadow.comp): cumulative
 * optical depth of the low layer along the sun's ray from its base up to each level. */
#define SKY_CLOUD_SUN_DEPTH_LEVELS 16

/* ---- passes that march the cloud layers (cloud_bindings.glsl) ---- */

/* Bindings 0-12 of the hemisphere and trace passes (and the slab self-test). */
#define SKY_CLOUD_MARCH_ATMOSPHERE 0
#define SKY_CLOUD_MARCH_FRAME 1
#define SKY_CLOUD_MARCH_TRANSMITTANCE 2
#define SKY_CLOUD_MARCH_MULTISCATTERING 3
#define SKY_CLOUD_MARCH_IRRADIANCE 4
#define SKY_CLOUD_MARCH_CLOUD 5
#define SKY_CLOUD_MARCH_BASE_NOISE 6
#define SKY_CLOUD_MARCH_DETAIL_NOISE 7
#define SKY_CLOUD_MARCH_CURL_NOISE 8
#define SKY_CLOUD_MARCH_WEATHER 9
#define SKY_CLOUD_MARCH_SKYVIEW 10
#define SKY_CLOUD_MARCH_SUN_DEPTH 11
#define SKY_CLOUD_MARCH_SUN_COLUMNS 12
#define SKY_LAYOUT_CLOUD_MARCH(X)                                                         \
    X(SKY_CLOUD_MARCH_ATMOSPHERE, BLOCK) X(SKY_CLOUD_MARCH_FRAME, BLOCK)                    \
    X(SKY_CLOUD_MARCH_TRANSMITTANCE, SAMPLED) X(SKY_CLOUD_MARCH_MULTISCATTERING, SAMPLED)   \
    X(SKY_CLOUD_MARCH_IRRADIANCE, SAMPLED) X(SKY_CLOUD_MARCH_CLOUD, BLOCK)                  \
    X(SKY_CLOUD_MARCH_BASE_NOISE, SAMPLED) X(SKY_CLOUD_MARCH_DETAIL_NOISE, SAMPLED)         \
    X(SKY_CLOUD_MARCH_CURL_NOISE, SAMPLED) X(SKY_CLOUD_MARCH_WEATHER, SAMPLED)              \
    X(SKY_CLOUD_MARCH_SKYVIEW, SAMPLED) X(SKY_CLOUD_MARCH_SUN_DEPTH, SAMPLED)               \
    X(SKY_CLOUD_MARCH_SUN_COLUMNS, SAMPLED)
/* Their specialization: the moon's light marched; towering clouds (cumulonimbus turrets and
 * anvils) in the weather map. */
#define SKY_CLOUD_CONST_MOONLIT 0
#define SKY_CLOUD_CONST_TOWERING 1

/* cloud_hemisphere.comp */
#define SKY_CLOUD_HEMISPHERE_ENV_OUT 13
#define SKY_LAYOUT_CLOUD_HEMISPHERE(X)                                                    \
    SKY_LAYOUT_CLOUD_MARCH(X) X(SKY_CLOUD_HEMISPHERE_ENV_OUT, BUFFER)

/* cloud_trace.comp: with the view's froxel volume. */
#define SKY_CLOUD_TRACE_COLOR_OUT 13
#define SKY_CLOUD_TRACE_DEPTH_OUT 14
#define SKY_CLOUD_TRACE_AP_INSCATTER 15
#define SKY_CLOUD_TRACE_AP_TRANSMITTANCE 16
#define SKY_LAYOUT_CLOUD_TRACE(X)                                                         \
    SKY_LAYOUT_CLOUD_MARCH(X) X(SKY_CLOUD_TRACE_COLOR_OUT, IMAGE)                           \
    X(SKY_CLOUD_TRACE_DEPTH_OUT, IMAGE) X(SKY_CLOUD_TRACE_AP_INSCATTER, SAMPLED)            \
    X(SKY_CLOUD_TRACE_AP_TRANSMITTANCE, SAMPLED)

/* cloud_pathtrace.comp (the path-traced reference): sums of the samples so far (rgb luminance,
 * a transmittance; x depth x weight, y depth weight, z samples), the cloud image it writes
 * (as the reconstruction does), the view's froxel volume, and counters (pt_stats). */
#define SKY_CLOUD_PATHTRACE_SUM 13
#define SKY_CLOUD_PATHTRACE_DEPTH_SUM 14
#define SKY_CLOUD_PATHTRACE_COLOR_OUT 15
#define SKY_CLOUD_PATHTRACE_AP_INSCATTER 16
#define SKY_CLOUD_PATHTRACE_AP_TRANSMITTANCE 17
#define SKY_CLOUD_PATHTRACE_STATS 18
#define SKY_CLOUD_PATHTRACE_GRID 19
#define SKY_LAYOUT_CLOUD_PATHTRACE(X)                                                     \
    SKY_LAYOUT_CLOUD_MARCH(X) X(SKY_CLOUD_PATHTRACE_SUM, IMAGE)                             \
    X(SKY_CLOUD_PATHTRACE_DEPTH_SUM, IMAGE) X(SKY_CLOUD_PATHTRACE_COLOR_OUT, IMAGE)         \
    X(SKY_CLOUD_PATHTRACE_AP_INSCATTER, SAMPLED)                                           \
    X(SKY_CLOUD_PATHTRACE_AP_TRANSMITTANCE, SAMPLED) X(SKY_CLOUD_PATHTRACE_STATS, BUFFER)   \
    X(SKY_CLOUD_PATHTRACE_GRID, SAMPLED)

/* cloud_majorant.comp: the path tracer's majorant grid from the weather map, a cell per
 * invocation. */
#define SKY_CLOUD_MAJORANT_GRID_SIZE 64
#define SKY_CLOUD_MAJORANT_WEATHER 0
#define SKY_CLOUD_MAJORANT_OUT 1
#define SKY_CLOUD_MAJORANT_CLOUD 2
#define SKY_LAYOUT_CLOUD_MAJORANT(X)                                                      \
    X(SKY_CLOUD_MAJORANT_WEATHER, SAMPLED) X(SKY_CLOUD_MAJORANT_OUT, IMAGE)                 \
    X(SKY_CLOUD_MAJORANT_CLOUD, BLOCK)

/* tests/shaders/cloud_slab_selftest.comp (tests/reference/test_cloud_accuracy.c): one ray per
 * invocation. */
#define SKY_CLOUD_SLAB_LOCAL 64
#define SKY_CLOUD_SLAB_CASES 13
#define SKY_CLOUD_SLAB_RAYS 14
#define SKY_CLOUD_SLAB_RESULTS 15
#define SKY_LAYOUT_CLOUD_SLAB(X)                                                          \
    SKY_LAYOUT_CLOUD_MARCH(X) X(SKY_CLOUD_SLAB_CASES, BUFFER) X(SKY_CLOUD_SLAB_RAYS, BUFFER) \
    X(SKY_CLOUD_SLAB_RESULTS, BUFFER)

/* tests/shaders/cloud_pathtrace_selftest.comp (tests/reference/test_cloud_pathtrace_slab.c):
 * the path tracer through a homogeneous deck, one sample per invocation; the slab self-test's
 * bindings with the path tracer's counters. */
#define SKY_CLOUD_PT_SLAB_STATS 16
#define SKY_LAYOUT_CLOUD_PT_SLAB(X) SKY_LAYOUT_CLOUD_SLAB(X) X(SKY_CLOUD_PT_SLAB_STATS, BUFFER)

/* ---- per-view passes ---- */

/* cloud_reconstruct.comp */
#define SKY_CLOUD_RECONSTRUCT_FRAME 0
#define SKY_CLOUD_RECONSTRUCT_TRACE_COLOR 1
#define SKY_CLOUD_RECONSTRUCT_TRACE_DEPTH 2
#define SKY_CLOUD_RECONSTRUCT_HISTORY_COLOR 3
#define SKY_CLOUD_RECONSTRUCT_HISTORY_AUX 4
#define SKY_CLOUD_RECONSTRUCT_COLOR_OUT 5
#define SKY_CLOUD_RECONSTRUCT_AUX_OUT 6
#define SKY_LAYOUT_CLOUD_RECONSTRUCT(X)                                                   \
    X(SKY_CLOUD_RECONSTRUCT_FRAME, BLOCK) X(SKY_CLOUD_RECONSTRUCT_TRACE_COLOR, SAMPLED)     \
    X(SKY_CLOUD_RECONSTRUCT_TRACE_DEPTH, SAMPLED)                                          \
    X(SKY_CLOUD_RECONSTRUCT_HISTORY_COLOR, SAMPLED)                                        \
    X(SKY_CLOUD_RECONSTRUCT_HISTORY_AUX, SAMPLED) X(SKY_CLOUD_RECONSTRUCT_COLOR_OUT, IMAGE) \
    X(SKY_CLOUD_RECONSTRUCT_AUX_OUT, IMAGE)

/* cloud_resolve.comp; GROUND false for rows where no pixel sees the ground. */
#define SKY_CLOUD_RESOLVE_ATMOSPHERE 0
#define SKY_CLOUD_RESOLVE_FRAME 1
#define SKY_CLOUD_RESOLVE_TRANSMITTANCE 2
#define SKY_CLOUD_RESOLVE_IRRADIANCE 3
#define SKY_CLOUD_RESOLVE_CLOUD 4
#define SKY_CLOUD_RESOLVE_ENV 5
#define SKY_CLOUD_RESOLVE_SHADOW 6
#define SKY_CLOUD_RESOLVE_AP_SHAFTS 7
#define SKY_CLOUD_RESOLVE_CLOUD_COLOR 8
#define SKY_CLOUD_RESOLVE_SKY_OUT 9
#define SKY_CLOUD_RESOLVE_GROUND_OUT 10
#define SKY_CLOUD_RESOLVE_CONST_GROUND 0
#define SKY_LAYOUT_CLOUD_RESOLVE(X)                                                       \
    X(SKY_CLOUD_RESOLVE_ATMOSPHERE, BLOCK) X(SKY_CLOUD_RESOLVE_FRAME, BLOCK)                \
    X(SKY_CLOUD_RESOLVE_TRANSMITTANCE, SAMPLED) X(SKY_CLOUD_RESOLVE_IRRADIANCE, SAMPLED)    \
    X(SKY_CLOUD_RESOLVE_CLOUD, BLOCK) X(SKY_CLOUD_RESOLVE_ENV, BUFFER)                      \
    X(SKY_CLOUD_RESOLVE_SHADOW, SAMPLED) X(SKY_CLOUD_RESOLVE_AP_SHAFTS, SAMPLED)            \
    X(SKY_CLOUD_RESOLVE_CLOUD_COLOR, SAMPLED) X(SKY_CLOUD_RESOLVE_SKY_OUT, IMAGE)           \
    X(SKY_CLOUD_RESOLVE_GROUND_OUT, IMAGE)

/* ---- noise (cloud_noise.comp) ---- */

/* The base and detail volumes, a z slab per dispatch. */
#define SKY_CLOUD_NOISE_VOLUME_LOCAL 4
#define SKY_CLOUD_NOISE_VOLUME_OUT 0
#define SKY_LAYOUT_CLOUD_NOISE_VOLUME(X) X(SKY_CLOUD_NOISE_VOLUME_OUT, IMAGE)

/* The curl noise, with the blue noise it tiles. */
#define SKY_CLOUD_NOISE_CURL_BLUE 0
#define SKY_CLOUD_NOISE_CURL_OUT 1
#define SKY_LAYOUT_CLOUD_NOISE_CURL(X)                                                    \
    X(SKY_CLOUD_NOISE_CURL_BLUE, BUFFER) X(SKY_CLOUD_NOISE_CURL_OUT, IMAGE)

#endif
