#version 450
#extension GL_GOOGLE_include_directive : require
// Sums the metering partials into the log-average luminance and turns it into an exposure:
// EV100 = log2(L_avg * S / K) with S = 100, K = 12.5, minus compensation; exposure =
// 1 / (1.2 * 2^EV100) (Lagarde & de Rousiers 2014, saturation-based sensitivity). With night
// adaptation the eye's incomplete adaptation to dim scenes is kept: the key value falls with
// the scene's luminance, a(L) = 1.03 - 2 / (2 + log10(L + 1)) (Krawczyk, Myszkowski & Seidel
// 2005, eq. 11), and the exposure follows a(L) / a(1000 cd/m2): daylight as metered, civil
// twilight about 2 EV darker, a starlit night about 4.4 EV darker than mid grey.
#include "sky_shared.h"
#include "sky_layouts.h"

layout(local_size_x = SKY_EXPOSURE_LOCAL) in;
SKY_PARAMETER_BLOCK(SKY_EXPOSURE_FRAME, FrameBlock, sky_frame_uniforms, frame);
layout(std430, binding = SKY_EXPOSURE_PARTIALS) readonly buffer Partials { vec2 partials[]; };
layout(std430, binding = SKY_EXPOSURE_OUT) writeonly buffer ExposureBlock { vec4 metered; };
layout(push_constant) uniform MeterPush { sky_meter_push meter; };

shared vec2 shared_sum[64];

void main()
{
    frame = frame_block;
    uint li = gl_LocalInvocationIndex;
    vec2 sum = vec2(0.0);
    for (uint i = li; i < meter.group_count; i += 64u)
        sum += partials[i];
    shared_sum[li] = sum;
    barrier();
    for (uint stride = 32u; stride > 0u; stride >>= 1u) {
        if (li < stride)
            shared_sum[li] += shared_sum[li + stride];
        barrier();
    }
    if (li == 0u) {
        // With nothing metered (all black) fall back to a night exposure, L_avg = 1e-3.
        float log_avg = shared_sum[0].y > 0.0 ? shared_sum[0].x / shared_sum[0].y : log2(1e-3);
        float ev100 = log_avg + log2(100.0 / 12.5) - frame.exposure.z;
        float l_avg = exp2(log_avg);
        float key = 1.03 - 2.0 / (2.0 + log(l_avg + 1.0) / log(10.0));
        const float DAYLIGHT_KEY = 1.03 - 2.0 / (2.0 + 3.0004341); // a(1000 cd/m2)
        float adaptation_ev = min(0.0, log2(max(key, 1e-4) / DAYLIGHT_KEY));
        ev100 -= step(1.5, frame.exposure.y) * adaptation_ev;
        metered = vec4(1.0 / (1.2 * exp2(ev100)), ev100, exp2(log_avg), 0.0);
    }
}
