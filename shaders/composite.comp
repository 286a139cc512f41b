#version 450
#extension GL_GOOGLE_include_directive : require
// Final image: per-pixel luminance from sky_shading.glsl, exposure (EV100, manual or metered),
// tonemapping and sRGB encoding into an 8-bit image; or, with SKY_OUTPUT_LINEAR, the
// luminance itself (cd/m2) into a float image.
#include "sky_shared.h"

layout(local_size_x = 8, local_size_y = 8) in;
#include "shading_bindings.glsl"
layout(std430, binding = 8) readonly buffer ExposureBlock { vec4 metered; }; // x exposure
#ifdef SKY_OUTPUT_LINEAR
layout(binding = 9, rgba32f) uniform writeonly image2D image_out;
#else
layout(binding = 9, rgba8) uniform writeonly image2D image_out;
#endif

#include "sky_shading.glsl"
#include "tonemap.glsl"

void main()
{
    ivec2 size = imageSize(image_out);
    ivec2 px = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(px, size)))
        return;
    vec2 uv = (vec2(px) + 0.5) / vec2(size);
    vec3 luminance = shade_direction(camera_ray(uv), true, uv, true);
#ifdef SKY_OUTPUT_LINEAR
    imageStore(image_out, px, vec4(luminance, 1.0));
#else
    float exposure = frame.exposure.y > 0.5 ? metered.x : frame.exposure.x;
    vec3 color = tonemap(luminance * exposure, int(frame.exposure.w + 0.5));
    imageStore(image_out, px, vec4(linear_to_srgb(color), 1.0));
#endif
}
