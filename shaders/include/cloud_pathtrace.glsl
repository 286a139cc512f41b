// Unbiased volumetric path tracing of the cloud layers (the reference of `skyd render
// --reference`): delta (Woodcock) tracking to real collisions, ratio tracking for
// transmittance (Novak et al. 2014, "Residual Ratio Tracking", eq. 5 and 11), next-event
// estimation of the sun and moon, directions drawn exactly from the dual-lobe phase of
// cloud_march.glsl, Russian roulette on the throughput. Uses only cloud_extinction(p, true),
// shell_segment, dual_lobe_phase and the uniforms, so it follows the renderer's density and
// phase wherever they go.
//
// The including shader includes cloud_bindings.glsl first, sets pt_precipitation_ceiling and
// pt_rng, and declares the buffer `pt_stats` (violations, max_ratio_bits, kilo_samples,
// overflows) and the majorant grid `pt_grid` (sampler2D; or defines PT_WITHOUT_GRID).
#ifndef CLOUD_PATHTRACE_GLSL
#define CLOUD_PATHTRACE_GLSL

// The largest precipitation any weather-map texel holds (the client map's largest alpha, the
// procedural map's clouds.precipitation): low_density grows with it.
float pt_precipitation_ceiling = 1.0;
uint pt_rng = 0u;
uint pt_samples = 0u; // density evaluations of this invocation

// Proposals (and grid stretches) per segment before it gives up (pt_stats.overflows).
const int PT_MAX_STEPS = 1 << 20;
// Shell segments a ray may cross (low, middle, high, low again past a grazing dip, ...).
const int PT_MAX_SEGMENTS = 8;
// A ray continues this far past a shell's boundary (km): 4 ulp of a planet-centred float.
const float PT_EPS_KM = 2e-3;
// Below this transmittance ratio tracking plays Russian roulette (unbiased).
const float PT_ROULETTE_T = 0.1;

// lavapipe (gallivm) ends every loop of an invocation once their iterations together reach
// 65535 (LP_MAX_TGSI_LOOP_ITERATIONS, counted per batch of SIMD lanes, never reset): past it
// each loop runs once more at most, and a path stops where it is, silently darker. A path
// through a deck toward a low sun (a few hundred collisions, each with a shadow ray) passes
// it. A loop that can still run twice says the limit was not reached; `zero` is 0 from a
// value no compiler knows (a push constant, a buffer), so that none unrolls the loop away.
bool pt_loops_intact(int zero)
{
    int trips = 0;
    for (int i = 0; i < zero + 2; i++)
        trips++;
    return trips == 2;
}

// PCG hash (Jarzynski and Olano 2020, "Hash Functions for GPU Rendering").
uint pt_hash(uint v)
{
    uint s = v * 747796405u + 2891336453u;
    uint w = ((s >> ((s >> 28u) + 4u)) ^ s) * 277803737u;
    return (w >> 22u) ^ w;
}

float pt_random()
{
    pt_rng = pt_hash(pt_rng);
    return float(pt_rng >> 8u) * (1.0 / 16777216.0);
}

// A free-flight distance for extinction m: -ln(1 - u) / m.
float pt_flight(float m)
{
    return -log(1.0 - pt_random()) / m;
}

// Upper bounds of cloud_extinction in each layer's shell: the low layer's density is at most
// low.z (1 + sheet) (1 + precipitation) (the envelope and the billows are at most 1; a sheet's
// share `sheet` of the cloud is denser toward its top, up to twice; precipitation darkens the
// base), the high layer's at most high.z. Without the grid's sheet share, the largest.
float pt_bound_low_sheet(float sheet)
{
    return cloud.low.z * (1.0 + sheet) * (1.0 + pt_precipitation_ceiling);
}

float pt_bound_low()
{
    return pt_bound_low_sheet(1.0);
}

float pt_bound_high()
{
    return cloud.high.w > 0.5 ? cloud.high.z : 0.0;
}

// The middle layer's: at most mid.z, twice that in a sheet's upper half (mid_density_or_empty).
float pt_bound_mid()
{
    return cloud.mid.w > 0.5 ? 2.0 * cloud.mid.z : 0.0;
}

float cloud_extinction_bound()
{
    return pt_bound_low() + pt_bound_mid() + pt_bound_high();
}

bool pt_shells_meet(vec4 a, vec4 b)
{
    return a.x < b.y && a.y > b.x;
}

// The bound over one layer's shell: its own and that of every layer whose shell overlaps it.
float pt_shell_bound(int layer)
{
    vec4 shell = layer_shell(layer);
    float m = 0.0;
    m += layer == LAYER_LOW || pt_shells_meet(shell, cloud.low) ? pt_bound_low() : 0.0;
    m += layer == LAYER_MID || (cloud.mid.w > 0.5 && pt_shells_meet(shell, cloud.mid))
             ? pt_bound_mid()
             : 0.0;
    m += layer == LAYER_HIGH || (cloud.high.w > 0.5 && pt_shells_meet(shell, cloud.high))
             ? pt_bound_high()
             : 0.0;
    return m;
}

