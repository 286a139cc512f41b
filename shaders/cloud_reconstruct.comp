#version 450
#extension GL_GOOGLE_include_directive : require
// Temporal reconstruction of the clouds at full resolution (seed 001 5.5.3; Schneider 2015).
// This frame's samples lie on a regular grid: one per block x block block of the cloud image,
// at the same place (view.frame.zw) in each. What a pixel takes from them varies continuously
// with its position, so that nothing jumps at block edges when the clouds change from frame to
// frame (a live time-lapse, a weather transition, wind, a parameter drag):
//  - the current estimate is the bilinear interpolation of the 2x2 samples around the pixel
//    (the sample itself at a traced pixel), and the history is reprojected through the
//    opacity-weighted depth of those samples (camera rotation, the wind's displacement);
//  - history rejection clamps to the range of the interpolated samples at the pixel and a
//    block away along each axis: a box that varies continuously with the pixel;
//  - each sample is compared with the history where it lies (where that history came from
//    traces rather than from interpolation). Where the history lies outside the range of this
//    frame's samples around, in two frames in a row (other samples each time) or far outside
//    now, the clouds changed: the history follows the samples' change, interpolated (keeping
//    its detail finer than a block), and loses its sample count so that the next traces
//    replace it; past a large change the interpolated samples replace it outright;
//  - where the history moved it was resampled anyway: the traced pixels' updates, interpolated,
//    go to the pixels between them too, so that the traced ones do not stand out where the
//    clouds change in ways the reprojection cannot follow.
// A traced pixel blends its sample in with a weight of 1 / samples (at least view.motion.z); a
// pixel not traced since its history began (or was replaced) moves toward the interpolation.
#include "sky_shared.h"
#include "cloud_shared.h"
#include "cloud_layouts.h"

layout(local_size_x = SKY_CLOUD_LOCAL, local_size_y = SKY_CLOUD_LOCAL) in;
SKY_PARAMETER_BLOCK(SKY_CLOUD_RECONSTRUCT_FRAME, FrameBlock, sky_frame_uniforms, frame);
layout(binding = SKY_CLOUD_RECONSTRUCT_TRACE_COLOR) uniform sampler2D trace_color;
// x depth, y transmittance, z opacity x depth
layout(binding = SKY_CLOUD_RECONSTRUCT_TRACE_DEPTH) uniform sampler2D trace_depth;
layout(binding = SKY_CLOUD_RECONSTRUCT_HISTORY_COLOR) uniform sampler2D history_color;
// x depth, y samples, z how far outside the samples' range the history was (change_now),
// w 1 where the history came from traces, 0 where it was interpolated
layout(binding = SKY_CLOUD_RECONSTRUCT_HISTORY_AUX) uniform sampler2D history_aux;
layout(binding = SKY_CLOUD_RECONSTRUCT_COLOR_OUT, rgba32f) uniform writeonly image2D out_color;
layout(binding = SKY_CLOUD_RECONSTRUCT_AUX_OUT, rgba32f) uniform writeonly image2D out_aux;
layout(push_constant) uniform ViewPush { sky_cloud_view_push view; };

#include "camera.glsl"

const float MAX_SAMPLES = 64.0;
// The samples' noise (relative luminance, opacity), added to the range of the samples around a
// pixel: the unit of how far outside it the history lies.
const float SAMPLE_NOISE = 0.1;
// From the first distance outside that range on, the history follows the samples' change,
// entirely from the second on.
const vec2 CHANGE_FOLLOW = vec2(0.1, 0.5);
// From this far outside on the history shows other clouds: the interpolated samples replace it.
const vec2 CHANGE_REPLACE = vec2(1.0, 4.0);

// The sizes in use, not the images' extents (which may be larger). Arithmetic and selects only,
// no branch on them alone: lavapipe would compile a variant per value of a push constant that a
// branch depends on.
ivec2 size;
int block;
ivec2 tlast; // the trace's last texel in use

vec2 previous_uv(vec3 dir)
{
    return camera_uv_of(dir, view.prev_forward.xyz, view.prev_right.xyz, view.prev_up.xyz,
                        view.prev_forward.w, view.prev_right.w, view.target.z);
}

