// Atmosphere model after Hillaire 2020 (seed 004, "Production Friendly Quick Sky"; seed 001
// sections 2-3): participating media, phase functions, LUT parameterizations and the
// energy-conserving ray march shared by every atmosphere pass.
//
// The including shader declares `atmo` (sky_atmosphere_uniforms) and, where it samples them,
// `transmittance_lut` and `multiscattering_lut` (define SKY_HAS_TRANSMITTANCE_LUT /
// SKY_HAS_MULTISCATTERING_LUT before including).

#ifndef SKY_ATMOSPHERE_GLSL
#define SKY_ATMOSPHERE_GLSL

const float PI = 3.14159265358979;

struct MediumSample {
    vec3 rayleigh_scattering;
    vec3 mie_scattering;
    vec3 scattering;
    vec3 extinction;
};

float bottom_radius() { return atmo.radii.x; }
float top_radius() { return atmo.radii.y; }

// Densities at altitude h (km): exponential Rayleigh and Mie, exponential height fog, ozone
// tent (seed 001 table 2; DESIGN.md). Zero outside the atmosphere.
MediumSample sample_medium(float h)
{
    MediumSample m;
    float inside = (h <= top_radius() - bottom_radius()) ? 1.0 : 0.0;
    h = max(h, 0.0);
    float rayleigh_density = exp(-h / atmo.radii.z) * inside;
    float mie_density = exp(-h / atmo.radii.w) * inside;
    float fog = atmo.mie_absorption.w * exp(-h / atmo.mie_extinction.w) * inside;
    float ozone = max(0.0, 1.0 - abs(h - atmo.rayleigh_scattering.w) / (0.5 * atmo.mie_scattering.w))
                  * inside;
    m.rayleigh_scattering = atmo.rayleigh_scattering.xyz * rayleigh_density;
    m.mie_scattering = atmo.mie_scattering.xyz * mie_density + vec3(fog);
    m.scattering = m.rayleigh_scattering + m.mie_scattering;
    m.extinction = m.rayleigh_scattering + atmo.mie_extinction.xyz * mie_density + vec3(fog)
                   + atmo.ozone_absorption.xyz * ozone;
    return m;
}

// Rayleigh phase 3/(16 pi) (1 + cos^2) (seed 000 eq. 14.12).
float rayleigh_phase(float cos_theta)
{
    return 3.0 / (16.0 * PI) * (1.0 + cos_theta * cos_theta);
}

// Cornette-Shanks phase, normalized over the sphere (seed 001 eq. 4 family; Hillaire 2020).
vec3 mie_phase(float cos_theta, vec3 g)
{
    vec3 g2 = g * g;
    vec3 denom = pow(max(vec3(1e-6), 1.0 + g2 - 2.0 * g * cos_theta), vec3(1.5));
    return 3.0 / (8.0 * PI) * (1.0 - g2) * (1.0 + cos_theta * cos_theta) / ((2.0 + g2) * denom);
}

// Nearest intersection t >= 0 of the ray with a centred sphere, or -1.
float ray_sphere_nearest(vec3 origin, vec3 dir, float radius)
{
    float b = dot(origin, dir);
    float c = dot(origin, origin) - radius * radius;
    float disc = b * b - c;
    if (disc < 0.0)
        return -1.0;
    float s = sqrt(disc);
    float t0 = -b - s;
    float t1 = -b + s;
    if (t0 >= 0.0)
        return t0;
    if (t1 >= 0.0)
        return t1;
    return -1.0;
}

// Half-texel remapping so the first and last texel centres hold the values at 0 and 1.
// (Hillaire 2020's code scales by size/(size+1) one way and size/(size-1) the other, which
// are not inverses; this pair is, as the self-test checks.)
float unit_to_sub_uv(float u, float size) { return (u * (size - 1.0) + 0.5) / size; }
float sub_uv_to_unit(float u, float size) { return (u * size - 0.5) / (size - 1.0); }

// Transmittance LUT parameterization of Bruneton & Neyret 2008 (section 4), as in Hillaire 2020.
vec2 transmittance_r_mu_to_unit(float r, float mu)
{
    float bottom = bottom_radius(), top = top_radius();
    float H = sqrt(max(0.0, top * top - bottom * bottom));
    float rho = sqrt(max(0.0, r * r - bottom * bottom));
    float disc = r * r * (mu * mu - 1.0) + top * top;
    float d = max(0.0, -r * mu + sqrt(max(disc, 0.0)));
    float d_min = top - r;
    float d_max = rho + H;
    return vec2((d - d_min) / max(d_max - d_min, 1e-6), rho / H);
}

