// The light at a cloud sample: phase functions, the sun's (or moon's) optical depth from a
// short march and the sun-space volume, and the sources of Wrenninge's multiple-scattering
// octaves (seed 000 eq. 14.18) from a two-stream column. Needs `cloud`, cloud_density.glsl and
// cloud_sun_depth.glsl (included by cloud_march.glsl).
#ifndef CLOUD_LIGHT_GLSL
#define CLOUD_LIGHT_GLSL

// Reach of the secondary march toward the sun: 2.4 km, or most of a thicker layer's depth
// (the core of a cumulonimbus is dark however far the sun's ray has to go).
float light_march_km(int layer)
{
    vec4 shell = layer_shell(layer);
    float thickness = shell.y - shell.x;
    return clamp(0.6 * thickness, 2.4, 8.0);
}
const float LIGHT_RATIO = 3.0;

const int MAX_OCTAVES = 8;

// Henyey-Greenstein phase, normalized over the sphere.
float hg_phase(float cos_theta, float g)
{
    float g2 = g * g;
    return (1.0 - g2) / (4.0 * PI * pow(max(1.0 + g2 - 2.0 * g * cos_theta, 1e-5), 1.5));
}

// The dual lobe's mean cosine (seed 000 eq. 14.17: g0 + w (g1 - g0)): the asymmetry the
// diffusion terms take.
float dual_lobe_mean_cosine()
{
    return mix(cloud.phase.x, cloud.phase.y, cloud.phase.z);
}

// seed 000 eq. 14.17: p0 + w (p1 - p0).
float dual_lobe_phase(float cos_theta, float g0, float g1, float w)
{
    float p0 = hg_phase(cos_theta, g0);
    return p0 + w * (hg_phase(cos_theta, g1) - p0);
}

// The sun's optical depth from p (to_sun) and along the same ray behind p, through the layer
// (behind: what the light that reaches p has still to cross); smooth_to_sun: to_sun without
// the near march's jitter (the volume's alone, where there is one), for the ratios below.
struct SunDepth {
    float to_sun, behind, smooth_to_sun, support;
};

// The low layer's sun march covers at least NEAR_KM, on to the volume's next altitude level,
// in NEAR_STEPS jittered samples, each step twice the last (the first 3-10 m: a fraction of
// an optical depth of a dense cloud), where the shape decides how a surface is lit; the rest of the sun's
// ray, from that level up, and the depth behind p come from the sun-space volume
// (cloud_sun_depth.glsl), smooth where single jittered kilometre steps made the optical depth
// jump by tens from one sample to the next. Read between its levels, the volume would spread a
// lit surface's cloud over the level above it, and put optical depth where the sun's ray has
// already left the cloud. Without the volume (a sun that moved since it was built, the high
// layer) a geometric march (below), and the layer below p at p's extinction.
const float NEAR_KM = 0.4;
// A fixed count, the steps scaled to the reach: a count that grew with the reach changed where
// the reach's level did, and drew contour lines along the tops of decks. Seven: with six, the
// sun's optical depth is noisy enough to texture an overcast deck below 200 m (its radiance
// spectrum's slope there 2.36 with six, 3.38 with seven; observed decks: 2.5 and steeper).
const float NEAR_STEPS = 7.0;

// Where the march hands over to the volume: the radius of the first level at or above p +
// NEAR_KM dir (the layer's top at most), and the distance to it along dir.
vec2 sun_march_reach(vec3 p, vec3 dir)
{
    float spacing = (cloud.low.y - cloud.low.x) / float(SKY_CLOUD_SUN_DEPTH_LEVELS - 1);
    float above = length(p + dir * NEAR_KM) - cloud.low.x;
    float r = cloud.low.x + min(ceil(max(above, 0.0) / spacing) * spacing,
                                cloud.low.y - cloud.low.x);
    float t = ray_sphere_far(p, dir, r);
    return vec2(r, t > 0.0 ? t : NEAR_KM);
}

