#version 450
#extension GL_GOOGLE_include_directive : require
// Temporal reconstruction of the clouds at full resolution (seed 001 5.5.3; Schneider 2015):
// each pixel reprojects the view's history through its cloud depth (camera rotation and the
// wind's displacement of the clouds), clamps it to the neighbourhood of this frame's trace
// (history rejection) and, where this frame traced it, blends the new sample in with a weight
// of 1 / samples (at least view.motion.z). Untraced pixels without history take the nearest
// traced sample.
#include "sky_shared.h"
#include "cloud_shared.h"

layout(local_size_x = 8, local_size_y = 8) in;
SKY_PARAMETER_BLOCK(0, FrameBlock, sky_frame_uniforms, frame);
layout(binding = 1) uniform sampler2D trace_color;
layout(binding = 2) uniform sampler2D trace_depth;
layout(binding = 3) uniform sampler2D history_color;
layout(binding = 4) uniform sampler2D history_aux;
layout(binding = 5, rgba32f) uniform writeonly image2D out_color;
layout(binding = 6, rgba32f) uniform writeonly image2D out_aux;
layout(push_constant) uniform ViewPush { sky_cloud_view_push view; };

#include "camera.glsl"

const float MAX_SAMPLES = 64.0;

vec2 previous_uv(vec3 dir)
{
    return camera_uv_of(dir, view.prev_forward.xyz, view.prev_right.xyz, view.prev_up.xyz,
                        view.prev_forward.w, view.prev_right.w, view.target.z);
}

void main()
{
    frame = frame_block;
    ivec2 px = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(px, imageSize(out_color))))
        return;
    // The images' sizes in use, not their extents (which may be larger); arithmetic only:
    // lavapipe would compile a variant per value of a push constant that a branch depends on.
    ivec2 size = view.target.xy;
    int block = view.frame.y;
    ivec2 tlast = (size + block - 1) / block - 1; // the trace's last texel in use
    ivec2 tp = min(px / block, tlast);
    bool traced = all(equal(px - tp * block, view.frame.zw));
    vec4 current = texelFetch(trace_color, tp, 0);
    if (view.motion.w < 0.5) {
        imageStore(out_color, px, current);
        imageStore(out_aux, px, vec4(texelFetch(trace_depth, tp, 0).x, 1.0, 0.0, 0.0));
        return;
    }
    // Neighbourhood of this frame's samples (the traced texel and its 8 neighbours), for
    // history rejection: the 3x3 keeps thin features whose samples fall a block away.
    vec4 lo = current, hi = current;
    for (int y = -1; y <= 1; y++)
        for (int x = -1; x <= 1; x++) {
            vec4 s = texelFetch(trace_color, clamp(tp + ivec2(x, y), ivec2(0), tlast), 0);
            lo = min(lo, s);
            hi = max(hi, s);
        }
    vec4 margin = (hi - lo) * 0.15 + vec4(vec3(1e-3 * max(hi.r, 1.0)), 0.01);
    lo -= margin;
    hi += margin;

    // Where this pixel's cloud was in the previous frame: its front point moved with the wind.
    vec3 dir = camera_ray((vec2(px) + 0.5) / vec2(size));
    float depth = texelFetch(trace_depth, tp, 0).x;
    vec3 prev_dir = dir;
    if (depth > 0.0) {
        vec3 p = dir * depth - vec3(view.motion.xy, 0.0);
        prev_dir = normalize(p);
    }
    vec2 uv = previous_uv(prev_dir);
    bool valid = view.prev_up.w > 0.5 && all(greaterThanEqual(uv, vec2(0.0)))
                 && all(lessThanEqual(uv, vec2(1.0)));
    vec4 result;
    float samples;
    if (!valid) {
        result = current;
        samples = traced ? 1.0 : 0.0;
    } else {
        // An untraced pixel whose history stays in place keeps it whole: clamping it to this
        // frame's sparse samples, a block away, would flatten features thinner than a block.
        // As the history moves (camera turning, clouds drifting) the clamp takes over within
        // a pixel's motion; a traced pixel's history is always clamped.
        // The history's texels past its size are never reached (clamp-to-edge at its size).
        vec2 history_uv = min(uv * vec2(size), vec2(size) - 0.5)
                          / vec2(textureSize(history_color, 0));
        vec4 history = textureLod(history_color, history_uv, 0.0);
        float moved_px = length((uv - (vec2(px) + 0.5) / vec2(size)) * vec2(size));
        float rejection = traced ? 1.0 : clamp(moved_px, 0.0, 1.0);
        history = mix(history, clamp(history, lo, hi), rejection);
        float history_samples = textureLod(history_aux, history_uv, 0.0).y;
        if (traced) {
            samples = min(history_samples + 1.0, MAX_SAMPLES);
            result = mix(history, current, max(1.0 / samples, view.motion.z));
        } else {
            samples = history_samples;
            result = history;
        }
    }
    imageStore(out_color, px, result);
    imageStore(out_aux, px, vec4(depth, samples, 0.0, 0.0));
}
