// Cloud density (extinction per km) at a planet-centred point (seed 001 5.3-5.4; Schneider
// 2015/2017, Nubis): the weather map's coverage is a threshold of the 3D base shape, so the
// noise draws every outline; a height profile per cloud type, a function of the height alone,
// raises that threshold toward the type's tops (clouds narrow into domes and towers over flat
// bases); detail noise erodes the edges only; curl noise moves the outlines. Three layers, the
// WMO's etages: a low cumulus-type layer, a middle one (altostratus, altocumulus) and a high
// thin one.
//
// The including shader declares `atmo`, `cloud` (sky_cloud_uniforms) and the samplers
// base_noise (3D), detail_noise (3D), curl_noise (2D: rg curl, b blue noise) and weather_map
// (2D), all sampled with repeat addressing.
#ifndef CLOUD_DENSITY_GLSL
#define CLOUD_DENSITY_GLSL

#include "cloud_profile.glsl"
#include "cloud_shell.glsl"

const float CURL_STRENGTH_KM = 0.25;

// False in the pipelines for weather maps with no cloud type above TOWERING_TYPE
// (render/clouds/cloud_renderer.c): they carry no doubled turrets and no anvil. On lavapipe
// every copy of that code in a march's loop slowed each sample, used or not.
layout(constant_id = SKY_CLOUD_CONST_TOWERING) const bool TOWERING = true;
const float TOWERING_TYPE = CLOUD_TOWERING_TYPE;

// How much the detail noise erodes, in [0, 1]: the march lowers it where its steps are longer
// than the detail's features (tens of metres), which it would only alias into grain.
float cloud_detail_weight = 1.0;
// Level of detail of the base shape, in [0, 1]: 0 its full turret-scale octaves, 1 its lowest
// octave alone with softer edges. The march raises it with its step length, so that clouds
// far away are filtered instead of aliased into speckle.
float cloud_lod = 0.0;

float remap(float v, float lo, float hi, float new_lo, float new_hi)
{
    return new_lo + (v - lo) / max(hi - lo, 1e-5) * (new_hi - new_lo);
}

// Horizontal coordinates of p in the wind-advected weather pattern (km).
vec2 cloud_pattern_xy(vec3 p)
{
    return p.xy - cloud.weather.xy;
}

vec4 sample_weather(vec2 pattern_xy)
{
    vec4 wm = textureLod(weather_map, pattern_xy * cloud.weather.z + 0.5, 0.0);
    return vec4(clamp(wm.rg, vec2(0.0), vec2(1.0)), wm.ba);
}

// Extinction ramps from the threshold over this much of the shape's range (with its level of
// detail, wider): the interior is dense, the edges tens of metres soft.
const vec2 EDGE_RAMP = vec2(0.12, 0.3);
// The share of the shape's lowest octave in every cloud: outlines of area-perimeter dimension about
// 1.35 from above, as observed (Lovejoy 1982), not 1.45.
const float TURRET_SMOOTHING = 0.4;
// Sheets: the share of the shape's relief they keep, and their edge ramp (soft: a deck's top
// thins over about 100 m).
const float SHEET_RELIEF = 0.15;
const float SHEET_RAMP = 0.6;
// Coverage below this holds no cloud (so the march can skip it; the specks it would leave are
// a few voxels).
const float MIN_COVERAGE = CLOUD_MIN_COVERAGE;
// Anvils: in the top of a cumulonimbus layer (types above CLOUD_ANVIL_TYPE) the coverage
// spreads from the towers around it, the largest of the columns ANVIL_REACH of the layer's
// thickness around.
const float ANVIL_REACH = 0.3;