// The marched part of the sun's optical depth: with the volume, the reach above in NEAR_STEPS
// steps doubling from the first; without it, light_march_km in the light steps of the clouds'
// parameters, each LIGHT_RATIO times the last (seed 001 5.5.2 doubles them; a first step of
// 38 m spans 1.5 optical depths and exp of its jittered estimate is biased high).
// With the volume, the march then measures the incidence: the sun's cosine to the surface above
// p, from the optical depth over its first INCIDENCE_STEPS steps along the sun against the same
// distance straight up (a deck's mu0; over 1 on a face lit from the side; 2, none, deeper than
// a few optical depths).
//
// The view march's loop takes the march one step per iteration (sun_march_point, then
// sun_march_add with the coarse extinction there), so that one density lookup serves the view
// and the light: lavapipe inlines every call, every copy of the density's code in that loop
// slowed all of its samples, and a nested march made every lane wait for the longest.
const float INCIDENCE_STEPS = 3.0;
const float INCIDENCE_DEPTH = 6.0;
struct SunMarch {
    vec3 p, dir;
    float jitter, steps, last, ratio, ds0; // last: the steps along the sun, then straight up
    float i, t, ds, tau, tau_first, tau_up;
    bool with_volume;
};

SunMarch sun_march_begin(vec3 p, vec3 dir, float jitter, int layer, bool with_volume,
                         vec2 reach)
{
    SunMarch m;
    m.p = p;
    m.dir = dir;
    m.jitter = jitter;
    m.with_volume = with_volume;
    m.steps = with_volume ? NEAR_STEPS : cloud.octaves.w;
    m.last = m.steps + (with_volume ? INCIDENCE_STEPS : 0.0);
    m.ratio = with_volume ? 2.0 : LIGHT_RATIO;
    m.ds0 = with_volume ? reach.y / (exp2(m.steps) - 1.0)
                        : light_march_km(layer) * (LIGHT_RATIO - 1.0) /
                              (pow(LIGHT_RATIO, m.steps) - 1.0);
    m.i = m.t = m.tau = m.tau_first = m.tau_up = 0.0;
    m.ds = m.ds0;
    return m;
}

bool sun_march_done(SunMarch m)
{
    return m.i >= m.last;
}

// Where the march's next sample lies.
vec3 sun_march_point(SunMarch m)
{
    vec3 along = m.i < m.steps ? m.dir : normalize(m.p);
    return m.p + along * (m.t + m.jitter * m.ds);
}

// Adds the extinction at sun_march_point and moves on.
void sun_march_add(inout SunMarch m, float sigma)
{
    float e = sigma * m.ds;
    bool along = m.i < m.steps;
    m.tau += along ? e : 0.0;
    m.tau_first += along && m.i < INCIDENCE_STEPS ? e : 0.0;
    m.tau_up += along ? 0.0 : e;
    m.i += 1.0;
    bool turn = m.i == m.steps; // on to the incidence's steps, from p again
    m.t = turn ? 0.0 : m.t + m.ds;
    m.ds = turn ? m.ds0 : m.ds * m.ratio;
}

// The finished march's incidence (2: none).
float sun_march_incidence(SunMarch m)
{
    // Only near the lit surface (the sun's ray leaves the cloud within a few optical depths)
    // does the surface above p say how the light came in.
    return m.with_volume ? mix(2.0, m.tau_first > 0.0 ? m.tau_up / m.tau_first : 1.0,
                               exp(-m.tau_first / INCIDENCE_DEPTH))
                         : 2.0;
}

// The depths at p from the marched part (which a sample may take from its neighbour along
// the view: the march is the costly part) up to the reach's level and the volume's, read at p
// itself.
SunDepth sun_depths(vec3 p, vec3 dir, float marched, bool with_volume, float reach_r,
                    float sigma_here, int layer)
{
    SunDepth s;
    float r = length(p);
    vec2 uv;
    if (with_volume && sun_depth_coords(p, dir, uv)) {
        float below = sun_column_below(uv, r);
        SunColumn column = sun_column(uv);
        s.to_sun = marched + max(column.depth - sun_column_below(uv, reach_r), 0.0);
        s.behind = below;
        s.smooth_to_sun = max(column.depth - below, 0.0);
        s.support = column.support;
        return s;
    }
    // The middle layer lies under the high one: the volume's high-layer optical depth along
    // the sun's ray through p (g) shadows it, where the volume was built for this sun.
    float above = 0.0;
    if (layer == LAYER_MID && sun_depth_coords(p, dir, uv))
        above = textureLod(sun_depth_volume, vec3(uv, 0.5 / float(SKY_CLOUD_SUN_DEPTH_LEVELS)),
                           0.0).g;
    // The march reaches light_march_km: a low sun's ray through a sheet goes on inside it for
    // ten times the sheet's depth below its top and more. The rest of the way out through
    // the layer's top at the march's mean extinction (a sheet's: its horizontal structure is
    // far finer than that path), or a deck at sunset would be lit as if it ended there.
    float reach_km = light_march_km(layer);
    vec3 end = p + dir * reach_km;
    float rest = length(end) < layer_shell(layer).y
                     ? max(ray_sphere_far(end, dir, layer_shell(layer).y), 0.0)
                     : 0.0;
    float rest_depth = marched / reach_km * rest;
    s.to_sun = marched + rest_depth + above;
    s.smooth_to_sun = s.to_sun;
    s.support = 1.0;
    float base = layer_shell(layer).x;
    s.behind = sigma_here * max(r - base, 0.0) / max(dot(dir, p / r), 0.1);
    return s;
}

