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
// cumulus, the tower of a cumulonimbus). Each cloud type has its own pattern and cell scale
// (render/cloud_params.c): stratus a near-uniform sheet, stratocumulus closed cells with thin
// clear borders, cumulus clumps of about 0.5-2 km, cumulonimbus towers about 10 km apart. A
// clump field is a sum of octaves of gradient noise (fBm, Hurst exponent about 0.5, so that its
// level sets have outlines of dimension about 1.35 as real clouds do: Lovejoy 1982) with round
// maxima (so cores are domes, not cones), thresholded at the quantile that leaves the asked
// coverage. Only the types present at a texel are evaluated.
#include "cloud_shared.h"
#include "cloud_layouts.h"

layout(local_size_x = SKY_CLOUD_LOCAL, local_size_y = SKY_CLOUD_LOCAL) in;
layout(binding = SKY_CLOUD_WEATHER_CLIENT_MAP) uniform sampler2D client_map;
layout(binding = SKY_CLOUD_WEATHER_OUT, rgba32f) uniform writeonly image2D weather_out;
layout(push_constant) uniform RowsPush { sky_cloud_rows_push push; };

#define noise_seed push.seed
#include "cloud_noise_lib.glsl"

// Cells across the map per cloud type (render/cloud_renderer.c: whole numbers, so the map
// tiles, chosen from the extent): x cumulus, y cumulonimbus, z stratocumulus, w stratus.
#define PERIODS push.size

// Deviation of one octave of gradient2() over the plane, and the mean and deviation of
// worley2() (measured over 3 seeds x 1024^2 texels).
const float OCTAVE_SIGMA = 0.2144;
const float WORLEY_MEAN = 0.5706, WORLEY_SIGMA = 0.1893;

// Octaves with fewer texels a cell than this fade out (gone at half of it): finer noise would
// change from texel to texel, and the bilinear lookup of such a map draws clouds whose outlines
// are stair steps one texel (117 m) high. The outlines' finer roughness comes from the 3D
// billows (cloud_density.glsl).
const float MIN_TEXELS_PER_CELL = 4.0;

// fBm of `octaves` octaves of gradient2 starting at `period` cells, amplitudes falling by
// 2^-hurst per octave, in units of its own deviation (mean 0, deviation about 1). texels: the
// map's width.
float fbm2(vec2 x, ivec2 period, uint salt, int octaves, float hurst, float texels)
{
    float sum = 0.0, power = 0.0, amp = 1.0;
    for (int o = 0; o < octaves; o++) {
        ivec2 cells = period << o;
        float resolved = texels / float(max(cells.x, cells.y));
        float a = amp * clamp(2.0 * resolved / MIN_TEXELS_PER_CELL - 1.0, 0.0, 1.0);
        if (a > 0.0)
            sum += a * gradient2(x, cells, salt + uint(o));
        power += a * a;
        amp *= exp2(-hurst);
    }
    return sum / (OCTAVE_SIGMA * sqrt(max(power, 1e-12)));
}

// Deviations of the field past the threshold over which a cumulus reaches the layer's full
// height: a clump's peak rises about 1 deviation above it, and its column rises as the square
// root of the footprint (cloud_density.glsl), so most fair cumulus are half as tall as wide to
// as tall as wide (humilis to mediocris) and only the largest fill the layer. Cumulonimbus
// cores reach the top sooner: towers.
const float CUMULUS_RAMP = 3.5, TOWER_RAMP = 3.0;
// Stratocumulus cells and stratus sheets reach their (low) tops just inside their edges.
const float CELL_RAMP = 0.8, SHEET_RAMP = 0.4;

// mix(a, b, t) of two independent fields of deviation 1, scaled back to deviation 1.
float blend(float a, float b, float t)
{
    return mix(a, b, t) / sqrt((1.0 - t) * (1.0 - t) + t * t);
}

// The normal quantile of 1 - coverage (logistic approximation of the probit).
float threshold_for(float coverage)
{
    coverage = clamp(coverage, 1e-4, 1.0 - 1e-4);
    return log((1.0 - coverage) / coverage) / 1.702;
}

