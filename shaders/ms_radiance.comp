#version 450
#extension GL_GOOGLE_include_directive : require
// Converged multiple scattering, one order's radiance (Bruneton & Neyret 2008, section 4 and
// eq. 3): L_n(x, v) = integral of T(x, p) J_n(p, v) along the ray + T(x, g) rho / pi E_{n-1}(g)
// when the ray ends on the ground. Order 1 is single scattering of the sun (J_1 = sigma_s p(nu)
// T_sun) with the sunlit ground; order n >= 2 reads the scattering density J_n of
// ms_density.comp (the logarithm of J_n / sigma_s) and the ground irradiance E_{n-1} of ms_ground.comp.
// Orders >= 2 add into the sum the sky-view reads; the last order adds the rest of the series
// as a geometric tail L_N q / (1 - q), q = L_N / L_{N-1} per texel and channel.
// A dispatch covers a range of texels (row-major), so that the work can be spread over frames.
#include "sky_shared.h"
#include "sky_layouts.h"

layout(local_size_x = SKY_MS_LOCAL) in;
SKY_PARAMETER_BLOCK(SKY_MS_RADIANCE_ATMOSPHERE, AtmosphereBlock, sky_atmosphere_uniforms, atmo);
layout(binding = SKY_MS_RADIANCE_TRANSMITTANCE) uniform sampler2D transmittance_lut;
layout(binding = SKY_MS_RADIANCE_DENSITY) uniform sampler3D density_table;
layout(binding = SKY_MS_RADIANCE_GROUND) uniform sampler2D ground_table;
layout(binding = SKY_MS_RADIANCE_PREVIOUS) uniform sampler3D previous_table;
layout(binding = SKY_MS_RADIANCE_OUT, rgba32f) uniform writeonly image3D radiance_out;
layout(binding = SKY_MS_RADIANCE_SUM, rgba32f) uniform image3D sum_table;
layout(push_constant) uniform OrderPush { sky_ms_push push; };
// Order 1 (the sun) or orders >= 2 (the scattering density): one pipeline each, so that neither
// pays for the other's branch (lavapipe runs both sides of a branch it cannot prove uniform).
layout(constant_id = SKY_MS_CONST_HIGHER) const bool HIGHER = false;

#define SKY_HAS_TRANSMITTANCE_LUT
#include "atmosphere.glsl"
#include "ms_table.glsl"

// March steps: orders 1 and 2 see the sun's sharp single scattering along the ray; the higher
// orders' density is smooth along it and takes fewer.
const float STEPS_LOW = 20.0, STEPS_HIGH = 12.0;

void main()
{
    atmo = atmo_block;
    ivec3 size = imageSize(radiance_out);
    uint index = push.first + gl_GlobalInvocationID.x; // texels in row-major order
    if (index >= push.end)
        return;
    uint row = index / uint(size.x);
    ivec3 texel = ivec3(int(index % uint(size.x)), int(row % uint(size.y)),
                        int(row / uint(size.y)));
    uint order = push.order;
    float r, mu, mu_s, nu;
    ms_texel_params(texel, r, mu, mu_s, nu);
    vec3 view, sun;
    ms_directions(mu, mu_s, nu, view, sun);
    // 1 m: float resolves about 0.5 m at planetary radii.
    r = clamp(r, bottom_radius() + 1e-3, top_radius() - 1e-3);
    vec3 origin = vec3(0.0, 0.0, r);

    vec3 L = vec3(0.0), throughput = vec3(1.0);
    float t_start, t_end;
    bool hits_ground;
    if (atmosphere_segment(origin, view, t_start, t_end, hits_ground)) {
        float phase_r = rayleigh_phase(nu);
        vec3 phase_m = mie_phase(nu, atmo.mie_g.xyz);
        float t_prev = 0.0;
        float steps = order <= 2u ? STEPS_LOW : STEPS_HIGH; // uniform: the push constant
        for (float k = 0.0; k < steps; k += 1.0) {
            float t_next = march_boundary(0.0, t_end, k + 1.0, steps);
            float dt = t_next - t_prev;
            vec3 p = origin + (t_prev + 0.5 * dt) * view;
            t_prev = t_next;
            float rp = length(p);
            MediumSample m = sample_medium(rp - bottom_radius());
            vec3 source;
            if (!HIGHER) {
                source = sun_transmittance(p, sun)
                         * (m.rayleigh_scattering * phase_r + m.mie_scattering * phase_m);
            } else {
                vec3 up = p / rp;
                source = m.scattering
                         * ms_lookup_of_log(density_table, rp, dot(view, up), dot(sun, up), nu);
            }
            vec3 step_t = exp(-m.extinction * dt);
            vec3 ext = max(m.extinction, vec3(1e-9));
            L += throughput * (source - source * step_t) / ext; // seed 001 eq. 23
            throughput *= step_t;
        }
        if (hits_ground) {
            vec3 g = origin + t_end * view;
            vec3 n = normalize(g);
            float mu_g = dot(n, sun);
            vec3 irradiance = !HIGHER
                ? sun_transmittance(g + n * 1e-3, sun) * max(mu_g, 0.0)
                : ms_ground_lookup(ground_table, mu_g);
            L += throughput * atmo.ground_albedo.xyz / PI * irradiance; // Lambert
        }
    }
    imageStore(radiance_out, texel, vec4(L, 1.0));
    if (!HIGHER) {
        imageStore(sum_table, texel, vec4(0.0));
        return;
    }
    vec3 sum = imageLoad(sum_table, texel).rgb + L;
    if (push.last != 0u) {
        // The rest of the series, orders N+1.. (the ratio of successive orders settles quickly).
        vec3 previous = texelFetch(previous_table, texel, 0).rgb;
        vec3 q = clamp(L / max(previous, vec3(1e-12)), vec3(0.0), vec3(0.9));
        sum += L * q / (1.0 - q);
    }
    imageStore(sum_table, texel, vec4(sum, 1.0));
}
