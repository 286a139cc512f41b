#version 450
#extension GL_GOOGLE_include_directive : require
// Transmittance LUT (Hillaire 2020 section 4; Bruneton 2008 parameterization): optical depth
// from (r, mu) to the top of the atmosphere; T = exp(-tau) (seed 001 eq. 1) is taken by the
// readers. A dispatch covers consecutive blocks of 64 texels (row-major) from block
// rows.row_offset, so that an amortized rebuild can slice it finely.
#include "sky_shared.h"
#include "sky_layouts.h"

layout(local_size_x = SKY_TRANSMITTANCE_LOCAL) in;
SKY_PARAMETER_BLOCK(SKY_TRANSMITTANCE_ATMOSPHERE, AtmosphereBlock, sky_atmosphere_uniforms, atmo);
layout(binding = SKY_TRANSMITTANCE_OUT, rgba32f) uniform writeonly image2D transmittance_out;
layout(push_constant) uniform RowsPush { sky_rows_push rows; };

#include "atmosphere.glsl"

const float STEPS = 64.0;

void main()
{
    atmo = atmo_block;
    ivec2 size = imageSize(transmittance_out);
    uint texel = (rows.row_offset + gl_WorkGroupID.x) * 64u + gl_LocalInvocationIndex;
    if (texel >= uint(size.x * size.y))
        return;
    ivec2 px = ivec2(int(texel % uint(size.x)), int(texel / uint(size.x)));
    vec2 uv = (vec2(px) + 0.5) / vec2(size);
    vec2 unit = vec2(sub_uv_to_unit(uv.x, float(size.x)), sub_uv_to_unit(uv.y, float(size.y)));
    float r, mu;
    transmittance_unit_to_r_mu(unit, r, mu);
    vec3 origin = vec3(0.0, 0.0, r);
    vec3 dir = vec3(sqrt(max(0.0, 1.0 - mu * mu)), 0.0, mu);
    float t_top = ray_sphere_nearest(origin, dir, top_radius());
    vec3 optical_depth = vec3(0.0);
    float t_prev = 0.0;
    for (float i = 0.0; i < STEPS; i += 1.0) {
        float t_next = march_boundary(0.0, t_top, i + 1.0, STEPS);
        float t = 0.5 * (t_prev + t_next);
        float h = length(origin + t * dir) - bottom_radius();
        optical_depth += sample_medium(h).extinction * (t_next - t_prev);
        t_prev = t_next;
    }
    // The LUT holds optical depth: it varies far more linearly than exp(-tau) across a texel,
    // so bilinear filtering of grazing rays stays accurate; readers take exp(-tau).
    imageStore(transmittance_out, px, vec4(optical_depth, 1.0));
}
