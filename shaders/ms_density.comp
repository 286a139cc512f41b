#version 450
#extension GL_GOOGLE_include_directive : require
// Converged multiple scattering, one order's scattering density (Bruneton & Neyret 2008,
// eq. 4 with the ground's light already inside L_{n-1}): J_n(x, v) = sum over the Rayleigh and
// Mie parts of sigma_i(x) * integral over the sphere of p_i(v . w) L_{n-1}(x, w) dw, stored
// divided by sigma_s(x) so that it varies slowly with altitude. Rayleigh's integral takes a
// Gauss-Legendre rule on each hemisphere, Mie's a rule stratified in its lobe around the view
// direction (its sharp forward peak falls between the nodes of any fixed rule); the weights of
// each are normalised to sum to one, so that a uniform radiance is scattered exactly.
#include "sky_shared.h"
#include "sky_layouts.h"

layout(local_size_x = SKY_MS_LOCAL) in;
SKY_PARAMETER_BLOCK(SKY_MS_DENSITY_ATMOSPHERE, AtmosphereBlock, sky_atmosphere_uniforms, atmo);
layout(binding = SKY_MS_DENSITY_RADIANCE) uniform sampler3D radiance_table;
layout(binding = SKY_MS_DENSITY_OUT, rgba32f) uniform writeonly image3D density_out;
layout(push_constant) uniform OrderPush { sky_ms_push push; };
// J_2 or J_n, n >= 3 (below): one pipeline each, so that the rules' sizes are constants.
layout(constant_id = SKY_MS_CONST_HIGHER) const bool HIGHER = false;

#include "atmosphere.glsl"
#include "ms_table.glsl"

// Gauss-Legendre nodes and weights on [0, 1] (Abramowitz & Stegun table 25.4, mapped), 4 points
// then 3.
const float GL4_X[4] = float[4](0.0694318442, 0.3300094782, 0.6699905218, 0.9305681558);
const float GL4_W[4] = float[4](0.1739274226, 0.3260725774, 0.3260725774, 0.1739274226);
const float GL3_X[3] = float[3](0.1127016654, 0.5, 0.8872983346);
const float GL3_W[3] = float[3](0.2777777778, 0.4444444444, 0.2777777778);
// J_2 integrates single scattering, whose Mie peak around the sun and horizon are sharp; the
// higher orders integrate radiance that has already been scattered at least twice and is
// smooth, and take fewer directions (orders: the push constant, the same for the whole
// dispatch; the rule: a specialization constant).
const int ZENITHS_FIRST = 4, AZIMUTHS_FIRST = 8, MIE_RINGS_FIRST = 6;
const int ZENITHS_HIGHER = 3, AZIMUTHS_HIGHER = 6, MIE_RINGS_HIGHER = 3;

void main()
{
    atmo = atmo_block;
    ivec3 size = imageSize(density_out);
    uint index = push.first + gl_GlobalInvocationID.x; // texels in row-major order
    if (index >= push.end)
        return;
    uint row = index / uint(size.x);
    ivec3 texel = ivec3(int(index % uint(size.x)), int(row % uint(size.y)),
                        int(row / uint(size.y)));
    float r, mu, mu_s, nu;
    ms_texel_params(texel, r, mu, mu_s, nu);
    vec3 view, sun;
    ms_directions(mu, mu_s, nu, view, sun);
    r = clamp(r, bottom_radius() + 1e-3, top_radius() - 1e-3);
    // The texel's altitude and sun zenith coordinates serve every direction.
    float u_mu_s = ms_mu_s_coord(mu_s), u_r = ms_r_coord(r);
    const bool first = !HIGHER;
    int zeniths = first ? ZENITHS_FIRST : ZENITHS_HIGHER;
    int azimuths = first ? AZIMUTHS_FIRST : AZIMUTHS_HIGHER;
    int mie_rings = first ? MIE_RINGS_FIRST : MIE_RINGS_HIGHER;

    // Rayleigh: each hemisphere apart (the horizon is where L jumps from sky to ground),
    // Gauss-Legendre zeniths (whose view-zenith coordinate serves a whole ring), uniform azimuths.
    vec3 sum_r = vec3(0.0);
    float weight_r = 0.0;
    for (int half_index = 0; half_index < 2; half_index++) {
        float side = half_index == 0 ? 1.0 : -1.0;
        for (int j = 0; j < zeniths; j++) {
            float cos_theta = side * (first ? GL4_X[j] : GL3_X[j]);
            float sin_theta = sqrt(max(0.0, 1.0 - cos_theta * cos_theta));
            // solid angle of a node
            float dw = (first ? GL4_W[j] : GL3_W[j]) * 2.0 * PI / float(azimuths);
            float u_mu = ms_mu_coord(r, cos_theta);
            for (int i = 0; i < azimuths; i++) {
                float phi = 2.0 * PI * (float(i) + 0.5) / float(azimuths);
                vec3 w = vec3(sin_theta * cos(phi), sin_theta * sin(phi), cos_theta);
                float pr = rayleigh_phase(dot(view, w)) * dw;
                vec4 c = vec4(u_mu_s, u_mu, u_r, clamp((dot(w, sun) + 1.0) * 0.5, 0.0, 1.0));
                sum_r += pr * ms_lookup_coords(radiance_table, c);
                weight_r += pr;
            }
        }
    }
    // Mie: around the view direction, stratified in the Henyey-Greenstein lobe's cumulative
    // distribution (its inverse, e.g. Pharr et al. PBRT 11.3.1), each node weighted by the
    // Cornette-Shanks phase over the Henyey-Greenstein density.
    float g = clamp(atmo.mie_g.y, -0.95, 0.95);
    vec3 t1 = normalize(abs(view.z) < 0.9 ? cross(view, vec3(0.0, 0.0, 1.0))
                                          : cross(view, vec3(1.0, 0.0, 0.0)));
    vec3 t2 = cross(view, t1);
    vec3 sum_m = vec3(0.0), weight_m = vec3(0.0);
    for (int j = 0; j < mie_rings; j++) {
        float xi = (float(j) + 0.5) / float(mie_rings);
        float c;
        if (abs(g) < 1e-3) {
            c = 1.0 - 2.0 * xi;
        } else {
            float k = (1.0 - g * g) / (1.0 - g + 2.0 * g * xi);
            c = clamp((1.0 + g * g - k * k) / (2.0 * g), -1.0, 1.0);
        }
        float s = sqrt(max(0.0, 1.0 - c * c));
        float hg = (1.0 - g * g) / (4.0 * PI * pow(max(1e-6, 1.0 + g * g - 2.0 * g * c), 1.5));
        vec3 ratio = mie_phase(c, atmo.mie_g.xyz) / hg;
        for (int i = 0; i < azimuths; i++) {
            float phi = 2.0 * PI * (float(i) + 0.5 * float(j % 2) + 0.25) / float(azimuths);
            vec3 w = c * view + s * (cos(phi) * t1 + sin(phi) * t2);
            vec4 cw = vec4(u_mu_s, ms_mu_coord(r, w.z), u_r,
                           clamp((dot(w, sun) + 1.0) * 0.5, 0.0, 1.0));
            sum_m += ratio * ms_lookup_coords(radiance_table, cw);
            weight_m += ratio;
        }
    }
    MediumSample m = sample_medium(r - bottom_radius());
    vec3 j = m.rayleigh_scattering * sum_r / max(weight_r, 1e-6)
             + m.mie_scattering * sum_m / max(weight_m, vec3(1e-6));
    imageStore(density_out, texel, vec4(j / max(m.scattering, vec3(1e-12)), 1.0));
}