// The nearest stretch [t0, t1] of the ray in a cloud shell and the majorant there.
bool pt_next_segment(vec3 o, vec3 d, out float t0, out float t1, out float majorant)
{
    float a0 = 0.0, a1 = 0.0, b0 = 0.0, b1 = 0.0, c0 = 0.0, c1 = 0.0;
    bool low = shell_segment(o, d, cloud.low.x, cloud.low.y, a0, a1);
    bool high = cloud.high.w > 0.5 && shell_segment(o, d, cloud.high.x, cloud.high.y, b0, b1);
    bool mid = cloud.mid.w > 0.5 && shell_segment(o, d, cloud.mid.x, cloud.mid.y, c0, c1);
    t0 = t1 = majorant = 0.0;
    float best = 1e30;
    if (low) {
        best = a0, t0 = a0, t1 = a1;
        majorant = pt_shell_bound(LAYER_LOW);
    }
    if (high && b0 < best) {
        best = b0, t0 = b0, t1 = b1;
        majorant = pt_shell_bound(LAYER_HIGH);
    }
    if (mid && c0 < best) {
        best = c0, t0 = c0, t1 = c1;
        majorant = pt_shell_bound(LAYER_MID);
    }
    // A grazing ray's sphere intersections can come out NaN or huge in float: no segment (a
    // real one is under 2 sqrt(2 R h) < 2000 km).
    return majorant > 0.0 && t1 > t0 && t1 - t0 < 2000.0;
}

// cloud_extinction(p, true), with a count of samples above the majorant (which would bias
// every estimate: tests assert there are none).
float pt_extinction(vec3 p, float majorant)
{
    pt_samples++;
    float sigma = cloud_extinction(p, true);
    if (sigma > majorant * 1.0001) {
        atomicAdd(pt_stats.violations, 1u);
        atomicMax(pt_stats.max_ratio_bits, floatBitsToUint(sigma / majorant));
    }
    return sigma;
}

// The majorant grid (cloud_majorant.comp) around p: x, y whether the low, high layer may hold
// cloud within a cell of it, z the largest sheet share of the low layer's cloud there, w the
// height fraction of the low layer above which it holds none. A stretch no longer than a cell
// stays within the cells around its middle, which the grid's cell covers. Without the grid
// (the self-test), every layer everywhere.
float pt_cell_km()
{
#ifdef PT_WITHOUT_GRID
    return 1e9;
#else
    return cloud.weather.w / float(textureSize(pt_grid, 0).x);
#endif
}

vec4 pt_grid_cell(vec3 p)
{
#ifdef PT_WITHOUT_GRID
    return vec4(1.0);
#else
    // The weather map's coordinates of p, as sample_weather (cloud_density.glsl) reads it.
    vec2 uv = fract(cloud_pattern_xy(p) * cloud.weather.z + 0.5);
    ivec2 n = textureSize(pt_grid, 0);
    return texelFetch(pt_grid, min(ivec2(uv * vec2(n)), n - 1), 0);
#endif
}

// Above this radius the cell's low layer holds no cloud: its top, raised by PT_TOP_MARGIN_KM
// for the round-off of planet-centred floats (half a metre) and of the top's bisection.
const float PT_TOP_MARGIN_KM = 0.02;
float pt_low_top_radius(vec4 g)
{
    return cloud.low.x + g.w * (cloud.low.y - cloud.low.x) + PT_TOP_MARGIN_KM;
}

// The majorant over a stretch in cell g: the layers' bounds where the grid says they may hold
// cloud (the low layer's only below its top), 0 elsewhere.
float pt_local_majorant(vec4 g, bool above_low_top, float segment_majorant)
{
    // (The middle layer's coverage is the same everywhere: its bound wherever it is on.)
    bool low = g.x > 0.0 && !above_low_top;
    return min(segment_majorant, (low ? pt_bound_low_sheet(g.z) : 0.0) +
                                     (g.y > 0.0 ? pt_bound_high() : 0.0) + pt_bound_mid());
}

// Proposed collisions along [t0, t1] of the ray o + t d: exponential flights under a majorant
// that is constant over each stretch (skipped where it is 0). A stretch is at most a cell long
// and ends where the ray crosses the cell's low top, so that it lies wholly above or below
// it. The state of one walk; pt_propose advances it to the next proposal, false past t1.
struct PtWalk {
    float t, stretch_end, majorant;
};

PtWalk pt_walk(float t0)
{
    return PtWalk(t0, t0, 0.0);
}

