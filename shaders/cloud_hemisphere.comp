#version 450
#extension GL_GOOGLE_include_directive : require
// The clouds over the upper hemisphere seen from the ground under the camera, averaged with a
// cosine weight: transmittance Tr_cloud and scattered luminance L_cloud per unit sun
// illuminance, the inputs of seed 001 eq. 22 (clouds on the aerial perspective below them),
// and from them the diffuse light under the clouds against a clear sky's (env_transmittance.yzw,
// which scales the air's multiple scattering under them, aerial_perspective.comp).
#include "cloud_shared.h"
#include "cloud_layouts.h"

layout(local_size_x = CLOUD_HEMISPHERE_RAYS) in;
#include "cloud_bindings.glsl"
layout(std430, binding = SKY_CLOUD_HEMISPHERE_ENV_OUT) writeonly buffer Env {
    vec4 env_luminance;
    vec4 env_transmittance;
};

const float STEPS = 24.0;
const float DIFFUSE_RATIO_MAX = 1.0;
shared vec4 partial[CLOUD_HEMISPHERE_RAYS];

void main()
{
    atmo = atmo_block;
    frame = frame_block;
    cloud = cloud_block;
    uint i = gl_LocalInvocationIndex;
    // Cosine-weighted directions on a Fibonacci spiral.
    float u = (float(i) + 0.5) / float(CLOUD_HEMISPHERE_RAYS);
    float phi = float(i) * 2.39996323;
    float sin_t = sqrt(u), cos_t = sqrt(1.0 - u);
    vec3 dir = vec3(sin_t * cos(phi), sin_t * sin(phi), cos_t);
    vec3 origin = vec3(0.0, 0.0, bottom_radius() + 0.002);
    CloudResult c = march_clouds(origin, dir, frame.sun_direction.xyz, 0.5, STEPS);
    vec3 per_lux = c.luminance / max(frame.sun_illuminance.xyz, vec3(1e-20));
    partial[i] = vec4(per_lux, c.transmittance);
    barrier();
    for (uint stride = CLOUD_HEMISPHERE_RAYS / 2u; stride > 0u; stride >>= 1u) {
        if (i < stride)
            partial[i] += partial[i + stride];
        barrier();
    }
    if (i == 0u) {
        vec4 mean = partial[0] / float(CLOUD_HEMISPHERE_RAYS);
        env_luminance = vec4(mean.rgb, 1.0);
        // The diffuse light under the clouds against a clear sky's, per channel: the sky's
        // mean radiance E_sky / pi through the gaps (mean.a) and the clouds' own (mean.rgb),
        // over E_sky / pi; at most 1 (bright broken clouds may light the air a little more
        // than a clear sky, which the light-shaft volume, a loss, does not hold).
        vec3 sky, direct;
        ground_light_per_lux(frame.sun_direction.xyz, sky, direct);
        vec3 diffuse = mean.a + PI * mean.rgb / max(sky, vec3(1e-9));
        env_transmittance = vec4(mean.a, clamp(diffuse, vec3(0.0), vec3(DIFFUSE_RATIO_MAX)));
    }
}
