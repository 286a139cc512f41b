// Ray march through the cloud layers (seed 001 5.5-5.8): energy-conserving integration
// (seed 001 eq. 17) of the light at each sample (cloud_light.glsl: phase, the sun's optical
// depth, the multiple-scattering octaves) and the atmosphere's transmittance LUT (so sunsets
// colour the clouds), sky ambient from the sky-view and irradiance LUTs (top) and the lit
// ground (bottom), early exit at low transmittance and empty-space skipping. Needs
// atmosphere.glsl with the transmittance and sky-view LUTs, cloud_density.glsl,
// cloud_sun_depth.glsl and an `irradiance_lut` sampler.
#ifndef CLOUD_MARCH_GLSL
#define CLOUD_MARCH_GLSL

#include "cloud_light.glsl"

const float EARLY_EXIT_T = 0.01;
struct CloudResult {
    vec3 luminance;   // scattered by the clouds toward the origin (cd/m2)
    float transmittance;
    float depth;      // transmittance-weighted front depth (seed 001 eq. 21), km
};

// Ambient radiance (cd/m2) under (top) and over (bottom) the clouds along one view ray: the sky
// lit by the sun, by the moon at night (the same irradiance LUT per unit illuminance outside the
// atmosphere, seed 001 4.2) and the airglow floor.
struct CloudAmbient {
    vec3 top, bottom;
    // The octaves' phases of the sky's light diffused down through the cloud (from the zenith).
    OctavePhases sky_phases;
    // The parts of bottom that the sun and its sky light on the ground, in a clear sky (bottom
    // holds half the first and all of the second).
    vec3 bottom_sun, bottom_sky;
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
    a.sky_phases = octave_phases(d.z); // at the camera's foot, up is +z
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
    a.bottom_sky = atmo.ground_albedo.xyz * sky * frame.sun_illuminance.xyz / PI * cloud.media.z;
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

// The share of the sun's (x) and of its sky's (y) light that reaches the ground through a
// column of cloud whose optical depth along the sun's ray is tau_sun, the sun at cosine mu0: the
// Eddington solution's total transmission of a conservative deck of vertical optical depth
// tau = mu0 tau_sun, [1/2 + 3/4 mu0 + (1/2 - 3/4 mu0) exp(-tau/mu0)] / (1 + 3/4 (1 - g) tau)
// (Joseph, Wiscombe & Weinman 1976), the direct beam included; the sky's diffuse light enters
// as at mu0 = 2/3. Under a deck the ground is lit by what the deck diffuses, not by the blue
// sky above it.
vec2 ground_transmission(float tau_sun, float mu0)
{
    mu0 = max(mu0, 0.05);
    float g = dual_lobe_mean_cosine();
    float diffusion = 1.0 + 0.75 * (1.0 - g) * mu0 * tau_sun;
    float sun = (0.5 + 0.75 * mu0 + (0.5 - 0.75 * mu0) * exp(-tau_sun)) / diffusion;
    return vec2(sun, 1.0 / diffusion);
}

// Empty-space skipping: after EMPTY_RUN empty fine samples the march probes where the layer may
// hold cloud (cloud_layer_sample's -1: the envelope, not the billows' level sets, so a fringe
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
// resolve storms a little better, but refine most fair cumulus too: 10 % more frame.) The
// march backs up to the last empty sample and comes in again in steps of 1 / REFINE of it, and inside takes steps of
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
// The loop's iterations per view sample at most, the light marches' steps included: one march
// of up to 12 steps for every other sample, and a sample stays short of it only in the
// thinnest clouds.
const float LIGHT_ITERATIONS = 8.0;
// Lit samples the march collects before it shades them (below): a few passes of the outer loop
// for a ray through a whole cloud.
const int LIT_BATCH = 16;

// What shading a lit sample needs from the march: where it is, its extinction and step, the
// view's transmittance in front of it and since the ray entered the cloud, and the light
// marches' optical depth and incidence with the radius where each handed over to the sun-space
// volume (negative: no volume).
struct LitSample {
    float t, sigma_t, step_t, transmittance, seen_since_entry;
    float sun_marched, sun_incidence, sun_reach_r;
    float moon_marched, moon_incidence, moon_reach_r;
};

// The ground under a cloud lies in its shadow: where the shadow map knows the sun's optical
// depth to the ground (every layer's), the ground's sun and sky light are what those columns let
// through (ground_transmission). A sample sees the ground over about its height on every side,
// not the one point below it, whose column would light or darken a whole base with the texture of
// the shadow right under it: the point below and a ring of GROUND_RING times the height.
const float GROUND_RING = 1.3;
const float GROUND_CENTRE_WEIGHT = 0.25;
const float GROUND_RING_WEIGHT = (1.0 - GROUND_CENTRE_WEIGHT) / 4.0;

vec3 ground_under(vec3 p, float r, vec3 sun_dir, CloudAmbient amb)
{
    vec3 below = p * (bottom_radius() / r);
    vec2 uv;
    if (!sun_depth_ground_coords(below, sun_dir, uv))
        return amb.bottom;
    vec2 through = GROUND_CENTRE_WEIGHT * ground_transmission(sun_column(uv).depth, sun_dir.z);
    float ring = GROUND_RING * (r - bottom_radius());
    for (int k = 0; k < 4; k++) {
        vec2 side = k < 2 ? vec2(k == 0 ? ring : -ring, 0.0) : vec2(0.0, k == 2 ? ring : -ring);
        if (sun_depth_ground_coords(below + vec3(side, 0.0), sun_dir, uv))
            through += GROUND_RING_WEIGHT * ground_transmission(sun_column(uv).depth, sun_dir.z);
        else
            through += GROUND_RING_WEIGHT * vec2(0.5, 1.0); // amb.bottom's own
    }
    return amb.bottom + amb.bottom_sun * (through.x - 0.5) + amb.bottom_sky * (through.y - 1.0);
}

// Shades one lit sample of the segment (seed 001 eq. 17: the sources integrated over the step
// against the extinction) and adds its light to res.
void shade_lit_sample(vec3 o, vec3 d, LitSample s, vec3 sun_dir, vec3 sun, vec3 moon,
                      OctavePhases phases, OctavePhases moon_phases, CloudAmbient amb,
                      int layer, inout CloudResult res)
{
    bool moon_on = moon_lights_clouds();
    vec3 p = o + s.t * d;
    float r = length(p);
    SunDepth sun_depth = sun_depths(p, sun_dir, s.sun_marched, s.sun_reach_r >= 0.0,
                                    s.sun_reach_r, s.sigma_t, layer);
    SunDepth moon_depth = sun_depth;
    if (moon_on)
        moon_depth = sun_depths(p, frame.moon_direction.xyz, s.moon_marched,
                                s.moon_reach_r >= 0.0, s.moon_reach_r, s.sigma_t, layer);
    vec3 ground = layer != LAYER_HIGH ? ground_under(p, r, sun_dir, amb) : amb.bottom;
    // The ambient's height in the low layer (the layers above it: its top), in the middle
    // layer its own: its base sees the lit ground and the low clouds' tops.
    vec4 amb_shell = layer == LAYER_MID ? cloud.mid : cloud.low;
    float h = clamp((r - amb_shell.x) / (amb_shell.y - amb_shell.x), 0.0, 1.0);
    vec3 ambient = mix(ground, amb.top, h);
    float src[MAX_OCTAVES], moon_src[MAX_OCTAVES];
    float top = layer_shell(layer).y;
    float tau_up = s.sigma_t * max(top - r, 0.0);
    float sun_mu0 = octave_mu0(sun_depth, tau_up, s.sun_incidence);
    vec3 up = p / r;
    light_octave_sources(phases, amb.sky_phases, sun_depth, sun_mu0, sun_dir, up, src);
    if (moon_on)
        light_octave_sources(moon_phases, amb.sky_phases, moon_depth,
                             octave_mu0(moon_depth, tau_up, s.moon_incidence),
                             frame.moon_direction.xyz, up, moon_src);
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
    float sky_seen = AMBIENT_SHARE * s.seen_since_entry;
    vec3 sky_through = amb.top * sky_diffuse_source(amb.sky_phases, sun_depth, sun_mu0);
    res.luminance += cloud.media.x * s.transmittance *
                     ((1.0 - s.step_t) * (sun * sun_sum + moon * moon_sum + sky_through) +
                      0.5 * (1.0 - s.step_t * s.step_t) * ambient * sky_seen);
}

// layer: which layer's density the segment marches (LAYER_*, a constant at every call).
//
// The march collects up to LIT_BATCH lit samples, then shades them in a loop of its own: its
// inner loop then holds only the density lookup, the view's bookkeeping and the light march's
// steps. lavapipe runs every instruction of a loop's body on every iteration, masked or not,
// and the shading (the sun-space volume's lookups, the octaves) would otherwise run on each
// step of every light march too.
void march_layer_segment(vec3 o, vec3 d, float t0, float t1, float steps, float jitter,
                         vec3 sun_dir, OctavePhases phases, OctavePhases moon_phases,
                         CloudAmbient amb, int layer, inout CloudResult res,
                         inout vec2 depth_sum)
{
    // Steps of (t1 - t0) / steps as before, but no longer than 2 % of the distance (a few
    // pixels' width) once past the layer's thickness / steps: a ray that grazes the layer
    // from inside it crosses 80 km of shell, and even steps of 1.25 km cut the clouds near
    // the camera into slices.
    vec4 shell = layer_shell(layer);
    float thickness = shell.y - shell.x;
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
    float t = t0 + jitter * ds;
    float t_fine = t; // the last fine sample: the skip never backs up behind it
    int empty = EMPTY_RUN;
    bool skipped = false; // the last probe stepped over empty space
    bool outside = true;  // the last fine sample was empty
    bool refining = false; // coming in again in short steps (until the ray leaves the cloud)
    float entry_t = 1.0;   // the view's transmittance where the ray came in
    float refine_left = 0.0; // samples the refinement may still take
    float sun_marched = 0.0;
    vec2 sun_reach = vec2(0.0), moon_reach = vec2(0.0);
    float sun_incidence = 2.0, moon_incidence = 2.0;
    bool sun_volume = false;
    bool fresh_light = true;
    // The sample being lit while a light march runs (sun, then moon), one step per iteration.
    SunMarch light;
    bool lighting = false, lighting_moon = false;
    vec3 p = o + t * d;
    float sigma_t = 0.0;
    float view_samples = 0.0; // the view's own samples and probes, as many as before the light
    const float max_samples = 2.0 * steps + 4.0 * REFINE;
    float i = 0.0;
    bool marching = true;
    LitSample lit[LIT_BATCH];
    while (marching) {
        int lit_count = 0;
        for (; lit_count < LIT_BATCH; i += 1.0) {
            if (!lighting) {
                if (res.transmittance < EARLY_EXIT_T || t >= t1 ||
                    view_samples >= max_samples || i >= LIGHT_ITERATIONS * max_samples) {
                    marching = false;
                    break;
                }
                view_samples += 1.0;
                ds = clamp(MARCH_LOD * t, ds_near, ds_far);
                // Level of detail from the distance (the step the distance asks for), not
                // from the step count: fewer steps must not change what the clouds are, only
                // how finely they are sampled.
                float footprint = MARCH_LOD * t;
                cloud_detail_weight = clamp((DETAIL_FADE_KM.y - footprint) /
                                                (DETAIL_FADE_KM.y - DETAIL_FADE_KM.x),
                                            0.0, 1.0);
                cloud_lod = clamp((footprint - LOD_FADE_KM.x) / (LOD_FADE_KM.y - LOD_FADE_KM.x),
                                  0.0, 1.0);
                p = o + t * d;
            }
            // The loop's one density lookup, for the view (a probe or a sample: -1 where the
            // layer's coverage holds no cloud) or for the light march on the coarse shape.
            float sampled = cloud_layer_sample(lighting ? sun_march_point(light) : p, !lighting,
                                               layer);
            if (lighting) {
                sun_march_add(light, max(sampled, 0.0));
                if (!sun_march_done(light))
                    continue;
                if (!lighting_moon) {
                    sun_marched = light.tau;
                    sun_incidence = sun_march_incidence(light);
                } else {
                    moon_marched = light.tau;
                    moon_incidence = sun_march_incidence(light);
                }
                if (moon_on && !lighting_moon) {
                    lighting_moon = true;
                    light = sun_march_begin(p, moon_dir, light.jitter, layer, moon_volume,
                                            moon_reach);
                    continue;
                }
                lighting = false; // on to the sample's light below
            } else {
                sigma_t = sampled;
                if (empty >= EMPTY_RUN && !refining) { // probing, not while coming in again
                    if (sigma_t < 0.0) { // where the layer may hold cloud, big steps
                        t += SKIP_FACTOR * ds;
                        skipped = true;
                        continue;
                    }
                    empty = 0;
                    // Back over the skipped stretch, never behind the last fine sample, and
                    // sample there next.
                    if (skipped) {
                        t = max(t_fine, t - (SKIP_FACTOR - 1.0) * ds);
                        skipped = false;
                        continue;
                    }
                }
                sigma_t = max(sigma_t, 0.0);
                float t_before = t_fine;
                t_fine = t;
                if (sigma_t <= 0.0) {
                    empty++;
                    // Short steps while coming in; a ray that has left the cloud steps as
                    // before.
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
                refining =
                    refining && refine_left > 0.0 && res.transmittance > REFINED_T * entry_t;
                // This sample stands for [t, t + ds]: shorter in dense cloud once coming in
                // again.
                if (refining)
                    ds = clamp(STEP_TAU / sigma_t, ds / REFINE, 2.0 * ds / REFINE);
                empty = 0;
                // The light march runs for every other sample; the one between reuses its
                // optical depth (samples are tens of metres apart, the march reaches
                // kilometres). A sample that enters a cloud marches its own: the optical depth
                // of the last one may be from deep inside another cloud further back along the
                // ray.
                bool fresh = fresh_light || entering;
                fresh_light = !fresh;
                if (fresh) {
                    // Each light march starts at its own offset (a golden-ratio sequence along
                    // the ray): with the pixel's one jitter for all of them, one unlucky offset
                    // would bias every light sample of the ray alike, and the octaves that see
                    // deep into the cloud would turn that into grain.
                    float light_jitter = fract(jitter + 0.6180340 * (view_samples - 1.0));
                    vec2 uv;
                    sun_volume = layer == LAYER_LOW && sun_depth_coords(p, sun_dir, uv);
                    sun_reach = sun_march_reach(p, sun_dir);
                    if (moon_on) {
                        moon_volume = layer == LAYER_LOW && sun_depth_coords(p, moon_dir, uv);
                        moon_reach = sun_march_reach(p, moon_dir);
                    }
                    light = sun_march_begin(p, sun_dir, light_jitter, layer, sun_volume,
                                            sun_reach);
                    lighting = true;
                    lighting_moon = false;
                    continue;
                }
            }
            // The sample at p, lit: kept for the shading below.
            float step_t = exp(-sigma_t * ds);
            LitSample s;
            s.t = t;
            s.sigma_t = sigma_t;
            s.step_t = step_t;
            s.transmittance = res.transmittance;
            s.seen_since_entry = res.transmittance / max(entry_t, 1e-6);
            s.sun_marched = sun_marched;
            s.sun_incidence = sun_incidence;
            s.sun_reach_r = sun_volume ? sun_reach.x : -1.0;
            s.moon_marched = moon_marched;
            s.moon_incidence = moon_incidence;
            s.moon_reach_r = moon_volume ? moon_reach.x : -1.0;
            lit[lit_count] = s;
            lit_count++;
            // seed 001 eq. 21: front depth weighted by the transmittance to the viewer.
            depth_sum += vec2(res.transmittance * t, res.transmittance);
            res.transmittance *= step_t;
            t += ds;
        }
        for (int k = 0; k < lit_count; k++)
            shade_lit_sample(o, d, lit[k], sun_dir, sun, moon, phases, moon_phases, amb,
                             layer, res);
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

// Marches the layers along the ray, nearest segment first. The shells lie one above the other
// (low, middle, high, by their bases), so a ray meets them in that order going up and in the
// reverse going down (overlapping shells are marched one after the other all the same).
CloudResult march_clouds(vec3 o, vec3 d, vec3 sun_dir, float jitter, float primary_steps)
{
    CloudResult res;
    res.luminance = vec3(0.0);
    res.transmittance = 1.0;
    res.depth = 0.0;
    if (cloud.march.z < 0.5)
        return res;
    float lo0 = 0.0, lo1 = 0.0, hi0 = 0.0, hi1 = 0.0, mi0 = 0.0, mi1 = 0.0;
    bool low = shell_segment(o, d, cloud.low.x, cloud.low.y, lo0, lo1);
    bool high = cloud.high.w > 0.5 && shell_segment(o, d, cloud.high.x, cloud.high.y, hi0, hi1);
    bool mid = cloud.mid.w > 0.5 && shell_segment(o, d, cloud.mid.x, cloud.mid.y, mi0, mi1);
    float longest = cloud.march.y;
    lo1 = min(lo1, lo0 + longest);
    hi1 = min(hi1, hi0 + longest);
    mi1 = min(mi1, mi0 + longest);
    OctavePhases phases = octave_phases(dot(d, sun_dir));
    OctavePhases moon_phases = phases;
    if (moon_lights_clouds())
        moon_phases = octave_phases(dot(d, frame.moon_direction.xyz));
    CloudAmbient amb = cloud_ambient(sun_dir, d);
    vec2 depth_sum = vec2(0.0);
    float high_steps = max(4.0, floor(primary_steps / 8.0));
    // The middle layer: a quarter of the low layer's steps (a sheet a kilometre or two thick).
    float mid_steps = max(8.0, floor(primary_steps / 4.0));
    // Descending (from above): high, middle, low; else ascending. The first two layers the ray
    // meets say which.
    bool descending = high ? (mid ? hi0 < mi0 : low && hi0 < lo0) : mid && low && mi0 < lo0;
    bool high_first = high && descending;
    bool mid_first = mid && descending;
    float rain0, rain1;
    bool rain = cloud.media.y > 0.0 && under_base_segment(o, d, rain0, rain1);
    if (rain && length(o) < cloud.low.x) // from under the base: the rain first
        march_rain(o, d, rain0, rain1, jitter, amb, res);
    if (high_first)
        march_layer_segment(o, d, hi0, hi1, high_steps, jitter, sun_dir, phases, moon_phases, amb,
                            LAYER_HIGH, res, depth_sum);
    if (mid_first)
        march_layer_segment(o, d, mi0, mi1, mid_steps, jitter, sun_dir, phases, moon_phases, amb,
                            LAYER_MID, res, depth_sum);
    if (low)
        march_layer_segment(o, d, lo0, lo1, primary_steps, jitter, sun_dir, phases, moon_phases,
                            amb, LAYER_LOW, res, depth_sum);
    if (rain && length(o) >= cloud.low.x) // from above: the rain under the layer
        march_rain(o, d, rain0, rain1, jitter, amb, res);
    if (mid && !mid_first)
        march_layer_segment(o, d, mi0, mi1, mid_steps, jitter, sun_dir, phases, moon_phases, amb,
                            LAYER_MID, res, depth_sum);
    if (high && !high_first)
        march_layer_segment(o, d, hi0, hi1, high_steps, jitter, sun_dir, phases, moon_phases, amb,
                            LAYER_HIGH, res, depth_sum);
    res.depth = depth_sum.y > 0.0 ? depth_sum.x / depth_sum.y : 0.0;
    // A march that stopped early went through an optical depth of 4.6 or more: nothing is
    // seen through it, the sun's disk included (1 % of a disk of 1e9 cd/m2 would still
    // outshine the cloud a thousandfold).
    if (res.transmittance < EARLY_EXIT_T)
        res.transmittance = 0.0;
    return res;
}

#endif
