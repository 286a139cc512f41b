#version 450
#extension GL_GOOGLE_include_directive : require
// Tileable cloud noise from a seed (seed 001 5.4; Schneider 2015), one z slab per dispatch:
//  CLOUD_NOISE_BASE   128^3: r Perlin-Worley, g b a Worley fBm of rising frequency
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
    float w4 = worley(x, 32, 4u), w5 = worley(x, 64, 5u);
    // Perlin-Worley: Perlin fBm remapped by the low Worley fBm (Schneider 2015).
    float perlin = perlin_fbm(x, 4, 9u);
    float perlin_worley = clamp(remap01(perlin, fbm_low - 1.0, 1.0), 0.0, 1.0);
    vec4 v = vec4(perlin_worley, fbm_low, w2 * 0.625 + w3 * 0.25 + w4 * 0.125,
                  w3 * 0.625 + w4 * 0.25 + w5 * 0.125);
#else
    float w4 = worley(x, 32, 4u);
    vec4 v = vec4(fbm_low * 0.8 + 0.1 * w1, w2 * 0.625 + w3 * 0.25 + w4 * 0.125,
                  w3 * 0.75 + w4 * 0.25, 1.0);
#endif
    imageStore(noise_out, id, clamp(v, 0.0, 1.0));
#endif
}
