// Luminance (cd/m2) arriving at the camera from one view direction, shared by the composite,
// probe and metering passes so that `skyd probe` reports exactly what a frame shows.
// Inside the atmosphere a pixel is one sky-view LUT sample (sky, or the lit ground seen
// through its aerial perspective) plus the sun disk; from space each pixel is ray-marched.
// Branch-free on purpose (see shading_bindings.glsl); the sun disk is added by a separate,
// small composite over the sun's bounding box (composite.comp, SUN_REGION).

#ifndef SKY_SHADING_GLSL
#define SKY_SHADING_GLSL

#include "atmosphere.glsl"
#include "scattering_march.glsl"
#include "camera.glsl"
#include "ground.glsl"

const float SPACE_MARCH_STEPS = 48.0;

// Limb darkening normalised so the disk still delivers the sun's illuminance
// (seed 001 appendix B, listings 6 and 7; the disk average of mu^a is 2/(2+a)).
vec3 limb_darkening(float center_to_edge)
{
    float model = frame.sun_illuminance.w;
    float mu = sqrt(max(1e-8, 1.0 - center_to_edge * center_to_edge));
    vec3 a = vec3(0.397, 0.503, 0.652);
    vec3 neckel = pow(vec3(mu), a) * (2.0 + a) / 2.0;
    vec3 a0 = vec3(0.34685, 0.26073, 0.15248), a1 = vec3(1.37539, 1.27428, 1.38517);
    vec3 a2 = vec3(-2.04425, -1.30352, -1.49615), a3 = vec3(2.70493, 1.47085, 1.99886);
    vec3 a4 = vec3(-1.94290, -0.96618, -1.48155), a5 = vec3(0.55999, 0.26384, 0.44119);
    vec3 hm = a0 + mu * (a1 + mu * (a2 + mu * (a3 + mu * (a4 + mu * a5))));
    // Disk average of the polynomial: 2 * sum a_k / (k + 2).
    hm /= 2.0 * (a0 / 2.0 + a1 / 3.0 + a2 / 4.0 + a3 / 5.0 + a4 / 6.0 + a5 / 7.0);
    return model > 1.5 ? hm : (model > 0.5 ? neckel : vec3(1.0));
}

// Sun disk luminance outside the atmosphere, E / solid angle (seed 001 eq. 16), or zero.
vec3 sun_disk_luminance(vec3 dir)
{
    float cos_angle = dot(dir, frame.sun_direction.xyz);
    float sin_angle = sqrt(max(0.0, 1.0 - cos_angle * cos_angle));
    float center_to_edge = clamp(sin_angle / frame.sun_disk.y, 0.0, 1.0);
    float inside = cos_angle >= frame.sun_direction.w ? 1.0 : 0.0;
    return frame.sun_illuminance.xyz / frame.sun_disk.x * limb_darkening(center_to_edge) * inside;
}

// The camera stands on the +z axis, so its up is +z and horizontal projections are .xy; the
// horizon angle and the sun's horizontal direction come with the frame uniforms.
// light_horizontal: the light's horizontal direction (frame.sun_horizontal, moon_horizontal).
vec2 skyview_uv_for(vec3 dir, bool hits_ground, vec4 light_horizontal)
{
    float dir_h_len2 = dot(dir.xy, dir.xy);
    float light_view_cos = dir_h_len2 > 1e-14 && light_horizontal.w > 0.5
                               ? dot(dir.xy, light_horizontal.xy) * inversesqrt(dir_h_len2)
                               : 1.0;
    return skyview_uv_at(dir.z, light_view_cos, hits_ground);
}

vec2 skyview_uv(vec3 dir, bool hits_ground)
{
    return skyview_uv_for(dir, hits_ground, frame.sun_horizontal);
}

#include "night_sky.glsl"

vec3 shade_from_space(vec3 origin, vec3 dir, bool include_sun)
{
    vec3 sun_dir = frame.sun_direction.xyz;
    MarchResult m = march_scattering(origin, dir, sun_dir, 1e9, SPACE_MARCH_STEPS);
    vec3 L = m.luminance;
    if (m.hits_ground)
        L += m.transmittance * ground_radiance_per_lux(origin + m.t_end * dir, sun_dir);
    L *= frame.sun_illuminance.xyz;
    if (!m.hits_ground && include_sun)
        L += m.transmittance * sun_disk_luminance(dir);
    return L + night_from_space(origin, dir, m, include_sun);
}

vec3 shade_from_atmosphere(vec3 cam, vec3 dir, bool include_sun)
{
    float mu = dir.z;
    // The ray meets the ground when it points below the geometric horizon.
    bool hits_ground = mu < frame.horizon.z;
    vec3 L = textureLod(skyview_lut, skyview_uv(dir, hits_ground), 0.0).rgb
             * frame.sun_illuminance.xyz;
    if (include_sun) {
        float r = max(length(cam), bottom_radius() + 1e-3);
        float sun_visible = hits_ground ? 0.0 : 1.0;
        L += sun_disk_luminance(dir) * transmittance_to_top(r, mu) * sun_visible;
    }
    return NIGHT_SKY ? L + night_from_atmosphere(cam, dir, hits_ground, include_sun, L) : L;
}

vec3 shade_direction(vec3 dir, bool include_sun)
{
    if (FROM_SPACE)
        return shade_from_space(frame.camera_position.xyz, dir, include_sun);
    return shade_from_atmosphere(frame.camera_position.xyz, dir, include_sun);
}

#endif
