#version 450
#extension GL_GOOGLE_include_directive : require
// The path tracer's majorant grid (cloud_pathtrace.glsl): per cell of a grid over the weather
// map, 1 in x (y) where the low (high) layer's coverage is positive in any texel of the 3x3
// cells around it or one texel beyond (the bilinear read's reach), else 0; in z the largest
// sheet share of the low layer's cloud there, whose density reaches 1 + z times the layer's
// (cloud_density.glsl: a deck is densest at its top); in w the height fraction of the low
// layer above which none of its columns there holds cloud (cloud_top_fraction, from the
// largest coverage and the range of types around it: a bilinear read lies between its
// texels'). The density is 0 where a layer's coverage is; the path tracer counts any sample
// that says otherwise.
#include "cloud_shared.h"
#include "cloud_layouts.h"

layout(local_size_x = SKY_CLOUD_LOCAL, local_size_y = SKY_CLOUD_LOCAL) in;
SKY_PARAMETER_BLOCK(SKY_CLOUD_MAJORANT_CLOUD, CloudBlock, sky_cloud_uniforms, cloud);
layout(binding = SKY_CLOUD_MAJORANT_WEATHER) uniform sampler2D weather_map;
layout(binding = SKY_CLOUD_MAJORANT_OUT, rgba32f) uniform writeonly image2D grid;

#include "cloud_profile.glsl"

void main()
{
    cloud = cloud_block;
    ivec2 cell = ivec2(gl_GlobalInvocationID.xy);
    ivec2 cells = imageSize(grid);
    if (any(greaterThanEqual(cell, cells)))
        return;
    ivec2 size = textureSize(weather_map, 0);
    ivec2 per_cell = max(size / cells, ivec2(1));
    ivec2 first = (cell - 1) * per_cell - 1, last = (cell + 2) * per_cell;
    vec2 flags = vec2(0.0);
    float sheet = 0.0, coverage = 0.0;
    vec2 types = vec2(1.0, 0.0); // the smallest and largest type
    for (int y = first.y; y <= last.y; y++)
        for (int x = first.x; x <= last.x; x++) {
            vec4 wm = texelFetch(weather_map, (ivec2(x, y) % size + size) % size, 0);
            flags = max(flags, vec2(greaterThan(wm.rg, vec2(0.0))));
            coverage = max(coverage, wm.r);
            types = vec2(min(types.x, wm.b), max(types.y, wm.b));
            // The share falls with the type, so a bilinear read between texels holds no more
            // than the largest texel's.
            if (wm.r > 0.0)
                sheet = max(sheet, cloud_sheet_share(wm.b));
        }
    types = clamp(types, 0.0, 1.0);
    float top = types.y > CLOUD_ANVIL_TYPE ? 1.0
                                           : cloud_top_fraction(coverage, highest_top(types.x, types.y));
    imageStore(grid, cell, vec4(flags, sheet, top));
}
