#version 450
#extension GL_GOOGLE_include_directive : require
// Weather map (seed 001 5.3; Schneider 2015/2017): r low-layer footprint, g high-layer
// coverage, b low-layer cloud type, a precipitation; tileable over weather.map_extent_km (the
// wind shifts the lookup, not the map). Procedural from the layer parameters and the weather
// seed, or resampled from a client's map. Written a slice of rows per dispatch so rebuilds
// spread over frames.
//
// The footprint is what cloud_density.glsl builds a cloud's column from: 0 outside a cloud,
// rising toward 1 in its core, where the cloud reaches its type's full height (the dome of a
// cumulus, the tower of a cumulonimbus). Each cloud type has its own cell scale: stratus a
// near-uniform sheet, stratocumulus closed cells about 1.5 km across with thin clear borders,
// cumulus clumps of about 1-3 km, cumulonimbus towers about 8-12 km apart. A clump field is a
// sum of octaves (fBm, Hurst exponent about 0.65, so that its level sets have outlines of
// dimension about 1.35 as real clouds do: Lovejoy 1982), thresholded at the quantile that
// leaves the asked coverage.
#include "cloud_shared.h"

layout(local_size_x = 8, local_size_y = 8) in;
layout(binding = 0) uniform sampler2D client_map;
layout(binding = 1, rgba32f) uniform writeonly image2D weather_out;
layout(push_constant) uniform RowsPush { sky_cloud_rows_push push; };

#define noise_seed push.seed
#include "cloud_noise_lib.glsl"

// Cells across the map per cloud type (render/cloud_renderer.c: whole numbers, so the map
// tiles, chosen from the extent): x cumulus, y cumulonimbus, z stratocumulus, w stratus.
#define PERIODS push.size

// One octave of gradient noise in [0, 1].
float perlin01(vec2 x, int period, uint salt)
{
    return clamp(gradient_noise(vec3(x, 0.37), period, salt) * 0.5 + 0.5, 0.0, 1.0);
}

// fBm of `octaves` octaves starting at `period` cells, amplitudes falling by 2^-H per octave;
// normalized to about mean 0.5, deviation 0.5 * deviation of one octave.
float clump_fbm(vec2 x, int period, uint salt, int octaves, float hurst)
{
    float sum = 0.0, norm = 0.0, amp = 1.0;
    for (int o = 0; o < octaves; o++) {
        float n = o == 0 ? worley(vec3(x, 0.5), period, salt)
                         : perlin01(x, period << o, salt + uint(o));
        sum += amp * n;
        norm += amp;
        amp *= exp2(-hurst);
    }
    return sum / norm;
}

// Footprint of a field of mean `mean` and deviation `sigma` thresholded so that about
// `coverage` of the map is inside (logistic approximation of the normal quantile), rising to
// 1 over `ramp` of the field past the threshold.
float footprint(float field, float coverage, float mean, float sigma, float ramp)
{
    if (coverage <= 0.0)
        return 0.0;
    if (coverage >= 1.0)
        return 1.0;
    float threshold = mean + sigma * log((1.0 - coverage) / coverage) / 1.702;
    return clamp((field - threshold) / ramp, 0.0, 1.0);
}

// Weights of the four tabulated types (stratus, stratocumulus, cumulus, cumulonimbus) at
// type t: tents over 0, 1/3, 2/3 and 1.
vec4 type_weights(float t)
{
    vec4 centres = vec4(0.0, 1.0, 2.0, 3.0) / 3.0;
    return max(vec4(0.0), 1.0 - abs(vec4(t) - centres) * 3.0);
}

void main()
{
    ivec2 size = imageSize(weather_out);
    ivec2 px = ivec2(gl_GlobalInvocationID.xy) + ivec2(0, int(push.row_offset));
    if (any(greaterThanEqual(px, size)))
        return;
    vec2 x = (vec2(px) + 0.5) / vec2(size);
    if (push.mode == 1u) {
        // Client rows run from the north edge southward; map rows from the south.
        imageStore(weather_out, px, textureLod(client_map, vec2(x.x, 1.0 - x.y), 0.0));
        return;
    }
    vec4 p = push.params;
    int cu_period = int(PERIODS.x), cb_period = int(PERIODS.y);
    int sc_period = int(PERIODS.z), st_period = int(PERIODS.w);
    // The type varies from cloud to cloud around the asked one (cumulus of several ages).
    float type = clamp(p.z + (perlin01(x, cu_period, 14u) - 0.5) * 0.3, 0.0, 1.0);
    vec4 w = type_weights(type);
    // Cumulus: clumps clustered by a field a few cells wide (cloud streets and clusters).
    float cluster = perlin01(x, max(1, cu_period / 6), 15u);
    float cu_field = mix(clump_fbm(x, cu_period, 11u, 4, 0.65), cluster, 0.3);
    float cu = footprint(cu_field, p.x, 0.5, 0.085, 0.06);
    // Cumulonimbus: few big cells whose cores are towers.
    float cb_field = mix(clump_fbm(x, cb_period, 21u, 4, 0.65), cluster, 0.15);
    float cb = footprint(cb_field, p.x, 0.5, 0.085, 0.22);
    // Stratocumulus: closed cells (inverted cellular noise is 1 at a cell's centre and low
    // along its borders), roughened.
    float sc_field = mix(worley(vec3(x, 0.5), sc_period, 31u), perlin01(x, sc_period * 2, 32u),
                         0.35);
    float sc = footprint(sc_field, p.x, 0.56, 0.09, 0.12);
    // Stratus: a sheet with gentle variations and ragged gaps below full coverage.
    float st_field = clump_fbm(x, st_period, 41u, 3, 0.5);
    float st = footprint(st_field, p.x, 0.5, 0.07, 0.05);
    float low = dot(w, vec4(st, sc, cu, cb));
    float high = footprint(perlin_fbm(vec3(x, 0.37), 3, 13u), p.y, 0.5, 0.11, 0.06);
    high *= mix(0.55, 1.0, p.y);
    float rain = p.w * smoothstep(0.3, 0.9, low);
    imageStore(weather_out, px, vec4(low, high, type, rain));
}
