#version 450
#extension GL_GOOGLE_include_directive : require
// Weather map (seed 001 5.3): r low-layer coverage, g high-layer coverage, b low-layer cloud
// type, a precipitation; tileable over weather.map_extent_km (the wind shifts the lookup, not
// the map). Procedural from the layer parameters and the weather seed, or resampled from a
// client's map. Written a slice of rows per dispatch so rebuilds spread over frames.
#include "cloud_shared.h"

layout(local_size_x = 8, local_size_y = 8) in;
layout(binding = 0) uniform sampler2D client_map;
layout(binding = 1, rgba8) uniform writeonly image2D weather_out;
layout(push_constant) uniform RowsPush { sky_cloud_rows_push push; };

#define noise_seed push.seed
#include "cloud_noise_lib.glsl"

float fbm2(vec2 x, int period, uint salt)
{
    return perlin_fbm(vec3(x, 0.37), period, salt);
}

const float FIELD_SIGMA = 0.11;

float clump(float field, float coverage)
{
    if (coverage <= 0.0)
        return 0.0;
    if (coverage >= 1.0)
        return 1.0;
    float threshold = 0.5 + FIELD_SIGMA * log((1.0 - coverage) / coverage) / 1.702;
    float inside = clamp((field - threshold) / 0.06, 0.0, 1.0);
    return inside * mix(0.55, 1.0, coverage);
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
    // Clumps of cloud covering about the asked fraction of the map: the clump field is near
    // normal (mean 0.5, deviation FIELD_SIGMA), so thresholding it at its (1 - coverage)
    // quantile (logistic approximation of the probit) covers that fraction; inside a clump
    // the local coverage rises toward 1 so overcast is overcast.
    float field = mix(fbm2(x, 4, 11u), worley(vec3(x, 0.5), 6, 12u), 0.35);
    float low = clump(field, p.x);
    float high = clump(fbm2(x, 3, 13u), p.y);
    float type = clamp(p.z + (fbm2(x, 2, 14u) - 0.5) * 0.25, 0.0, 1.0);
    float rain = p.w * smoothstep(0.3, 0.9, low);
    imageStore(weather_out, px, vec4(low, high, type, rain));
}
