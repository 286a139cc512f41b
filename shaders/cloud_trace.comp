#version 450
#extension GL_GOOGLE_include_directive : require
// Cloud trace: one pixel of each block x block block of the cloud image per frame (the one
// the frame index selects), ray-marched through the layers from a blue-noise jittered start, then
// aerial perspective applied at the transmittance-weighted depth (seed 001 eq. 21), read from
// the view's froxel volume as the sky's own is (Hillaire 2020 5.4).
// Writes premultiplied cloud luminance with opacity (1 - transmittance), and the depth with the
// transmittance and the opacity-weighted depth (which the reconstruction interpolates).
#include "cloud_shared.h"
#include "cloud_layouts.h"

layout(local_size_x = SKY_CLOUD_LOCAL, local_size_y = SKY_CLOUD_LOCAL) in;
#include "cloud_bindings.glsl"
layout(binding = SKY_CLOUD_TRACE_COLOR_OUT, rgba32f) uniform writeonly image2D trace_color;
layout(binding = SKY_CLOUD_TRACE_DEPTH_OUT, rgba32f) uniform writeonly image2D trace_depth;
// The view's froxel volume.
layout(binding = SKY_CLOUD_TRACE_AP_INSCATTER) uniform sampler3D ap_inscatter;
layout(binding = SKY_CLOUD_TRACE_AP_TRANSMITTANCE) uniform sampler3D ap_transmittance;
layout(push_constant) uniform ViewPush { sky_cloud_view_push view; };

#include "scattering_march.glsl"
#include "camera.glsl"

const float AP_STEPS = 8.0;

// Aerial perspective from the camera to `depth` along the ray through uv, read from the
// froxel volume. False beyond the volume.
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
    ivec2 tsize = imageSize(trace_color);
    ivec2 tp = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(tp, tsize)))
        return;
    ivec2 size = view.target.xy; // the cloud image: the output's size or half of it
    ivec2 px = min(tp * view.frame.y + view.frame.zw, size - 1);
    vec2 uv = (vec2(px) + 0.5) / vec2(size);
    vec3 dir = camera_ray(uv);
    vec3 origin = frame.camera_position.xyz;
    vec3 sun_dir = frame.sun_direction.xyz;
    float blue = texelFetch(curl_noise, px % textureSize(curl_noise, 0), 0).b;
    float jitter = fract(blue + float(view.frame.x) * 0.61803398875);
    CloudResult c = march_clouds(origin, dir, sun_dir, jitter, cloud.march.x);
    vec3 L = c.luminance;
    float opacity = 1.0 - c.transmittance;
    if (opacity > 1e-4) {
        // Aerial perspective between the camera and the clouds' front (seed 001 5.9.1): the
        // view's froxel volume, or a short march of its own beyond it.
        vec3 inscatter, transmittance;
        if (!aerial_perspective_froxel(uv, c.depth, inscatter, transmittance)) {
            MarchResult ap = march_scattering(origin, dir, sun_dir, c.depth, AP_STEPS);
            inscatter = ap.luminance;
            transmittance = ap.transmittance;
        }
        L = L * transmittance + opacity * inscatter * frame.sun_illuminance.xyz;
    }
    imageStore(trace_color, tp, vec4(L, opacity));
    imageStore(trace_depth, tp, vec4(c.depth, c.transmittance, opacity * c.depth, 0.0));
}
