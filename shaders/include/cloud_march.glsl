// Ray march through the cloud layers (seed 001 5.5-5.8): energy-conserving integration
// (seed 001 eq. 17), dual-lobe Henyey-Greenstein phase (seed 000 eq. 14.17), Wrenninge's
// multiple-scattering octaves (seed 000 eq. 14.18), sun light through a short secondary march
// and the atmosphere's transmittance LUT (so sunsets colour the clouds), sky ambient from the
// sky-view and irradiance LUTs (top) and the lit ground (bottom), early exit at low
// transmittance and empty-space skipping. Needs atmosphere.glsl with the transmittance and
// sky-view LUTs, cloud_density.glsl and an `irradiance_lut` sampler.
#ifndef CLOUD_MARCH_GLSL
#define CLOUD_MARCH_GLSL

// Reach of the secondary march toward the sun: 2.4 km, or most of a thicker layer's depth
// (the core of a cumulonimbus is dark however far the sun's ray has to go).
float light_march_km(bool low_layer)
{
    float thickness = low_layer ? cloud.low.y - cloud.low.x : cloud.high.y - cloud.high.x;
    return clamp(0.6 * thickness, 2.4, 8.0);
}
const float EARLY_EXIT_T = 0.01;
const float LIGHT_RATIO = 3.0;

const int MAX_OCTAVES = 8;
struct CloudResult {
    vec3 luminance;   // scattered by the clouds toward the origin (cd/m2)
    float transmittance;
    float depth;      // transmittance-weighted front depth (seed 001 eq. 21), km
};

// Henyey-Greenstein phase, normalized over the sphere.
float hg_phase(float cos_theta, float g)
{
    float g2 = g * g;
    return (1.0 - g2) / (4.0 * PI * pow(max(1.0 + g2 - 2.0 * g * cos_theta, 1e-5), 1.5));
}

// seed 000 eq. 14.17: p0 + w (p1 - p0).
float dual_lobe_phase(float cos_theta, float g0, float g1, float w)
{
    float p0 = hg_phase(cos_theta, g0);
    return p0 + w * (hg_phase(cos_theta, g1) - p0);
}

// Optical depth toward the sun over light_march_km() in light_steps samples, each step
// LIGHT_RATIO times the previous one (seed 001 5.5.2 doubles them; a first step of 38 m spans
// 1.5 optical depths and exp of its jittered estimate is biased high), on the coarse shape of
// the sample's own layer.
float light_optical_depth(vec3 p, vec3 sun_dir, float jitter, bool low_layer)
{
    float steps = cloud.octaves.w;
    float ds = light_march_km(low_layer) * (LIGHT_RATIO - 1.0) / (pow(LIGHT_RATIO, steps) - 1.0);
    float t = 0.0, tau = 0.0;
    for (float i = 0.0; i < steps; i += 1.0) {
        tau += cloud_layer_extinction(p + sun_dir * (t + jitter * ds), false, low_layer) * ds;
        t += ds;
        ds *= LIGHT_RATIO;
    }
    return tau;
}

// The sun's optical depth from p (to_sun) and along the same ray behind p, through the layer
// (behind: what the light that reaches p has still to cross); smooth_to_sun: to_sun without
// the near march's jitter (the volume's alone, where there is one), for the ratios below.
struct SunDepth {
    float to_sun, behind, smooth_to_sun, support;
};

// The low layer's sun march covers at least NEAR_KM, on to the volume's next altitude level,
// in NEAR_STEPS jittered samples, each step twice the last (the first 13 m: half an optical
// depth of a dense cloud), where the shape decides how a surface is lit; the rest of the sun's
// ray, from that level up, and the depth behind p come from the sun-space volume
// (cloud_sun_depth.glsl), smooth where single jittered kilometre steps made the optical depth
// jump by tens from one sample to the next. Read between its levels, the volume would spread a
// lit surface's cloud over the level above it, and put optical depth where the sun's ray has
// already left the cloud. Without the volume (a sun that moved since it was built, the high
// layer) the geometric march above, and the layer below p at p's extinction.
const float NEAR_KM = 0.4;
const float NEAR_STEPS = 5.0;

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

