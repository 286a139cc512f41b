#version 450
#extension GL_GOOGLE_include_directive : require
// Weather map (seed 001 5.3; Schneider 2015/2017): r low-layer coverage, g high-layer
// coverage, b low-layer cloud type, a precipitation; tileable over weather.map_extent_km (the
// wind shifts the lookup, not the map). Procedural from the layer parameters and the weather
// seed, or resampled from a client's map. Written a slice of rows per dispatch so rebuilds
// spread over frames.
//
// Coverage is a threshold of the 3D base shape (cloud_density.glsl): a texel of coverage c
// keeps the part c of the shape above 1 - c, so the map says where clouds gather and the shape
// draws them. Each cloud type has its own pattern (render/cloud_params.c): cumulus separate
// clouds in cells of 2.4 km down to 150 m, roughened and clustered by fractional Brownian
// fields up to 20 km, cumulonimbus cells about 10 km apart whose cores are towers, stratocumulus closed cells in a
// varying deck, stratus a sheet. The map's share of the field and the shape's are weighed so
// that about the asked coverage of the layer is cloud. Only the types present at a texel are
// evaluated.
#include "cloud_shared.h"
#include "cloud_layouts.h"

layout(local_size_x = SKY_CLOUD_LOCAL, local_size_y = SKY_CLOUD_LOCAL) in;
layout(binding = SKY_CLOUD_WEATHER_CLIENT_MAP) uniform sampler2D client_map;
layout(binding = SKY_CLOUD_WEATHER_OUT, rgba16f) uniform writeonly image2D weather_out;
layout(push_constant) uniform RowsPush { sky_cloud_rows_push push; };

#define noise_seed push.seed
#include "cloud_noise_lib.glsl"

// Cells across the map per cloud type (render/cloud_renderer.c: whole numbers, so the map
// tiles, chosen from the extent): x cumulus, y cumulonimbus, z stratocumulus, w stratus.
#define PERIODS push.size

// Deviation of one octave of gradient2() over the plane, and the mean and deviation of
// worley2() (measured over 3 seeds x 1024^2 texels).
const float OCTAVE_SIGMA = 0.2144;
const float WORLEY_MEAN = 0.5706, WORLEY_SIGMA = 0.1893;

// Octaves with fewer texels a cell than this fade out (gone at half of it): finer noise would
// change from texel to texel, and the bilinear lookup of such a map draws clouds whose outlines
// are stair steps one texel high. The stratus field goes down to it (cells of 234 m over the
// default 60 km map): the sheet's structure ends there, and below it its radiance falls
// steeply with the finest octave's spectrum, as radiative smoothing leaves real decks below
// 200 m (Davis et al. 1997); without that octave, the 3D shape's faint texture sets the slope
// there. (At twice the texel, the bilinear lookup's kinks along the texel grid were the
// decks' texture from 118 to 200 m.)
const float MIN_TEXELS_PER_CELL = 4.0;
// The fields that draw cumulus, towers, stratocumulus (which fair cumulus blend into) and the
// high layer stop at cells of 1/128 of the map (470 m over 60 km): the outlines' finer
// roughness comes from the 3D billows
// (cloud_density.glsl), whose outlines have the area-perimeter dimension observed (about 1.35,
// Lovejoy 1982); finer octaves of the map roughen them past 1.42.
const float SHAPED_FINEST_CELLS = 128.0;

// fBm of `octaves` octaves of gradient2 starting at `period` cells, amplitudes falling by
// 2^-hurst per octave, in units of its own deviation (mean 0, deviation about 1). Octaves of
// more cells across the map than finest_cells fade out (gone at twice as many).
float fbm2(vec2 x, ivec2 period, uint salt, int octaves, float hurst, float finest_cells)
{
    float sum = 0.0, power = 0.0, amp = 1.0;
    for (int o = 0; o < octaves; o++) {
        ivec2 cells = period << o;
        float resolved = finest_cells / float(max(cells.x, cells.y));
        float a = amp * clamp(2.0 * resolved - 1.0, 0.0, 1.0);
        if (a > 0.0)
            sum += a * gradient2(x, cells, salt + uint(o));
        power += a * a;
        amp *= exp2(-hurst);
    }
    return sum / (OCTAVE_SIGMA * sqrt(max(power, 1e-12)));
}

