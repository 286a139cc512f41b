#version 450
#extension GL_GOOGLE_include_directive : require
// Exercises the renderer's own GLSL functions on the device: LUT parameterization round trips
// and phase-function normalization. Invocation i writes results[i] (see test_units.c).
#include "sky_shared.h"

layout(local_size_x = 1) in;
SKY_PARAMETER_BLOCK(0, AtmosphereBlock, sky_atmosphere_uniforms, atmo);
layout(std430, binding = 1) writeonly buffer Results { vec4 results[]; };

#include "atmosphere.glsl"

const int GRID = 64;

// Max |unit - unit'| over a grid for unit -> (r, mu) -> unit, and max |mu - mu'|.
vec4 transmittance_round_trip()
{
    float worst_unit = 0.0, worst_mu = 0.0;
    for (int i = 0; i <= GRID; i++) {
        for (int j = 0; j <= GRID; j++) {
            vec2 unit = vec2(float(i), float(j)) / float(GRID);
            float r, mu;
            transmittance_unit_to_r_mu(unit, r, mu);
            vec2 back = transmittance_r_mu_to_unit(r, mu);
            worst_unit = max(worst_unit, max(abs(back.x - unit.x), abs(back.y - unit.y)));
            float r2, mu2;
            transmittance_unit_to_r_mu(back, r2, mu2);
            worst_mu = max(worst_mu, abs(mu2 - mu));
        }
    }
    return vec4(worst_unit, worst_mu, 0.0, 0.0);
}

// Sky-view: unit -> (view zenith cos, light-view cos) -> unit, at several altitudes.
vec4 skyview_round_trip()
{
    float worst = 0.0;
    float altitudes[4] = float[4](0.001, 0.2, 10.0, 99.0);
    for (int a = 0; a < 4; a++) {
        float r = bottom_radius() + altitudes[a];
        for (int i = 0; i <= GRID; i++) {
            for (int j = 0; j <= GRID; j++) {
                vec2 unit = vec2(float(i), float(j)) / float(GRID);
                // Exactly on the horizon row the ground/sky choice is ambiguous; skip it.
                if (abs(unit.y - 0.5) < 0.5 / float(GRID))
                    continue;
                float zc, lc;
                skyview_unit_to_dir(r, unit, zc, lc);
                vec2 back = skyview_dir_to_unit(r, zc, lc, unit.y >= 0.5);
                worst = max(worst, max(abs(back.x - unit.x), abs(back.y - unit.y)));
            }
        }
    }
    return vec4(worst, 0.0, 0.0, 0.0);
}

// Sub-uv remapping: unit -> texture uv -> unit.
vec4 sub_uv_round_trip()
{
    float worst = 0.0;
    for (int i = 0; i <= GRID; i++) {
        float u = float(i) / float(GRID);
        worst = max(worst, abs(sub_uv_to_unit(unit_to_sub_uv(u, 64.0), 64.0) - u));
    }
    return vec4(worst, 0.0, 0.0, 0.0);
}

// Integral of a phase function over the sphere, 2 pi * int p(cos t) sin t dt, by Simpson.
vec4 phase_integrals(float g)
{
    const int N = 4000;
    float h = PI / float(N);
    float rayleigh = 0.0;
    vec3 mie = vec3(0.0);
    for (int k = 0; k <= N; k++) {
        float t = float(k) * h;
        float w = (k == 0 || k == N) ? 1.0 : ((k % 2 == 1) ? 4.0 : 2.0);
        rayleigh += w * rayleigh_phase(cos(t)) * sin(t);
        mie += w * mie_phase(cos(t), vec3(g, 0.0, -g)) * sin(t);
    }
    float scale = 2.0 * PI * h / 3.0;
    return vec4(rayleigh * scale, mie * scale);
}

void main()
{
    atmo = atmo_block;
    uint i = gl_GlobalInvocationID.x;
    if (i == 0u) results[0] = transmittance_round_trip();
    if (i == 1u) results[1] = skyview_round_trip();
    if (i == 2u) results[2] = sub_uv_round_trip();
    if (i == 3u) results[3] = phase_integrals(0.8);
    if (i == 4u) results[4] = phase_integrals(0.5);
    if (i == 5u) results[5] = phase_integrals(0.3);
}
