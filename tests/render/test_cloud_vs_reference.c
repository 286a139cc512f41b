/* The real-time clouds against their path-traced reference (sky_render_clouds.reference_spp,
 * shaders/cloud_pathtrace.comp), both through the same resolve and composite: one cumulus
 * (a client weather map with one round cell, as test_cloud_shapes places it) lit from behind
 * the camera, from the side and from behind the cloud (the sun out of the frame), and one
 * cumulonimbus, seen from the ground (an overcast deck's base has checks of its own,
 * compare_deck_base, and so has the middle layer's altostratus toward a low sun,
 * compare_mid_deck_low_sun). Over the cloud's pixels (where the reference differs from the clear sky
 * by more than 10 %, above the horizon; tests/common/cloud_compare.h):
 *   - mean relative luminance error <= 15 %;
 *   - outline (2 px band) / interior brightness within 15 % of the reference's;
 *   - pixel-scale grain (high-pass std / mean, inside the outline) at most 1.2 x the
 *     reference's.
 * The reference is rendered twice with different seeds: its own noise (the relative difference
 * of the two, and the grain of their half difference) is reported, and must stay well under
 * the figures it judges. The renderer uses the state's defaults (its one-off render
 * accumulates); the reference traces 64-320 samples per pixel a case (scenes[]), twice.
 * $SKYD_COMPARE_CASE runs one case by name.
 * argv[1]: where each case is saved as renderer | reference side by side; argv[2]: the config
 * directory. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "check.h"
#include "cloud_compare.h"
#include "png_write.h"
#include "presets.h"
#include "test_support.h"

#define W 128
#define H 96
/* Samples per pixel of each reference render: enough that the reference's own grain (its
 * Monte Carlo noise) is below the grain it judges; the front-lit and side-lit cumulus, whose
 * lit faces are smooth, need the most. $SKYD_REFERENCE_SPP sets one count for every case. */
#define BAND 2
/* The relative error compares 4x4 blocks: at pixel scale the reference's own noise would
 * dominate (several % at the spp two CPU cores afford); the outline and grain are per pixel. */
#define ERROR_BLOCK 4
#define DEG (3.14159265358979323846 / 180.0)

#define MAX_RELATIVE_ERROR 0.15
#define MAX_OUTLINE_DEVIATION 0.15
#define MAX_GRAIN_RATIO 1.2

static const char *out_dir = ".";
static const char *config_dir = "config";
static struct sky_renderer *renderer;
static uint64_t next_key = 1;
static uint32_t ref_spp_override;

struct scene {
    const char *name;
    const char *preset;
    double sun_azimuth_deg, sun_elevation_deg;
    double radius_km, north_km, fov_deg;
    uint8_t type, rain;
    uint32_t spp;
};

static const struct scene scenes[] = {
    { "cumulus_front", "fair_cumulus", 180.0, 30.0, 1.5, 8.0, 40.0, 168, 0, 320 },
    { "cumulus_side", "fair_cumulus", 90.0, 30.0, 1.5, 8.0, 40.0, 168, 0, 192 },
    { "cumulus_back", "fair_cumulus", 0.0, 40.0, 1.5, 8.0, 40.0, 168, 0, 64 },
    { "cumulonimbus", "storm", 180.0, 30.0, 3.0, 25.0, 60.0, 255, 0, 96 },
};

static double seconds(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return t.tv_sec + 1e-9 * t.tv_nsec;
}

/* The defaults with a weather preset applied. */
static bool weather_state(const char *preset, struct proto_world_state *s)
{
    proto_world_state_defaults(s);
    char msg[1024] = "";
    bool ok = world_preset_apply(config_dir, "weather", preset, s, NULL, msg, sizeof msg);
    CHECK_MSG(ok, "weather preset %s: %s", preset, msg);
    return ok;
}

static bool scene_state(const struct scene *sc, struct proto_world_state *s)
{
    bool ok = weather_state(sc->preset, s);
    s->weather.map_source = PROTO_WEATHER_MAP_CLIENT;
    s->clouds.high.coverage = 0.0;
    /* No rain: the shafts under a base are the renderer's own march, not cloud density, and
     * the reference traces the density alone. */
    s->clouds.precipitation = 0.0;
    s->camera.altitude_km = 0.2;
    s->camera.yaw_deg = 0.0;
    s->camera.pitch_deg = 12.0;
    s->camera.fov_deg = sc->fov_deg;
    s->sun.azimuth_deg = sc->sun_azimuth_deg;
    s->sun.elevation_deg = sc->sun_elevation_deg;
    return ok;
}

