#version 450
#extension GL_GOOGLE_include_directive : require
// Final image: per-pixel luminance from sky_shading.glsl, exposure (EV100, manual or metered),
// tonemapping and sRGB encoding into an 8-bit image; or, with SKY_OUTPUT_LINEAR, the
// luminance itself (cd/m2) into a float image. Covers the pixel rectangle in the push
// constants. Specialized with SUN_REGION it is the sun-disk pass: the same shading with the
// sun included, run only over the sun's bounding box after the main pass.
#include "sky_shared.h"
#include "cloud_shared.h"

layout(local_size_x = 8, local_size_y = 8) in;
#include "shading_bindings.glsl"
layout(std430, binding = 8) readonly buffer ExposureBlock { vec4 metered; }; // x exposure
#ifdef SKY_OUTPUT_LINEAR
layout(binding = 9, rgba32f) uniform writeonly image2D image_out;
#else
layout(binding = 9, rgba8) uniform writeonly image2D image_out;
#endif
layout(binding = 10) uniform sampler2D cloud_image;      // premultiplied luminance, opacity
layout(binding = 11) uniform sampler2D cloud_shadow_map; // r: transmittance toward the sun
layout(std140, binding = 12) uniform CloudBlock { sky_cloud_uniforms cloud; };
layout(std430, binding = 13) readonly buffer CloudEnv { vec4 env_luminance; vec4 env_transmittance; };
layout(binding = 14) uniform sampler3D ap_shafts; // in-scattering taken by cloud shadows
layout(push_constant) uniform RegionPush { sky_region_push region; };
layout(constant_id = 1) const bool SUN_REGION = false;

#include "sky_shading.glsl"
#include "tonemap.glsl"
#include "cloud_composite.glsl"

void main()
{
    ivec2 size = imageSize(image_out);
    ivec2 local = ivec2(gl_GlobalInvocationID.xy);
    ivec2 px = region.rect.xy + local;
    if (any(greaterThanEqual(local, region.rect.zw)) || any(greaterThanEqual(px, size)))
        return;
    vec2 uv = (vec2(px) + 0.5) / vec2(size);
    // From space the march adds the sun itself; inside, only the sun-region pass does.
    vec3 dir = camera_ray(uv);
    vec3 luminance = apply_clouds(px, dir, shade_direction(dir, SUN_REGION || FROM_SPACE));
#ifdef SKY_OUTPUT_LINEAR
    imageStore(image_out, px, vec4(luminance, 1.0));
#else
    float exposure = frame.exposure.y > 0.5 ? metered.x : frame.exposure.x;
    vec3 color = tonemap(luminance * exposure, int(frame.exposure.w + 0.5));
    imageStore(image_out, px, vec4(linear_to_srgb(color), 1.0));
#endif
}
