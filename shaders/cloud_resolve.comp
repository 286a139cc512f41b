#version 450
#extension GL_GOOGLE_include_directive : require
// Cloud resolve, at the cloud image's size: everything the clouds do to a pixel of the final
// image, as the pair (rgb, a) that the composite applies as L (1 - a) + rgb to the luminance L
// it shades. Two images, because a pixel that sees the ground takes more than one that does
// not (the composite picks by its own ray, so the two never blend across the horizon):
//  - sky: the reconstructed clouds over the sky, less the single scattering their shadows take
//    from the sky-view LUT's in-scattering (light shafts, read from the froxel volume at its
//    far end);
//  - ground: the same over the ground, which is relit under the clouds (seed 001 eq. 22): the
//    sun through the shadow map, the sky through the clouds' mean transmittance plus the
//    clouds' own light, and its aerial perspective likewise, less the shafts up to the ground.
//    Rays above the horizon are lowered to graze it, so that ground pixels next to the horizon
//    interpolate toward the horizon's values.
// Each term is affine in L; its coefficients (scalar tr, vec3 offset) fold into (rgb, a).
#include "sky_shared.h"
#include "cloud_shared.h"
#include "cloud_layouts.h"

layout(local_size_x = SKY_CLOUD_LOCAL, local_size_y = SKY_CLOUD_LOCAL) in;
SKY_PARAMETER_BLOCK(SKY_CLOUD_RESOLVE_ATMOSPHERE, AtmosphereBlock, sky_atmosphere_uniforms, atmo);
SKY_PARAMETER_BLOCK(SKY_CLOUD_RESOLVE_FRAME, FrameBlock, sky_frame_uniforms, frame);
layout(binding = SKY_CLOUD_RESOLVE_TRANSMITTANCE) uniform sampler2D transmittance_lut;
layout(binding = SKY_CLOUD_RESOLVE_IRRADIANCE) uniform sampler2D irradiance_lut;
SKY_PARAMETER_BLOCK(SKY_CLOUD_RESOLVE_CLOUD, CloudBlock, sky_cloud_uniforms, cloud);
layout(std430, binding = SKY_CLOUD_RESOLVE_ENV) readonly buffer CloudEnv {
    vec4 env_luminance;
    vec4 env_transmittance;
};
// r: transmittance toward the sun
layout(binding = SKY_CLOUD_RESOLVE_SHADOW) uniform sampler2D cloud_shadow_map;
// in-scattering the shadows take away
layout(binding = SKY_CLOUD_RESOLVE_AP_SHAFTS) uniform sampler3D ap_shafts;
// reconstructed: premultiplied, opacity
layout(binding = SKY_CLOUD_RESOLVE_CLOUD_COLOR) uniform sampler2D cloud_color;
layout(binding = SKY_CLOUD_RESOLVE_SKY_OUT, rgba32f) uniform writeonly image2D resolved_sky;
layout(binding = SKY_CLOUD_RESOLVE_GROUND_OUT, rgba32f) uniform writeonly image2D resolved_ground;
layout(push_constant) uniform RowsPush { sky_cloud_rows_push rows; };
// False for rows where no pixel sees the ground: their ground image is never read
// (render/cloud_renderer.c), and lavapipe would run the ground's part under a mask.
layout(constant_id = SKY_CLOUD_RESOLVE_CONST_GROUND) const bool GROUND = true;

#define SKY_HAS_TRANSMITTANCE_LUT
#include "atmosphere.glsl"
#include "camera.glsl"
#include "ground.glsl"
#include "cloud_ground_shadow.glsl"

// In-scattering (cd/m2) the clouds' shadows remove between the camera and `depth` km along
// the ray through uv (aerial_perspective.comp).
vec3 light_shafts(vec2 uv, float depth)
{
    float max_km = frame.image.z;
    vec2 slice = aerial_perspective_slice(min(depth, max_km), max_km,
                                          float(textureSize(ap_shafts, 0).z));
    return textureLod(ap_shafts, vec3(uv, slice.x), 0.0).rgb * slice.y * frame.sun_illuminance.xyz;
}

