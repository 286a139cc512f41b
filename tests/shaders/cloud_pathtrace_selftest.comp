#version 450
#extension GL_GOOGLE_include_directive : require
// The path tracer (cloud_pathtrace.glsl, unchanged) through a homogeneous plane-parallel deck,
// for the Monte Carlo comparison of tests/reference/test_cloud_pathtrace_slab.c: in place of
// cloud_density.glsl a low layer of uniform extinction (as cloud_slab_selftest.comp does).
// One invocation is one sample of (case, kind, bin):
//   kind 0: radiance reflected upward, kind 1: diffuse radiance transmitted downward, both at
//           a view cosine drawn in the bin (weighted by mu dmu) and a random azimuth, per unit
//           sun illuminance;
//   kind 2: ratio-tracking transmittance along the sun's direction through the deck.
#include "cloud_shared.h"
#include "cloud_layouts.h"

layout(local_size_x = SKY_CLOUD_SLAB_LOCAL) in;

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

// One case: the deck (cloud.low), the sun (xyz toward it), the phase (cloud.phase) and x the
// albedo.
struct PtCase {
    vec4 low;
    vec4 sun;
    vec4 phase;
    vec4 media;
};
layout(std430, binding = SKY_CLOUD_SLAB_CASES) readonly buffer Cases { PtCase cases[]; };
// x cases, y kinds, z bins, w samples per (case, kind, bin)
layout(std430, binding = SKY_CLOUD_SLAB_RAYS) readonly buffer Counts { uvec4 counts; };
layout(std430, binding = SKY_CLOUD_SLAB_RESULTS) writeonly buffer Results { float result[]; };
layout(std430, binding = SKY_CLOUD_PT_SLAB_STATS) buffer Stats {
    sky_cloud_reference_stats pt_stats;
};

#define SKY_HAS_TRANSMITTANCE_LUT
#define SKY_HAS_MULTISCATTERING_LUT
#define SKY_HAS_SKYVIEW_LUT
#include "atmosphere.glsl"

#define CLOUD_DENSITY_GLSL
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


float cloud_extinction(vec3 p, bool detail)
{
    float r = length(p);
    return r > cloud.low.x && r < cloud.low.y ? cloud.low.z : 0.0;
}

float cloud_layer_extinction(vec3 p, bool detail, int layer)
{
    return layer == LAYER_LOW ? cloud_extinction(p, detail) : 0.0;
}

// -1 outside the layer: empty space the march may skip.
float cloud_layer_sample(vec3 p, bool detail, int layer)
{
    float sigma = cloud_layer_extinction(p, detail, layer);
    return sigma > 0.0 ? sigma : -1.0;
}

vec2 cloud_rain(vec3 p)
{
    return vec2(0.0);
}

#include "cloud_shell.glsl"

#include "slab_sun_depth.glsl"
#include "cloud_march.glsl"
#define PT_WITHOUT_GRID
#include "cloud_pathtrace.glsl"

void main()
{
    uint i = gl_GlobalInvocationID.x;
    uint per_case = counts.y * counts.z * counts.w;
    if (i >= counts.x * per_case)
        return;
    atmo = atmo_block;
    frame = frame_block;
    cloud = cloud_block;
    PtCase c = cases[i / per_case];
    uint kind = (i % per_case) / (counts.z * counts.w);
    uint bin = (i % (counts.z * counts.w)) / counts.w;
    cloud.low = c.low;
    cloud.phase = c.phase;
    cloud.media.x = c.media.x;
    frame.sun_direction.xyz = c.sun.xyz;
    pt_precipitation_ceiling = 0.0;
    pt_rng = pt_hash(i ^ pt_hash(0x9e3779b9u));
    vec3 up = vec3(0.0, 0.0, 1.0);
    if (kind == 2u) {
        vec3 below = up * (cloud.low.x - 0.05);
        result[i] = pt_transmittance(below, c.sun.xyz);
        return;
    }
    // mu drawn with density proportional to mu in [lo, hi]: mu^2 uniform.
    float lo = float(bin) / float(counts.z), hi = float(bin + 1u) / float(counts.z);
    float mu = sqrt(mix(lo * lo, hi * hi, pt_random()));
    float phi = 2.0 * PI * pt_random();
    float s = sqrt(max(0.0, 1.0 - mu * mu));
    // The camera looks against the light it receives: down onto the top, up at the bottom.
    bool reflect = kind == 0u;
    vec3 d = vec3(s * cos(phi), s * sin(phi), reflect ? -mu : mu);
    vec3 o = up * (reflect ? cloud.low.y + 0.05 : cloud.low.x - 0.05);
    float L = 0.0;
    if (pt_track(o, d))
        L = pt_path(o, d).g;
    result[i] = L / frame.sun_illuminance.y;
    // lavapipe's loop limit (cloud_pathtrace.glsl): a path cut short is counted.
    if (!pt_loops_intact(int(counts.x >> 31)))
        atomicAdd(pt_stats.truncated, 1u);
}