// How far outside [lo, hi] v lies, in units of that range widened by the samples' noise (the
// largest of the channels).
float outside_range(vec4 v, vec4 lo, vec4 hi)
{
    vec4 outside = abs(v - clamp(v, lo, hi)) / (hi - lo + SAMPLE_NOISE * vec4(hi.rgb, 1.0));
    return max(max(outside.r, outside.g), max(outside.b, outside.a));
}

// Where trace texel t's sample lies in the cloud image (the trace clamps the last ones).
vec2 sample_position(ivec2 t)
{
    return vec2(min(t * block + view.frame.zw, size - 1));
}

// The continuous trace coordinate of pixel position p (texel t's sample at t exactly),
// clamped to the texels in use.
vec2 trace_coordinate(vec2 p)
{
    vec2 f = (p - vec2(view.frame.zw)) / float(block);
    vec2 before = sample_position(tlast - 1), last = sample_position(tlast);
    vec2 f_last = vec2(tlast - 1) + (p - before) / max(last - before, vec2(1.0));
    return clamp(mix(f, f_last, greaterThan(p, before)), vec2(0.0), vec2(tlast));
}

// Bilinear interpolation of a trace image at trace coordinate f.
vec4 trace_at(sampler2D image, vec2 f)
{
    return textureLod(image, (f + 0.5) / vec2(textureSize(image, 0)), 0.0);
}

// A history image at pixel position h (pixel centres at +0.5), clamped to the size in use.
vec4 history_at(sampler2D image, vec2 h)
{
    h = clamp(h, vec2(0.5), vec2(size) - 0.5);
    return textureLod(image, h / vec2(textureSize(image, 0)), 0.0);
}