// Footprint of a field of deviation 1 thresholded so that about `coverage` of the map is
// inside, rising to 1 over `ramp` deviations past the threshold. Stored signed: outside the
// cloud it goes on falling to -1, and the lookup clamps it at 0 (cloud_density.glsl). The
// bilinear lookup of a footprint clamped here would be positive over whole squares between
// texel centres around every texel inside a cloud, and outlines would follow their edges: stair
// steps of one texel.
float footprint(float field, float coverage, float ramp)
{
    if (coverage <= 0.0)
        return -1.0;
    if (coverage >= 1.0)
        return 1.0;
    return clamp((field - threshold_for(coverage)) / ramp, -1.0, 1.0);
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
    float texels = float(size.x);
    if (push.mode == 1u) {
        // Client rows run from the north edge southward; map rows from the south.
        imageStore(weather_out, px, textureLod(client_map, vec2(x.x, 1.0 - x.y), 0.0));
        return;
    }
    vec4 p = push.params;
    int cu_period = int(PERIODS.x), cb_period = int(PERIODS.y);
    int sc_period = int(PERIODS.z), st_period = int(PERIODS.w);
    // The type varies from cloud to cloud around the asked one (cumulus of several ages).
    float type = clamp(p.z + gradient2(x, ivec2(max(1, cu_period / 4)), 14u) * 0.3, 0.0, 1.0);
    vec4 w = type_weights(type);
    // The fields of the types present, blended with their weights (each has deviation 1, and
    // so has the blend), thresholded once: a sum of thresholded fields would cover their union.
    float low = 0.0;
    if (p.x > 0.0) {
        float field = 0.0, ramp = 0.0;
        // Clusters a few cells wide (cloud streets and groups) shift the clump fields.
        float cluster = gradient2(x, ivec2(max(1, cu_period / 6)), 15u) / OCTAVE_SIGMA;
        if (w.z > 0.0) { // cumulus: round clumps of many sizes
            field += w.z * blend(fbm2(x, ivec2(cu_period), 11u, 4, 0.8, texels), cluster, 0.25);
            ramp += w.z * CUMULUS_RAMP;
        }
        if (w.w > 0.0) { // cumulonimbus: few big cells whose cores are towers
            field += w.w * blend(fbm2(x, ivec2(cb_period), 21u, 4, 0.6, texels), cluster, 0.15);
            ramp += w.w * TOWER_RAMP;
        }
        if (w.y > 0.0) {
            // Stratocumulus: closed cells (inverted cellular noise is high at a cell's centre
            // and low along its borders), roughened.
            float cells = (worley2(x, sc_period, 31u) - WORLEY_MEAN) / WORLEY_SIGMA;
            field += w.y * blend(cells, gradient2(x, ivec2(sc_period * 2), 32u) / OCTAVE_SIGMA,
                                 0.35);
            ramp += w.y * CELL_RAMP;
        }
        if (w.x > 0.0) { // stratus: a sheet with gentle variations and ragged gaps
            field += w.x * fbm2(x, ivec2(st_period), 41u, 3, 0.5, texels);
            ramp += w.x * SHEET_RAMP;
        }
        low = footprint(field / length(w), p.x, ramp);
    }
    // The high layer: cirrostratus a veil of gentle variations (type 0), cirrus streaks ten
    // times longer east-west than wide (type 1).
    float high = 0.0;
    if (p.y > 0.0) {
        float fibrous = float(push.high_fibrous) / 1000.0;
        float veil = fbm2(x, ivec2(6), 13u, 3, 0.5, texels);
        float streaks = fbm2(x, ivec2(3, 30), 16u, 4, 0.4, texels);
        high = footprint(blend(veil, streaks, fibrous), p.y, 0.6);
        high *= mix(0.55, 1.0, p.y);
    }
    float rain = p.w * smoothstep(0.3, 0.9, low);
    imageStore(weather_out, px, vec4(low, high, type, rain));
}
