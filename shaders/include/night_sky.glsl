// The night sky, added to the day's shading (sky_shading.glsl): the moonlit sky and ground
// from a second sky-view LUT lit by the moon, the airglow, the stars of night_shared.h and the
// moon's disc lit as a sphere by the sun (seed 001 sections 4.2-4.3). All of it goes through
// the atmosphere's transmittance like the sun; nothing is switched off by day except what
// adds less than 0.1 % to a pixel.
#ifndef NIGHT_SKY_GLSL
#define NIGHT_SKY_GLSL

#include "night_shared.h"

float luminance_of(vec3 rgb) { return dot(rgb, vec3(0.2126, 0.7152, 0.0722)); }

// Stars in one view direction: the pixel's J2000 direction picks one cell of the grid; each
// star listed there adds a Gaussian of its illuminance, E exp(-theta^2 / 2 s^2) / (2 pi s^2)
// (cd/m2; integrates to E over the sphere), outside the atmosphere.
vec3 star_luminance(vec3 dir)
{
    vec3 eq = dir.x * frame.star_rotation[0].xyz + dir.y * frame.star_rotation[1].xyz
              + dir.z * frame.star_rotation[2].xyz;
    uvec4 header = star_words[0];
    float ra = atan(eq.y, eq.x);
    ra = ra < 0.0 ? ra + 2.0 * PI : ra;
    float dec = asin(clamp(eq.z, -1.0, 1.0));
    uint cx = min(uint(ra / (2.0 * PI) * float(header.x)), header.x - 1u);
    uint cy = min(uint((dec / PI + 0.5) * float(header.y)), header.y - 1u);
    uint cell = cy * header.x + cx;
    uvec4 w = star_words[1u + cell / 2u];
    uvec2 slots = (cell & 1u) == 0u ? w.xy : w.zw;
    uint base = 1u + (header.x * header.y + 1u) / 2u;
    float sigma = frame.night.z;
    float inv_two_s2 = 0.5 / (sigma * sigma);
    vec3 L = vec3(0.0);
    for (uint k = 0u; k < uint(NIGHT_STAR_CELL_CAPACITY); k++) {
        uint idx = ((k < 2u ? slots.x : slots.y) >> (16u * (k & 1u))) & 0xFFFFu;
        if (idx == NIGHT_STAR_EMPTY)
            break;
        vec3 d = uintBitsToFloat(star_words[base + 2u * idx].xyz) - eq;
        L += uintBitsToFloat(star_words[base + 2u * idx + 1u].xyz) * exp(-dot(d, d) * inv_two_s2);
    }
    return L * (frame.night.y / (2.0 * PI * sigma * sigma));
}

float mare_albedo(vec3 p, float lat, float lon, float radius)
{
    vec3 c = vec3(cos(radians(lat)) * sin(radians(lon)), sin(radians(lat)),
                  cos(radians(lat)) * cos(radians(lon)));
    float angle = degrees(acos(clamp(dot(p, c), -1.0, 1.0)));
    return mix(NIGHT_MARE_ALBEDO, 1.0, smoothstep(radius - 1.5, radius + 1.5, angle));
}

// Albedo of the near side relative to the highlands (night_moon_albedo in render/night_sky.c).
float moon_albedo(vec2 q, float z)
{
    vec3 p = vec3(q, z);
    float a = 1.0;
#define MARE_TERM(lat, lon, r) a = min(a, mare_albedo(p, lat, lon, r));
    NIGHT_MARIA(MARE_TERM)
#undef MARE_TERM
    return a;
}

