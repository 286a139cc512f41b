#version 450
#extension GL_GOOGLE_include_directive : require
// Converged multiple scattering, one order's scattering density (Bruneton & Neyret 2008,
// eq. 4 with the ground's light already inside L_{n-1}): J_n(x, v) = sum over the Rayleigh and
// Mie parts of sigma_i(x) * integral over the sphere of p_i(v . w) L_{n-1}(x, w) dw, stored
// divided by sigma_s(x) so that it varies slowly with altitude, and as its logarithm so that
// ms_radiance.comp's filtered fetches interpolate it geometrically (ms_lookup_of_log).
// Rayleigh's phase is a quadratic, so its integral comes from the radiance's second moments at
// the texel's altitude and sun (ms_moments.comp: 20 zeniths x 16 azimuths, shared by every view
// and view-sun angle);
// Mie's takes a rule stratified in its lobe around the view direction (its sharp forward peak
// falls between the nodes of any fixed rule), normalised so that a uniform radiance is
// scattered exactly.
#include "sky_shared.h"
#include "sky_layouts.h"

layout(local_size_x = SKY_MS_LOCAL) in;
SKY_PARAMETER_BLOCK(SKY_MS_DENSITY_ATMOSPHERE, AtmosphereBlock, sky_atmosphere_uniforms, atmo);
layout(binding = SKY_MS_DENSITY_RADIANCE) uniform sampler3D radiance_table;
layout(binding = SKY_MS_DENSITY_OUT, rgba32f) uniform writeonly image3D density_out;
layout(binding = SKY_MS_DENSITY_MOMENTS) uniform sampler2D moments;
layout(push_constant) uniform OrderPush { sky_ms_push push; };
// J_2 or J_n, n >= 3 (below): one pipeline each, so that the rules' sizes are constants.
layout(constant_id = SKY_MS_CONST_HIGHER) const bool HIGHER = false;

#include "atmosphere.glsl"
#include "ms_table.glsl"

// J_2 integrates single scattering, whose Mie peak around the sun is sharp; the higher orders
// integrate radiance that has already been scattered at least twice and is smooth, and take
// fewer directions in Mie's lobe (rings x azimuths).
const int MIE_RINGS = HIGHER ? 3 : 6;
const int AZIMUTHS = HIGHER ? 6 : 8;

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

    // Rayleigh: from the radiance's second moments at this altitude and sun (ms_moments.comp),
    // in the moments' frame: the sun's azimuth along +x.
    ivec2 base = ivec2(SKY_MS_MOMENTS * (texel.x % SKY_MS_MU_S), texel.z);
    vec3 m_xx = texelFetch(moments, base, 0).rgb;
    vec3 m_yy = texelFetch(moments, base + ivec2(1, 0), 0).rgb;
    vec3 m_zz = texelFetch(moments, base + ivec2(2, 0), 0).rgb;
    vec3 m_xz = texelFetch(moments, base + ivec2(3, 0), 0).rgb;
    float sun_h = length(sun.xy);
    vec2 toward_sun = sun_h > 1e-6 ? sun.xy / sun_h : vec2(1.0, 0.0);
    float vx = dot(view.xy, toward_sun);
    float vy2 = max(0.0, 1.0 - view.z * view.z - vx * vx);
    float vz = view.z;
    // 3 / (16 pi) (tr M + v^T M v), ms_moments.comp
    vec3 sum_r = 3.0 / (16.0 * PI)
                 * (m_xx + m_yy + m_zz + vx * vx * m_xx + vy2 * m_yy + vz * vz * m_zz
                    + 2.0 * vx * vz * m_xz);
    // Mie: around the view direction, stratified in the Henyey-Greenstein lobe's cumulative
    // distribution (its inverse, e.g. Pharr et al. PBRT 11.3.1), each node weighted by the
    // Cornette-Shanks phase over the Henyey-Greenstein density.
    float g = clamp(atmo.mie_g.y, -0.95, 0.95);
    vec3 t1 = normalize(abs(view.z) < 0.9 ? cross(view, vec3(0.0, 0.0, 1.0))
                                          : cross(view, vec3(1.0, 0.0, 0.0)));
    vec3 t2 = cross(view, t1);
    vec3 sum_m = vec3(0.0), weight_m = vec3(0.0);
    for (int j = 0; j < MIE_RINGS; j++) {
        float xi = (float(j) + 0.5) / float(MIE_RINGS);
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
        for (int i = 0; i < AZIMUTHS; i++) {
            float phi = 2.0 * PI * (float(i) + 0.5 * float(j % 2) + 0.25) / float(AZIMUTHS);
            vec3 w = c * view + s * (cos(phi) * t1 + sin(phi) * t2);
            vec4 cw = vec4(u_mu_s, ms_mu_coord(r, w.z), u_r,
                           clamp((dot(w, sun) + 1.0) * 0.5, 0.0, 1.0));
            sum_m += ratio * ms_lookup_coords(radiance_table, cw);
            weight_m += ratio;
        }
    }
    MediumSample m = sample_medium(r - bottom_radius());
    vec3 j = m.rayleigh_scattering * sum_r
             + m.mie_scattering * sum_m / max(weight_m, vec3(1e-6));
    imageStore(density_out, texel,
               vec4(log(max(j / max(m.scattering, vec3(1e-12)), vec3(1e-30))), 1.0));
}