// The low layer's coverage at height fraction h over pattern position xy (0 outside the layer).
float low_coverage(float h, vec2 xy, vec4 wm, vec4 shape)
{
    if (h <= 0.0 || h >= 1.0 || wm.r <= 0.0)
        return 0.0;
    float c = coverage_at(wm.r, profile_rise(h, shape));
    // (Cumulonimbus alone: the anvil's four lookups are not spent on the cumulus around it.)
    if (TOWERING && shape.w > 0.0 && wm.b > CLOUD_ANVIL_TYPE && h > 0.6) {
        float reach = ANVIL_REACH * (cloud.low.y - cloud.low.x);
        float around = max(max(sample_weather(xy + vec2(reach, 0.0)).r,
                               sample_weather(xy - vec2(reach, 0.0)).r),
                           max(sample_weather(xy + vec2(0.0, reach)).r,
                               sample_weather(xy - vec2(0.0, reach)).r));
        float spread = shape.w * smoothstep(0.65, 0.8, h) * (1.0 - smoothstep(0.9, 0.98, h));
        c = max(c, spread * coverage_at(max(around, wm.r), 0.6));
    }
    return c;
}

// Low layer. `detail` false gives the coarse shape (no detail erosion) of light and shadow
// marches. -1 where the coverage holds no cloud at all (empty space the march may skip).
float low_density_or_empty(vec3 p, float r, vec4 wm, bool detail)
{
    float h = layer_fraction(r, cloud.low);
    vec4 shape = type_shape(wm.b);
    vec2 xy = cloud_pattern_xy(p);
    float c = low_coverage(h, xy, wm, shape) - MIN_COVERAGE;
    if (c <= 0.0)
        return -1.0;
    vec3 q = vec3(xy, r - bottom_radius());
    // Curl distortion moves the outlines, most in the turrets (Schneider 2015).
    vec2 curl = textureLod(curl_noise, q.xy / cloud.tiles.z, 0.0).rg;
    q.xy += curl * CURL_STRENGTH_KM * (0.5 + h);
    // Towering clouds boil in turrets twice as large (a kilometre and more in a cumulonimbus);
    // the base tile repeats an even number of times over the weather extent
    // (render/clouds/cloud_params.c), so twice it still tiles.
    float towering = TOWERING ? smoothstep(TOWERING_TYPE, 1.0, wm.b) : 0.0;
    vec4 n = vec4(0.0);
    if (towering < 1.0)
        n = textureLod(base_noise, q / cloud.tiles.x, 0.0);
    if (towering > 0.0)
        n = mix(n, textureLod(base_noise, q / (2.0 * cloud.tiles.x), 0.0), towering);
    // Sheets (stratus, stratocumulus) keep the shape's lowest octave at a fraction of its
    // relief, with soft tops and no detail erosion: radiative smoothing leaves real decks
    // smooth below a few hundred metres, and their structure is the weather map's, on every
    // scale (cloud_weather.comp); at full relief the base tile's cells would tile the deck.
    float sheet = cloud_sheet_share(wm.b);
    float u = mix(n.r, n.g, max(max(cloud_lod, sheet), TURRET_SMOOTHING));
    u = 0.5 + (u - 0.5) * mix(1.0, SHEET_RELIEF, sheet);
    float ramp = mix(mix(EDGE_RAMP.x, EDGE_RAMP.y, cloud_lod), SHEET_RAMP, sheet);
    float d = clamp((u - (1.0 - c)) / ramp, 0.0, 1.0);
    // Flat bases: the cloud starts at the layer's bottom (the condensation level), rounded
    // over shape.y.
    d *= smoothstep(0.0, shape.y, h);
    if (detail && d > 0.0 && d < 1.0) {
        vec3 dn = textureLod(detail_noise, q / cloud.tiles.y, 0.0).rgb;
        float dfbm = dot(dn, vec3(0.625, 0.25, 0.125));
        // Wispy at the base, billowy toward the top (Schneider 2015); edges only: the remap
        // leaves the dense interior (d near 1) as it is.
        float modifier = mix(dfbm, 1.0 - dfbm, clamp(h * 6.0, 0.0, 1.0));
        float erosion = shape.z * cloud_detail_weight * (1.0 - sheet);
        d = clamp(remap(d, modifier * erosion, 1.0, 0.0, 1.0), 0.0, 1.0);
    }
    // A sheet's liquid water grows with the height above its base (adiabatic ascent), so a
    // thicker part of a deck is also denser: up to 1 + sheet times the layer's density.
    d *= mix(1.0, clamp(2.0 * h / shape.x, 0.25, 2.0), sheet);
    // Precipitation also darkens the base: denser toward it.
    return d * cloud.low.z * (1.0 + wm.a * (1.0 - h));
}