/* Renders `s` (reference_spp 0: the renderer) into rgba and its luminance into luma. A
 * reference must be whole: at most one sample in 10^5 cut short by lavapipe's loop limit
 * (cloud_pathtrace.glsl's pt_loops_intact; none in any case since the shells' descending exit,
 * 8 of 1.2e6 in the cumulonimbus before). */
static void render(const struct proto_world_state *s, uint32_t spp, uint32_t seed, float *rgba,
                   float *luma)
{
    struct sky_render_atmosphere atm;
    struct sky_render_view view;
    struct sky_render_clouds clouds;
    struct sky_render_night night;
    world_to_render_atmosphere(s, &atm);
    world_to_render_view(s, W, H, SKY_RENDER_OUTPUT_LINEAR, &view);
    view.history_key = next_key++;
    world_to_render_clouds(s, &clouds);
    clouds.reference_spp = spp;
    clouds.reference_seed = seed;
    CHECK(sky_renderer_set_clouds(renderer, &clouds) == 0);
    world_to_render_night(s, &night);
    sky_renderer_set_night(renderer, &night);
    CHECK(sky_renderer_render(renderer, &atm, &view, rgba, (size_t)W * H * 16, NULL) == 0);
    CHECK(test_count_bad(rgba, (size_t)W * H) == 0);
    for (int i = 0; i < W * H; i++)
        luma[i] = (float)test_pixel_luminance(rgba + 4 * i);
    if (spp > 0) {
        struct sky_render_reference_stats st;
        CHECK(sky_renderer_cloud_reference_stats(renderer, &st) == 0);
        CHECK_MSG(st.bound_violations == 0, "%u density samples above the majorant (up to %.3f x)",
                  st.bound_violations, st.max_bound_ratio);
        /* Walks that end as if past the step cap: a storm's had one in 10^7 density samples
         * while paths ran through the planet under a shell (the loop limit below then ended
         * pt_propose's loop early); none since. Counted, and bounded. */
        CHECK_MSG(st.overflows <= 1e-6 * st.density_samples, "%u ray segments cut short",
                  st.overflows);
        if (st.overflows > 0)
            printf("  %u ray segments cut short\n", st.overflows);
        CHECK_MSG(st.truncated <= 1e-5 * spp * W * H,
                  "%u reference samples cut short by the device's loop limit", st.truncated);
        printf("  reference (seed %u): %.3g density samples, %u above the majorant, %u of %u "
               "samples cut short by the device's loop limit\n",
               seed, st.density_samples, st.bound_violations, st.truncated, spp * W * H);
    }
}

static uint8_t srgb8(double v)
{
    v = v <= 0.0031308 ? 12.92 * v : 1.055 * pow(v, 1.0 / 2.4) - 0.055;
    return (uint8_t)lround(fmin(fmax(v, 0.0), 1.0) * 255.0);
}

/* renderer | reference, exposed alike for the reference's mean luminance (Reinhard). */
static void save_pair(const char *name, const float *a, const float *b)
{
    static uint8_t pixels[2 * W * H * 4];
    double mean = 0.0;
    for (int i = 0; i < W * H; i++)
        mean += test_pixel_luminance(b + 4 * i);
    double k = 0.25 / fmax(mean / (W * H), 1e-9);
    for (int y = 0; y < H; y++)
        for (int x = 0; x < 2 * W; x++) {
            const float *src = (x < W ? a : b) + 4 * ((size_t)y * W + (size_t)(x % W));
            uint8_t *p = pixels + 4 * ((size_t)y * 2 * W + (size_t)x);
            for (int c = 0; c < 3; c++) {
                double v = src[c] * k;
                p[c] = srgb8(v / (1.0 + v));
            }
            p[3] = 255;
        }
    char path[1024], err[256];
    snprintf(path, sizeof path, "%s/cloud_vs_reference_%s.png", out_dir, name);
    CHECK(png_write_rgba8_file(path, pixels, 2 * W, H, err, sizeof err) == 0);
    printf("  saved %s (renderer | reference)\n", path);
}

/* The cloud: where the reference differs from the clear sky by over 10 %, above the horizon
 * (under it the clouds' shadows change the ground). */