// The marched part of the sun's optical depth, over the reach above where the volume holds
// the rest (with_volume), the whole reach of light_optical_depth otherwise. incidence: the
// sun's cosine to the surface above p, from the optical depth over the march's first
// INCIDENCE_STEPS steps along the sun against the same distance straight up (a deck's mu0;
// over 1 on a face lit from the side; 2, none, deeper than a few optical depths).
const float INCIDENCE_STEPS = 3.0;
const float INCIDENCE_DEPTH = 6.0;
float sun_march(vec3 p, vec3 dir, float jitter, bool low_layer, bool with_volume, vec2 reach,
                out float incidence)
{
    incidence = 2.0;
    if (!with_volume)
        return light_optical_depth(p, dir, jitter, low_layer);
    // A longer reach (a thick layer's sparse levels, a low sun) takes more steps.
    float steps = NEAR_STEPS + ceil(log2(max(reach.y / NEAR_KM, 1.0)));
    float ds0 = reach.y / (exp2(steps) - 1.0);
    float ds = ds0, t = 0.0, tau = 0.0, tau_first = 0.0, tau_up = 0.0;
    vec3 up = normalize(p);
    for (float i = 0.0; i < steps; i += 1.0) {
        tau += cloud_layer_extinction(p + dir * (t + jitter * ds), false, true) * ds;
        if (i < INCIDENCE_STEPS) {
            tau_first = tau;
            tau_up += cloud_layer_extinction(p + up * (t + jitter * ds), false, true) * ds;
        }
        t += ds;
        ds *= 2.0;
    }
    // Only near the lit surface (the sun's ray leaves the cloud within a few optical depths)
    // does the surface above p say how the light came in.
    incidence = mix(2.0, tau_first > 0.0 ? tau_up / tau_first : 1.0,
                    exp(-tau_first / INCIDENCE_DEPTH));
    return tau;
}

// The depths at p from the marched part (which a sample may take from its neighbour along
// the view: the march is the costly part) up to the reach's level and the volume's, read at p
// itself.
SunDepth sun_depths(vec3 p, vec3 dir, float marched, bool with_volume, float reach_r,
                    float sigma_here, bool low_layer)
{
    SunDepth s;
    float r = length(p);
    vec2 uv;
    if (with_volume && sun_depth_coords(p, dir, uv)) {
        vec3 here = sun_column_depths(uv, r);
        vec3 beyond = sun_column_depths(uv, reach_r);
        s.to_sun = marched + max(beyond.y - beyond.x, 0.0) + here.z;
        s.behind = here.x;
        s.smooth_to_sun = max(here.y - here.x, 0.0) + here.z;
        s.support = 1.0;
        return s;
    }
    s.to_sun = marched;
    s.smooth_to_sun = marched;
    s.support = 1.0;
    float base = low_layer ? cloud.low.x : cloud.high.x;
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
};