float low_density(vec3 p, float r, vec4 wm, bool detail)
{
    return max(low_density_or_empty(p, r, wm, detail), 0.0);
}

// High layer: a thin sheet, stretched along the wind-free x axis when fibrous; -1 where it
// holds no cloud at all.
float high_density_or_empty(vec3 p, float r, vec4 wm)
{
    float h = layer_fraction(r, cloud.high);
    if (cloud.high.w < 0.5 || h <= 0.0 || h >= 1.0 || wm.g <= 0.0)
        return -1.0;
    float profile = smoothstep(0.0, 0.25, h) * (1.0 - smoothstep(0.5, 1.0, h));
    float stretch = mix(1.0, 4.0, cloud.media.w);
    vec3 q = vec3(cloud_pattern_xy(p) * vec2(1.0 / stretch, 1.0), (r - bottom_radius()) * 3.0);
    vec4 n = textureLod(base_noise, q / (cloud.tiles.x * 2.0), 0.0);
    float shape = mix(n.g, n.r, 0.3) * profile;
    float d = clamp(remap(shape, 1.0 - wm.g, 1.0, 0.0, 1.0), 0.0, 1.0) * wm.g;
    return d * cloud.high.z;
}

float high_density(vec3 p, float r, vec4 wm)
{
    return max(high_density_or_empty(p, r, wm), 0.0);
}

// Middle layer (altostratus .. altocumulus, mid_shape.y 0 .. 1), on the low layer's machinery
// with its coverage from the uniforms, not the weather map. Two shapes, mixed by the type:
//  - altostratus, a sheet: the columns where a patch pattern lies above 1 - coverage hold it,
//    so coverage is the fraction of the sky it covers, with soft breaks; it fills its layer
//    from a base rounded over 10 % of it up to an undulating top (50-100 % of the layer), its
//    liquid water growing with the height above the base as in a low sheet;
//  - altocumulus, cells: the low layer's threshold of the base shape's lowest octave at about
//    half the base tile, cells of about 300 m (WMO: elements of 1-5 degrees, some hundreds of metres
//    at 3-6 km), the coverage varied from column to column by the patch pattern (normal
//    scores, as coverage_at) so that the cells come in patches, tops rising as the low
//    layer's (profile_rise) to 90 % of the layer.
// The patch pattern combines the base shape's lowest octave on two lattices of incommensurate
// size and orientation (tiles of about 5 and 11 km), each read on a plane that climbs slowly
// through the noise's third dimension, so that neither repeats on its lattice; the cells'
// and the undulation's lookups move through that dimension with the patch pattern. Within
// the extent no shift brings both lattices and their climbs within 3/4 of a cell of
// themselves, and nothing repeats short of the extent.
// -1 where it holds no cloud at all.
//
// Each lattice is a Gaussian integer k, given for 24 base tiles over the extent and scaled
// with their count: a lookup reads the noise at k (x + iy) / extent, its tiles turned by arg k
// and repeating |k| times over the extent, so that every pattern still tiles the extent and
// the wind's wrap at it (cloud_params.c) stays seamless. Their norms (136, 29, 2341) are
// coprime, so no shorter period is common to all three.
const vec2 MID_PATCH_LATTICE = vec2(10.0, 6.0);  // 5.1 km tiles over 60 km, at 31 degrees
const vec2 MID_SWELL_LATTICE = vec2(5.0, 2.0);   // 11.1 km, at 22 degrees
const vec2 MID_CELL_LATTICE = vec2(46.0, -15.0); // 1.24 km, at -18 degrees
// Tiles of the noise each plane climbs across the extent eastward and northward: whole ones,
// so that it tiles the extent too; slopes of a third of a tile per tile and less, which hardly
// squeeze the features. The patch's starts half a tile from the swell's, independent of it.
const vec2 MID_PATCH_CLIMB = vec2(4.0, -1.0);
const vec2 MID_SWELL_CLIMB = vec2(1.0, 1.0);
const float MID_PATCH_SLICE = 0.5;
// How far (of their tile) the cells' and the undulation's lookups move as the patch pattern
// goes from 0 to 1.
const float MID_CELL_DRIFT = 1.0;
const float MID_UNDULATION_DRIFT = 0.25;
const float MID_BREAK_RAMP = 0.15;   // of the pattern's range: the soft edge of a break
const float MID_SHEET_BASE = 0.1;    // base rounding, of the layer
const vec2 MID_SHEET_TOP = vec2(0.5, 1.0);
const vec4 MID_CELL_SHAPE = vec4(0.9, 0.2, 0.0, 0.0); // top, base rounding
const float MID_CELL_SPREAD = 2.0;

