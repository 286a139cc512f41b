// Cloud density (extinction per km) at a planet-centred point (seed 001 5.3-5.4; Schneider
// 2015): weather map (coverage, type, precipitation) x height profile of the cloud type x
// Perlin-Worley base shape, eroded by Worley detail noise, distorted by curl noise. Two layers:
// a low cumulus-type layer and a high thin one.
//
// The including shader declares `atmo`, `cloud` (sky_cloud_uniforms) and the samplers
// base_noise (3D), detail_noise (3D), curl_noise (2D: rg curl, b blue noise) and weather_map
// (2D), all sampled with repeat addressing.
#ifndef CLOUD_DENSITY_GLSL
#define CLOUD_DENSITY_GLSL

const float CURL_STRENGTH_KM = 0.35;

// How much the detail noise erodes, in [0, 1]: the march lowers it where its steps are longer
// than the detail's features (tens of metres), which it would only alias into grain.
float cloud_detail_weight = 1.0;

float remap(float v, float lo, float hi, float new_lo, float new_hi)
{
    return new_lo + (v - lo) / max(hi - lo, 1e-5) * (new_hi - new_lo);
}

// Horizontal coordinates of p in the wind-advected weather pattern (km).
vec2 cloud_pattern_xy(vec3 p)
{
    return p.xy - cloud.weather.xy;
}

// The map's footprints are signed (cloud_weather.comp): their zero crossings, interpolated,
// are the outlines; clamped here.
vec4 sample_weather(vec2 pattern_xy)
{
    vec4 wm = textureLod(weather_map, pattern_xy * cloud.weather.z + 0.5, 0.0);
    return vec4(max(wm.rg, vec2(0.0)), wm.ba);
}

// Shape parameters of a cloud type in [0, 1] (stratus .. cumulonimbus), interpolated between
// the tabulated types (render/cloud_params.c): x core height, y base rounding, z erosion,
// w anvil.
vec4 type_shape(float type)
{
    float x = clamp(type, 0.0, 1.0) * float(CLOUD_PROFILE_COUNT - 1);
    int i = min(int(x), CLOUD_PROFILE_COUNT - 2);
    return mix(cloud.profiles[i], cloud.profiles[i + 1], x - float(i));
}

float layer_fraction(float r, vec4 layer)
{
    return (r - layer.x) / (layer.y - layer.x);
}

// Where a cloud may be at height fraction h over a point of footprint f (Schneider 2017's
// density-height gradient, made to follow the footprint): the column of a clump reaches
// shape.x * sqrt(c (2 - c)), a quarter circle in c = f / CORE_FOOTPRINT; the footprint rises
// smoothly toward a clump's core (cloud_weather.comp), so a clump is a dome with steep sides on
// a flat base and a cumulonimbus core a tower. The top levels off over the core (f past
// CORE_FOOTPRINT) instead of following the footprint to its peak, which made pyramids; the
// billows carve its upper 40 % into cauliflower domes. Under
// the layer top the anvil spreads over the whole footprint (f^0.3 widens it, Schneider 2017's
// anvil bias).
const float CORE_FOOTPRINT = 0.7;
float cloud_envelope(float h, float f, vec4 shape)
{
    float core = clamp(f / CORE_FOOTPRINT, 0.0, 1.0);
    float top = shape.x * sqrt(core * (2.0 - core));
    float column = smoothstep(0.0, shape.y, h) * (1.0 - smoothstep(0.6 * top, top, h));
    float anvil = shape.w * smoothstep(0.7, 0.8, h) * (1.0 - smoothstep(0.9, 0.98, h))
                  * pow(f, 0.3);
    return max(column, anvil);
}

// The low layer's envelope at height fraction h over a point of weather wm (0 outside the
// layer or the footprint). Precipitation widens the footprint (seed 001 5.4: weather drives the
// shape).
float low_envelope(float h, vec4 wm, vec4 shape)
{
    if (h <= 0.0 || h >= 1.0 || wm.r <= 0.0)
        return 0.0;
    return cloud_envelope(h, clamp(wm.r * (1.0 + 0.5 * wm.a), 0.0, 1.0), shape);
}

// Low layer. `detail` false gives the coarse shape used by shadow and light marches.
float low_density(vec3 p, float r, vec4 wm, bool detail)
{
    float h = layer_fraction(r, cloud.low);
    vec4 shape = type_shape(wm.b);
    float envelope = low_envelope(h, wm, shape);
    if (envelope <= 0.0)
        return 0.0;
    float altitude = r - bottom_radius();
    vec3 q = vec3(cloud_pattern_xy(p), altitude);
    if (detail) { // the coarse shape of light and shadow marches skips the distortion
        vec2 curl = textureLod(curl_noise, q.xy / cloud.tiles.z, 0.0).rg;
        q.xy += curl * CURL_STRENGTH_KM * (1.0 - h);
    }
    vec4 n = textureLod(base_noise, q / cloud.tiles.x, 0.0);
    float fbm = dot(n.gba, vec3(0.625, 0.25, 0.125));
    // Perlin-Worley billows (Schneider 2015), then the envelope as coverage: only the densest
    // billows survive where the envelope is low, so outlines are billowy level sets.
    float billows = clamp(remap(n.r, fbm - 1.0, 1.0, 0.0, 1.0), 0.0, 1.0);
    float d = clamp(remap(billows, 1.0 - envelope, 1.0, 0.0, 1.0), 0.0, 1.0) * envelope;
    if (detail && d > 0.0) {
        vec3 dn = textureLod(detail_noise, q / cloud.tiles.y, 0.0).rgb;
        float dfbm = dot(dn, vec3(0.625, 0.25, 0.125));
        // Wispy at the base, billowy toward the top (Schneider 2015).
        float modifier = mix(dfbm, 1.0 - dfbm, clamp(h * 6.0, 0.0, 1.0));
        d = clamp(remap(d, modifier * shape.z * cloud_detail_weight, 1.0, 0.0, 1.0), 0.0, 1.0);
    }
    // Precipitation also darkens the base: denser toward it.
    return d * cloud.low.z * (1.0 + wm.a * (1.0 - h));
}