void transmittance_unit_to_r_mu(vec2 unit, out float r, out float mu)
{
    float bottom = bottom_radius(), top = top_radius();
    float H = sqrt(max(0.0, top * top - bottom * bottom));
    float rho = H * unit.y;
    r = sqrt(rho * rho + bottom * bottom);
    float d_min = top - r;
    float d_max = rho + H;
    float d = d_min + unit.x * (d_max - d_min);
    mu = d == 0.0 ? 1.0 : (H * H - rho * rho - d * d) / (2.0 * r * d);
    mu = clamp(mu, -1.0, 1.0);
}

// Multiple-scattering LUT: (cos sun zenith, altitude) linear (Hillaire 2020, section 5.2).
vec2 multiscattering_r_mu_to_unit(float r, float mu_s)
{
    return vec2(clamp(mu_s * 0.5 + 0.5, 0.0, 1.0),
                clamp((r - bottom_radius()) / (top_radius() - bottom_radius()), 0.0, 1.0));
}

// Sky-view LUT: longitude/latitude around the camera with the horizon at v = 0.5 and a
// square-root compression that puts texels near the horizon (Hillaire 2020, section 5.3).
// acos with |error| < 7e-5 rad (Abramowitz & Stegun 4.4.45): the library acos is several
// times more expensive on CPU Vulkan, and the sky-view mapping only needs it to be smooth
// and monotonic (the LUT is built with the same function's inverse up to that error).
float fast_acos(float x)
{
    float a = abs(x);
    float r = sqrt(1.0 - a) * (1.5707288 + a * (-0.2121144 + a * (0.0742610 - 0.0187293 * a)));
    return x >= 0.0 ? r : PI - r;
}

// beta: angle between the horizon and the nadir seen from the camera, acos(sqrt(r^2-R^2)/r).
vec2 skyview_dir_to_unit_beta(float beta, float view_zenith_cos, float light_view_cos,
                              bool hits_ground)
{
    float zenith_horizon_angle = PI - beta;
    float view_zenith = fast_acos(clamp(view_zenith_cos, -1.0, 1.0));
    // Above the horizon v = (1 - sqrt(1 - z/z_h)) / 2, below v = (1 + sqrt((z - z_h)/beta)) / 2:
    // one square root of the selected argument.
    float above = 1.0 - clamp(view_zenith / zenith_horizon_angle, 0.0, 1.0);
    float below = clamp((view_zenith - zenith_horizon_angle) / max(beta, 1e-6), 0.0, 1.0);
    float root = sqrt(hits_ground ? below : above);
    float v = 0.5 + (hits_ground ? 0.5 : -0.5) * root;
    float u = sqrt(clamp(-light_view_cos * 0.5 + 0.5, 0.0, 1.0));
    return vec2(u, v);
}

vec2 skyview_dir_to_unit(float r, float view_zenith_cos, float light_view_cos, bool hits_ground)
{
    float bottom = bottom_radius();
    float beta = acos(clamp(sqrt(max(0.0, r * r - bottom * bottom)) / r, -1.0, 1.0));
    return skyview_dir_to_unit_beta(beta, view_zenith_cos, light_view_cos, hits_ground);
}

void skyview_unit_to_dir(float r, vec2 unit, out float view_zenith_cos, out float light_view_cos)
{
    float bottom = bottom_radius();
    float v_horizon = sqrt(max(0.0, r * r - bottom * bottom));
    float beta = acos(clamp(v_horizon / r, -1.0, 1.0));
    float zenith_horizon_angle = PI - beta;
    if (unit.y < 0.5) {
        float coord = 1.0 - 2.0 * unit.y;
        coord = 1.0 - coord * coord;
        view_zenith_cos = cos(coord * zenith_horizon_angle);
    } else {
        float coord = unit.y * 2.0 - 1.0;
        coord *= coord;
        view_zenith_cos = cos(zenith_horizon_angle + beta * coord);
    }
    float c = unit.x * unit.x;
    light_view_cos = -(c * 2.0 - 1.0);
}