// Where the stretch that starts at a along o + t d ends, and its majorant.
void pt_next_stretch(inout PtWalk w, vec3 o, vec3 d, float t1, float segment_majorant)
{
    float a = w.stretch_end;
    float b = min(a + pt_cell_km(), t1);
    vec3 pa = o + d * a;
    vec4 g = pt_grid_cell(pa + d * (0.5 * (b - a)));
    float r_top = pt_low_top_radius(g);
    // (A crossing closer than a metre is the one the last stretch ended on.)
    float crossing = ray_sphere_nearest(pa, d, r_top);
    if (crossing > 1e-3 && a + crossing < b)
        b = a + crossing;
    bool above = length(pa + d * (0.5 * (b - a))) > r_top;
    w.stretch_end = b;
    w.majorant = pt_local_majorant(g, above, segment_majorant);
    w.t = w.majorant > 0.0 ? a : b;
}

bool pt_propose(inout PtWalk w, vec3 o, vec3 d, float t1, float segment_majorant)
{
    for (int i = 0; i < PT_MAX_STEPS; i++) {
        if (w.t >= w.stretch_end) {
            if (w.stretch_end >= t1)
                return false;
            pt_next_stretch(w, o, d, t1, segment_majorant);
            continue;
        }
        float next = w.t + pt_flight(w.majorant);
        if (next < w.stretch_end) {
            w.t = next;
            return true;
        }
        w.t = w.stretch_end; // memoryless: the next stretch starts afresh
    }
    atomicAdd(pt_stats.overflows, 1u);
    return false;
}

// Delta tracking from o along d: true at a real collision, with o moved there; false when the
// ray leaves the shells, with o at its last exit (or where it started).
bool pt_track(inout vec3 o, vec3 d)
{
    for (int s = 0; s < PT_MAX_SEGMENTS; s++) {
        float t0, t1, m;
        if (!pt_next_segment(o, d, t0, t1, m))
            return false;
        PtWalk w = pt_walk(t0);
        while (pt_propose(w, o, d, t1, m)) {
            vec3 p = o + w.t * d;
            if (pt_random() * w.majorant < pt_extinction(p, w.majorant)) {
                o = p;
                return true;
            }
        }
        o += d * (t1 + PT_EPS_KM);
    }
    return false;
}

// Ratio tracking: an unbiased estimate of the clouds' transmittance from o along d to the
// end of the shells (Novak et al. 2014 eq. 5: the product of 1 - sigma / majorant over the
// proposed collisions), with Russian roulette once it falls below PT_ROULETTE_T.
float pt_transmittance(vec3 o, vec3 d)
{
    float T = 1.0;
    for (int s = 0; s < PT_MAX_SEGMENTS; s++) {
        float t0, t1, m;
        if (!pt_next_segment(o, d, t0, t1, m))
            return T;
        PtWalk w = pt_walk(t0);
        while (pt_propose(w, o, d, t1, m)) {
            T *= 1.0 - pt_extinction(o + w.t * d, w.majorant) / w.majorant;
            if (T < PT_ROULETTE_T) {
                if (pt_random() * PT_ROULETTE_T >= T)
                    return 0.0;
                T = PT_ROULETTE_T;
            }
        }
        o += d * (t1 + PT_EPS_KM);
    }
    return T;
}

// A direction around d drawn from Henyey-Greenstein with g (the inverse of its CDF in the
// cosine: Pharr et al., PBRT 3rd ed., eq. 15.6).
vec3 pt_sample_hg(vec3 d, float g)
{
    float u = pt_random(), phi = 2.0 * PI * pt_random();
    float cos_t;
    if (abs(g) < 1e-3) {
        cos_t = 1.0 - 2.0 * u;
    } else {
        float q = (1.0 - g * g) / (1.0 - g + 2.0 * g * u);
        cos_t = clamp((1.0 + g * g - q * q) / (2.0 * g), -1.0, 1.0);
    }
    float sin_t = sqrt(max(0.0, 1.0 - cos_t * cos_t));
    vec3 a = abs(d.z) < 0.9 ? vec3(0.0, 0.0, 1.0) : vec3(1.0, 0.0, 0.0);
    vec3 x = normalize(cross(a, d)), y = cross(d, x);
    return normalize(x * (sin_t * cos(phi)) + y * (sin_t * sin(phi)) + d * cos_t);
}

// seed 000 eq. 14.17 sampled exactly: lobe g1 with probability w, else g0 (w in [0, 1]).
vec3 pt_sample_phase(vec3 d)
{
    float g = pt_random() < cloud.phase.z ? cloud.phase.y : cloud.phase.x;
    return pt_sample_hg(d, g);
}

float pt_phase(float cos_theta)
{
    return dual_lobe_phase(cos_theta, cloud.phase.x, cloud.phase.y, cloud.phase.z);
}

