#version 450
#extension GL_GOOGLE_include_directive : require
// Blends the displayed atmosphere LUT from the last complete build toward a new one
// (seed 001, 3.5.1: amortized updates keep rendering with the last result, then blend).
// Also copies a LUT (weight 0 with from = the source).
#include "sky_shared.h"
#include "sky_layouts.h"

layout(local_size_x = SKY_LUT_BLEND_LOCAL, local_size_y = SKY_LUT_BLEND_LOCAL) in;
layout(binding = SKY_LUT_BLEND_FROM, rgba32f) uniform readonly image2D from_lut;
layout(binding = SKY_LUT_BLEND_TO, rgba32f) uniform readonly image2D to_lut;
layout(binding = SKY_LUT_BLEND_OUT, rgba32f) uniform writeonly image2D out_lut;
layout(push_constant) uniform BlendPush { sky_blend_push blend; };

void main()
{
    ivec2 px = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(px, imageSize(out_lut))))
        return;
    imageStore(out_lut, px, mix(imageLoad(from_lut, px), imageLoad(to_lut, px), blend.weight));
}