static int cloud_mask(const struct proto_world_state *s, const float *ref, const float *clear,
                      unsigned char *mask)
{
    double f[3], r[3], u[3];
    double yaw = s->camera.yaw_deg * DEG;
    sky_direction_from_angles(s->camera.yaw_deg, s->camera.pitch_deg, f);
    r[0] = cos(yaw), r[1] = -sin(yaw), r[2] = 0.0;
    u[0] = r[1] * f[2] - r[2] * f[1];
    u[1] = r[2] * f[0] - r[0] * f[2];
    u[2] = r[0] * f[1] - r[1] * f[0];
    double tan_half = tan(0.5 * s->camera.fov_deg * DEG);
    int on = 0;
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
            double ny = 1.0 - 2.0 * ((y + 0.5) / H), nx = 2.0 * ((x + 0.5) / W) - 1.0;
            double d[3], len = 0.0;
            for (int c = 0; c < 3; c++) {
                d[c] = f[c] + r[c] * nx * tan_half * W / H + u[c] * ny * tan_half;
                len += d[c] * d[c];
            }
            size_t i = (size_t)y * W + (size_t)x;
            mask[i] = d[2] / sqrt(len) > sin(1.0 * DEG) &&
                      fabs((double)ref[i] - clear[i]) > 0.10 * clear[i];
            on += mask[i];
        }
    return on;
}

/* $SKYD_REFERENCE_CACHE: a folder that keeps each case's reference renders (for work on the
 * renderer's light, which leaves the reference as it is): read from it when there, written
 * to it otherwise. Unset in ctest: the reference is rendered every run. */
static bool cache_path(const char *name, uint32_t spp, int k, char *path, size_t size)
{
    const char *dir = getenv("SKYD_REFERENCE_CACHE");
    if (!dir || !*dir)
        return false;
    snprintf(path, size, "%s/%s-%u-%d.f32", dir, name, spp, k);
    return true;
}

static bool load_cached(const char *name, uint32_t spp, int k, float *rgba, float *luma)
{
    char path[1024];
    if (!cache_path(name, spp, k, path, sizeof path))
        return false;
    FILE *f = fopen(path, "rb");
    if (!f)
        return false;
    size_t got = fread(rgba, sizeof(float), (size_t)W * H * 4, f);
    fclose(f);
    if (got != (size_t)W * H * 4)
        return false;
    for (int i = 0; i < W * H; i++)
        luma[i] = (float)test_pixel_luminance(rgba + 4 * i);
    printf("  reference (seed %d) from %s\n", k + 1, path);
    return true;
}

static void save_cached(const char *name, uint32_t spp, int k, const float *rgba)
{
    char path[1024];
    if (!cache_path(name, spp, k, path, sizeof path))
        return;
    FILE *f = fopen(path, "wb");
    if (!f)
        return;
    fwrite(rgba, sizeof(float), (size_t)W * H * 4, f);
    fclose(f);
}

static float rt_rgba[W * H * 4], ref_rgba[2][W * H * 4], clear_rgba[W * H * 4];
static float rt[W * H], ref[2][W * H], ref_mean[W * H], clear[W * H], half_diff[W * H];
static unsigned char mask[W * H];