// High layer: a thin sheet, stretched along the wind-free x axis when fibrous.
float high_density(vec3 p, float r, vec4 wm)
{
    float h = layer_fraction(r, cloud.high);
    if (cloud.high.w < 0.5 || h <= 0.0 || h >= 1.0 || wm.g <= 0.0)
        return 0.0;
    float profile = smoothstep(0.0, 0.25, h) * (1.0 - smoothstep(0.5, 1.0, h));
    float stretch = mix(1.0, 4.0, cloud.media.w);
    vec3 q = vec3(cloud_pattern_xy(p) * vec2(1.0 / stretch, 1.0), (r - bottom_radius()) * 3.0);
    vec4 n = textureLod(base_noise, q / (cloud.tiles.x * 2.0), 0.0);
    float shape = mix(n.r, dot(n.gba, vec3(0.625, 0.25, 0.125)), 0.5) * profile;
    float d = clamp(remap(shape, 1.0 - wm.g, 1.0, 0.0, 1.0), 0.0, 1.0) * wm.g;
    return d * cloud.high.z;
}

// Extinction (per km) at p; detail false for coarse (shadow, light) samples.
float cloud_extinction(vec3 p, bool detail)
{
    float r = length(p);
    if (r < cloud.low.x || r > max(cloud.low.y, cloud.high.y))
        return 0.0;
    vec4 wm = sample_weather(cloud_pattern_xy(p));
    return low_density(p, r, wm, detail) + high_density(p, r, wm);
}

// The same for one layer. Marches call it with a constant `low_layer`, so that each loop holds
// the noise lookups of its own layer only: lavapipe executes both sides of every branch, so
// the other layer's early return would not spare its lookups.
float cloud_layer_extinction(vec3 p, bool detail, bool low_layer)
{
    float r = length(p);
    vec4 wm = sample_weather(cloud_pattern_xy(p));
    return low_layer ? low_density(p, r, wm, detail) : high_density(p, r, wm);
}

// Whether the layer may hold cloud around p: its envelope (low) or its coverage (high) is
// positive there. Unlike the density, which the billows cut into level sets, this stays
// positive over a cloud's whole fringe, so a march that probes it steps over empty space
// without jumping across fringes thinner than its probe spacing.
bool cloud_layer_occupied(vec3 p, bool low_layer)
{
    float r = length(p);
    vec4 wm = sample_weather(cloud_pattern_xy(p));
    if (!low_layer) {
        float h = layer_fraction(r, cloud.high);
        return cloud.high.w > 0.5 && h > 0.0 && h < 1.0 && wm.g > 0.0;
    }
    return low_envelope(layer_fraction(r, cloud.low), wm, type_shape(wm.b)) > 0.0;
}

// Rain under the low layer's precipitating bases, 0..1 (the weather map's precipitation, which
// lies under the cores of the footprint), the same from the base down to the ground: shafts.
// y: the layer's nominal optical depth over p (its coverage there, full density).
vec2 cloud_rain(vec3 p)
{
    vec4 wm = sample_weather(cloud_pattern_xy(p));
    return vec2(wm.a, wm.r * cloud.low.z * (cloud.low.y - cloud.low.x));
}

// Range [t0, t1] of a ray inside the spherical shell [r_in, r_out], first crossing only;
// false when it misses it or the planet is in the way first.
bool shell_segment(vec3 o, vec3 d, float r_in, float r_out, out float t0, out float t1)
{
    float r = length(o);
    float t_ground = ray_sphere_nearest(o, d, bottom_radius());
    float t_in_near = ray_sphere_nearest(o, d, r_in);
    if (r < r_in) {
        // Below: from the exit of the inner sphere to the exit of the outer one.
        t0 = ray_sphere_far(o, d, r_in);
        t1 = ray_sphere_far(o, d, r_out);
        return t_ground < 0.0 && t1 > t0;
    }
    if (r <= r_out) {
        // Inside the shell. A camera on its inner sphere (at the cloud base) meets that sphere
        // at t = 0 on a level or rising ray: that is no exit.
        t0 = 0.0;
        t1 = t_in_near > 1e-4 ? t_in_near : ray_sphere_far(o, d, r_out);
        return t1 > 0.0;
    }
    float t_out = ray_sphere_nearest(o, d, r_out);
    if (t_out < 0.0)
        return false;
    t0 = t_out;
    t1 = t_in_near >= 0.0 ? t_in_near : ray_sphere_far(o, d, r_out);
    return t1 > t0;
}

#endif