// Distinct cumulus at several sizes: CELL_LEVELS grids of `period` cells across the map, then
// twice, four and eight times as many, each cell holding at most one cloud: a dome falling as
// 1 - (d/r)^2 to 0 at its radius, of random height. A cell of level k holds one with
// probability CELL_PRESENCE * CELL_PRESENCE_RATIO^k, so the clouds per size octave grow
// 4 * 0.8 = 3.2 times an octave smaller: n(L) ~ L^-(3 + log2 0.8) = L^-2.7 as placed, which the
// threshold and merging flatten (rendered fields measure b 1.6-2.3; observed 1.7-2.9, Neggers
// et al. 2003). Smaller clouds are a little lower (cell_height_ratio a level): a smaller cloud
// is also a shallower one (humilis), and thin towers would stand where the domes were equal.
// In a sparse field the clouds differ less in height (all humilis): with 0.85 a level at
// coverage 0.2-0.25 the threshold left the smallest levels no cloud and b fell to 1.56-1.65
// over some seeds; with 0.9 there 1.75-1.88 (cloud_field_probe, seeds 1, 3, 4, 5). Higher up
// the smaller levels pass the threshold anyway, and more of them only roughen the outlines
// (at coverage 0.35, 0.875 raised D by 0.03-0.06, to 1.405) and steepen b (at 0.5, 0.9 gave
// 2.94 for seed 15): so 0.9 up to coverage 0.2, 0.85 from 0.35.
// Separate domes keep clouds apart, as observed; a single thresholded field joined turrets
// into networks whose outlines reached an area-perimeter dimension of 1.5 at mid coverage.
const int CELL_LEVELS = 5;
const float CELL_PRESENCE = 0.9, CELL_PRESENCE_RATIO = 0.8, CELL_RADIUS = 0.62;
const float CELL_HEIGHT_RATIO_SPARSE = 0.9, CELL_HEIGHT_RATIO = 0.85;
float cell_height_ratio(float coverage)
{
    return mix(CELL_HEIGHT_RATIO_SPARSE, CELL_HEIGHT_RATIO, smoothstep(0.2, 0.35, coverage));
}
// Mean and deviation of cumulus_cells() before its normalisation (sampled at 40 000 points of
// the same construction): the mean 0.477 at CELL_HEIGHT_RATIO (0.85), 0.489 at 0.875 and
// 0.502 at 0.9, the deviation 0.177-0.178.
const float CELLS_MEAN = 0.477, CELLS_MEAN_PER_RATIO = 0.5, CELLS_SIGMA = 0.177;
// A cell's rank among the cloud sizes, uniform on [0, 1): the cells of the largest level are
// stratified in blocks of 2 x 2, each block holding one rank from each quarter (a hashed
// permutation), so that a big cloud stands beside smaller ones and no neighbourhood is all big
// or all empty. With independent draws an 8.6 km disc's cloud fraction scattered by 0.033
// between seeds (tests/render/cloud_field_views.h's four discs, coverage 0.25-0.45), from the
// few 2.4 km cells it holds; stratified, by 0.016. Ranks below 1 - presence hold no cloud.
float cell_size_rank(ivec2 wrapped, int level, uint level_salt)
{
    vec2 draw = hash2(wrapped, level_salt + 1u);
    if (level > 0)
        return draw.x;
    uint quarter = uint((wrapped.x & 1) + 2 * (wrapped.y & 1));
    uint mask = uint(hash2(wrapped >> 1, level_salt + 2u).x * 4.0) & 3u;
    return (float(quarter ^ mask) + draw.y) / 4.0;
}