static void compare_scene(const struct scene *sc)
{
    struct proto_world_state s;
    if (!scene_state(sc, &s))
        return;
    uint32_t spp = ref_spp_override ? ref_spp_override : sc->spp;
    printf("%s: sun at azimuth %.0f, elevation %.0f deg; %dx%d, reference %d spp x 2\n", sc->name,
           sc->sun_azimuth_deg, sc->sun_elevation_deg, W, H, spp);
    CHECK(test_set_cell_map(renderer, &s, sc->radius_km, sc->north_km, sc->type, sc->rain) == 0);
    double t0 = seconds();
    render(&s, 0, 0, rt_rgba, rt);
    double t1 = seconds();
    for (int k = 0; k < 2; k++)
        if (!load_cached(sc->name, spp, k, ref_rgba[k], ref[k])) {
            render(&s, spp, (uint32_t)k + 1, ref_rgba[k], ref[k]);
            save_cached(sc->name, spp, k, ref_rgba[k]);
        }
    double t2 = seconds();
    struct proto_world_state c = s;
    c.weather.map_source = PROTO_WEATHER_MAP_PROCEDURAL;
    c.clouds.low.coverage = 0.0;
    render(&c, 0, 0, clear_rgba, clear);
    for (int i = 0; i < W * H; i++) {
        ref_mean[i] = 0.5f * (ref[0][i] + ref[1][i]);
        half_diff[i] = 0.5f * (ref[0][i] - ref[1][i]);
        for (int k = 0; k < 4; k++)
            ref_rgba[0][4 * i + k] = 0.5f * (ref_rgba[0][4 * i + k] + ref_rgba[1][4 * i + k]);
    }
    save_pair(sc->name, rt_rgba, ref_rgba[0]);
    int pixels = cloud_mask(&s, ref_mean, clear, mask);
    double err = cloud_compare_block_relative_error(rt, ref_mean, mask, W, H, ERROR_BLOCK);
    double err_pixel = cloud_compare_relative_error(rt, ref_mean, mask, W, H);
    double outline_rt = cloud_compare_outline_ratio(rt, mask, W, H, BAND);
    double outline_ref = cloud_compare_outline_ratio(ref_mean, mask, W, H, BAND);
    double grain_rt = cloud_compare_grain(rt, mask, W, H, BAND);
    double grain_ref = cloud_compare_grain(ref_mean, mask, W, H, BAND);
    /* The reference's own noise: its two halves differ by twice the noise of their mean in
     * quadrature (sqrt 2 each way): relative error of one against the other / 2, and the
     * grain of their half difference over the mean luminance. */
    double noise_err = 0.5 *
                       cloud_compare_block_relative_error(ref[0], ref[1], mask, W, H, ERROR_BLOCK);
    double noise_err_pixel = 0.5 * cloud_compare_relative_error(ref[0], ref[1], mask, W, H);
    double interior_mean = 0.0;
    {
        unsigned char bands[W * H];
        cloud_compare_bands(mask, W, H, BAND, bands);
        long n = 0;
        for (int i = 0; i < W * H; i++)
            if (bands[i] == 2)
                interior_mean += ref_mean[i], n++;
        interior_mean = n ? interior_mean / n : NAN;
    }
    double noise_grain = NAN;
    {
        /* std of the high-pass of the half difference, over the interior's mean luminance:
         * cloud_compare_grain divides by the image's own mean, so scale it back. */
        float shifted[W * H];
        for (int i = 0; i < W * H; i++)
            shifted[i] = half_diff[i] + (float)interior_mean;
        noise_grain = cloud_compare_grain(shifted, mask, W, H, BAND);
    }
    double outline_dev = outline_rt / outline_ref - 1.0;
    /* The reference's grain without its noise (independent, so their variances add). */
    double grain_clean = sqrt(fmax(grain_ref * grain_ref - noise_grain * noise_grain, 0.0));
    double sum_rt = 0.0, sum_ref = 0.0;
    for (int i = 0; i < W * H; i++)
        if (mask[i])
            sum_rt += rt[i], sum_ref += ref_mean[i];
    printf("  cloud pixels %d; renderer %.1f s, reference %.1f s (two renders)\n", pixels, t1 - t0,
           t2 - t1);
    printf("  mean luminance over the cloud: renderer / reference %.3f\n", sum_rt / sum_ref);
    printf("  mean relative luminance error over %dx%d blocks %.3f (target <= %.2f), per pixel "
           "%.3f; the reference's own noise %.3f per block, %.3f per pixel\n",
           ERROR_BLOCK, ERROR_BLOCK, err, MAX_RELATIVE_ERROR, err_pixel, noise_err,
           noise_err_pixel);
    printf("  outline / interior: renderer %.3f, reference %.3f (%+.1f %%, target within "
           "%.0f %%)\n",
           outline_rt, outline_ref, 100.0 * outline_dev, 100.0 * MAX_OUTLINE_DEVIATION);
    printf("  grain: renderer %.4f, reference %.4f with its noise %.4f, %.4f without it "
           "(ratio %.2f, target <= %.1f)\n",
           grain_rt, grain_ref, noise_grain, grain_clean, grain_rt / grain_clean, MAX_GRAIN_RATIO);
    CHECK_MSG(pixels > 100, "%s: only %d cloud pixels", sc->name, pixels);
    CHECK_MSG(noise_err < MAX_RELATIVE_ERROR / 3.0, "%s: the reference's noise %.3f", sc->name,
              noise_err);
    CHECK_MSG(err <= MAX_RELATIVE_ERROR, "%s: relative error %.3f", sc->name, err);
    CHECK_MSG(fabs(outline_dev) <= MAX_OUTLINE_DEVIATION,
              "%s: outline / interior %.3f, "
              "reference %.3f",
              sc->name, outline_rt, outline_ref);
    /* A verdict on grain needs a reference whose own noise is below the grain it judges. */
    CHECK_MSG(noise_grain < grain_clean,
              "%s: the reference's noise grain %.4f is not under its "
              "grain %.4f: more samples per pixel",
              sc->name, noise_grain, grain_clean);
    CHECK_MSG(grain_rt <= MAX_GRAIN_RATIO * grain_clean, "%s: grain %.4f, reference %.4f", sc->name,
              grain_rt, grain_clean);
}

