#version 450
#extension GL_GOOGLE_include_directive : require
// The renderer's cloud march (cloud_march.glsl, unchanged) through a homogeneous plane-parallel
// deck, for the Monte Carlo comparison of tests/test_cloud_accuracy.c: the bindings of
// cloud_bindings.glsl, the real atmosphere and march code, and in place of cloud_density.glsl a
// low layer of uniform extinction. One invocation marches one ray (origin, direction, jitter)
// of one case (deck, sun, phase, octaves) and writes the luminance per unit sun illuminance.
#include "cloud_shared.h"
#include "cloud_layouts.h"

layout(local_size_x = SKY_CLOUD_SLAB_LOCAL) in;

// The declarations of cloud_bindings.glsl (which would include cloud_density.glsl).
SKY_PARAMETER_BLOCK(SKY_CLOUD_MARCH_ATMOSPHERE, AtmosphereBlock, sky_atmosphere_uniforms, atmo);
SKY_PARAMETER_BLOCK(SKY_CLOUD_MARCH_FRAME, FrameBlock, sky_frame_uniforms, frame);
layout(binding = SKY_CLOUD_MARCH_TRANSMITTANCE) uniform sampler2D transmittance_lut;
layout(binding = SKY_CLOUD_MARCH_MULTISCATTERING) uniform sampler2D multiscattering_lut;
layout(binding = SKY_CLOUD_MARCH_IRRADIANCE) uniform sampler2D irradiance_lut;
SKY_PARAMETER_BLOCK(SKY_CLOUD_MARCH_CLOUD, CloudBlock, sky_cloud_uniforms, cloud);
layout(binding = SKY_CLOUD_MARCH_BASE_NOISE) uniform sampler3D base_noise;
layout(binding = SKY_CLOUD_MARCH_DETAIL_NOISE) uniform sampler3D detail_noise;
layout(binding = SKY_CLOUD_MARCH_CURL_NOISE) uniform sampler2D curl_noise;
layout(binding = SKY_CLOUD_MARCH_WEATHER) uniform sampler2D weather_map;
layout(binding = SKY_CLOUD_MARCH_SKYVIEW) uniform sampler2D skyview_lut;
layout(constant_id = SKY_CLOUD_CONST_MOONLIT) const bool MOONLIT = true;

// One case: the deck, the sun and the cloud parameters that the comparison varies.
struct SlabCase {
    vec4 low;     // cloud.low: x bottom radius, y top radius, z extinction per km, w 1
    vec4 sun;     // xyz toward the sun, w primary steps
    vec4 phase;   // cloud.phase: g0, g1, w, octave count
    vec4 octaves; // cloud.octaves: a, b, c, light steps
};
// One ray: xyz origin (planet-centred km), w the case; xyz direction, w the jitter.
struct SlabRay {
    vec4 origin;
    vec4 direction;
};
layout(std430, binding = SKY_CLOUD_SLAB_CASES) readonly buffer Cases { SlabCase cases[]; };
layout(std430, binding = SKY_CLOUD_SLAB_RAYS) readonly buffer Rays {
    uvec4 ray_count;
    SlabRay rays[];
};
layout(std430, binding = SKY_CLOUD_SLAB_RESULTS) writeonly buffer Results { float luminance[]; };

#define SKY_HAS_TRANSMITTANCE_LUT
#define SKY_HAS_MULTISCATTERING_LUT
#define SKY_HAS_SKYVIEW_LUT
#include "atmosphere.glsl"

// In place of cloud_density.glsl: the low layer's shell filled with extinction cloud.low.z,
// nothing in the high layer.
#define CLOUD_DENSITY_GLSL
// The march sets it per step (cloud_density.glsl); the uniform deck has no detail to fade.
float cloud_detail_weight = 1.0;
float cloud_lod = 0.0;

// cloud_density.glsl's layer names and shells.
const int LAYER_LOW = 0;
const int LAYER_HIGH = 1;
const int LAYER_MID = 2;

vec4 layer_shell(int layer)
{
    return layer == LAYER_LOW ? cloud.low : layer == LAYER_MID ? cloud.mid : cloud.high;
}


// No rain under the deck.
vec2 cloud_rain(vec3 p)
{
    return vec2(0.0);
}

float cloud_layer_extinction(vec3 p, bool detail, int layer)
{
    float r = length(p);
    return layer == LAYER_LOW && r > cloud.low.x && r < cloud.low.y ? cloud.low.z : 0.0;
}

// -1 outside the layer: empty space the march may skip.
float cloud_layer_sample(vec3 p, bool detail, int layer)
{
    float sigma = cloud_layer_extinction(p, detail, layer);
    return sigma > 0.0 ? sigma : -1.0;
}

#include "cloud_shell.glsl"

#include "slab_sun_depth.glsl"
#include "cloud_march.glsl"

void main()
{
    uint i = gl_GlobalInvocationID.x;
    if (i >= ray_count.x)
        return;
    atmo = atmo_block;
    frame = frame_block;
    cloud = cloud_block;
    SlabRay ray = rays[i];
    SlabCase c = cases[uint(ray.origin.w)];
    cloud.low = c.low;
    cloud.phase = c.phase;
    cloud.octaves = c.octaves;
    frame.sun_direction.xyz = c.sun.xyz;
    CloudResult res = march_clouds(ray.origin.xyz, ray.direction.xyz, c.sun.xyz,
                                   ray.direction.w, c.sun.w);
    luminance[i] = res.luminance.g / frame.sun_illuminance.y;
}