#ifdef SKY_HAS_TRANSMITTANCE_LUT
// Transmittance from radius r along cos-zenith mu to the top of the atmosphere.
vec3 transmittance_to_top(float r, float mu)
{
    vec2 unit = transmittance_r_mu_to_unit(r, mu);
    vec2 size = vec2(textureSize(transmittance_lut, 0));
    vec2 uv = vec2(unit_to_sub_uv(unit.x, size.x), unit_to_sub_uv(unit.y, size.y));
    return exp(-textureLod(transmittance_lut, uv, 0.0).rgb);
}

// Transmittance from point p toward the sun, zero when the planet is in the way.
vec3 sun_transmittance(vec3 p, vec3 sun_dir)
{
    float r = length(p);
    float mu_s = dot(p / r, sun_dir);
    float planet = ray_sphere_nearest(p, sun_dir, bottom_radius());
    return planet >= 0.0 ? vec3(0.0) : transmittance_to_top(r, mu_s);
}
#endif

#ifdef SKY_HAS_SKYVIEW_LUT
// Texture coordinates in `skyview_lut` (Hillaire 2020 5.3) of a direction seen from the camera,
// by its zenith cosine and the cosine of its azimuth from the light's. Needs `frame` (the
// camera's horizon angle).
vec2 skyview_uv_at(float view_zenith_cos, float light_view_cos, bool hits_ground)
{
    vec2 unit = skyview_dir_to_unit_beta(frame.horizon.x, view_zenith_cos, light_view_cos,
                                         hits_ground);
    vec2 size = vec2(textureSize(skyview_lut, 0));
    return vec2(unit_to_sub_uv(unit.x, size.x), unit_to_sub_uv(unit.y, size.y));
}
#endif

#ifdef SKY_HAS_MULTISCATTERING_LUT
// Psi_ms: isotropic multiple-scattered luminance per unit illuminance (Hillaire 2020 eq. 10).
vec3 multiscattering(float r, float mu_s)
{
    vec2 unit = multiscattering_r_mu_to_unit(r, mu_s);
    vec2 size = vec2(textureSize(multiscattering_lut, 0));
    vec2 uv = vec2(unit_to_sub_uv(unit.x, size.x), unit_to_sub_uv(unit.y, size.y));
    return textureLod(multiscattering_lut, uv, 0.0).rgb;
}
#endif

// Far intersection t of the ray with a centred sphere, or -1 when it misses.
float ray_sphere_far(vec3 origin, vec3 dir, float radius)
{
    float b = dot(origin, dir);
    float disc = b * b - (dot(origin, origin) - radius * radius);
    return disc < 0.0 ? -1.0 : -b + sqrt(disc);
}

// Distance range [t_start, t_end] of a ray inside the atmosphere shell, stopping at the
// ground; false when the ray misses the atmosphere.
bool atmosphere_segment(vec3 origin, vec3 dir, out float t_start, out float t_end,
                        out bool hits_ground)
{
    float top = top_radius();
    float r = length(origin);
    t_start = 0.0;
    if (r > top) {
        float t_top = ray_sphere_nearest(origin, dir, top);
        if (t_top < 0.0)
            return false;
        t_start = t_top;
    }
    float t_ground = ray_sphere_nearest(origin, dir, bottom_radius());
    hits_ground = t_ground >= 0.0;
    // The exit is the far root from the original origin: re-intersecting from the entry
    // point loses it to float rounding at planetary radii.
    t_end = hits_ground ? t_ground : max(ray_sphere_far(origin, dir, top), 0.0);
    return t_end > t_start;
}

// Segment boundaries distributed quadratically: short steps near the origin, where density
// and its gradient are largest for the rays we care about.
float march_boundary(float t_start, float t_end, float i, float count)
{
    float x = i / count;
    return t_start + (t_end - t_start) * x * x;
}

// Where a distance falls in the aerial-perspective volume, whose slice k ends at
// max_km * ((k + 1) / slices)^2 (aerial_perspective.comp): x the texture coordinate of the
// slice holding it, y the fade from nothing before the first slice's end.
vec2 aerial_perspective_slice(float depth, float max_km, float slices)
{
    float slice = sqrt(depth / max_km) * slices - 1.0;
    return vec2((max(slice, 0.0) + 0.5) / slices, clamp(slice + 1.0, 0.0, 1.0));
}

#endif