/* A deck seen from 200 m without rain (the shafts are the renderer's own), 60 degrees wide. */
static void deck_view(struct proto_world_state *s, double yaw_deg, double pitch_deg,
                      double sun_azimuth_deg, double sun_elevation_deg)
{
    s->clouds.precipitation = 0.0;
    s->camera.altitude_km = 0.2;
    s->camera.yaw_deg = yaw_deg;
    s->camera.pitch_deg = pitch_deg;
    s->camera.fov_deg = 60.0;
    s->sun.azimuth_deg = sun_azimuth_deg;
    s->sun.elevation_deg = sun_elevation_deg;
}

/* A deck's mean luminance and colour over every pixel above the horizon, renderer against
 * reference (both seeds); returns false when it could not be measured. */
struct deck_figures {
    double luminance_ratio, reference_noise, tint, reference_tint;
};

static bool measure_deck(const char *name, const struct proto_world_state *s, uint32_t spp,
                         struct deck_figures *out)
{
    render(s, 0, 0, rt_rgba, rt);
    for (int k = 0; k < 2; k++)
        if (!load_cached(name, spp, k, ref_rgba[k], ref[k])) {
            render(s, spp, (uint32_t)k + 1, ref_rgba[k], ref[k]);
            save_cached(name, spp, k, ref_rgba[k]);
        }
    for (int i = 0; i < W * H; i++)
        clear[i] = 0.0f; /* every pixel above the horizon is cloud */
    for (int i = 0; i < W * H * 4; i++)
        ref_rgba[0][i] = 0.5f * (ref_rgba[0][i] + ref_rgba[1][i]);
    save_pair(name, rt_rgba, ref_rgba[0]);
    int pixels = cloud_mask(s, ref[0], clear, mask);
    double sum[3][3] = { { 0 } }; /* renderer, reference (both seeds), seed 2: r, g, b */
    for (int i = 0; i < W * H; i++)
        if (mask[i])
            for (int c = 0; c < 3; c++) {
                sum[0][c] += rt_rgba[4 * i + c];
                sum[1][c] += ref_rgba[0][4 * i + c];
                sum[2][c] += ref_rgba[1][4 * i + c];
            }
    double lum[3], tint[3];
    for (int k = 0; k < 3; k++) {
        lum[k] = 0.2126 * sum[k][0] + 0.7152 * sum[k][1] + 0.0722 * sum[k][2];
        tint[k] = sum[k][2] / sum[k][0];
    }
    CHECK_MSG(pixels > W * H / 2, "%s: only %d sky pixels", name, pixels);
    /* Seed 2 against the mean of both: half the two seeds' difference. */
    *out = (struct deck_figures){ lum[0] / lum[1], fabs(lum[2] / lum[1] - 1.0), tint[0], tint[1] };
    printf("  sky pixels %d; mean luminance renderer / reference %.3f (the reference's own noise "
           "%.3f); blue / red: renderer %.3f, reference %.3f (%+.1f %%)\n",
           pixels, out->luminance_ratio, out->reference_noise, tint[0], tint[1],
           100.0 * (tint[0] / tint[1] - 1.0));
    return pixels > W * H / 2;
}

/* An overcast deck seen from below: its base is lit by the sun's and the sky's light diffused
 * down through it (cloud_light.glsl's octaves and sky_diffuse_source) and by the ground, which
 * the deck itself lights (the Eddington transmission of its column, cloud_march.glsl's
 * ground_transmission). Over the sky (every pixel above the horizon is deck):
 *   - mean luminance renderer / reference within DECK_BASE_RATIO (measured 0.837; 0.820
 *     with the octaves' flux along the sun's ray, 0.751 without the sky's diffused light).
 *     The lower end is the renderer's known shortfall, not the 15 % the clouds are held to:
 *     the whole reference (since the shells' descending exit, cloud_shell.glsl) showed the
 *     base's sunlight diffused through the deck at about 0.8 of the path tracer's
 *     (docs/ACCURACY.md, "Under a deck"), which the octaves, fitted to uniform slabs, do not
 *     yet carry; a regression darker than it, or any excess over 15 %, fails;
 *   - its colour, blue over red, within MAX_DECK_TINT (measured +7.4 %; -6.4 % without the
 *     sky's light, whose part of the reference's base, 8 % of its luminance at blue over red
 *     4.9, the renderer's term matches: 393 against 412 cd/m2, 5.1). */
