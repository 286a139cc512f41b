// Luminance (cd/m2) arriving at the camera from one view direction: sky from the sky-view LUT
// (or a per-pixel march from space), the planet surface lit by sun and sky with aerial
// perspective, and the sun disk. Shared by the composite, probe and metering passes so that
// `skyd probe` reports exactly what a frame shows.

#ifndef SKY_SHADING_GLSL
#define SKY_SHADING_GLSL

#include "atmosphere.glsl"
#include "scattering_march.glsl"
#include "camera.glsl"

const float SPACE_MARCH_STEPS = 48.0;

vec3 ground_irradiance_per_lux(float mu_s)
{
    float size = float(textureSize(irradiance_lut, 0).x);
    float u = unit_to_sub_uv(clamp(mu_s * 0.5 + 0.5, 0.0, 1.0), size);
    return textureLod(irradiance_lut, vec2(u, 0.5), 0.0).rgb;
}

// Lambertian ground lit by the sun (with transmittance and planet shadow) and the sky.
vec3 ground_luminance(vec3 p)
{
    vec3 n = normalize(p);
    vec3 sun_dir = frame.sun_direction.xyz;
    vec3 direct = sun_transmittance(p + n * 1e-3, sun_dir) * max(dot(n, sun_dir), 0.0);
    vec3 sky = ground_irradiance_per_lux(dot(n, sun_dir));
    return atmo.ground_albedo.xyz / PI * (direct + sky) * frame.sun_illuminance.xyz;
}

// Limb darkening factor normalised so the disk still delivers the sun's illuminance
// (seed 001 appendix B, listings 6 and 7; disk average of mu^a is 2/(2+a)).
vec3 limb_darkening(float center_to_edge)
{
    int model = int(frame.sun_illuminance.w + 0.5);
    float mu = sqrt(max(0.0, 1.0 - center_to_edge * center_to_edge));
    if (model == SKY_LIMB_NECKEL96) {
        vec3 a = vec3(0.397, 0.503, 0.652);
        return pow(vec3(max(mu, 1e-4)), a) * (2.0 + a) / 2.0;
    }
    if (model == SKY_LIMB_HM98) {
        vec3 a0 = vec3(0.34685, 0.26073, 0.15248), a1 = vec3(1.37539, 1.27428, 1.38517);
        vec3 a2 = vec3(-2.04425, -1.30352, -1.49615), a3 = vec3(2.70493, 1.47085, 1.99886);
        vec3 a4 = vec3(-1.94290, -0.96618, -1.48155), a5 = vec3(0.55999, 0.26384, 0.44119);
        float mu2 = mu * mu, mu3 = mu2 * mu, mu4 = mu2 * mu2, mu5 = mu4 * mu;
        vec3 f = a0 + a1 * mu + a2 * mu2 + a3 * mu3 + a4 * mu4 + a5 * mu5;
        // Disk average: 2 * sum a_k / (k + 2).
        vec3 avg = 2.0 * (a0 / 2.0 + a1 / 3.0 + a2 / 4.0 + a3 / 5.0 + a4 / 6.0 + a5 / 7.0);
        return f / avg;
    }
    return vec3(1.0);
}

// Sun disk luminance outside the atmosphere: E / solid angle (seed 001 eq. 16), or zero.
vec3 sun_disk_luminance(vec3 dir)
{
    float cos_angle = dot(dir, frame.sun_direction.xyz);
    if (cos_angle < frame.sun_direction.w)
        return vec3(0.0);
    float sin_angle = sqrt(max(0.0, 1.0 - cos_angle * cos_angle));
    float center_to_edge = clamp(sin_angle / frame.sun_disk.y, 0.0, 1.0);
    return frame.sun_illuminance.xyz / frame.sun_disk.x * limb_darkening(center_to_edge);
}

vec2 skyview_uv(float r, vec3 up, vec3 dir, bool hits_ground)
{
    vec3 sun_dir = frame.sun_direction.xyz;
    vec3 dir_h = dir - up * dot(dir, up);
    vec3 sun_h = sun_dir - up * dot(sun_dir, up);
    float lengths = length(dir_h) * length(sun_h);
    float light_view_cos = lengths > 1e-7 ? dot(dir_h, sun_h) / lengths : 1.0;
    vec2 unit = skyview_dir_to_unit(r, dot(dir, up), light_view_cos, hits_ground);
    vec2 size = vec2(textureSize(skyview_lut, 0));
    return vec2(unit_to_sub_uv(unit.x, size.x), unit_to_sub_uv(unit.y, size.y));
}

