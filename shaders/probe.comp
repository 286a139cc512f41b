#version 450
#extension GL_GOOGLE_include_directive : require
// Probes for `skyd probe`: per input, luminance (cd/m2) in a view direction through the same
// shading as frames, or transmittance from (radius, mu) to the top of the atmosphere.
#include "sky_shared.h"
#include "sky_layouts.h"

layout(local_size_x = SKY_PROBE_LOCAL) in;
#include "shading_bindings.glsl"
layout(std430, binding = SKY_PROBE_IN) readonly buffer ProbeIn { vec4 probe_in[]; };
layout(std430, binding = SKY_PROBE_OUT) writeonly buffer ProbeOut { vec4 probe_out[]; };
layout(push_constant) uniform ProbePush { sky_probe_push probe; };

#include "sky_shading.glsl"

void main()
{
    atmo = atmo_block;
    frame = frame_block;
    uint i = gl_GlobalInvocationID.x;
    if (i >= probe.count)
        return;
    vec4 q = probe_in[i];
    vec3 value;
    if (probe.mode == SKY_PROBE_TRANSMITTANCE)
        value = transmittance_to_top(q.x, q.y); // q.x radius km, q.y cos-zenith
    else
        value = shade_direction(normalize(q.xyz), probe.mode == SKY_PROBE_LUMINANCE);
    probe_out[i] = vec4(value, 0.0);
}