float cumulus_cells(vec2 x, int period, uint salt, float height_ratio)
{
    float best = 0.0;
    for (int k = 0; k < CELL_LEVELS; k++) {
        int n = period << k;
        vec2 p = x * float(n);
        ivec2 cell = ivec2(floor(p));
        float presence = CELL_PRESENCE * pow(CELL_PRESENCE_RATIO, float(k));
        uint level_salt = salt + 16u * uint(k);
        for (int j = -1; j <= 1; j++)
            for (int i = -1; i <= 1; i++) {
                ivec2 c = cell + ivec2(i, j);
                ivec2 wrapped = ((c % n) + n) % n;
                float size = cell_size_rank(wrapped, k, level_salt);
                if (size < 1.0 - presence)
                    continue;
                size = (size - (1.0 - presence)) / presence;
                vec2 centre = vec2(c) + 0.25 + 0.5 * hash2(wrapped, level_salt);
                float d2 = dot(p - centre, p - centre) / (CELL_RADIUS * CELL_RADIUS);
                float amp = mix(0.4, 1.0, size) * pow(height_ratio, float(k));
                best = max(best, amp * (1.0 - d2));
            }
    }
    return (best - CELLS_MEAN - CELLS_MEAN_PER_RATIO * (height_ratio - CELL_HEIGHT_RATIO)) /
           CELLS_SIGMA;
}

// The normal quantile of p (logistic approximation of the probit) and its inverse.
const float LOGISTIC_PROBIT = 1.702;
float probit(float p)
{
    p = clamp(p, 1e-4, 1.0 - 1e-4);
    return log(p / (1.0 - p)) / LOGISTIC_PROBIT;
}
float normal_cdf(float z)
{
    return 1.0 / (1.0 + exp(-LOGISTIC_PROBIT * z));
}

// The coverage a texel stores: cloud_density.glsl keeps cloud where the 3D shape's normal score
// S (deviation 1) exceeds -probit(coverage), so a texel of field value W (deviation 1) holds
// cloud where weight W + S > threshold, a Gaussian field of deviation sqrt(1 + weight^2):
// the threshold that leaves `coverage` of it is that deviation times probit(1 - coverage).
// `weight` says how much the map's own pattern (clusters, cells, sheets) rules over the
// shape's turrets. The score is returned, not the coverage, so types can be blended.
// threshold_score: the same with the threshold's spread and offset given.
const float PROJECTION_OFFSET = 0.55;
float threshold_score(float field, float coverage, float weight, float spread, float offset)
{
    if (coverage <= 0.0)
        return -20.0;
    if (coverage >= 1.0)
        return 20.0;
    return weight * field - (spread * probit(1.0 - coverage) + offset);
}

float coverage_score(float field, float coverage, float weight)
{
    return threshold_score(field, coverage, weight, sqrt(1.0 + weight * weight),
                           PROJECTION_OFFSET);
}

