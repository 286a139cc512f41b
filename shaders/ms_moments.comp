#version 450
#extension GL_GOOGLE_include_directive : require
// Converged multiple scattering, the second moments of one order's radiance for Rayleigh's
// part of the next order's scattering density. Rayleigh's phase is a quadratic in the cosine,
// p(v . w) = 3 / (16 pi) (1 + (v . w)^2), so its integral against the radiance is
//   integral of p(v . w) L(w) dw = 3 / (16 pi) (tr M + v^T M v),   M = integral of w w^T L(w) dw
// (Bruneton & Neyret 2008 eq. 4 with the phase expanded): M depends on the altitude and the
// sun only, so one integral per (r, mu_s) serves every view direction and view-sun angle of the
// 4D table. With the sun in the xz plane L is even in y, so M_xy = M_yz = 0; stored: M_xx, M_yy,
// M_zz, M_xz in four texels of a row per altitude. The rule: each hemisphere apart (the
// radiance jumps at the horizon), two 4-point Gauss-Legendre panels in cos theta, 8 azimuths
// over the half circle y >= 0 counted twice. It integrates w w^T exactly, so the phase
// integrates to one.
#include "sky_shared.h"
#include "sky_layouts.h"

layout(local_size_x = SKY_MS_LOCAL) in;
SKY_PARAMETER_BLOCK(SKY_MS_MOMENTS_ATMOSPHERE, AtmosphereBlock, sky_atmosphere_uniforms, atmo);
layout(binding = SKY_MS_MOMENTS_RADIANCE) uniform sampler3D radiance_table;
layout(binding = SKY_MS_MOMENTS_OUT, rgba32f) uniform writeonly image2D moments_out;
layout(push_constant) uniform OrderPush { sky_ms_push push; };

#include "atmosphere.glsl"
#include "ms_table.glsl"

// 4-point Gauss-Legendre nodes and weights on [0, 1] (Abramowitz & Stegun table 25.4, mapped).
const float GL4_X[4] = float[4](0.0694318442, 0.3300094782, 0.6699905218, 0.9305681558);
const float GL4_W[4] = float[4](0.1739274226, 0.3260725774, 0.3260725774, 0.1739274226);
const int PANELS = 2;
const int AZIMUTHS = 8; // over the half circle

void main()
{
    atmo = atmo_block;
    uint index = push.first + gl_GlobalInvocationID.x; // (mu_s, r) in row-major order
    if (index >= push.end)
        return;
    int i_mu_s = int(index % uint(SKY_MS_MU_S)), i_r = int(index / uint(SKY_MS_MU_S));
    float r, mu, mu_s, nu;
    // the same altitude and sun zenith as the density's texels of this (mu_s, r)
    ms_texel_params(ivec3(i_mu_s, SKY_MS_MU / 2, i_r), r, mu, mu_s, nu);
    r = clamp(r, bottom_radius() + 1e-3, top_radius() - 1e-3);
    vec3 sun = vec3(sqrt(max(0.0, 1.0 - mu_s * mu_s)), 0.0, mu_s);
    float u_mu_s = ms_mu_s_coord(mu_s), u_r = ms_r_coord(r);
    vec3 m_xx = vec3(0.0), m_yy = vec3(0.0), m_zz = vec3(0.0), m_xz = vec3(0.0);
    for (int half_index = 0; half_index < 2; half_index++) {
        float side = half_index == 0 ? 1.0 : -1.0;
        for (int panel = 0; panel < PANELS; panel++) {
            for (int j = 0; j < 4; j++) {
                float cos_theta = side * (float(panel) + GL4_X[j]) / float(PANELS);
                float sin_theta = sqrt(max(0.0, 1.0 - cos_theta * cos_theta));
                // solid angle of a node: both halves of the circle
                float dw = GL4_W[j] / float(PANELS) * 2.0 * PI / float(AZIMUTHS);
                float u_mu = ms_mu_coord(r, cos_theta);
                for (int i = 0; i < AZIMUTHS; i++) {
                    float phi = PI * (float(i) + 0.5) / float(AZIMUTHS);
                    vec3 w = vec3(sin_theta * cos(phi), sin_theta * sin(phi), cos_theta);
                    vec4 c = vec4(u_mu_s, u_mu, u_r, clamp((dot(w, sun) + 1.0) * 0.5, 0.0, 1.0));
                    vec3 L = ms_lookup_coords(radiance_table, c) * dw;
                    m_xx += w.x * w.x * L;
                    m_yy += w.y * w.y * L;
                    m_zz += w.z * w.z * L;
                    m_xz += w.x * w.z * L;
                }
            }
        }
    }
    ivec2 base = ivec2(4 * i_mu_s, i_r);
    imageStore(moments_out, base, vec4(m_xx, 0.0));
    imageStore(moments_out, base + ivec2(1, 0), vec4(m_yy, 0.0));
    imageStore(moments_out, base + ivec2(2, 0), vec4(m_zz, 0.0));
    imageStore(moments_out, base + ivec2(3, 0), vec4(m_xz, 0.0));
}