// Wrenninge et al.'s octaves (seed 000 eq. 14.18): octave n is the light scattered once more,
// with scattering a^n sigma_s, phase p(g c^n) (p the dual lobe of seed 000 eq. 14.17) and the
// sun's extinction thinned to b^n sigma_t: light that has wandered deeper than the sun's ray.
// Their sum is the in-scattered radiance at a point, so the view ray attenuates every octave
// by the full extinction, as it does the single scattering: thinned along the view too, the
// octaves would be gathered from several optical depths inside every outline, where sunlight
// hardly reaches, and each silhouette would glow.
struct OctavePhases {
    float weighted[MAX_OCTAVES]; // a^n p(g c^n): the angle to the light is fixed along a ray
    float cos_theta;             // between the view's direction and the light's
    float toward_light;          // the flux's share of the light's direction (diffuse_phases)
};

OctavePhases octave_phases(float cos_theta)
{
    OctavePhases o;
    o.cos_theta = cos_theta;
    o.toward_light = 1.0;
    float a = 1.0, c = 1.0;
    for (int n = 0; n < MAX_OCTAVES; n++) {
        o.weighted[n] = float(n) < cloud.phase.w
                            ? a * dual_lobe_phase(cos_theta, cloud.phase.x * c,
                                                  cloud.phase.y * c, cloud.phase.z)
                            : 0.0;
        a *= cloud.octaves.x;
        c *= cloud.octaves.z;
    }
    return o;
}

// The octaves n >= 1 stand for light that has forgotten the sun's direction: the diffuse light
// of a two-stream (Eddington) column along the sun's ray through the sample (Bohren 1987, Am.
// J. Phys. 55, 524): at depth x_s below the lit side and x_b above the dark side (optical depths
// along the surface's normal), with s = 3/4 (1 - g), the column passes T = 1 / (1 + s (x_s +
// x_b)) of the flux and its mean diffuse radiance is E mu0 T (k0 + s x_b) / pi: near the flux
// entering at the lit side, falling linearly to T E mu0 k0 / pi at the dark side. Octave n
// crosses the column with its extinction thinned by b^n (seed 000 eq. 14.18), so later octaves
// reach deeper, and is scattered with a^n p(g c^n) (4 pi p ~ 1 turns the mean radiance into the
// source). mu0, the sun's cosine to the lit surface: tau_up = sigma (top - r), the depth below
// the layer's top at the local extinction, over the sun's optical depth (mu0 of a deck; 1
// inside a cloud lit from the side, where the sun's ray is the shorter way out), or the
// incidence the short marches measure near a lit surface (sun_march), whichever is smaller.
const float MU0_FLOOR = 0.1;
// Fitted with the octaves to the Monte Carlo decks of tests/reference/test_cloud_accuracy.c:
// k0, the dark side's diffuse radiance over the flux through it, and the share of the
// diffusion's absorption rate that the octaves (already thinned by b^n) still need.
const float DIFFUSE_DARK_SIDE = 0.5;
const float ABSORPTION_SCALE = 0.5;
// Fitted to the path-traced cumulus and cumulonimbus of tests/render/test_cloud_vs_reference.c
// (the decks do not depend on them): the diffuse light a cloud's sides let out at the edge of
// an isolated cloud (below), how strongly the diffuse light's flow away from the sun shows
// toward a viewer who looks along it (1: the diffusion approximation's 3/4 F / I, below), and
// the sky ambient's share at a cloud's surface (0.5 would be half the sky scattered once;
// more: the sky's light scattered again).
const float LATERAL_LOSS = 1.0;
const float FLOW_SCALE = 1.65;
const float AMBIENT_SHARE = 1.3;

// Multiply scattered light is not all there yet at the lit surface: it builds up over the first
// optical depths below it (Schneider 2015's "powder" darkening of sun-facing creases, seen where
// a view ray grazes a lit surface and gathers its light from that shallow layer), from half its
// value at the surface, at the rate K (clouds.multiscatter.powder) per optical depth.
float octave_build_up(float depth)
{
    return 1.0 - 0.5 * exp(-cloud.build_up.x * depth);
}