// The map's weight per type: cumulus fields are the map's cells, the 3D shape's turrets their
// outlines; cumulonimbus towers the map's cores, stratocumulus its cells (stratus: below).
const float CUMULUS_WEIGHT = 1.5, TOWER_WEIGHT = 2.5, CELL_WEIGHT = 2.5;
// Hurst exponents of the fBm fields (amplitude 2^-H per octave). Level sets of a field of
// exponent H have outlines of dimension (3 - H) / 2 and a size distribution n(L) ~ L^-(3 - H)
// (Kondev & Henley 1995); observed cumulus: D 1.3-1.4 (Lovejoy 1982), b 1.7-2.9. Decks: a
// radiance spectrum k^-5/3 over 1-8 km (Cahalan & Snider 1989), E(k) ~ k^-(2H + 1): H = 1/3.
// The stratocumulus deck's field a little smoother (H = 0.4): its threshold and its cells
// flatten the rendered spectrum to k^-1.30 over 1-8 km at H = 1/3, k^-1.37 at 0.4 (smoother
// still, its small scales fade into the 3D shape's texture: k^-2.4 below 200 m at 0.45).
const float CUMULUS_HURST = 0.3, TOWER_HURST = 0.6, DECK_HURST = 0.33, SC_DECK_HURST = 0.4;
// The largest scales (6-25 km) of a cumulus field only nudge it: at full amplitude they would
// clear or fill whole views, and a view's cloud fraction would stray from the coverage.
const float CLUSTER_AMPLITUDE = 0.03;
// The share of a fractional Brownian field (of cells of 1.6 km and less) in the cumulus cells:
// the domes alone draw outlines smoother than observed (dimension 1.20 at coverage 0.2). At 0.3
// the dimension at coverage 0.2 was 1.20-1.25 over eight seeds; at 0.4 it is 1.25-1.32, and
// 1.25-1.38 at coverage 0.35-0.5 (observed 1.3-1.4).
const float CELL_ROUGHNESS = 0.4;
// Stratus: the map holds the sheet's thickness, not a share of the shape (sheets keep a fraction
// of its relief, cloud_density.glsl): a normal score around probit(coverage), at most
// SHEET_MAX_COVERAGE's, spread by SHEET_SPREAD times the deck's field and at least SHEET_FLOOR
// below its mean (an overcast deck has thin parts, not holes), so that it is thinner and
// thicker on every scale instead of one uniform slab. Stratocumulus: the share of the deck's
// field against its cells, mostly the field, whose k^-5/3 spectrum the cells' single scale
// would flatten over 1-8 km; its coverage capped alike (a full one would saturate the blend of
// the two deck types into a uniform slab).
const float SHEET_MAX_COVERAGE = 0.98, SHEET_SPREAD = 1.2, SHEET_FLOOR = 1.5;
const float DECK_SHARE = 0.85;

// Cumulus seen from above: a column is cloud where any of its heights is, so the fraction seen
// from above is more than the share above the threshold at one height, the more so the lower
// the coverage. The threshold is fitted to skyd's renders from 14 km (tests/render/
// test_cloud_field.c's views: coverage 0.2, 0.35 and 0.5, six seeds, four places each): the
// projected field acts as one of deviation CUMULUS_PROJECTED_SPREAD shifted by
// CUMULUS_PROJECTED_OFFSET.
const float CUMULUS_PROJECTED_SPREAD = 1.48, CUMULUS_PROJECTED_OFFSET = 0.575;
float cumulus_score(float field, float coverage)
{
    return threshold_score(field, coverage, CUMULUS_WEIGHT, CUMULUS_PROJECTED_SPREAD,
                           CUMULUS_PROJECTED_OFFSET);
}

// mix(a, b, t) of two independent fields of deviation 1, scaled back to deviation 1.
float blend(float a, float b, float t)
{
    return mix(a, b, t) / sqrt((1.0 - t) * (1.0 - t) + t * t);
}

// Weights of the four tabulated types (stratus, stratocumulus, cumulus, cumulonimbus) at
// type t: tents over 0, 1/3, 2/3 and 1.
vec4 type_weights(float t)
{
    vec4 centres = vec4(0.0, 1.0, 2.0, 3.0) / 3.0;
    return max(vec4(0.0), 1.0 - abs(vec4(t) - centres) * 3.0);
}

