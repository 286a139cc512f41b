#version 450
#extension GL_GOOGLE_include_directive : require
// Cloud shadow map (seed 001 5.9): transmittance toward the sun through both layers from the
// ground, over the tileable weather pattern (texel = pattern position), on the coarse shape.
// The wind moves the lookup, not the map; it is rebuilt when the sun or the clouds change, a
// slice of rows per dispatch.
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
layout(push_constant) uniform RowsPush { sky_cloud_rows_push push; };

#include "atmosphere.glsl"
#include "cloud_density.glsl"

const float STEPS = 12.0;

float optical_depth(vec3 o, vec3 d, vec4 layer)
{
    float t0, t1;
    if (!shell_segment(o, d, layer.x, layer.y, t0, t1))
        return 0.0;
    t1 = min(t1, t0 + cloud.march.y);
    float ds = (t1 - t0) / STEPS, tau = 0.0;
    for (float i = 0.0; i < STEPS; i += 1.0)
        tau += cloud_extinction(o + (t0 + (i + 0.5) * ds) * d, false) * ds;
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
    vec3 sun = cloud.shadow_sun.xyz;
    float tau = optical_depth(ground, sun, cloud.low);
    // Weighted by cloud.high.w, not branched on: written while `cloud` was a uniform buffer,
    // whose branch-deciding values lavapipe (Mesa 22.3) inlined, compiling the shader again at
    // every slice (sky_shared.h, SKY_PARAMETER_BLOCK). The high layer is marched even when off.
    tau += step(0.5, cloud.high.w) * optical_depth(ground, sun, cloud.high);
    imageStore(shadow_out, px, vec4(exp(-tau), tau, 0.0, 1.0));
}