// The droplets' single-scattering albedo, as the renderer's march uses it. Rain darkens a
// cloud's base through its extinction (cloud_density.glsl), not through absorption.
float pt_albedo()
{
    return cloud.media.x;
}

// Illuminance (lux) of the sun and of the moon when it lights, reaching p through the
// atmosphere and the clouds, each weighted by `weight(cos to the light)`: the next-event
// estimate at a collision (weight = phase) or on the ground (cosine / pi x albedo).
vec3 pt_light_at(vec3 p, vec3 w, bool surface, vec3 normal)
{
    vec3 total = vec3(0.0);
    for (int k = 0; k < 2; k++) {
        bool moon = k == 1;
        if (moon && !moon_lights_clouds())
            break;
        vec3 l = moon ? frame.moon_direction.xyz : frame.sun_direction.xyz;
        // On the ground the planet test of sun_transmittance would meet float round-off.
        float mu = dot(normal, l);
        vec3 e = (moon ? frame.moon_illuminance.xyz : frame.sun_illuminance.xyz)
                 * (surface ? (mu > 0.0 ? transmittance_to_top(length(p), mu) : vec3(0.0))
                            : sun_transmittance(p, l));
        float weight = surface ? max(mu, 0.0) / PI : pt_phase(dot(w, l));
        if (max(e.r, max(e.g, e.b)) * weight <= 0.0)
            continue;
        total += e * weight * pt_transmittance(p, l);
    }
    return total;
}

// Radiance (cd/m2) of the sky seen from p along an escaping direction d that misses the
// ground: the sky-view LUT (the sky around the camera) in d's zenith angle and azimuth from
// the sun at p, and the airglow.
vec3 pt_sky(vec3 p, vec3 d)
{
    vec3 up = normalize(p);
    vec3 s = frame.sun_direction.xyz;
    vec3 dh = d - up * dot(d, up), sh = s - up * dot(s, up);
    float lens = length(dh) * length(sh);
    float cos_az = lens > 1e-6 ? dot(dh, sh) / lens : 1.0;
    vec3 L = textureLod(skyview_lut, skyview_uv_at(dot(d, up), cos_az, false), 0.0).rgb;
    return L * frame.sun_illuminance.xyz + vec3(frame.night.x);
}

// The light a path gathers after its first collision at p (direction w toward it): at each
// collision the lights' next-event estimate, then a direction from the phase; on the ground
// (Lambertian, the atmosphere's ground albedo) the lights through the clouds, then a
// cosine-weighted direction; the sky where it escapes. Throughput-driven Russian roulette
// from PT_ROULETTE_BOUNCES on keeps it unbiased without a cap.
const int PT_ROULETTE_BOUNCES = 32;
const int PT_MAX_BOUNCES = 1 << 16;
vec3 pt_path(vec3 p, vec3 w)
{
    vec3 L = vec3(0.0), throughput = vec3(1.0);
    float albedo = pt_albedo();
    bool in_cloud = true;
    for (int bounce = 0; bounce < PT_MAX_BOUNCES; bounce++) {
        if (in_cloud) {
            L += throughput * albedo * pt_light_at(p, w, false, vec3(0.0));
            throughput *= albedo;
            w = pt_sample_phase(w);
        } else {
            vec3 n = normalize(p);
            vec3 ground = atmo.ground_albedo.xyz;
            p = n * (bottom_radius() + 1e-3);
            L += throughput * ground * pt_light_at(p, w, true, n);
            throughput *= ground;
            // Cosine-weighted about the normal (Malley's method).
            float r = sqrt(pt_random()), phi = 2.0 * PI * pt_random();
            vec3 a = abs(n.z) < 0.9 ? vec3(0.0, 0.0, 1.0) : vec3(1.0, 0.0, 0.0);
            vec3 x = normalize(cross(a, n)), y = cross(n, x);
            w = normalize(x * (r * cos(phi)) + y * (r * sin(phi)) + n * sqrt(max(0.0, 1.0 - r * r)));
        }
        if (bounce >= PT_ROULETTE_BOUNCES) {
            float survive = min(max(throughput.r, max(throughput.g, throughput.b)), 1.0);
            if (pt_random() >= survive)
                break;
            throughput /= survive;
        }
        if (max(throughput.r, max(throughput.g, throughput.b)) <= 0.0)
            break;
        in_cloud = pt_track(p, w);
        if (in_cloud)
            continue;
        // Only a descending ray can meet the ground (the test alone is unreliable on it).
        float t_ground = dot(w, p) < 0.0 ? ray_sphere_nearest(p, w, bottom_radius()) : -1.0;
        if (t_ground < 0.0) {
            L += throughput * pt_sky(p, w);
            break;
        }
        p += w * t_ground;
    }
    return L;
}

#endif