// The ground's share: with the ground luminance L seen along dir (skyview LUT, aerial
// perspective included), the clouds' effect is k L + offset (seed 001 eq. 22 with the sky's
// light through tr, the sun's through the shadow map, and the clouds' own luminance l_cloud):
//   k (L - S - t_path G) + l_cloud t_above (1 - t_below) + t_path (albedo (E_sun shadow
//   + E_sky tr) + albedo pi l_cloud), with G = albedo (E_sun + E_sky) the ground's unshadowed
//   luminance. The clouds dim and light only the air under their base: t_above and t_below
// split the path's transmittance t_path there, and k = 1 - w (1 - tr) with w the share of the
// path's in-scattering under the base (for a uniform source, t_above (1 - t_below) /
// (1 - t_path)). From under the base t_above = 1, w = 1 and k = tr (eq. 22 as it stands);
// from above the clouds the air over them keeps its light.
vec3 ground_offset(vec3 cam, vec3 dir, vec2 uv, float tr, out float k)
{
    float r_cam = max(length(cam), bottom_radius() + 1e-3);
    float t = ray_sphere_nearest(cam, dir, bottom_radius());
    if (t < 0.0) {
        // Above the horizon: the grazing ray at the same azimuth.
        float horizontal = length(dir.xy);
        vec2 across = horizontal > 1e-6 ? dir.xy / horizontal : vec2(1.0, 0.0);
        float z = frame.horizon.z - 1e-4;
        dir = vec3(across * sqrt(max(0.0, 1.0 - z * z)), z);
        t = ray_sphere_nearest(cam, dir, bottom_radius());
        if (t < 0.0)
            t = sqrt(max(0.0, r_cam * r_cam - bottom_radius() * bottom_radius()));
    }
    vec3 p = cam + t * dir;
    vec3 n = normalize(p);
    vec3 sun_dir = frame.sun_direction.xyz;
    float mu_s = dot(n, sun_dir);
    vec3 e_top = frame.sun_illuminance.xyz;
    vec3 direct = sun_transmittance(p + n * 1e-3, sun_dir) * max(mu_s, 0.0);
    vec3 albedo = atmo.ground_albedo.xyz / PI;
    // Transmittance camera <-> ground from the LUT: T(p, -dir) / T(cam, -dir).
    vec3 t_cam = transmittance_to_top(r_cam, dot(cam / r_cam, -dir));
    vec3 t_path = transmittance_to_top(bottom_radius() + 1e-3, dot(n, -dir))
                  / max(t_cam, vec3(1e-6));
    t_path = clamp(t_path, 0.0, 1.0);
    vec3 t_above = vec3(1.0);
    float t_base = length(cam) > cloud.low.x ? ray_sphere_nearest(cam, dir, cloud.low.x) : -1.0;
    if (t_base >= 0.0 && t_base < t) {
        vec3 b = cam + t_base * dir;
        float r_b = length(b);
        t_above = clamp(transmittance_to_top(r_b, dot(b / r_b, -dir)) / max(t_cam, vec3(1e-6)),
                        t_path, vec3(1.0));
    }
    vec3 t_below = t_path / max(t_above, vec3(1e-6));
    vec3 w3 = t_above * (1.0 - t_below) / max(1.0 - t_path, vec3(1e-6));
    float w = clamp(dot(w3, vec3(1.0 / 3.0)), 0.0, 1.0);
    k = 1.0 - w * (1.0 - tr);
    vec3 sun_part = t_path * albedo * direct * e_top;
    vec3 sky_part = t_path * albedo * ground_irradiance_per_lux(mu_s) * e_top;
    vec3 l_cloud = env_luminance.rgb * e_top;
    return -k * light_shafts(uv, t) + sun_part * (cloud_ground_shadow(p) - k)
           + sky_part * (tr - k)
           + l_cloud * (t_above * (1.0 - t_below) + t_path * atmo.ground_albedo.xyz); // eq. 22
}

void main()
{
    atmo = atmo_block;
    frame = frame_block;
    cloud = cloud_block;
    ivec2 px = ivec2(gl_GlobalInvocationID.xy) + ivec2(0, int(rows.row_offset));
    if (any(greaterThanEqual(px, imageSize(resolved_sky))))
        return;
    // The size in use, not the extent (which may be larger); arithmetic only: lavapipe would
    // compile a variant per value of a push constant that a branch depends on.
    vec2 uv = (vec2(px) + 0.5) / rows.size.xy;
    vec4 c = texelFetch(cloud_color, px, 0);
    vec3 cam = frame.camera_position.xyz;
    // From space the march has done everything; until the shadow map exists, the clouds
    // neither shadow nor relight (as before it is built).
    bool interact = length(cam) < top_radius() && cloud.shadow_sun.w > 0.5;
    if (!interact) {
        imageStore(resolved_sky, px, c);
        imageStore(resolved_ground, px, c);
        return;
    }
    vec3 dir = camera_ray(uv);
    float clear = 1.0 - c.a;
    vec3 sky_shafts = light_shafts(uv, frame.image.z);
    imageStore(resolved_sky, px, vec4(c.rgb - clear * sky_shafts, c.a));
    if (!GROUND)
        return;
    float k;
    vec3 offset = ground_offset(cam, dir, uv, env_transmittance.x, k);
    imageStore(resolved_ground, px, vec4(c.rgb + clear * offset, 1.0 - clear * k));
}
