#version 450
#extension GL_GOOGLE_include_directive : require
// Final image: per-pixel luminance from sky_shading.glsl under the clouds (cloud_resolve.comp),
// exposure (EV100, manual or metered), tonemapping and sRGB encoding into an 8-bit image; or, with SKY_OUTPUT_LINEAR, the
// luminance itself (cd/m2) into a float image. Covers the pixel rectangle in the push
// constants. Specialized with SUN_REGION it is the sun-disk pass: the same shading with the
// sun included, run only over the sun's bounding box after the main pass.
#include "sky_shared.h"
#include "sky_layouts.h"

layout(local_size_x = SKY_COMPOSITE_LOCAL, local_size_y = SKY_COMPOSITE_LOCAL) in;
#include "shading_bindings.glsl"
layout(std430, binding = SKY_COMPOSITE_EXPOSURE) readonly buffer ExposureBlock { vec4 metered; }; // x exposure
#ifdef SKY_OUTPUT_LINEAR
layout(binding = SKY_COMPOSITE_OUT, rgba32f) uniform writeonly image2D image_out;
#else
layout(binding = SKY_COMPOSITE_OUT, rgba8) uniform writeonly image2D image_out;
#endif
// The clouds' effect on a pixel as (rgb, a), applied as L (1 - a) + rgb (cloud_resolve.comp):
// for pixels that see the sky, and for those that see the ground.
layout(binding = SKY_COMPOSITE_CLOUDS_OVER_SKY) uniform sampler2D clouds_over_sky;
layout(binding = SKY_COMPOSITE_CLOUDS_OVER_GROUND) uniform sampler2D clouds_over_ground;
layout(push_constant) uniform RegionPush { sky_region_push region; };
layout(constant_id = SKY_CONST_SUN_REGION) const bool SUN_REGION = false;
// False without a cloud layer; GROUND false where no pixel of the dispatch sees the ground
// (render/composite_variants.h: lavapipe runs every branch, so only leaving code out saves
// its cost).
layout(constant_id = SKY_CONST_CLOUDS) const bool CLOUDS = true;
layout(constant_id = SKY_CONST_GROUND) const bool GROUND = true;

#include "sky_shading.glsl"
#include "tonemap.glsl"

// The clouds over the shaded luminance L. The cloud images may be half the output's size:
// bilinear on their premultiplied colour.
vec3 apply_clouds(ivec2 px, vec3 dir, vec3 L)
{
    if (!CLOUDS)
        return L;
    // Their texels past their size (up to their extent) are never reached: the last one in
    // use stands for the edge, as clamp-to-edge would.
    vec2 texels = region.clouds.xy;
    vec2 uv = min((vec2(px) + 0.5) / frame.image.xy * texels, texels - 0.5)
              / vec2(textureSize(clouds_over_sky, 0));
    vec4 c = textureLod(clouds_over_sky, uv, 0.0);
    if (GROUND && !FROM_SPACE && dir.z < frame.horizon.z)
        c = textureLod(clouds_over_ground, uv, 0.0);
    return max(L * (1.0 - c.a) + c.rgb, vec3(0.0));
}

void main()
{
    atmo = atmo_block;
    frame = frame_block;
    ivec2 size = ivec2(frame.image.xy); // the image's extent may be larger
    // Lanes past the rectangle redo its last pixel rather than branch on the push constants:
    // lavapipe compiles a variant per value of a uniform that a branch depends on, which
    // recompiled the sun-disk pass whenever its rectangle moved.
    ivec2 last = min(region.rect.xy + region.rect.zw, size) - 1;
    ivec2 px = min(region.rect.xy + ivec2(gl_GlobalInvocationID.xy), last);
    vec2 uv = (vec2(px) + 0.5) / vec2(size);
    // From space the march adds the sun itself; inside, only the sun-region pass does.
    vec3 dir = camera_ray(uv);
    vec3 luminance = apply_clouds(px, dir, shade_direction(dir, SUN_REGION || FROM_SPACE));
#ifdef SKY_OUTPUT_LINEAR
    imageStore(image_out, px, vec4(luminance, 1.0));
#else
    float exposure = mix(frame.exposure.x, metered.x, step(0.5, frame.exposure.y));
    vec3 color = tonemap(luminance * exposure, int(frame.exposure.w + 0.5));
    imageStore(image_out, px, vec4(linear_to_srgb(color), 1.0));
#endif
}
