#version 450
#extension GL_GOOGLE_include_directive : require
// Converged multiple scattering, the second moments of one order's radiance for Rayleigh's
// part of the next order's scattering density. Rayleigh's phase is a quadratic in the cosine,
// p(v . w) = 3 / (16 pi) (1 + (v . w)^2), so its integral against the radiance is
//   integral of p(v . w) L(w) dw = 3 / (16 pi) (tr M + v^T M v),   M = integral of w w^T L(w) dw
// (Bruneton & Neyret 2008 eq. 4 with the phase expanded): M depends on the altitude and the
// sun only, so one integral per (r, mu_s) serves every view direction and view-sun angle of the
// 4D table. With the sun in the xz plane L is even in y, so M_xy = M_yz = 0; stored: M_xx, M_yy,
// M_zz, M_xz in four texels of a row per altitude. The rule: 20 zenith cosines in three parts
// (below in main), 8 azimuths over the half circle y >= 0 counted twice. It integrates w w^T
// exactly, so the phase integrates to one. Split only at the horizontal (two panels of
// 4 per hemisphere, as at first), it missed the grazing rays' twilight glow and left the light
// scattered back from it 8% too bright in red, 13% looking 10 deg above the horizon away from
// a sun 6 deg down.
#include "sky_shared.h"
#include "sky_layouts.h"

layout(local_size_x = SKY_MS_LOCAL) in;
SKY_PARAMETER_BLOCK(SKY_MS_MOMENTS_ATMOSPHERE, AtmosphereBlock, sky_atmosphere_uniforms, atmo);
layout(binding = SKY_MS_MOMENTS_RADIANCE) uniform sampler3D radiance_table;
layout(binding = SKY_MS_MOMENTS_OUT, rgba32f) uniform writeonly image2D moments_out;
layout(push_constant) uniform OrderPush { sky_ms_push push; };

#include "atmosphere.glsl"
#include "ms_table.glsl"

const int GRAZING_PANELS = 1;
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
    // Zenith cosines in three parts split where the radiance is least smooth: above the
    // horizontal, from it down to the horizon (rays that graze the planet, the longest and, in
    // twilight, the brightest: they reach the sunlit air), and the ground below, in 4-point
    // Gauss-Legendre panels: the first and last parts graded quadratically toward the horizon.
    float mu_horizon = -sqrt(max(0.0, 1.0 - (bottom_radius() / r) * (bottom_radius() / r)));
    for (int part = 0; part < 3; part++) {
        int panels = part == 1 ? GRAZING_PANELS : PANELS;
        for (int panel = 0; panel < panels; panel++) {
            for (int j = 0; j < 4; j++) {
                float u = (float(panel) + GL4_X[j]) / float(panels);
                float du = GL4_W[j] / float(panels);
                float cos_theta, dcos;
                if (part == 0) {
                    cos_theta = u * u, dcos = 2.0 * u * du;
                } else if (part == 1) {
                    cos_theta = mu_horizon * u, dcos = -mu_horizon * du;
                } else {
                    cos_theta = mu_horizon - (1.0 + mu_horizon) * u * u;
                    dcos = (1.0 + mu_horizon) * 2.0 * u * du;
                }
                float sin_theta = sqrt(max(0.0, 1.0 - cos_theta * cos_theta));
                // solid angle of a node: both halves of the circle
                float dw = dcos * 2.0 * PI / float(AZIMUTHS);
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