void main()
{
    ivec2 size = imageSize(weather_out);
    ivec2 px = ivec2(gl_GlobalInvocationID.xy) + ivec2(0, int(push.row_offset));
    if (any(greaterThanEqual(px, size)))
        return;
    vec2 x = (vec2(px) + 0.5) / vec2(size);
    float shaped = min(SHAPED_FINEST_CELLS, float(size.x) / MIN_TEXELS_PER_CELL);
    float decks = float(size.x) / MIN_TEXELS_PER_CELL;
    if (push.mode == 1u) {
        // Client rows run from the north edge southward; map rows from the south.
        imageStore(weather_out, px, textureLod(client_map, vec2(x.x, 1.0 - x.y), 0.0));
        return;
    }
    vec4 p = push.params;
    // A coarse map (a forecast's grid of cloud cover) gives the field its local coverage, type
    // and rain, smoothly between its cells; the cells and sheets below fill them.
    if (push.mode == 2u)
        p = textureLod(client_map, vec2(x.x, 1.0 - x.y), 0.0);
    int cu_period = int(PERIODS.x), cb_period = int(PERIODS.y);
    int sc_period = int(PERIODS.z), st_period = int(PERIODS.w);
    // The type varies from cloud to cloud around the asked one (cumulus of several ages).
    float type = clamp(p.z + gradient2(x, ivec2(max(1, cu_period / 4)), 14u) * CLOUD_TYPE_VARIATION, 0.0, 1.0);
    vec4 w = type_weights(type);
    // The score of each type present, blended with their weights, then the coverage.
    float low = 0.0;
    if (p.x > 0.0) {
        float score = 0.0;
        if (w.z > 0.0) {
            // Cumulus: separate clouds of 2.4 km cells and less, their outlines roughened,
            // nudged by clusters of 6-25 km (weak, so that a view of ten kilometres holds
            // about the coverage).
            float clusters = fbm2(x, ivec2(max(1, cu_period / 16)), 15u, 3, CUMULUS_HURST, shaped);
            float cells = cumulus_cells(x, max(1, cu_period * 2 / 3), 11u, cell_height_ratio(p.x));
            float rough = fbm2(x, ivec2(cu_period), 12u, 3, CUMULUS_HURST, shaped);
            float field = blend(cells, rough, CELL_ROUGHNESS);
            score += w.z * cumulus_score(blend(field, clusters, CLUSTER_AMPLITUDE), p.x);
        }
        if (w.w > 0.0) { // cumulonimbus: few big cells whose cores are towers
            float field = fbm2(x, ivec2(cb_period), 21u, 6, TOWER_HURST, shaped);
            score += w.w * coverage_score(field, p.x, TOWER_WEIGHT);
        }
        if (w.y > 0.0) {
            // Stratocumulus: closed cells (inverted cellular noise is high at a cell's centre
            // and low along its borders) in a deck that varies on every scale.
            float cells = (worley2(x, sc_period, 31u) - WORLEY_MEAN) / WORLEY_SIGMA;
            float deck = fbm2(x, ivec2(max(1, st_period)), 32u, 7, SC_DECK_HURST, shaped);
            score += w.y * coverage_score(blend(cells, deck, DECK_SHARE),
                                          min(p.x, SHEET_MAX_COVERAGE), CELL_WEIGHT);
        }
        if (w.x > 0.0) { // stratus: a sheet whose thickness varies on every scale (above)
            float field = fbm2(x, ivec2(st_period), 41u, 7, DECK_HURST, decks);
            float mean = probit(min(p.x, SHEET_MAX_COVERAGE));
            score += w.x * max(mean + SHEET_SPREAD * field, mean - SHEET_FLOOR);
        }
        low = normal_cdf(score / (w.x + w.y + w.z + w.w));
        // Below the least coverage that holds cloud, falling on to below 0 (cloud_shared.h).
        low = low >= CLOUD_MIN_COVERAGE ? low : 2.0 * low - CLOUD_MIN_COVERAGE;
    }
    // The high layer: cirrostratus a veil of gentle variations (type 0), cirrus streaks ten
    // times longer east-west than wide (type 1).
    float high = 0.0;
    if (p.y > 0.0) {
        float fibrous = float(push.high_fibrous) / 1000.0;
        float veil = fbm2(x, ivec2(6), 13u, 3, 0.5, shaped);
        float streaks = fbm2(x, ivec2(3, 30), 16u, 4, 0.4, shaped);
        // Signed: outside the veil it falls on to -1 and the lookup clamps it at 0, so that
        // the bilinear lookup draws its outlines between texel centres, not along texel edges.
        high = clamp((blend(veil, streaks, fibrous) - probit(1.0 - p.y)) / 0.6, -1.0, 1.0);
        high *= mix(0.55, 1.0, p.y);
    }
    float rain = p.w * smoothstep(0.5, 0.95, low);
    imageStore(weather_out, px, vec4(low, high, type, rain));
}
