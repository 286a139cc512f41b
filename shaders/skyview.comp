#version 450
#extension GL_GOOGLE_include_directive : require
// Sky-view LUT (Hillaire 2020 section 5.3): in-scattered luminance per unit sun illuminance
// for every direction around the camera, latitude/longitude with the sun at azimuth 0 and
// horizon-dense rows. Rays below the horizon end at the ground, whose lit radiance is added
// through the path's transmittance: the ground with its aerial perspective, exactly along
// the ray. Where the converged multiple scattering is complete (ms_refine.h), it replaces
// Hillaire's LUT by frame.multiple_scattering.x: single scattering and the sunlit ground from
// this march, every higher order (the sky's light on the ground included) from its table.
#include "sky_shared.h"
#include "sky_layouts.h"

layout(local_size_x = SKY_SKYVIEW_LOCAL, local_size_y = SKY_SKYVIEW_LOCAL) in;
SKY_PARAMETER_BLOCK(SKY_SKYVIEW_ATMOSPHERE, AtmosphereBlock, sky_atmosphere_uniforms, atmo);
SKY_PARAMETER_BLOCK(SKY_SKYVIEW_FRAME, FrameBlock, sky_frame_uniforms, frame);
layout(binding = SKY_SKYVIEW_TRANSMITTANCE) uniform sampler2D transmittance_lut;
layout(binding = SKY_SKYVIEW_MULTISCATTERING) uniform sampler2D multiscattering_lut;
layout(binding = SKY_SKYVIEW_IRRADIANCE) uniform sampler2D irradiance_lut;
layout(binding = SKY_SKYVIEW_OUT, rgba32f) uniform writeonly image2D skyview_out;
layout(binding = SKY_SKYVIEW_MS_SUM) uniform sampler3D ms_sum_table;
// The moonlit sky-view LUT: the same integral with the moon as the light (seed 001 4.2).
layout(constant_id = SKY_SKYVIEW_CONST_MOON_LIGHT) const bool MOON_LIGHT = false;

#define SKY_HAS_TRANSMITTANCE_LUT
#define SKY_HAS_MULTISCATTERING_LUT
#include "atmosphere.glsl"
#include "scattering_march.glsl"
#include "ground.glsl"
#include "ms_table.glsl"

// Step count grows with the ray's length (Hillaire 2020, 5.3): 16 for short upward rays,
// up to 40 toward the horizon. Rows of the LUT share a zenith angle, so neighbouring
// invocations take the same count.
const float MIN_STEPS = 16.0;
const float MAX_STEPS = 40.0;
const float LONG_RAY_KM = 600.0;

void main()
{
    atmo = atmo_block;
    frame = frame_block;
    ivec2 size = imageSize(skyview_out);
    ivec2 px = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(px, size)))
        return;
    vec2 uv = (vec2(px) + 0.5) / vec2(size);
    vec2 unit = vec2(sub_uv_to_unit(uv.x, float(size.x)), sub_uv_to_unit(uv.y, float(size.y)));
    float r = clamp(length(frame.camera_position.xyz), bottom_radius() + 1e-3,
                    top_radius() - 1e-3);
    float view_zenith_cos, light_view_cos;
    skyview_unit_to_dir(r, unit, view_zenith_cos, light_view_cos);
    float sin_zenith = sqrt(max(0.0, 1.0 - view_zenith_cos * view_zenith_cos));
    float sin_azimuth = sqrt(max(0.0, 1.0 - light_view_cos * light_view_cos));
    vec3 dir = vec3(sin_zenith * light_view_cos, sin_zenith * sin_azimuth, view_zenith_cos);
    // The local sun lies in the x-z plane (azimuth 0).
    vec3 origin = vec3(0.0, 0.0, r);
    vec3 sun_dir = MOON_LIGHT ? frame.moon_local.xyz : frame.sun_local.xyz;
    float t_start, t_end;
    bool hits;
    atmosphere_segment(origin, dir, t_start, t_end, hits);
    float steps = floor(mix(MIN_STEPS, MAX_STEPS, clamp((t_end - t_start) / LONG_RAY_KM, 0.0, 1.0)));
    // The moonlit sky keeps Hillaire's LUT: the table is the sun's.
    float converged = MOON_LIGHT ? 0.0 : frame.multiple_scattering.x;
    MarchResult m = march_scattering_weighted(origin, dir, sun_dir, 1e9, steps, 1.0 - converged);
    vec3 L = m.luminance;
    if (m.hits_ground)
        L += m.transmittance
             * ground_radiance_weighted(origin + m.t_end * dir, sun_dir, 1.0 - converged);
    if (converged > 0.0)
        L += converged * frame.multiple_scattering.y
             * ms_lookup_log_cubic(ms_sum_table, r, view_zenith_cos, sun_dir.z, dot(dir, sun_dir));
    imageStore(skyview_out, px, vec4(L, 1.0));
}
