#version 450
#extension GL_GOOGLE_include_directive : require
// Aerial-perspective froxel volume (Hillaire 2020 section 5.4; seed 000 eq. 14.15-14.16):
// for each froxel column over the view frustum, in-scattered luminance (per unit sun
// illuminance) and transmittance from the camera to the end of every depth slice. Slices
// follow a squared distribution so that near slices are thin. With clouds, the sun's light is
// shadowed by the cloud shadow map at every sample (light shafts under broken clouds), the
// multiple scattering under the clouds follows the light they let through, and what the
// clouds take away is kept in a third volume for the sky and ground pixels, whose
// in-scattering comes from the cloudless sky-view LUT.
#include "sky_shared.h"
#include "sky_layouts.h"
#include "cloud_shared.h"

layout(local_size_x = SKY_AP_LOCAL, local_size_y = SKY_AP_LOCAL) in;
SKY_PARAMETER_BLOCK(SKY_AP_ATMOSPHERE, AtmosphereBlock, sky_atmosphere_uniforms, atmo);
SKY_PARAMETER_BLOCK(SKY_AP_FRAME, FrameBlock, sky_frame_uniforms, frame);
layout(binding = SKY_AP_TRANSMITTANCE) uniform sampler2D transmittance_lut;
layout(binding = SKY_AP_MULTISCATTERING) uniform sampler2D multiscattering_lut;
layout(binding = SKY_AP_INSCATTER_OUT, rgba32f) uniform writeonly image3D ap_inscatter_out;
layout(binding = SKY_AP_TRANSMITTANCE_OUT, rgba32f) uniform writeonly image3D ap_transmittance_out;
layout(binding = SKY_AP_SHAFTS_OUT, rgba32f) uniform writeonly image3D ap_shafts_out;
layout(binding = SKY_AP_CLOUD_SHADOW) uniform sampler2D cloud_shadow_map; // r: transmittance toward the sun
SKY_PARAMETER_BLOCK(SKY_AP_CLOUD, CloudBlock, sky_cloud_uniforms, cloud);
// The clouds' hemisphere averages (cloud_hemisphere.comp): yzw the diffuse light under them
// against a clear sky's.
layout(std430, binding = SKY_AP_CLOUD_ENV) readonly buffer CloudEnv {
    vec4 env_luminance;
    vec4 env_transmittance;
};

#define SKY_HAS_TRANSMITTANCE_LUT
#define SKY_HAS_MULTISCATTERING_LUT
#include "atmosphere.glsl"
#include "camera.glsl"
#include "cloud_ground_shadow.glsl"

const float STEPS_PER_SLICE = 2.0;

// Transmittance toward the sun through the clouds at p below the low layer: the shadow map
// holds it for ground points, so p slides down along the sun to the ground it shares the
// column of cloud with (the flat-planet projection of cloud_ground_shadow.glsl).
float cloud_sun_visibility(vec3 p, vec3 sun_dir)
{
    float r = length(p);
    vec3 up = p / r;
    float h = r - bottom_radius();
    if (r >= cloud.low.x)
        return 1.0;
    return cloud_ground_shadow(p - sun_dir * (h / max(dot(up, sun_dir), 0.05)));
}

void main()
{
    atmo = atmo_block;
    frame = frame_block;
    cloud = cloud_block;
    ivec3 size = imageSize(ap_inscatter_out);
    ivec2 px = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(px, size.xy)))
        return;
    vec2 uv = (vec2(px) + 0.5) / vec2(size.xy);
    vec3 dir = camera_ray(uv);
    vec3 origin = frame.camera_position.xyz;
    vec3 sun_dir = frame.sun_direction.xyz;
    float cos_theta = dot(dir, sun_dir);
    float phase_r = rayleigh_phase(cos_theta);
    vec3 phase_m = mie_phase(cos_theta, atmo.mie_g.xyz);
    float t_ground = ray_sphere_nearest(origin, dir, bottom_radius());
    float t_max = t_ground >= 0.0 ? t_ground : 1e9;

    bool shafts = cloud.march.z > 0.5 && cloud.shadow_sun.w > 0.5;
    // Under the clouds the air's multiple scattering is lit by the light they let through and
    // their own, not by a clear sky's: a deck's base would otherwise stand behind the blue glow
    // of a sunlit sky's air (and fog under an overcast glow). The multiple-scattering LUT's
    // source (seed 000 eq. 14.16's isotropic term) scales by the hemisphere's ratio there.
    vec3 under_clouds = shafts ? env_transmittance.yzw : vec3(1.0);
    vec3 luminance = vec3(0.0), throughput = vec3(1.0), shadowed = vec3(0.0);
    float t_prev = 0.0;
    float slices = float(size.z);
    for (int slice = 0; slice < size.z; slice++) {
        float x = (float(slice) + 1.0) / slices;
        float t_slice = frame.image.z * x * x;
        float t_slice_end = min(t_slice, t_max);
        float dt = (t_slice_end - t_prev) / STEPS_PER_SLICE;
        for (float k = 0.0; k < STEPS_PER_SLICE && dt > 0.0; k += 1.0) {
            vec3 p = origin + (t_prev + (k + 0.5) * dt) * dir;
            float r = length(p);
            MediumSample m = sample_medium(r - bottom_radius());
            vec3 single = sun_transmittance(p, sun_dir)
                          * (m.rayleigh_scattering * phase_r + m.mie_scattering * phase_m);
            float visible = shafts ? cloud_sun_visibility(p, sun_dir) : 1.0;
            vec3 ms = multiscattering(r, dot(p / r, sun_dir)) * m.scattering;
            vec3 ms_kept = r < cloud.low.x ? under_clouds : vec3(1.0);
            vec3 source = single * visible + ms * ms_kept;
            vec3 step_t = exp(-m.extinction * dt);
            vec3 ext = max(m.extinction, vec3(1e-9));
            luminance += throughput * (source - source * step_t) / ext; // seed 001 eq. 23
            vec3 lost = single * (1.0 - visible) + ms * (1.0 - ms_kept);
            shadowed += throughput * (lost - lost * step_t) / ext;
            throughput *= step_t;
        }
        t_prev = max(t_prev, t_slice_end);
        imageStore(ap_inscatter_out, ivec3(px, slice), vec4(luminance, 1.0));
        imageStore(ap_transmittance_out, ivec3(px, slice), vec4(throughput, 1.0));
        imageStore(ap_shafts_out, ivec3(px, slice), vec4(shadowed, 1.0));
    }
}
