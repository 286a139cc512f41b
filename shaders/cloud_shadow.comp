#version 450
#extension GL_GOOGLE_include_directive : require
// Cloud shadow map (seed 001 5.9): transmittance toward the sun through both layers from the
// ground, over the tileable weather pattern (texel = pattern position), on the coarse shape.
// The middle layer adds its optical depth to the map's (so it shadows the ground and the low
// layer). With it, the sun-space optical-depth volume that the marches read the sun's far optical
// depth from (cloud_sun_depth.glsl): along the same ray, the low layer's optical depth from its
// base up to each of SKY_CLOUD_SUN_DEPTH_LEVELS altitudes (r), and the high layer's (g).
// The wind moves the lookups, not the maps; they are rebuilt when the sun or the clouds
// change, a slice of rows per dispatch.
#include "cloud_shared.h"
#include "cloud_layouts.h"

layout(local_size_x = SKY_CLOUD_LOCAL, local_size_y = SKY_CLOUD_LOCAL) in;
SKY_PARAMETER_BLOCK(SKY_CLOUD_SHADOW_ATMOSPHERE, AtmosphereBlock, sky_atmosphere_uniforms, atmo);
SKY_PARAMETER_BLOCK(SKY_CLOUD_SHADOW_CLOUD, CloudBlock, sky_cloud_uniforms, cloud);
layout(binding = SKY_CLOUD_SHADOW_BASE_NOISE) uniform sampler3D base_noise;
layout(binding = SKY_CLOUD_SHADOW_DETAIL_NOISE) uniform sampler3D detail_noise;
layout(binding = SKY_CLOUD_SHADOW_CURL_NOISE) uniform sampler2D curl_noise;
layout(binding = SKY_CLOUD_SHADOW_WEATHER) uniform sampler2D weather_map;
layout(binding = SKY_CLOUD_SHADOW_OUT, rgba32f) uniform writeonly image2D shadow_out;
layout(binding = SKY_CLOUD_SHADOW_SUN_DEPTH_OUT, rg32f) uniform writeonly image3D sun_depth_out;
layout(push_constant) uniform RowsPush { sky_cloud_rows_push push; };

#include "atmosphere.glsl"
#include "cloud_density.glsl"

const float STEPS = 12.0;
// Steps of the low layer between two levels of the volume.
const float STEPS_PER_LEVEL = 3.0;

// The low and high layers' optical depth along the ray through one of their shells (the
// middle layer's is mid_optical_depth's).
float optical_depth(vec3 o, vec3 d, vec4 layer)
{
    float t0, t1;
    if (!shell_segment(o, d, layer.x, layer.y, t0, t1))
        return 0.0;
    t1 = min(t1, t0 + cloud.march.y);
    float ds = (t1 - t0) / STEPS, tau = 0.0;
    for (float i = 0.0; i < STEPS; i += 1.0)
        tau += cloud_extinction_low_high(o + (t0 + (i + 0.5) * ds) * d, false) * ds;
    return tau;
}

// The middle layer's own optical depth along the ray (its shell may overlap the others').
float mid_optical_depth(vec3 o, vec3 d)
{
    float t0, t1;
    if (!shell_segment(o, d, cloud.mid.x, cloud.mid.y, t0, t1))
        return 0.0;
    t1 = min(t1, t0 + cloud.march.y);
    float ds = (t1 - t0) / STEPS, tau = 0.0;
    for (float i = 0.0; i < STEPS; i += 1.0)
        tau += cloud_layer_extinction(o + (t0 + (i + 0.5) * ds) * d, false, LAYER_MID) * ds;
    return tau;
}

// The low layer's optical depth along the ray from o (on the ground) from the layer's base up
// to each level of the volume; returns the whole layer's.
float low_layer_levels(vec3 o, vec3 d, out float cumulative[SKY_CLOUD_SUN_DEPTH_LEVELS])
{
    const int levels = SKY_CLOUD_SUN_DEPTH_LEVELS;
    float t_prev = ray_sphere_far(o, d, cloud.low.x);
    float tau = 0.0;
    cumulative[0] = 0.0;
    for (int k = 1; k < levels; k++) {
        float r = mix(cloud.low.x, cloud.low.y, float(k) / float(levels - 1));
        float t = ray_sphere_far(o, d, r);
        // Beyond the longest march (a grazing sun) the layer's far stretch adds nothing.
        float t_end = min(t, t_prev + cloud.march.y);
        float ds = max(t_end - t_prev, 0.0) / STEPS_PER_LEVEL;
        for (float i = 0.0; i < STEPS_PER_LEVEL; i += 1.0)
            tau += cloud_layer_extinction(o + (t_prev + (i + 0.5) * ds) * d, false, LAYER_LOW) * ds;
        cumulative[k] = tau;
        t_prev = t;
    }
    return tau;
}

void main()
{
    atmo = atmo_block;
    cloud = cloud_block;
    ivec2 size = imageSize(shadow_out);
    ivec2 px = ivec2(gl_GlobalInvocationID.xy) + ivec2(0, int(push.row_offset));
    if (any(greaterThanEqual(px, size)))
        return;
    vec2 pattern = ((vec2(px) + 0.5) / vec2(size) - 0.5) * cloud.weather.w;
    vec2 xy = pattern + cloud.weather.xy;
    xy -= cloud.weather.w * round(xy / cloud.weather.w); // the copy nearest the camera
    float R = bottom_radius();
    vec3 ground = normalize(vec3(xy, R)) * (R + 0.002);
    vec3 sun = push.params.xyz;
    // From the ground point's own zenith: the sun is up there when it is up in the layer.
    float up = dot(sun, normalize(ground));
    float cumulative[SKY_CLOUD_SUN_DEPTH_LEVELS];
    float tau_low = 0.0;
    if (up > 0.0) {
        tau_low = low_layer_levels(ground, sun, cumulative);
    } else {
        for (int k = 0; k < SKY_CLOUD_SUN_DEPTH_LEVELS; k++)
            cumulative[k] = 0.0;
        tau_low = optical_depth(ground, sun, cloud.low);
    }
    // Weighted by cloud.high.w, not branched on: written while `cloud` was a uniform buffer,
    // whose branch-deciding values lavapipe (Mesa 22.3) inlined, compiling the shader again at
    // every slice (sky_shared.h, SKY_PARAMETER_BLOCK). The high layer is marched even when off.
    float tau_high = step(0.5, cloud.high.w) * optical_depth(ground, sun, cloud.high);
    // The middle layer: in the column's whole depth, which shadows the ground and the low layer
    // under it.
    float tau_mid = 0.0;
    if (cloud.mid.w > 0.5)
        tau_mid = mid_optical_depth(ground, sun);
    for (int k = 0; k < SKY_CLOUD_SUN_DEPTH_LEVELS; k++)
        imageStore(sun_depth_out, ivec3(px, k), vec4(cumulative[k], tau_high, 0.0, 0.0));
    float tau = tau_low + tau_mid + tau_high;
    imageStore(shadow_out, px, vec4(exp(-tau), tau, 0.0, 1.0));
}
