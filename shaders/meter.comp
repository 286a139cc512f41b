#version 450
#extension GL_GOOGLE_include_directive : require
// Auto-exposure metering: shades a coarse grid over the view with the frame's own shading
// and writes, per workgroup, the sum of log2(luminance) and the sample count.
#include "sky_shared.h"
#include "sky_layouts.h"

layout(local_size_x = SKY_METER_LOCAL, local_size_y = SKY_METER_LOCAL) in;
#include "shading_bindings.glsl"
layout(std430, binding = SKY_METER_PARTIALS) writeonly buffer Partials { vec2 partials[]; };
layout(push_constant) uniform MeterPush { sky_meter_push meter; };

#include "sky_shading.glsl"

shared vec2 shared_sum[SKY_METER_LOCAL * SKY_METER_LOCAL];

void main()
{
    atmo = atmo_block;
    frame = frame_block;
    uvec2 px = gl_GlobalInvocationID.xy;
    vec2 value = vec2(0.0);
    if (px.x < meter.grid_width && px.y < meter.grid_height) {
        vec2 uv = (vec2(px) + 0.5) / vec2(meter.grid_width, meter.grid_height);
        vec3 L = shade_direction(camera_ray(uv), true);
        float Y = dot(L, vec3(0.2126, 0.7152, 0.0722));
        // Empty space (exactly black) carries no exposure information: leave it out. Each
        // sample counts for its solid angle (a panorama's polar rows are small).
        float w = camera_pixel_weight(uv);
        value = Y > 1e-7 ? w * vec2(log2(Y), 1.0) : vec2(0.0);
    }
    uint li = gl_LocalInvocationIndex;
    shared_sum[li] = value;
    barrier();
    for (uint stride = (SKY_METER_LOCAL * SKY_METER_LOCAL) / 2u; stride > 0u; stride >>= 1u) {
        if (li < stride)
            shared_sum[li] += shared_sum[li + stride];
        barrier();
    }
    if (li == 0u) {
        uint group = gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x;
        partials[group] = shared_sum[0];
    }
}
