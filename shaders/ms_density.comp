#version 450
#extension GL_GOOGLE_include_directive : require
// Converged multiple scattering, one order's scattering density (Bruneton & Neyret 2008,
// eq. 4 with the ground's light already inside L_{n-1}): J_n(x, v) = sum over the Rayleigh and
// Mie parts of sigma_i(x) * integral over the sphere of p_i(v . w) L_{n-1}(x, w) dw, stored
// divided by sigma_s(x) so that it varies slowly with altitude. The sphere is sampled by
// SKY_MS_DENSITY_DIRS directions (Gauss-Legendre in cos theta x uniform in azimuth); the
// quadrature weights of each phase function are normalised to sum to one, so that the
// sharp Mie lobe still conserves energy.
#include "sky_shared.h"
#include "sky_layouts.h"

layout(local_size_x = SKY_MS_LOCAL, local_size_y = SKY_MS_LOCAL) in;
SKY_PARAMETER_BLOCK(SKY_MS_DENSITY_ATMOSPHERE, AtmosphereBlock, sky_atmosphere_uniforms, atmo);
layout(binding = SKY_MS_DENSITY_RADIANCE) uniform sampler3D radiance_table;
layout(binding = SKY_MS_DENSITY_OUT, rgba32f) uniform writeonly image3D density_out;
layout(push_constant) uniform OrderPush { sky_ms_push push; };

#include "atmosphere.glsl"
#include "ms_table.glsl"

// 8-point Gauss-Legendre nodes and weights on [-1, 1] (Abramowitz & Stegun table 25.4).
const float GL_X[8] = float[8](-0.9602898565, -0.7966664774, -0.5255324099, -0.1834346425,
                               0.1834346425, 0.5255324099, 0.7966664774, 0.9602898565);
const float GL_W[8] = float[8](0.1012285363, 0.2223810345, 0.3137066459, 0.3626837834,
                               0.3626837834, 0.3137066459, 0.2223810345, 0.1012285363);
const int AZIMUTHS = SKY_MS_DENSITY_DIRS / 8;

void main()
{
    atmo = atmo_block;
    ivec3 size = imageSize(density_out);
    uint row = push.row_offset + gl_GlobalInvocationID.y;
    ivec3 texel = ivec3(int(gl_GlobalInvocationID.x), int(row % uint(size.y)),
                        int(row / uint(size.y)));
    if (texel.x >= size.x || row >= push.row_end)
        return;
    float r, mu, mu_s, nu;
    ms_texel_params(texel, r, mu, mu_s, nu);
    vec3 view, sun;
    ms_directions(mu, mu_s, nu, view, sun);
    r = clamp(r, bottom_radius() + 1e-3, top_radius() - 1e-3);

    vec3 sum_r = vec3(0.0), sum_m = vec3(0.0);
    float weight_r = 0.0;
    vec3 weight_m = vec3(0.0);
    for (int j = 0; j < 8; j++) {
        float cos_theta = GL_X[j];
        float sin_theta = sqrt(max(0.0, 1.0 - cos_theta * cos_theta));
        for (int i = 0; i < AZIMUTHS; i++) {
            float phi = 2.0 * PI * (float(i) + 0.5) / float(AZIMUTHS);
            vec3 w = vec3(sin_theta * cos(phi), sin_theta * sin(phi), cos_theta);
            float dw = GL_W[j] * 2.0 * PI / float(AZIMUTHS); // solid angle of the node
            vec3 L = ms_lookup(radiance_table, r, w.z, mu_s, dot(w, sun));
            float c = dot(view, w);
            float pr = rayleigh_phase(c) * dw;
            vec3 pm = mie_phase(c, atmo.mie_g.xyz) * dw;
            sum_r += pr * L;
            sum_m += pm * L;
            weight_r += pr;
            weight_m += pm;
        }
    }
    MediumSample m = sample_medium(r - bottom_radius());
    vec3 j = m.rayleigh_scattering * sum_r / max(weight_r, 1e-6)
             + m.mie_scattering * sum_m / max(weight_m, vec3(1e-6));
    imageStore(density_out, texel, vec4(j / max(m.scattering, vec3(1e-12)), 1.0));
}