// The sun's cosine to the lit surface (above). Both estimates are too large where they err
// (below a cloud's top the layer's top is further; the short marches reach past a deck's
// surface): the smaller.
float octave_mu0(SunDepth sd, float tau_up, float incidence)
{
    return clamp(min(tau_up / max(sd.smooth_to_sun, 1e-6), incidence), MU0_FLOOR, 1.0);
}

// The diffuse octaves flow along the lit surface's normal, not along the light's ray, once the
// light has lost its direction: in a two-stream column the flux runs along the column (Bohren
// 1987, above). That normal lies between the light's direction (mu0 = 1: a face lit head-on)
// and the local vertical (a deck, whose mu0 is the light's elevation sine e): the share of the
// light's direction, (mu0 - e) / (1 - e). Near the lit side the light still runs along its ray
// (a deck lit by a low sun reflects most toward grazing views away from it): that memory fades
// as exp(-FLUX_MEMORY (1 - g) x_s), x_s the depth along the normal and 1 / (1 - g) the
// transport mean free path. Below a deck, toward a low sun, the octaves then scatter the light
// that flows down through it, not a forward lobe toward the sun that tens of optical depths
// have long since blurred (mid_deck_low_sun of tests/render/test_cloud_vs_reference.c: the
// renderer 1.27 of the reference and 16 % too red before, 1.18 and 11 % now).
// FLUX_MEMORY is fitted to the Monte Carlo decks of tests/reference/test_cloud_accuracy.c:
// 1 (one transport mean free path) leaves their reflection 10.9 % off on average, 0.25 7.9 %
// (7.1 % with the flux along the light everywhere, which puts a low sun's diffuse light in a
// forward lobe toward it), their transmission 11.4 % and 11.6 % (11.0 %).
const float FLUX_MEMORY = 0.25;
float flux_toward_light(vec3 light_dir, vec3 up, float mu0, float to_light)
{
    float e = dot(light_dir, up);
    float normal_share = clamp((mu0 - e) / max(1.0 - e, 1e-3), 0.0, 1.0);
    float memory = exp(-FLUX_MEMORY * (1.0 - dual_lobe_mean_cosine()) * mu0 * to_light);
    return max(normal_share, memory);
}

// The octaves' phases (n >= 1) and the view's cosine to the flux for a flux that is w of the
// way from the vertical (toward_zenith: the phases at the view's cosine to the zenith) to the
// light's direction (toward_light); single scattering (n = 0) keeps the light's own phase.
OctavePhases diffuse_phases(OctavePhases toward_light, OctavePhases toward_zenith, float w)
{
    OctavePhases o = toward_light;
    for (int n = 1; n < MAX_OCTAVES; n++)
        o.weighted[n] = mix(toward_zenith.weighted[n], toward_light.weighted[n], w);
    o.cos_theta = mix(toward_zenith.cos_theta, toward_light.cos_theta, w);
    o.toward_light = w;
    return o;
}