void main()
{
    frame = frame_block;
    ivec2 px = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(px, imageSize(out_color))))
        return;
    size = view.target.xy;
    block = view.frame.y;
    tlast = (size + block - 1) / block - 1;
    vec2 p = vec2(px);
    vec2 f = trace_coordinate(p);
    bool traced = all(equal(px, ivec2(sample_position(ivec2(round(f))))));

    // The 2x2 samples around and their bilinear weights.
    ivec2 t0 = ivec2(floor(f)), t1 = min(t0 + 1, tlast);
    vec2 w = f - vec2(t0);
    ivec2 texel[4] = ivec2[](t0, ivec2(t1.x, t0.y), ivec2(t0.x, t1.y), t1);
    float weight[4] = float[]((1.0 - w.x) * (1.0 - w.y), w.x * (1.0 - w.y),
                              (1.0 - w.x) * w.y, w.x * w.y);
    vec4 s[4];
    vec4 current = vec4(0.0);
    for (int k = 0; k < 4; k++) {
        s[k] = texelFetch(trace_color, texel[k], 0);
        current += weight[k] * s[k];
    }
    // Opacity-weighted depth of the samples around: continuous, and the clouds' own where
    // some are near (a sample without clouds has no depth).
    vec3 d = trace_at(trace_depth, f).xyz;
    float opacity = 1.0 - d.y;
    float depth = opacity > 1e-4 ? d.z / opacity : 0.0; // km; 0 without clouds
    if (view.motion.w < 0.5) {
        imageStore(out_color, px, current);
        imageStore(out_aux, px, vec4(depth, 1.0, 0.0, 1.0));
        return;
    }
    // History rejection: the range of the interpolated samples here and a block away along
    // each axis (the samples of the 3x3 texels around, weighted continuously).
    const vec2 AROUND[4] = vec2[](vec2(1.0, 0.0), vec2(-1.0, 0.0), vec2(0.0, 1.0),
                                  vec2(0.0, -1.0));
    vec4 lo = current, hi = current;
    for (int i = 0; i < 4; i++) {
        vec4 b = trace_at(trace_color, clamp(f + AROUND[i], vec2(0.0), vec2(tlast)));
        lo = min(lo, b);
        hi = max(hi, b);
    }
    vec4 margin = (hi - lo) * 0.15 + vec4(vec3(1e-3 * max(hi.r, 1.0)), 0.01);
    lo -= margin;
    hi += margin;

    // Where this pixel's cloud was in the previous frame: its front point moved with the wind.
    vec3 dir = camera_ray((p + 0.5) / vec2(size));
    vec3 prev_dir = dir;
    if (depth > 0.0) {
        vec3 q = dir * depth - vec3(view.motion.xy, 0.0) * smoothstep(1e-3, 1e-2, opacity);
        prev_dir = normalize(q);
    }
    vec2 uv = previous_uv(prev_dir);
    bool valid = view.prev_up.w > 0.5 && all(greaterThanEqual(uv, vec2(0.0)))
                 && all(lessThanEqual(uv, vec2(1.0)));
    vec4 result;
    float samples, confidence, change_now = 0.0;
    if (!valid) {
        result = current;
        samples = traced ? 1.0 : 0.0;
        confidence = samples;
    } else {
        vec2 hp = uv * vec2(size); // the pixel's place in the history
        vec4 history = history_at(history_color, hp);
        vec4 aux = history_at(history_aux, hp);
        // The samples against the history where they lie (moved as this pixel moved; the
        // nearest texel), where that history came from traces.
        vec4 now_sum = vec4(0.0), then_sum = vec4(0.0), updates = vec4(0.0);
        float known = 0.0;
        for (int k = 0; k < 4; k++) {
            vec2 at = hp + sample_position(texel[k]) - p;
            ivec2 texel_at = clamp(ivec2(at), ivec2(0), size - 1);
            vec4 h = texelFetch(history_color, texel_at, 0);
            vec4 a = texelFetch(history_aux, texel_at, 0);
            float c = weight[k] * a.w;
            updates += c * max(1.0 / (a.y + 1.0), view.motion.z) * (s[k] - h);
            now_sum += c * s[k];
            then_sum += c * h;
            known += c;
        }
        vec4 change = (now_sum - then_sum) / max(known, 1e-6);
        change_now = known * outside_range(then_sum / max(known, 1e-6), lo, hi);
        // Seen in the previous frame too (other samples), or far beyond the range now: the
        // clouds', not the samples' noise.
        float seen = max(min(change_now, aux.z), change_now - 1.0);
        float follow = smoothstep(CHANGE_FOLLOW.x, CHANGE_FOLLOW.y, seen);
        float replace = smoothstep(CHANGE_REPLACE.x, CHANGE_REPLACE.y, seen);
        float moved_px = length(hp - (p + 0.5));
        // A history that moved (camera turning, clouds drifting) was resampled: the traced
        // pixels' updates, interpolated, go to the pixels between them too, so that the traced
        // ones do not stand out where the clouds change in ways the reprojection misses.
        vec4 spread = traced ? vec4(0.0) : updates * clamp(moved_px, 0.0, 1.0);
        vec4 moved = mix(history + mix(spread, change, follow), current, replace);
        // A traced history that stays in place while its clouds do not change is kept whole:
        // clamping it to this frame's sparse samples, a block away, would flatten features
        // thinner than a block. Where the history moved or the clouds changed, and for a
        // history that was only interpolated, the clamp takes over. Where this frame's samples
        // see no clouds the history's own would have moved too (they may have gone).
        float depth_before = aux.x;
        vec3 q = dir * depth_before - vec3(view.motion.xy, 0.0) * step(1e-6, depth_before);
        float gone_px = length(previous_uv(normalize(q)) * vec2(size) - (p + 0.5));
        float rejection = max(max(clamp(max(moved_px, gone_px), 0.0, 1.0), follow),
                              1.0 - aux.w);
        moved = mix(moved, clamp(moved, lo, hi), rejection);
        moved = clamp(moved, vec4(0.0), vec4(vec3(1e30), 1.0));
        samples = aux.y * (1.0 - follow);
        confidence = aux.w * (1.0 - replace);
        if (traced) {
            samples = min(samples + 1.0, MAX_SAMPLES);
            confidence = 1.0;
            result = mix(moved, current, max(1.0 / samples, view.motion.z));
        } else {
            // Not traced since its history began or since the clouds changed beyond it: an
            // average of the interpolations.
            result = mix(moved, current, 0.5 * (1.0 - confidence));
        }
    }
    imageStore(out_color, px, result);
    imageStore(out_aux, px, vec4(depth, samples, change_now, confidence));
}
