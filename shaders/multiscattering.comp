#version 450
#extension GL_GOOGLE_include_directive : require
// Multiple-scattering LUT (Hillaire 2020 section 5.2, eqs. 5-10): for each (sun cos-zenith,
// altitude), second-order luminance L2 and transfer f_ms integrated over the sphere with an
// isotropic phase, Psi_ms = L2 / (1 - f_ms). One workgroup per texel, one invocation per
// direction of an 8x8 sphere grid's half: the sun lies in the y-z plane and the atmosphere is
// spherical, so a direction and its mirror x -> -x see the same light, and the grid's azimuths
// (i + 0.5) / 8 turns pair up as i and 3 - i (mod 8); each marched direction counts twice,
// the same sum as the whole grid's. A dispatch covers consecutive texels (row-major) from
// rows.row_offset, so that an amortized rebuild can slice it finer than a row.
#include "sky_shared.h"
#include "sky_layouts.h"

layout(local_size_x = SKY_MULTISCATTERING_LOCAL) in;
SKY_PARAMETER_BLOCK(SKY_MULTISCATTERING_ATMOSPHERE, AtmosphereBlock, sky_atmosphere_uniforms, atmo);
layout(binding = SKY_MULTISCATTERING_TRANSMITTANCE) uniform sampler2D transmittance_lut;
layout(binding = SKY_MULTISCATTERING_OUT, rgba32f) uniform writeonly image2D multiscattering_out;
layout(push_constant) uniform RowsPush { sky_rows_push rows; };

#define SKY_HAS_TRANSMITTANCE_LUT
#include "atmosphere.glsl"

const float STEPS = 20.0;
shared vec3 shared_l2[SKY_MULTISCATTERING_LOCAL];
shared vec3 shared_fms[SKY_MULTISCATTERING_LOCAL];

void main()
{
    atmo = atmo_block;
    ivec2 size = imageSize(multiscattering_out);
    uint texel = rows.row_offset + gl_WorkGroupID.x;
    ivec2 px = ivec2(int(texel % uint(size.x)), int(texel / uint(size.x)));
    uint dir_index = gl_LocalInvocationIndex;
    vec2 uv = (vec2(px) + 0.5) / vec2(size);
    vec2 unit = vec2(sub_uv_to_unit(uv.x, float(size.x)), sub_uv_to_unit(uv.y, float(size.y)));
    float mu_s = unit.x * 2.0 - 1.0;
    float r = bottom_radius() + unit.y * (top_radius() - bottom_radius());
    r = clamp(r, bottom_radius() + 1e-3, top_radius() - 1e-3);
    vec3 origin = vec3(0.0, 0.0, r);
    vec3 sun_dir = vec3(0.0, sqrt(max(0.0, 1.0 - mu_s * mu_s)), mu_s);

    // Uniform sphere directions: stratified in azimuth and in cos(zenith); azimuths 0, 1, 4, 5
    // of 8 (their mirrors are 3, 2, 7, 6).
    uint azimuth = dir_index % 4u;
    float i = float(azimuth < 2u ? azimuth : azimuth + 2u), j = float(dir_index / 4u);
    float phi = 2.0 * PI * (i + 0.5) / 8.0;
    float cos_theta = 1.0 - 2.0 * (j + 0.5) / 8.0;
    float sin_theta = sqrt(max(0.0, 1.0 - cos_theta * cos_theta));
    vec3 dir = vec3(sin_theta * cos(phi), sin_theta * sin(phi), cos_theta);

    const float isotropic_phase = 1.0 / (4.0 * PI);
    vec3 l2 = vec3(0.0), fms = vec3(0.0), throughput = vec3(1.0);
    float t_start, t_end;
    bool hits_ground;
    if (atmosphere_segment(origin, dir, t_start, t_end, hits_ground)) {
        float t_prev = 0.0;
        for (float k = 0.0; k < STEPS; k += 1.0) {
            float t_next = march_boundary(0.0, t_end, k + 1.0, STEPS);
            float dt = t_next - t_prev;
            vec3 p = origin + (t_prev + 0.5 * dt) * dir;
            t_prev = t_next;
            MediumSample m = sample_medium(length(p) - bottom_radius());
            vec3 step_t = exp(-m.extinction * dt);
            vec3 ext = max(m.extinction, vec3(1e-9));
            vec3 source = sun_transmittance(p, sun_dir) * m.scattering * isotropic_phase;
            l2 += throughput * (source - source * step_t) / ext;              // seed 001 eq. 23
            fms += throughput * (m.scattering - m.scattering * step_t) / ext; // f_ms, eq. 7
            throughput *= step_t;
        }
        if (hits_ground) {
            // Lambertian ground lit by the sun, seen through the path (Hillaire 2020 eq. 6).
            vec3 p = origin + t_end * dir;
            vec3 n = normalize(p);
            l2 += throughput * sun_transmittance(p + n * 1e-3, sun_dir)
                  * max(dot(n, sun_dir), 0.0) * atmo.ground_albedo.xyz / PI;
            // The ground also returns the multiply-scattered light: under the same isotropic
            // unit source it receives pi * A and reflects albedo * A (ground_transfer.h).
            fms += throughput * atmo.ground_albedo.xyz * atmo.ground_transfer.xyz;
        }
    }
    shared_l2[dir_index] = l2;
    shared_fms[dir_index] = fms;
    barrier();
    for (uint stride = SKY_MULTISCATTERING_LOCAL / 2u; stride > 0u; stride >>= 1u) {
        if (dir_index < stride) {
            shared_l2[dir_index] += shared_l2[dir_index + stride];
            shared_fms[dir_index] += shared_fms[dir_index + stride];
        }
        barrier();
    }
    if (dir_index == 0u) {
        // Sphere integrals with an isotropic phase: 4 pi / 64 per direction times 1 / (4 pi),
        // each of the 32 marched directions twice.
        vec3 l2_total = shared_l2[0] * (2.0 / 64.0);
        vec3 fms_total = shared_fms[0] * (2.0 / 64.0);
        vec3 psi = l2_total / max(vec3(1e-6), 1.0 - fms_total); // eq. 9-10
        imageStore(multiscattering_out, px, vec4(psi, 1.0));
    }
}