// The moon's disc outside the atmosphere: a sphere lit by the sun with the Lommel-Seeliger
// law mu0 / (mu0 + mu) (Hapke 1981 eq. 16), times the maria albedo, normalised on the CPU so
// that the disc delivers moon_illuminance (seed 001 4.2, L = E / solid angle at full moon);
// plus the faint earthshine over the whole disc.
vec3 moon_disk_luminance(vec3 dir)
{
    vec3 m = frame.moon_direction.xyz;
    float c = dot(dir, m);
    // Inside from the offset across the line of sight: 1 - cos(radius) ~ 1e-5 is too close to
    // float precision to test c against it (the limb would grow by pixels).
    vec3 perp = (dir - m * c) / frame.moon_disk.y;
    vec3 up = frame.moon_up.xyz;
    vec2 q = vec2(dot(perp, cross(m, up)), dot(perp, up));
    if (c <= 0.0 || dot(q, q) > 1.0 || frame.moon_disk.z < 0.5)
        return vec3(0.0);
    float z = sqrt(max(0.0, 1.0 - dot(q, q)));
    float mu0 = dot(perp - z * m, frame.sun_direction.xyz);
    float reflectance = mu0 > 0.0 ? mu0 / (mu0 + z) : 0.0;
    float albedo = moon_albedo(q, z);
    return albedo * (frame.moon_illuminance.xyz * (reflectance * frame.moon_disk.x)
                     + frame.moon_earthshine.xyz);
}

// Airglow seen through a thin emitting shell at NIGHT_AIRGLOW_LAYER_KM: brighter toward the
// horizon by the van Rhijn factor 1 / sqrt(1 - (R / (R + h))^2 sin^2 z).
float airglow_luminance(float mu)
{
    float k = bottom_radius() / (bottom_radius() + NIGHT_AIRGLOW_LAYER_KM);
    return frame.night.x * inversesqrt(max(1e-4, 1.0 - k * k * (1.0 - mu * mu)));
}

// Inside the atmosphere. day: what the sun adds to this pixel (for the star cull).
vec3 night_from_atmosphere(vec3 cam, vec3 dir, bool hits_ground, bool include_bodies, vec3 day)
{
    // Selected, not branched on: lavapipe inlines a uniform that decides a branch and may
    // compile the pipeline again at every dispatch (camera.glsl), which this flag did to the
    // moon-disk and night metering passes every frame. The sample is discarded when the
    // moonlit LUT is not computed.
    vec3 moonlit = textureLod(moon_skyview_lut,
                              skyview_uv_for(dir, hits_ground, frame.moon_horizontal), 0.0).rgb
                   * frame.moon_illuminance.xyz;
    vec3 L = mix(vec3(0.0), moonlit, bvec3(frame.moon_illuminance.w > 0.5));
    float r = max(length(cam), bottom_radius() + 1e-3);
    vec3 T = hits_ground ? vec3(0.0) : transmittance_to_top(r, dir.z);
    // The ground under a sky of airglow luminance L reflects albedo x L (Lambert).
    L += hits_ground ? atmo.ground_albedo.xyz * frame.night.x : T * airglow_luminance(dir.z);
    if (!hits_ground && luminance_of(day + L) < frame.night.w)
        L += T * star_luminance(dir);
    if (include_bodies)
        L += T * moon_disk_luminance(dir);
    return L;
}

// Above the atmosphere: the moonlit atmosphere and ground are marched like the sunlit ones.
vec3 night_from_space(vec3 origin, vec3 dir, MarchResult day, bool include_bodies)
{
    vec3 L = vec3(0.0);
    if (frame.moon_illuminance.w > 0.5) {
        vec3 moon = frame.moon_direction.xyz;
        MarchResult m = march_scattering(origin, dir, moon, 1e9, SPACE_MARCH_STEPS);
        vec3 lit = m.luminance;
        if (m.hits_ground)
            lit += m.transmittance * ground_radiance_per_lux(origin + m.t_end * dir, moon);
        L += lit * frame.moon_illuminance.xyz;
    }
    if (!day.hits_ground) {
        if (frame.night.y > 0.0)
            L += day.transmittance * star_luminance(dir);
        if (include_bodies)
            L += day.transmittance * moon_disk_luminance(dir);
    }
    return L;
}

#endif