// The light each octave scatters toward the viewer per unit optical depth, per unit
// illuminance: single scattering p exp(-tau_sun), and the diffuse octaves above, absorbed over
// the depth below the lit side at the diffusion rate sqrt(3 (1 - albedo) (1 - albedo g)). mu0:
// the light's cosine to the lit surface (octave_mu0 for the sun and the moon).
void octave_sources(OctavePhases o, SunDepth sd, float mu0, out float src[MAX_OCTAVES])
{
    float x_s = mu0 * sd.to_sun, x_b = mu0 * sd.behind;
    src[0] = o.weighted[0] * exp(-sd.to_sun);
    float g = dual_lobe_mean_cosine();
    float s = 0.75 * (1.0 - g);
    float albedo = cloud.media.x;
    float absorption = sqrt(3.0 * max(1.0 - albedo, 0.0) * (1.0 - albedo * g));
    // The diffuse light the column sends back from behind the sample comes from within a
    // diffusion length: in an absorbing medium the diffuse field falls as exp(-k x) (k the
    // diffusion rate above, ABSORPTION_SCALE of it as at the lit side), so the dark side's depth
    // counts as int_0^x_b exp(-k x) dx = (1 - exp(-k x_b)) / k. Without it the kilometres of a
    // storm tower behind its lit face stored light as a deck of that depth would.
    float k_absorb = ABSORPTION_SCALE * absorption;
    if (k_absorb > 1e-4)
        x_b = (1.0 - exp(-k_absorb * x_b)) / k_absorb;
    // Only what the column scatters at least twice is diffuse: 1 - exp(-tau) of the sun's beam
    // is scattered once, mostly forward (g ~ 0.5-0.8), so about as likely again.
    float once = 1.0 - exp(-(sd.smooth_to_sun + sd.behind));
    float scattered = once * once;
    // A cloud a few kilometres wide loses diffuse light through its sides too (a deck only
    // through its top and base): of the light stored between a sample and the dark side,
    // LATERAL_LOSS at the edge of an isolated cloud; what reaches the dark side has escaped.
    float kept = 1.0 - LATERAL_LOSS * (1.0 - sd.support);
    float common_part = 4.0 * PI * mu0 * scattered * octave_build_up(x_s) *
                        exp(-ABSORPTION_SCALE * absorption * x_s);
    // Light entering at a grazing angle is scattered near the surface and leaves the way it
    // came more often: the dark side's share falls with mu0 as the Eddington solution's
    // transmission does, (1/2 + 3/4 mu0) / (5/4) (Joseph, Wiscombe & Weinman 1976).
    float dark_side = DIFFUSE_DARK_SIDE * (0.5 + 0.75 * mu0) / 1.25;
    // The diffuse light flows away from the light: its radiance is I (1 + 3/(4 pi) F.w / I)
    // (the diffusion approximation), the flux F = T E mu0 against the mean, which the phase's
    // mean cosine g passes on to the scattered light: brighter toward a viewer who looks at the
    // dark side with the light behind it (o.cos_theta: the cosine between the view and the flux).
    // Not darker the other way: at the lit side the light leaving toward the sun is what the
    // build-up and the decks fit. With the mean radiance T (stored) and the flow's term
    // T F_scale, the sum is T (stored + flow).
    // A flux turned toward the vertical carries the Eddington factor (1/2 + 3/4 mu0) / (5/4)
    // of the light that a low sun sends on through a deck, in the light stored below the
    // sample as in the flow; along the light's ray the geometry did that (a grazing flux
    // passes a horizontal surface with about a third, 1/pi, of a vertical one's radiance).
    float flux_factor = mix(dark_side / DIFFUSE_DARK_SIDE, 1.0, o.toward_light);
    float flow = FLOW_SCALE * g * 0.75 * max(o.cos_theta, 0.0) * flux_factor;
    float b = cloud.octaves.y;
    for (int n = 1; n < MAX_OCTAVES && float(n) < cloud.phase.w; n++) {
        float stored = dark_side + kept * s * b * x_b * flux_factor;
        src[n] = o.weighted[n] * common_part * (stored + flow) /
                 (PI * (1.0 + s * b * (x_s + x_b)));
        b *= cloud.octaves.y;
    }
}

// The octaves of a light toward light_dir at a point whose vertical is up, their flux between
// the light's ray and the vertical (flux_toward_light, diffuse_phases).
void light_octave_sources(OctavePhases toward_light, OctavePhases toward_zenith, SunDepth sd,
                          float mu0, vec3 light_dir, vec3 up, out float src[MAX_OCTAVES])
{
    float w = flux_toward_light(light_dir, up, mu0, sd.smooth_to_sun);
    octave_sources(diffuse_phases(toward_light, toward_zenith, w), sd, mu0, src);
}

// The sky's light diffused through the column as the sun's is (octave_sources' octaves n >= 1:
// its single scattering is the march's ambient term), per unit radiance of the sky above: the
// sky's irradiance E = pi L enters the column's lit side as diffuse light does, as a beam at
// mu0 = 2/3 would (the Eddington closure), through the same column as the sun's (its depths
// along the normal, x_s and x_b, from the sun's). Without it a deck's base is lit by the sun
// and the ground alone; the path-traced deck's base (tests/render/test_cloud_vs_reference.c)
// gets 8 % of its light from the sky, of blue over red about 5, and so does this term.
const float SKY_MU0 = 2.0 / 3.0;
float sky_diffuse_source(OctavePhases sky_phases, SunDepth sd, float sun_mu0)
{
    float to_normal = sun_mu0 / SKY_MU0;
    SunDepth sky = SunDepth(to_normal * sd.to_sun, to_normal * sd.behind,
                            to_normal * sd.smooth_to_sun, sd.support);
    float src[MAX_OCTAVES];
    // (Its flux runs straight down: the view's cosine to it is the phases'.)
    octave_sources(sky_phases, sky, SKY_MU0, src);
    float sum = 0.0;
    for (int n = 1; n < MAX_OCTAVES && float(n) < cloud.phase.w; n++)
        sum += src[n];
    return PI / SKY_MU0 * sum;
}

#endif
