#version 450
#extension GL_GOOGLE_include_directive : require
// Ground irradiance LUT: horizontal irradiance at the ground from the sky (single scattering
// plus the multiple-scattering LUT) per unit sun illuminance, against the sun's cos-zenith.
// E = integral of L cos(theta) over the upper hemisphere (seed 000 eq. 14.3 family), by a
// midpoint rule in zenith and azimuth.
#include "sky_shared.h"
#include "sky_layouts.h"

layout(local_size_x = SKY_IRRADIANCE_DIRECTIONS) in;
SKY_PARAMETER_BLOCK(SKY_IRRADIANCE_ATMOSPHERE, AtmosphereBlock, sky_atmosphere_uniforms, atmo);
layout(binding = SKY_IRRADIANCE_TRANSMITTANCE) uniform sampler2D transmittance_lut;
layout(binding = SKY_IRRADIANCE_MULTISCATTERING) uniform sampler2D multiscattering_lut;
layout(binding = SKY_IRRADIANCE_OUT, rgba32f) uniform writeonly image2D irradiance_out;

#define SKY_HAS_TRANSMITTANCE_LUT
#define SKY_HAS_MULTISCATTERING_LUT
#include "atmosphere.glsl"
#include "scattering_march.glsl"

// A workgroup is one texel, a lane one direction of the hemisphere: the texel's 128 marches
// in one lane each would leave a GPU with 64 busy threads. The sky is mirror-symmetric about
// the sun's vertical plane, and the midpoint rule's azimuths phi and 2 pi - phi pair up, so the
// lanes march the half 0 < phi < pi and count twice.
const int ZENITH_STEPS = 8;
const int AZIMUTH_STEPS = 16;
const float MARCH_STEPS = 16.0;
shared vec3 shared_irradiance[SKY_IRRADIANCE_DIRECTIONS];

void main()
{
    atmo = atmo_block;
    int size = imageSize(irradiance_out).x;
    int px = int(gl_WorkGroupID.x);
    uint lane = gl_LocalInvocationIndex;
    float mu_s = sub_uv_to_unit((float(px) + 0.5) / float(size), float(size)) * 2.0 - 1.0;
    vec3 sun_dir = vec3(sqrt(max(0.0, 1.0 - mu_s * mu_s)), 0.0, mu_s);
    vec3 origin = vec3(0.0, 0.0, bottom_radius() + 1e-3);
    float d_theta = 0.5 * PI / float(ZENITH_STEPS);
    float d_phi = 2.0 * PI / float(AZIMUTH_STEPS);
    int i = int(lane) / (AZIMUTH_STEPS / 2), j = int(lane) % (AZIMUTH_STEPS / 2);
    float theta = (float(i) + 0.5) * d_theta;
    float phi = (float(j) + 0.5) * d_phi;
    vec3 dir = vec3(sin(theta) * cos(phi), sin(theta) * sin(phi), cos(theta));
    MarchResult m = march_scattering(origin, dir, sun_dir, 1e9, MARCH_STEPS);
    shared_irradiance[lane] = 2.0 * m.luminance * cos(theta) * sin(theta) * d_theta * d_phi;
    barrier();
    for (uint stride = SKY_IRRADIANCE_DIRECTIONS / 2; stride > 0u; stride >>= 1) {
        if (lane < stride)
            shared_irradiance[lane] += shared_irradiance[lane + stride];
        barrier();
    }
    if (lane == 0u && px < size)
        imageStore(irradiance_out, ivec2(px, 0), vec4(shared_irradiance[0], 1.0));
}
