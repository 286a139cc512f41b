#version 450
#extension GL_GOOGLE_include_directive : require
// The clouds' path-traced reference (cloud_pathtrace.glsl): every pixel of the cloud image
// takes view.samples.y more samples per dispatch, summed over dispatches, and a last dispatch
// without samples (view.target.w 1) writes the image from the sums. Each sample jitters
// its ray within the pixel; ratio tracking along it gives the transmittance and the
// transmittance-weighted depth (seed 001 eq. 21), delta tracking on the same proposed
// collisions the path's first collision. The image it writes holds what the reconstruction
// would: premultiplied luminance with aerial perspective applied at that depth (as
// cloud_trace.comp does), and opacity 1 - transmittance, for the resolve to composite.
#include "cloud_shared.h"
#include "cloud_layouts.h"

layout(local_size_x = SKY_CLOUD_LOCAL, local_size_y = SKY_CLOUD_LOCAL) in;
#include "cloud_bindings.glsl"
layout(binding = SKY_CLOUD_PATHTRACE_SUM, rgba32f) uniform image2D sum_image;
layout(binding = SKY_CLOUD_PATHTRACE_DEPTH_SUM, rgba32f) uniform image2D depth_sum_image;
layout(binding = SKY_CLOUD_PATHTRACE_COLOR_OUT, rgba32f) uniform writeonly image2D color_out;
layout(binding = SKY_CLOUD_PATHTRACE_AP_INSCATTER) uniform sampler3D ap_inscatter;
layout(binding = SKY_CLOUD_PATHTRACE_AP_TRANSMITTANCE) uniform sampler3D ap_transmittance;
// Per cell of the weather map: x, y 1 where the low, high layer may hold cloud (near it).
layout(binding = SKY_CLOUD_PATHTRACE_GRID) uniform sampler2D pt_grid;
layout(std430, binding = SKY_CLOUD_PATHTRACE_STATS) buffer Stats {
    sky_cloud_reference_stats pt_stats;
};
layout(push_constant) uniform ReferencePush { sky_cloud_reference_push view; };

#include "scattering_march.glsl"
#include "camera.glsl"
#include "cloud_pathtrace.glsl"

const float AP_STEPS = 8.0;
// The primary ray's depth weights stop mattering here (the renderer's early exit, seed 001
// 5.5.1); its transmittance plays Russian roulette below it.
const float PRIMARY_ROULETTE_T = 0.01;

struct Primary {
    bool hit;   // a real collision was found
    vec3 p;     // where
    float T;    // ratio-tracking estimate of the transmittance
    vec2 depth; // sums of T t and T over the proposed collisions in cloud
};

Primary primary_ray(vec3 cam, vec3 d)
{
    Primary r = Primary(false, cam, 1.0, vec2(0.0));
    vec3 o = cam;
    float base = 0.0; // o's distance from the camera
    for (int s = 0; s < PT_MAX_SEGMENTS; s++) {
        float t0, t1, m;
        if (!pt_next_segment(o, d, t0, t1, m))
            break;
        PtWalk w = pt_walk(t0);
        while (pt_propose(w, o, d, t1, m)) {
            float t = w.t;
            vec3 p = o + t * d;
            float sigma = pt_extinction(p, w.majorant);
            // Proposals are uniform in t at the rate of the majorant, so these sums, weighted by
            // its inverse, estimate the integrals of T t and T over the cloud: their ratio is
            // eq. 21's depth.
            if (sigma > 0.0)
                r.depth += r.T / w.majorant * vec2(base + t, 1.0);
            if (!r.hit && pt_random() * w.majorant < sigma) {
                r.hit = true;
                r.p = p;
            }
            r.T *= 1.0 - sigma / w.majorant;
            if (r.T < PRIMARY_ROULETTE_T && r.T > 0.0)
                r.T = pt_random() * PRIMARY_ROULETTE_T < r.T ? PRIMARY_ROULETTE_T : 0.0;
            if (r.hit && r.T <= 0.0)
                return r;
        }
        base += t1 + PT_EPS_KM;
        o += d * (t1 + PT_EPS_KM);
    }
    return r;
}

// As cloud_trace.comp: aerial perspective to `depth` from the froxel volume, false beyond it.
bool aerial_perspective_froxel(vec2 uv, float depth, out vec3 inscatter, out vec3 transmittance)
{
    float max_km = frame.image.z;
    if (depth > max_km)
        return false;
    vec2 slice = aerial_perspective_slice(depth, max_km, float(textureSize(ap_inscatter, 0).z));
    vec3 at = vec3(uv, slice.x);
    inscatter = textureLod(ap_inscatter, at, 0.0).rgb * slice.y;
    transmittance = mix(vec3(1.0), textureLod(ap_transmittance, at, 0.0).rgb, slice.y);
    return true;
}

void main()
{
    atmo = atmo_block;
    frame = frame_block;
    cloud = cloud_block;
    cloud_detail_weight = 1.0;
    ivec2 size = view.target.xy;
    ivec2 px = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(px, size)))
        return;
    pt_precipitation_ceiling = view.media.x;
    vec4 sum = vec4(0.0), depth_sum = vec4(0.0);
    if (view.samples.x > 0) {
        sum = imageLoad(sum_image, px);
        depth_sum = imageLoad(depth_sum_image, px);
    }
    vec3 cam = frame.camera_position.xyz;
    uint seed = pt_hash(uint(view.samples.z));
    for (int k = 0; k < view.samples.y; k++) {
        uint index = uint(view.samples.x + k);
        pt_rng = pt_hash(uint(px.x) ^ pt_hash(uint(px.y) ^ pt_hash(index ^ seed)));
        vec2 uv = (vec2(px) + vec2(pt_random(), pt_random())) / vec2(size);
        vec3 d = camera_ray(uv);
        Primary r = primary_ray(cam, d);
        vec3 L = r.hit ? pt_path(r.p, d) : vec3(0.0);
        if (!pt_loops_intact(view.target.z))
            atomicAdd(pt_stats.truncated, 1u);
        sum += vec4(L, r.T);
        depth_sum += vec4(r.depth, 1.0, 0.0);
    }
    imageStore(sum_image, px, sum);
    imageStore(depth_sum_image, px, depth_sum);
    atomicAdd(pt_stats.kilo_samples, (pt_samples + 512u) / 1024u);
    if (view.target.w != 1)
        return;

    float n = max(depth_sum.z, 1.0);
    vec3 L = sum.rgb / n;
    float opacity = clamp(1.0 - sum.a / n, 0.0, 1.0);
    float depth = depth_sum.y > 0.0 ? depth_sum.x / depth_sum.y : 0.0;
    if (opacity > 1e-4) {
        vec2 uv = (vec2(px) + 0.5) / vec2(size);
        vec3 inscatter, transmittance;
        if (!aerial_perspective_froxel(uv, depth, inscatter, transmittance)) {
            MarchResult ap = march_scattering(cam, camera_ray(uv), frame.sun_direction.xyz,
                                              depth, AP_STEPS);
            inscatter = ap.luminance;
            transmittance = ap.transmittance;
        }
        L = L * transmittance + opacity * inscatter * frame.sun_illuminance.xyz;
    }
    imageStore(color_out, px, vec4(L, opacity));
}