// Noise coordinates (in tiles) of pattern position xy at height z (km) on lattice k.
vec3 mid_lattice(vec2 xy, float z, vec2 k)
{
    k = round(k * (cloud.weather.w / (24.0 * cloud.tiles.x)));
    return vec3(k.x * xy.x - k.y * xy.y, k.y * xy.x + k.x * xy.y, length(k) * z) * cloud.weather.z;
}

float mid_density_or_empty(vec3 p, float r)
{
    float h = layer_fraction(r, cloud.mid);
    if (cloud.mid.w < 0.5 || h <= 0.0 || h >= 1.0)
        return -1.0;
    float coverage = cloud.mid_shape.x, type = cloud.mid_shape.y;
    vec2 xy = cloud_pattern_xy(p);
    float z = r - bottom_radius();
    vec3 patch_at = mid_lattice(xy, 0.0, MID_PATCH_LATTICE);
    patch_at.z = MID_PATCH_SLICE + dot(xy, MID_PATCH_CLIMB) * cloud.weather.z;
    float patchiness = textureLod(base_noise, patch_at, 0.0).g;
    vec3 swell_at = mid_lattice(xy, 0.0, MID_SWELL_LATTICE);
    swell_at.z = dot(xy, MID_SWELL_CLIMB) * cloud.weather.z;
    float swell = textureLod(base_noise, swell_at, 0.0).g;
    // Both uniform and independent: (Phi^-1(a) + Phi^-1(b)) / sqrt(2) is a normal score again.
    // In the logistic approximation of Phi (coverage_at), Phi^-1(u) is u's log odds over
    // LOGISTIC_PROBIT, so the column's odds are the product of theirs to the power 1 / sqrt(2);
    // 0.96 fits the sum's lighter tails (to 0.5 % of coverage).
    vec2 both = clamp(vec2(patchiness, swell), 1e-3, 1.0 - 1e-3);
    float odds = both.x * both.y / ((1.0 - both.x) * (1.0 - both.y));
    float column = 1.0 / (1.0 + pow(odds, -0.96 / sqrt(2.0)));
    float sheet = -1.0, cells = -1.0;
    if (type < 1.0) {
        float covered = clamp((column - (1.0 - coverage)) / MID_BREAK_RAMP, 0.0, 1.0);
        if (covered > 0.0) {
            vec3 at = mid_lattice(xy, 0.5 * z, MID_PATCH_LATTICE);
            at.z += MID_UNDULATION_DRIFT * column;
            float undulation = textureLod(base_noise, at, 0.0).r;
            float top = mix(MID_SHEET_TOP.x, MID_SHEET_TOP.y, undulation);
            sheet = covered * smoothstep(0.0, MID_SHEET_BASE, h) *
                    (1.0 - smoothstep(top - 0.3, top, h)) * clamp(2.0 * h, 0.25, 2.0);
        }
    }
    if (type > 0.0) {
        float c_column = coverage_at(coverage, MID_CELL_SPREAD * (0.5 - column));
        float c = coverage_at(c_column, profile_rise(h, MID_CELL_SHAPE)) - MIN_COVERAGE;
        if (c > 0.0) {
            vec3 at = mid_lattice(xy, z, MID_CELL_LATTICE);
            at.z += MID_CELL_DRIFT * column;
            float u = textureLod(base_noise, at, 0.0).g;
            // Far away (the march's level of detail) the cells' edges soften.
            float ramp = mix(EDGE_RAMP.x, EDGE_RAMP.y, cloud_lod);
            cells = clamp((u - (1.0 - c)) / ramp, 0.0, 1.0) * smoothstep(0.0, MID_CELL_SHAPE.y, h);
        }
    }
    if (sheet < 0.0 && cells < 0.0)
        return -1.0;
    return mix(max(sheet, 0.0), max(cells, 0.0), type) * cloud.mid.z;
}