OctavePhases octave_phases(float cos_theta)
{
    OctavePhases o;
    o.cos_theta = cos_theta;
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
const float FLOW_SCALE = 1.5;
const float AMBIENT_SHARE = 1.3;

// Multiply scattered light is not all there yet at the lit surface: it builds up over the first
// optical depths below it (Schneider 2015's "powder" darkening of sun-facing creases, seen where
// a view ray grazes a lit surface and gathers its light from that shallow layer), from half its
// value at the surface, at the rate K (clouds.multiscatter.powder) per optical depth.
float octave_build_up(float depth)
{
    return 1.0 - 0.5 * exp(-cloud.build_up.x * depth);
}

// The light each octave scatters toward the viewer per unit optical depth, per unit
// illuminance: single scattering p exp(-tau_sun), and the diffuse octaves above, absorbed over
// the depth below the lit side at the diffusion rate sqrt(3 (1 - albedo) (1 - albedo g)).
void octave_sources(OctavePhases o, SunDepth sd, float tau_up, float incidence,
                    out float src[MAX_OCTAVES])
{
    // Both estimates of mu0 are too large where they err (below a cloud's top the layer's top
    // is further; the short marches reach past a deck's surface): the smaller.
    float mu0 = clamp(min(tau_up / max(sd.smooth_to_sun, 1e-6), incidence), MU0_FLOOR, 1.0);
    float x_s = mu0 * sd.to_sun, x_b = mu0 * sd.behind;
    src[0] = o.weighted[0] * exp(-sd.to_sun);
    float g = mix(cloud.phase.x, cloud.phase.y, cloud.phase.z);
    float s = 0.75 * (1.0 - g);
    float albedo = cloud.media.x;
    float absorption = sqrt(3.0 * max(1.0 - albedo, 0.0) * (1.0 - albedo * g));
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
    float b = cloud.octaves.y;
    for (int n = 1; n < MAX_OCTAVES && float(n) < cloud.phase.w; n++) {
        float stored = dark_side + kept * s * b * x_b;
        // The diffuse light flows away from the sun: its radiance is I (1 + 3/(4 pi) F.w / I)
        // (the diffusion approximation), the flux F = T E mu0 against the mean, which the
        // phase's mean cosine g passes on to the scattered light: brighter toward a viewer who
        // looks at the dark side with the sun behind it. Not darker the other way: at the lit
        // side the light leaving toward the sun is what the build-up and the decks fit.
        float flow = 1.0 + FLOW_SCALE * g * 0.75 * max(o.cos_theta, 0.0) / stored;
        float diffuse = stored / (1.0 + s * b * (x_s + x_b));
        src[n] = o.weighted[n] * common_part * diffuse * max(flow, 0.0) / PI;
        b *= cloud.octaves.y;
    }
}

// Ambient radiance (cd/m2) under (top) and over (bottom) the clouds along one view ray: the sky
// lit by the sun, by the moon at night (the same irradiance LUT per unit illuminance outside the
// atmosphere, seed 001 4.2) and the airglow floor.
struct CloudAmbient {
    vec3 top, bottom;
    vec3 bottom_sun; // the part of bottom that the sun lights on the ground, at full sun
};

// Directions of the sky ambient's quadrature: cosine-weighted over the upper hemisphere on a
// Fibonacci spiral, fixed in the sun's azimuth frame (so each frame fetches the same sky, and a
// sample that sweeps across the sun's aureole cannot make bands across the picture).
const int AMBIENT_DIRECTIONS = 16;

// The sky's light as the clouds scatter it toward the viewer along d, per unit sun illuminance:
// the cosine-weighted sky radiance of the sky-view LUT (whose mean over the hemisphere is E / pi),
// each direction w weighted by the phase function truncated to its first two Legendre terms,
// 1 + 3 g (w . d) with g the mean cosine of seed 000 eq. 14.17, so the sky behind a cloud (the
// glow around a low sun) lights it most, as the sun lights a silver lining. Returned as the
// ratio to the unweighted mean, per colour channel: the irradiance LUT keeps the level.
vec3 sky_ambient_shape(vec3 d)
{
    // The view in the sun's frame: x toward the sun's azimuth.
    vec2 s = frame.sun_horizontal.w > 0.5 ? frame.sun_horizontal.xy : vec2(1.0, 0.0);
    vec3 v = vec3(dot(d.xy, s), dot(d.xy, vec2(-s.y, s.x)), d.z);
    float g = cloud.phase.x + cloud.phase.z * (cloud.phase.y - cloud.phase.x);
    vec3 weighted = vec3(0.0), plain = vec3(0.0);
    float weight_sum = 0.0;
    for (int k = 0; k < AMBIENT_DIRECTIONS; k++) {
        float u = (float(k) + 0.5) / float(AMBIENT_DIRECTIONS);
        float phi = float(k) * 2.39996323;
        float sin_t = sqrt(u), cos_t = sqrt(1.0 - u);
        vec3 w = vec3(sin_t * cos(phi), sin_t * sin(phi), cos_t);
        vec3 L = textureLod(skyview_lut, skyview_uv_at(cos_t, cos(phi), false), 0.0).rgb;
        float lobe = max(0.0, 1.0 + 3.0 * g * dot(w, v));
        weighted += lobe * L;
        weight_sum += lobe;
        plain += L;
    }
    vec3 mean = plain / float(AMBIENT_DIRECTIONS);
    vec3 shaped = weighted / max(weight_sum, 1e-6);
    return mix(vec3(1.0), shaped / max(mean, vec3(1e-30)), step(vec3(1e-30), mean));
}

// Sky irradiance and direct irradiance at the ground per unit illuminance of a light toward l.
void ground_light_per_lux(vec3 l, out vec3 sky, out vec3 direct)
{
    float mu = l.z; // at the camera's foot, up is +z
    float size = float(textureSize(irradiance_lut, 0).x);
    float u = unit_to_sub_uv(clamp(mu * 0.5 + 0.5, 0.0, 1.0), size);
    sky = textureLod(irradiance_lut, vec2(u, 0.5), 0.0).rgb;
    vec3 ground = vec3(0.0, 0.0, bottom_radius() + 1e-3);
    direct = sun_transmittance(ground, l) * max(mu, 0.0);
}

// True when the moon lights the sky (sun down, moon up). MOONLIT (cloud_bindings.glsl) leaves
// the moon's light march out of the daytime pipelines: lavapipe would run it under a mask.
bool moon_lights_clouds()
{
    return MOONLIT && frame.moon_illuminance.w > 0.5;
}

// d: the view ray's direction.
CloudAmbient cloud_ambient(vec3 sun_dir, vec3 d)
{
    CloudAmbient a;
    vec3 sky, direct;
    ground_light_per_lux(sun_dir, sky, direct);
    // The sky-view LUT holds the sky around a camera inside the atmosphere only.
    bool sky_view = length(frame.camera_position.xyz) < top_radius();
    vec3 sky_e = sky * frame.sun_illuminance.xyz * (sky_view ? sky_ambient_shape(d) : vec3(1.0));
    // The ground under the clouds is lit by a light they half hide, on average (the march
    // puts the sun's part in the shadow it knows, bottom_sun).
    vec3 ground_e = (0.5 * direct + sky) * frame.sun_illuminance.xyz;
    a.bottom_sun = atmo.ground_albedo.xyz * direct * frame.sun_illuminance.xyz / PI *
                   cloud.media.z;
    if (moon_lights_clouds()) {
        ground_light_per_lux(frame.moon_direction.xyz, sky, direct);
        sky_e += sky * frame.moon_illuminance.xyz;
        ground_e += (0.5 * direct + sky) * frame.moon_illuminance.xyz;
    }
    // Airglow: a sky of about its zenith luminance all over, E = pi L.
    vec3 airglow = vec3(frame.night.x);
    a.top = (sky_e / PI + airglow) * cloud.media.z;
    a.bottom = atmo.ground_albedo.xyz * (ground_e / PI + airglow) * cloud.media.z;
    return a;
}

// Empty-space skipping: after EMPTY_RUN empty fine samples the march probes where the layer may
// hold cloud (cloud_layer_occupied: the envelope, not the billows' level sets, so a fringe
// thinner than the probe spacing is not jumped; 16 steps through a layer then give the light
// of 256 within 1 %) SKIP_FACTOR steps at a time; on a hit it backs up one probe and marches
// finely again.
const float SKIP_FACTOR = 3.0;
const float MARCH_LOD = 0.008; // longest primary step per km of distance
// Footprints (km: the step the distance asks for, MARCH_LOD t) over which the detail erosion
// fades out: its features are 50-200 m.
const vec2 DETAIL_FADE_KM = vec2(0.1, 0.3);
// Footprints (km) over which the base shape falls back to its lowest octave (cells of 600 m) with
// softer edges: its turrets (150-600 m) would alias into speckle and striations.
const vec2 LOD_FADE_KM = vec2(0.12, 0.45);
const int EMPTY_RUN = 3;
// Dense cloud (a storm's core holds 60 optical depths per km): a step that enters it over more
// than ENTRY_TAU optical depths would put the visible surface wherever its jittered sample
// fell, grain and bands of the step's length on every tower. (ENTRY_TAU 1 and STEP_TAU 0.5
// resolve storms a little better, but refine most fair cumulus too: 10 % more frame.) The march backs up to the last
// empty sample and comes in again in steps of 1 / REFINE of it, and inside takes steps of
// STEP_TAU optical depths, between 1 and 2 / REFINE of the step (the thin fringe it comes
// through first must not take a whole step again), for at most REFINED_SAMPLES samples and until
// the view's transmittance has fallen to REFINED_T of what it was at the surface: deeper, the
// surface's place no longer shows, and short steps through a whole cloud would spend the loop's
// samples before the clouds behind it.
const float ENTRY_TAU = 4.0;
const float STEP_TAU = 1.0;
const float REFINE = 8.0;
const float REFINED_T = 0.05;
const float REFINED_SAMPLES = 3.0 * REFINE;

// low_layer: which layer's density the segment marches (a constant at every call).
void march_layer_segment(vec3 o, vec3 d, float t0, float t1, float steps, float jitter,
                         vec3 sun_dir, OctavePhases phases, OctavePhases moon_phases,
                         CloudAmbient amb, bool low_layer, inout CloudResult res,
                         inout vec2 depth_sum)
{
    // Steps of (t1 - t0) / steps as before, but no longer than 2 % of the distance (a few
    // pixels' width) once past the layer's thickness / steps: a ray that grazes the layer
    // from inside it crosses 80 km of shell, and even steps of 1.25 km cut the clouds near
    // the camera into slices.
    float thickness = low_layer ? cloud.low.y - cloud.low.x : cloud.high.y - cloud.high.x;
    float ds_far = (t1 - t0) / steps, ds_near = min(ds_far, thickness / steps);
    float ds = clamp(MARCH_LOD * t0, ds_near, ds_far);
    vec3 sun_top = frame.sun_illuminance.xyz;
    // Sunlight through the atmosphere at the segment's middle: its colour barely changes
    // across one layer.
    vec3 mid = o + d * (0.5 * (t0 + t1));
    vec3 sun = sun_top * sun_transmittance(mid, sun_dir);
    // The moon: a second directional light with its illuminance, at night only.
    bool moon_on = moon_lights_clouds();
    vec3 moon_dir = frame.moon_direction.xyz;
    vec3 moon = moon_on ? frame.moon_illuminance.xyz * sun_transmittance(mid, moon_dir) : vec3(0.0);
    float moon_marched = 0.0;
    bool moon_volume = false;
    float albedo = cloud.media.x;
    float t = t0 + jitter * ds;
    float t_fine = t; // the last fine sample: the skip never backs up behind it
    int empty = EMPTY_RUN;
    bool skipped = false; // the last probe stepped over empty space
    bool outside = true;  // the last fine sample was empty
    bool refining = false; // coming in again in short steps (until the ray leaves the cloud)
    float entry_t = 1.0;   // the view's transmittance where the ray came in
    float refine_left = 0.0; // samples the refinement may still take
    float sun_marched = 0.0, sun_support = 1.0, ground_sun = 0.5;
    vec2 sun_reach = vec2(0.0), moon_reach = vec2(0.0);
    float sun_incidence = 2.0, moon_incidence = 2.0;
    bool sun_volume = false;
    bool fresh_light = true;
    for (float i = 0.0; i < 2.0 * steps + 4.0 * REFINE && t < t1; i += 1.0) {
        if (res.transmittance < EARLY_EXIT_T)
            break;
        ds = clamp(MARCH_LOD * t, ds_near, ds_far);
        // Level of detail from the distance (the step the distance asks for), not from the
        // step count: fewer steps must not change what the clouds are, only how finely they are
        // sampled.
        float footprint = MARCH_LOD * t;
        cloud_detail_weight = clamp((DETAIL_FADE_KM.y - footprint) /
                                        (DETAIL_FADE_KM.y - DETAIL_FADE_KM.x), 0.0, 1.0);
        cloud_lod = clamp((footprint - LOD_FADE_KM.x) / (LOD_FADE_KM.y - LOD_FADE_KM.x), 0.0, 1.0);
        vec3 p = o + t * d;
        if (empty >= EMPTY_RUN && !refining) { // not while coming in again
            // Probing where the layer may hold cloud, big steps.
            if (!cloud_layer_occupied(p, low_layer)) {
                t += SKIP_FACTOR * ds;
                skipped = true;
                continue;
            }
            empty = 0;
            // Back over the skipped stretch, never behind the last fine sample.
            if (skipped)
                t = max(t_fine, t - (SKIP_FACTOR - 1.0) * ds);
            skipped = false;
            p = o + t * d;
        }
        float sigma_t = cloud_layer_extinction(p, true, low_layer);
        float t_before = t_fine;
        t_fine = t;
        if (sigma_t <= 0.0) {
            empty++;
            // Short steps while coming in; a ray that has left the cloud steps as before.
            t += refining && outside ? ds / REFINE : ds;
            refining = refining && outside;
            outside = true;
            continue;
        }
        if (outside && !refining && sigma_t * ds > ENTRY_TAU && t - ds >= t0) {
            refining = true;
            refine_left = REFINED_SAMPLES;
            t = max(t_before, t - ds) + ds / REFINE;
            t_fine = t;
            continue;
        }
        bool entering = outside;
        outside = false;
        if (entering)
            entry_t = res.transmittance;
        refine_left -= 1.0;
        refining = refining && refine_left > 0.0 && res.transmittance > REFINED_T * entry_t;
        // This sample stands for [t, t + ds]: shorter in dense cloud once coming in again.
        if (refining)
            ds = clamp(STEP_TAU / sigma_t, ds / REFINE, 2.0 * ds / REFINE);
        empty = 0;
        float r = length(p);
        // The secondary march runs on every other sample; the one between reuses its optical
        // depth (samples are tens of metres apart, the march reaches kilometres).
        // A sample that enters a cloud marches its own: the optical depth of the last one may
        // be from deep inside another cloud further back along the ray.
        if (fresh_light || entering) {
            // Each light march starts at its own offset (a golden-ratio sequence along the
            // ray): with the pixel's one jitter for all of them, one unlucky offset would
            // bias every light sample of the ray alike, and the octaves that see deep into
            // the cloud would turn that into grain.
            float light_jitter = fract(jitter + 0.6180340 * i);
            vec2 uv;
            sun_volume = low_layer && sun_depth_coords(p, sun_dir, uv);
            sun_reach = sun_march_reach(p, sun_dir);
            sun_marched = sun_march(p, sun_dir, light_jitter, low_layer, sun_volume, sun_reach,
                                    sun_incidence);
            // It varies over hundreds of metres: the neighbour's serves too.
            sun_support = sun_volume ? sun_column_support(uv, sun_dir) : 1.0;
            // The ground under a cloud lies in its shadow: where the volume knows the sun's
            // optical depth to the ground below the sample, its sunlit half becomes that share.
            vec2 below_uv;
            ground_sun = 0.5;
            if (low_layer && sun_depth_coords(p - (r - bottom_radius()) * (p / r), sun_dir,
                                              below_uv)) {
                vec3 column = sun_column_depths(below_uv, cloud.low.y);
                ground_sun = exp(-(column.y + column.z));
            }
            if (moon_on) {
                moon_volume = low_layer && sun_depth_coords(p, moon_dir, uv);
                moon_reach = sun_march_reach(p, moon_dir);
                moon_marched = sun_march(p, moon_dir, light_jitter, low_layer, moon_volume,
                                         moon_reach, moon_incidence);
            }
        }
        SunDepth sun_depth =
            sun_depths(p, sun_dir, sun_marched, sun_volume, sun_reach.x, sigma_t, low_layer);
        sun_depth.support = sun_support;
        SunDepth moon_depth = sun_depth;
        if (moon_on)
            moon_depth = sun_depths(p, moon_dir, moon_marched, moon_volume, moon_reach.x, sigma_t,
                                    low_layer);
        fresh_light = !(fresh_light || entering);
        float h = clamp((r - cloud.low.x) / (cloud.low.y - cloud.low.x), 0.0, 1.0);
        vec3 ambient = mix(amb.bottom + amb.bottom_sun * (ground_sun - 0.5), amb.top, h);
        float src[MAX_OCTAVES], moon_src[MAX_OCTAVES];
        float top = low_layer ? cloud.low.y : cloud.high.y;
        float tau_up = sigma_t * max(top - r, 0.0);
        octave_sources(phases, sun_depth, tau_up, sun_incidence, src);
        if (moon_on)
            octave_sources(moon_phases, moon_depth, tau_up, moon_incidence, moon_src);
        // seed 001 eq. 17: the sources integrated over the step against the extinction.
        float step_t = exp(-sigma_t * ds);
        float sun_sum = 0.0, moon_sum = 0.0;
        for (int n = 0; n < MAX_OCTAVES && float(n) < cloud.phase.w; n++) {
            sun_sum += src[n];
            if (moon_on)
                moon_sum += moon_src[n];
        }
        // The sky's ambient light is scattered once (octave 0).
        // The sky's light reaches a sample through the cloud around it, less the deeper it
        // lies, which the view's own transmittance since it entered the cloud stands for:
        // the source falls as exp(-tau) along the view as the view's transmittance does, and
        // over the step int sigma exp(-2 sigma t) dt = (1 - step_t^2) / 2.
        float sky_seen = AMBIENT_SHARE * res.transmittance / max(entry_t, 1e-6);
        res.luminance += albedo * res.transmittance *
                         ((1.0 - step_t) * (sun * sun_sum + moon * moon_sum) +
                          0.5 * (1.0 - step_t * step_t) * ambient * sky_seen);
        // seed 001 eq. 21: front depth weighted by the transmittance to the viewer.
        depth_sum += vec2(res.transmittance * t, res.transmittance);
        res.transmittance *= step_t;
        if (res.transmittance < EARLY_EXIT_T)
            break;
        t += ds;
    }
}

// Rain shafts: under a precipitating base the air holds drops that scatter without colour,
// extinction RAIN_EXTINCTION per km in the heaviest rain (Koschmieder's visibility 3.912 / sigma:
// 3.9 km). The drops are lit isotropically (their forward peak is too narrow to matter for
// diffuse light) by the sky and the ground: the low sky beside and under the base, RAIN_SIDE_SKY
// of it, in full, and the rest through the cloud above at the diffuse transmittance of a
// conservative two-stream deck, T = 1 / (1 + 3/4 (1 - g) tau) (Bohren 1987, Am. J. Phys. 55,
// 524; g 0.5 for the renderer's phase).
const float RAIN_EXTINCTION = 1.0;
const float RAIN_SIDE_SKY = 0.3;
const float RAIN_STEPS = 12.0;
const float RAIN_REACH_KM = 40.0;

void march_rain(vec3 o, vec3 d, float t0, float t1, float jitter, CloudAmbient amb,
                inout CloudResult res)
{
    t1 = min(t1, t0 + RAIN_REACH_KM);
    if (cloud.media.y <= 0.0 || t1 <= t0)
        return;
    float ds = (t1 - t0) / RAIN_STEPS;
    for (float i = 0.0; i < RAIN_STEPS; i += 1.0) {
        vec2 rain = cloud_rain(o + d * (t0 + (i + jitter) * ds));
        float sigma = RAIN_EXTINCTION * rain.x;
        if (sigma <= 0.0)
            continue;
        float through_cloud = 1.0 / (1.0 + 0.375 * rain.y);
        vec3 light = (amb.top + amb.bottom) * mix(RAIN_SIDE_SKY, 1.0, through_cloud);
        float step_t = exp(-sigma * ds);
        // seed 001 eq. 17 with a constant source; albedo 1.
        res.luminance += res.transmittance * light * (1.0 - step_t);
        res.transmittance *= step_t;
    }
}

// The ray's stretch between the ground and the low layer's base: [t0, t1], false when none.
bool under_base_segment(vec3 o, vec3 d, out float t0, out float t1)
{
    float base = cloud.low.x;
    float t_ground = ray_sphere_nearest(o, d, bottom_radius());
    // From under the base at once; from above where the ray enters the base's sphere (-1: never).
    t0 = length(o) < base ? 0.0 : ray_sphere_nearest(o, d, base);
    t1 = t_ground >= 0.0 ? t_ground : ray_sphere_far(o, d, base);
    return t0 >= 0.0 && t1 > t0;
}

// Marches both layers along the ray, nearest segment first.
CloudResult march_clouds(vec3 o, vec3 d, vec3 sun_dir, float jitter, float primary_steps)
{
    CloudResult res;
    res.luminance = vec3(0.0);
    res.transmittance = 1.0;
    res.depth = 0.0;
    if (cloud.march.z < 0.5)
        return res;
    float lo0, lo1, hi0, hi1;
    bool low = shell_segment(o, d, cloud.low.x, cloud.low.y, lo0, lo1);
    bool high = cloud.high.w > 0.5 && shell_segment(o, d, cloud.high.x, cloud.high.y, hi0, hi1);
    float longest = cloud.march.y;
    lo1 = min(lo1, lo0 + longest);
    hi1 = min(hi1, hi0 + longest);
    OctavePhases phases = octave_phases(dot(d, sun_dir));
    OctavePhases moon_phases = phases;
    if (moon_lights_clouds())
        moon_phases = octave_phases(dot(d, frame.moon_direction.xyz));
    CloudAmbient amb = cloud_ambient(sun_dir, d);
    vec2 depth_sum = vec2(0.0);
    float high_steps = max(4.0, floor(primary_steps / 8.0));
    bool high_first = high && (!low || hi0 < lo0);
    float rain0, rain1;
    bool rain = cloud.media.y > 0.0 && under_base_segment(o, d, rain0, rain1);
    if (rain && length(o) < cloud.low.x) // from under the base: the rain first
        march_rain(o, d, rain0, rain1, jitter, amb, res);
    if (high_first)
        march_layer_segment(o, d, hi0, hi1, high_steps, jitter, sun_dir, phases, moon_phases, amb,
                            false, res, depth_sum);
    if (low)
        march_layer_segment(o, d, lo0, lo1, primary_steps, jitter, sun_dir, phases, moon_phases,
                            amb, true, res, depth_sum);
    if (rain && length(o) >= cloud.low.x) // from above: the rain under the layer
        march_rain(o, d, rain0, rain1, jitter, amb, res);
    if (high && !high_first)
        march_layer_segment(o, d, hi0, hi1, high_steps, jitter, sun_dir, phases, moon_phases, amb,
                            false, res, depth_sum);
    res.depth = depth_sum.y > 0.0 ? depth_sum.x / depth_sum.y : 0.0;
    // A march that stopped early went through an optical depth of 4.6 or more: nothing is
    // seen through it, the sun's disk included (1 % of a disk of 1e9 cd/m2 would still
    // outshine the cloud a thousandfold).
    if (res.transmittance < EARLY_EXIT_T)
        res.transmittance = 0.0;
    return res;
}

#endif
