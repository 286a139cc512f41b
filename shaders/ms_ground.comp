#version 450
#extension GL_GOOGLE_include_directive : require
// Converged multiple scattering, one order's ground irradiance (Bruneton & Neyret 2008,
// eq. 5): E_n(mu_s) = integral over the upper hemisphere of L_n(R, w) (w . n) dw, read from the
// order's radiance table at the ground; ms_radiance.comp reflects it in the next order.
#include "sky_shared.h"
#include "sky_layouts.h"

layout(local_size_x = SKY_MS_LOCAL) in;
SKY_PARAMETER_BLOCK(SKY_MS_GROUND_ATMOSPHERE, AtmosphereBlock, sky_atmosphere_uniforms, atmo);
layout(binding = SKY_MS_GROUND_RADIANCE) uniform sampler3D radiance_table;
layout(binding = SKY_MS_GROUND_OUT, rgba32f) uniform writeonly image2D ground_out;

#include "atmosphere.glsl"
#include "ms_table.glsl"

// 4-point Gauss-Legendre panels in cos theta graded quadratically toward the horizon, where the
// twilight sky is brightest (ms_moments.comp).
const int PANELS = 4;
const int AZIMUTHS = 16;

void main()
{
    atmo = atmo_block;
    int i = int(gl_GlobalInvocationID.x);
    if (i >= SKY_MS_GROUND)
        return;
    float mu_s = ms_ground_mu_s(i);
    vec3 sun = vec3(sqrt(max(0.0, 1.0 - mu_s * mu_s)), 0.0, mu_s);
    vec3 E = vec3(0.0);
    // cos theta dw = mu dmu dphi, mu = u^2
    for (int panel = 0; panel < PANELS; panel++) {
        for (int j = 0; j < 4; j++) {
            float u = (float(panel) + GL4_X[j]) / float(PANELS);
            float c = u * u, dc = 2.0 * u * GL4_W[j] / float(PANELS);
            float s = sqrt(max(0.0, 1.0 - c * c));
            for (int k = 0; k < AZIMUTHS; k++) {
                float phi = 2.0 * PI * (float(k) + 0.5) / float(AZIMUTHS);
                vec3 w = vec3(s * cos(phi), s * sin(phi), c);
                E += ms_lookup_log_cubic(radiance_table, bottom_radius() + 1e-3, c, mu_s,
                                         dot(w, sun))
                     * c * dc;
            }
        }
    }
    E *= 2.0 * PI / float(AZIMUTHS);
    imageStore(ground_out, ivec2(i, 0), vec4(E, 1.0));
}