float mid_density(vec3 p, float r)
{
    return max(mid_density_or_empty(p, r), 0.0);
}

// Which layer a march or a lookup is for (a constant at every call).
const int LAYER_LOW = 0;
const int LAYER_HIGH = 1;
const int LAYER_MID = 2;

// The layer's shell: x bottom radius, y top radius, z extinction at full density, w on.
vec4 layer_shell(int layer)
{
    return layer == LAYER_LOW ? cloud.low : layer == LAYER_MID ? cloud.mid : cloud.high;
}

// Extinction (per km) of the low and high layers at p, which share a weather-map lookup.
float cloud_extinction_low_high(vec3 p, bool detail)
{
    float r = length(p);
    if (r < cloud.low.x || r > max(cloud.low.y, cloud.high.y))
        return 0.0;
    vec4 wm = sample_weather(cloud_pattern_xy(p));
    return low_density(p, r, wm, detail) + high_density(p, r, wm);
}

// Extinction (per km) at p, every layer; detail false for coarse (shadow, light) samples.
float cloud_extinction(vec3 p, bool detail)
{
    float sigma = cloud_extinction_low_high(p, detail);
    // The middle layer's lookups only where it is on (a uniform: lavapipe still runs them
    // under a mask, so passes that do not need them call the function above).
    if (cloud.mid.w > 0.5)
        sigma += mid_density(p, length(p));
    return sigma;
}

// The same for one layer, or -1 where the layer's coverage holds no cloud around p (below
// MIN_COVERAGE: the shape's level sets cannot reach there), so a march that probes it steps over
// empty space without jumping across fringes thinner than its probe spacing. Marches call it
// with a constant `layer`, so that each loop holds the noise lookups of its own layer only:
// lavapipe executes both sides of every branch, so another layer's early return would not
// spare its lookups.
float cloud_layer_sample(vec3 p, bool detail, int layer)
{
    float r = length(p);
    if (layer == LAYER_MID)
        return mid_density_or_empty(p, r);
    vec4 wm = sample_weather(cloud_pattern_xy(p));
    return layer == LAYER_LOW ? low_density_or_empty(p, r, wm, detail)
                              : high_density_or_empty(p, r, wm);
}

float cloud_layer_extinction(vec3 p, bool detail, int layer)
{
    return max(cloud_layer_sample(p, detail, layer), 0.0);
}

// Rain under the low layer's precipitating bases, 0..1 (the weather map's precipitation, which
// lies under the cores of the footprint), the same from the base down to the ground: shafts.
// y: the layer's nominal optical depth over p (its coverage there, full density).
vec2 cloud_rain(vec3 p)
{
    vec4 wm = sample_weather(cloud_pattern_xy(p));
    return vec2(wm.a, wm.r * cloud.low.z * (cloud.low.y - cloud.low.x));
}

#endif