static const double DECK_BASE_RATIO[2] = { 0.8, 1.0 + MAX_RELATIVE_ERROR };
#define MAX_DECK_TINT 0.12
#define DECK_SPP 8
static void compare_deck_base(void)
{
    struct proto_world_state s;
    if (!weather_state("overcast", &s))
        return;
    s.clouds.high.coverage = 0.0;
    deck_view(&s, 20.0, 25.0, 150.0, 40.0);
    uint32_t spp = ref_spp_override ? ref_spp_override : DECK_SPP;
    printf("deck_base: overcast from below, sun at elevation 40 deg; %dx%d, reference %u spp x 2\n",
           W, H, spp);
    struct deck_figures f;
    if (!measure_deck("deck_base", &s, spp, &f))
        return;
    CHECK_MSG(f.reference_noise < MAX_RELATIVE_ERROR / 3.0, "deck_base: the reference's noise %.3f",
              f.reference_noise);
    CHECK_MSG(f.luminance_ratio >= DECK_BASE_RATIO[0] && f.luminance_ratio <= DECK_BASE_RATIO[1],
              "deck_base: mean luminance renderer / reference %.3f", f.luminance_ratio);
    CHECK_MSG(fabs(f.tint / f.reference_tint - 1.0) <= MAX_DECK_TINT,
              "deck_base: blue / red %.3f, reference %.3f", f.tint, f.reference_tint);
}

/* The middle layer's altostratus (warm_front's, the low and high layers off) from the ground
 * toward a sun 4 degrees up: the sun's ray runs inside the sheet for ten times its depth below
 * the top and more, far past the light march's reach, and the renderer takes the rest of it at
 * the march's mean extinction (cloud_light.glsl, sun_depths). Without that rest the sheet was
 * lit as if it ended at the march: 4.07 times the reference's luminance. Judged: the mean
 * luminance within MAX_MID_DECK_RATIO either way (measured 1.178; 1.267 with the octaves'
 * flux along the sun's ray, toward this view, where deep in a sheet it runs down through it,
 * cloud_light.glsl's flux_toward_light). What is left (blue over red 11.5 % under the
 * reference's, 16 % before) is printed, not judged. */
#define MAX_MID_DECK_RATIO 1.4
#define MID_DECK_SPP 4
static void compare_mid_deck_low_sun(void)
{
    struct proto_world_state s;
    if (!weather_state("warm_front", &s))
        return;
    s.clouds.low.coverage = 0.0;
    s.clouds.high.coverage = 0.0;
    deck_view(&s, 270.0, 12.0, 270.0, 4.0);
    uint32_t spp = ref_spp_override ? ref_spp_override : MID_DECK_SPP;
    printf("mid_deck_low_sun: altostratus from below toward a sun 4 deg up; %dx%d, reference %u "
           "spp x 2\n",
           W, H, spp);
    struct deck_figures f;
    if (!measure_deck("mid_deck_low_sun", &s, spp, &f))
        return;
    CHECK_MSG(f.reference_noise < 0.05, "mid_deck_low_sun: the reference's noise %.3f",
              f.reference_noise);
    CHECK_MSG(f.luminance_ratio <= MAX_MID_DECK_RATIO &&
                  f.luminance_ratio >= 1.0 / MAX_MID_DECK_RATIO,
              "mid_deck_low_sun: mean luminance renderer / reference %.3f", f.luminance_ratio);
}

static void run(void)
{
    const char *only = getenv("SKYD_COMPARE_CASE");
    const char *spp = getenv("SKYD_REFERENCE_SPP");
    if (spp && atoi(spp) > 0)
        ref_spp_override = (uint32_t)atoi(spp);
    for (size_t k = 0; k < sizeof scenes / sizeof scenes[0]; k++)
        if (!only || strcmp(only, scenes[k].name) == 0)
            compare_scene(&scenes[k]);
    if (!only || strcmp(only, "deck_base") == 0)
        compare_deck_base();
    if (!only || strcmp(only, "mid_deck_low_sun") == 0)
        compare_mid_deck_low_sun();
    CHECK(sky_renderer_set_weather_map(renderer, NULL, 0, 0) == 0);
}

int main(int argc, char **argv)
{
    if (argc > 1)
        out_dir = argv[1];
    if (argc > 2)
        config_dir = argv[2];
    return test_run_with_renderer(&renderer, run);
}
