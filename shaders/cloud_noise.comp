#version 450
#extension GL_GOOGLE_include_directive : require
// Tileable cloud noise from a seed (seed 001 5.4; Schneider 2015), one z slab per dispatch:
//  CLOUD_NOISE_BASE   128^3: r Perlin-Worley billows, g their lowest octave (both uniform on
//                     [0, 1]), b a Worley fBm of rising frequency
//  CLOUD_NOISE_DETAIL  32^3: r g b Worley fBm of rising frequency
//  CLOUD_NOISE_CURL   128^2: rg curl of a tileable Perlin fBm (distortion), b blue noise
//                     (void-and-cluster, render/cloud_noise.c) tiled from the input buffer
#include "cloud_shared.h"
#include "cloud_layouts.h"

layout(push_constant) uniform NoisePush { sky_cloud_noise_push push; };

#ifdef CLOUD_NOISE_CURL
layout(local_size_x = SKY_CLOUD_LOCAL, local_size_y = SKY_CLOUD_LOCAL) in;
layout(std430, binding = SKY_CLOUD_NOISE_CURL_BLUE) readonly buffer BlueNoise { float blue[]; };
layout(binding = SKY_CLOUD_NOISE_CURL_OUT, rgba32f) uniform writeonly image2D noise_out;
const int BLUE_SIZE = 64;
#else
layout(local_size_x = SKY_CLOUD_NOISE_VOLUME_LOCAL, local_size_y = SKY_CLOUD_NOISE_VOLUME_LOCAL,
       local_size_z = SKY_CLOUD_NOISE_VOLUME_LOCAL) in;
layout(binding = SKY_CLOUD_NOISE_VOLUME_OUT, rgba8) uniform writeonly image3D noise_out;
#endif

#define noise_seed push.seed
#include "cloud_noise_lib.glsl"

float remap01(float v, float lo, float hi)
{
    return (v - lo) / max(hi - lo, 1e-5);
}

#ifdef CLOUD_NOISE_BASE
// Quantiles of the billows at probabilities 0.002, 1/16 .. 15/16, 0.998, measured over 60 000
// points of four seeds by tests/tools/measure_cloud_noise.py (a port of cloud_noise_lib.glsl);
// they vary between seeds by less than 0.003.
const int QUANTILES = 17;
const float FULL_QUANTILES[QUANTILES] = float[](
    0.4522, 0.5479, 0.5786, 0.6000, 0.6179, 0.6328, 0.6464, 0.6591, 0.6714, 0.6835, 0.6960,
    0.7083, 0.7221, 0.7377, 0.7570, 0.7845, 0.8665);
const float LOW_QUANTILES[QUANTILES] = float[](
    0.4256, 0.5433, 0.5780, 0.5999, 0.6185, 0.6342, 0.6486, 0.6607, 0.6720, 0.6828, 0.6941,
    0.7059, 0.7193, 0.7335, 0.7516, 0.7769, 0.8502);

// The distribution function through the quantiles, linear between them.
float probability_of(float v, const float q[QUANTILES])
{
    if (v <= q[0])
        return 0.002 * clamp(v / q[0], 0.0, 1.0);
    for (int i = 1; i < QUANTILES; i++) {
        if (v < q[i]) {
            float p0 = i == 1 ? 0.002 : float(i - 1) / 16.0;
            float p1 = i == QUANTILES - 1 ? 0.998 : float(i) / 16.0;
            return mix(p0, p1, (v - q[i - 1]) / (q[i] - q[i - 1]));
        }
    }
    return mix(0.998, 1.0, clamp((v - q[QUANTILES - 1]) / (1.0 - q[QUANTILES - 1]), 0.0, 1.0));
}

float uniform_full(float v)
{
    return probability_of(v, FULL_QUANTILES);
}

float uniform_low(float v)
{
    return probability_of(v, LOW_QUANTILES);
}

// One octave of perlin_fbm's, scaled as perlin_fbm scales its sum.
float perlin_octave(vec3 x, int period, uint salt)
{
    return clamp(0.5 * gradient_noise(x, period, salt) / 0.875 * 0.5 + 0.5, 0.0, 1.0);
}
#endif

void main()
{
#ifdef CLOUD_NOISE_CURL
    ivec2 size = imageSize(noise_out);
    ivec2 px = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(px, size)))
        return;
    vec3 x = vec3((vec2(px) + 0.5) / vec2(size), 0.5);
    float e = 0.5 / float(size.x);
    float dx = perlin_fbm(x + vec3(e, 0, 0), 4, 31u) - perlin_fbm(x - vec3(e, 0, 0), 4, 31u);
    float dy = perlin_fbm(x + vec3(0, e, 0), 4, 31u) - perlin_fbm(x - vec3(0, e, 0), 4, 31u);
    vec2 curl = vec2(dy, -dx) / (2.0 * e) / 8.0; // about unit magnitude
    float b = blue[(px.y % BLUE_SIZE) * BLUE_SIZE + (px.x % BLUE_SIZE)];
    imageStore(noise_out, px, vec4(clamp(curl, -1.0, 1.0), b, 1.0));
#else
    ivec3 size = imageSize(noise_out);
    ivec3 id = ivec3(gl_GlobalInvocationID) + ivec3(0, 0, int(push.z_offset));
    if (any(greaterThanEqual(id, size)))
        return;
    vec3 x = (vec3(id) + 0.5) / vec3(size);
    float w1 = worley(x, 4, 1u), w2 = worley(x, 8, 2u), w3 = worley(x, 16, 3u);
    float fbm_low = w1 * 0.625 + w2 * 0.25 + w3 * 0.125;
#ifdef CLOUD_NOISE_BASE
    float w4 = worley(x, 32, 4u);
    // Perlin-Worley billows (Schneider 2015): Perlin fBm remapped by the Worley fBm; r all
    // three octaves (cells of a quarter, an eighth and a sixteenth of the tile: cumulus turrets),
    // g the lowest alone (the level of detail of far and sheet clouds). Both stored through
    // their distribution function, uniform on [0, 1], so that cloud_density.glsl's coverage c
    // keeps the fraction c of the volume above 1 - c.
    float billows = clamp(remap01(perlin_fbm(x, 4, 9u), fbm_low - 1.0, 1.0), 0.0, 1.0);
    float billows_low = clamp(remap01(perlin_octave(x, 4, 9u), w1 - 1.0, 1.0), 0.0, 1.0);
    vec4 v = vec4(uniform_full(billows), uniform_low(billows_low), fbm_low,
                  w2 * 0.625 + w3 * 0.25 + w4 * 0.125);
#else
    float w4 = worley(x, 32, 4u);
    vec4 v = vec4(fbm_low * 0.8 + 0.1 * w1, w2 * 0.625 + w3 * 0.25 + w4 * 0.125,
                  w3 * 0.75 + w4 * 0.25, 1.0);
#endif
    imageStore(noise_out, id, clamp(v, 0.0, 1.0));
#endif
}