// Froxel lookup at distance t along the pixel at uv: rgb in-scatter, and transmittance.
void sample_aerial_perspective(vec2 uv, float t, out vec3 inscatter, out vec3 transmittance)
{
    float slices = float(textureSize(ap_inscatter_lut, 0).z);
    float s = sqrt(max(t, 0.0) / frame.image.z) * slices - 1.0; // slice i ends at ((i+1)/N)^2
    vec3 coord = vec3(uv, (max(s, 0.0) + 0.5) / slices);
    inscatter = textureLod(ap_inscatter_lut, coord, 0.0).rgb;
    transmittance = textureLod(ap_transmittance_lut, coord, 0.0).rgb;
    if (s < 0.0) { // between the camera (nothing yet) and the end of the first slice
        float w = clamp(s + 1.0, 0.0, 1.0);
        inscatter *= w;
        transmittance = mix(vec3(1.0), transmittance, w);
    }
}

vec3 shade_from_space(vec3 origin, vec3 dir, bool include_sun)
{
    vec3 sun_dir = frame.sun_direction.xyz;
    MarchResult m = march_scattering(origin, dir, sun_dir, 1e9, SPACE_MARCH_STEPS);
    vec3 L = m.luminance * frame.sun_illuminance.xyz;
    WHEN(m.hits_ground)
        L += m.transmittance * ground_luminance(origin + m.t_end * dir);
    WHEN(!m.hits_ground && include_sun)
        L += m.transmittance * sun_disk_luminance(dir);
    return L;
}

// Ground seen from inside the atmosphere at distance t_ground: its lit luminance through the
// path transmittance plus the in-scattered light, from the froxels near the camera and from
// the sky-view LUT (whose below-horizon rows end at the ground) beyond them.
vec3 shade_ground(vec3 cam, float r, vec3 up, vec3 dir, float t_ground, vec3 sky_inscatter,
                  bool use_froxels, vec2 uv)
{
    vec3 p = cam + t_ground * dir;
    vec3 np = normalize(p);
    // Camera-to-ground transmittance from two upward LUT rays (Bruneton 2008, eq. 2 ratio).
    vec3 path_t = transmittance_to_top(bottom_radius(), dot(np, -dir))
                  / max(transmittance_to_top(r, dot(up, -dir)), vec3(1e-20));
    path_t = min(path_t, vec3(1.0));
    vec3 inscatter = sky_inscatter;
    float ap_max = frame.image.z;
    WHEN(use_froxels && t_ground < ap_max) {
        vec3 ap_in, ap_t;
        sample_aerial_perspective(uv, t_ground, ap_in, ap_t);
        // Hand over to the sky-view path over the last fifth of the froxel range.
        float w = smoothstep(0.8 * ap_max, ap_max, t_ground);
        inscatter = mix(ap_in * frame.sun_illuminance.xyz, sky_inscatter, w);
        path_t = mix(ap_t, path_t, w);
    }
    return ground_luminance(p) * path_t + inscatter;
}

vec3 shade_from_atmosphere(vec3 cam, vec3 dir, bool use_froxels, vec2 uv, bool include_sun)
{
    float r = max(length(cam), bottom_radius() + 1e-3);
    vec3 up = normalize(cam);
    cam = up * r;
    float t_ground = ray_sphere_nearest(cam, dir, bottom_radius());
    bool hits_ground = t_ground >= 0.0;
    vec3 L = textureLod(skyview_lut, skyview_uv(r, up, dir, hits_ground), 0.0).rgb
             * frame.sun_illuminance.xyz;
    WHEN(hits_ground)
        L = shade_ground(cam, r, up, dir, t_ground, L, use_froxels, uv);
    WHEN(!hits_ground && include_sun && dot(dir, frame.sun_direction.xyz) >= frame.sun_direction.w)
        L += sun_disk_luminance(dir) * transmittance_to_top(r, dot(up, dir));
    return L;
}

vec3 shade_direction(vec3 dir, bool use_froxels, vec2 uv, bool include_sun)
{
    vec3 cam = frame.camera_position.xyz;
    bool in_space = length(cam) >= top_radius();
    vec3 L = vec3(0.0);
    WHEN(in_space)
        L = shade_from_space(cam, dir, include_sun);
    WHEN(!in_space)
        L = shade_from_atmosphere(cam, dir, use_froxels, uv, include_sun);
    return L;
}

#endif
