/* Render tests on lavapipe with validation: physical invariants over whole frames (no NaN or
 * Inf, night darker than day, sunset redder than noon, Mars' blue sunset halo, the planet and
 * its limb from orbit, sun photometry) and the review images noon/sunset/dusk/orbit/mars.png
 * written to the directory given as argv[1]. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "field_errors.h"
#include "presets.h"
#include "png_write.h"
#include "test_support.h"

#define W 320
#define H 180

struct frame {
    float rgba[W * H * 4];
};

static const char *out_dir = ".";

static struct sky_renderer *renderer;

static void state_for(struct proto_world_state *s, const char *preset, double sun_elevation)
{
    proto_world_state_defaults(s);
    if (preset) {
        struct proto_field_errors errors;
        char msg[512];
        bool ok = world_preset_apply(SKYD_SOURCE_DIR "/config", "atmosphere", preset, s, &errors,
                                     msg, sizeof msg);
        if (!ok)
            printf("preset %s: %s\n", preset, msg);
        CHECK(ok);
    }
    s->sun.elevation_deg = sun_elevation;
}

/* Renders linear luminance (cd/m2) for the state. */
static void render_linear(const struct proto_world_state *s, struct frame *f)
{
    struct sky_render_atmosphere atm;
    struct sky_render_view view;
    world_to_render_atmosphere(s, &atm);
    world_to_render_view(s, W, H, SKY_RENDER_OUTPUT_LINEAR, &view);
    CHECK(sky_renderer_render(renderer, &atm, &view, f->rgba, sizeof f->rgba, NULL) == 0);
}

static void save_png(const struct proto_world_state *s, const char *name)
{
    static uint8_t pixels[W * H * 4];
    struct sky_render_atmosphere atm;
    struct sky_render_view view;
    world_to_render_atmosphere(s, &atm);
    world_to_render_view(s, W, H, SKY_RENDER_OUTPUT_SRGB8, &view);
    CHECK(sky_renderer_render(renderer, &atm, &view, pixels, sizeof pixels, NULL) == 0);
    char path[1024], err[256];
    snprintf(path, sizeof path, "%s/%s.png", out_dir, name);
    CHECK(png_write_rgba8_file(path, pixels, W, H, err, sizeof err) == 0);
    printf("wrote %s\n", path);
}

static int count_non_finite(const struct frame *f)
{
    int bad = 0;
    for (int i = 0; i < W * H; i++)
        for (int c = 0; c < 3; c++)
            if (!isfinite(f->rgba[i * 4 + c]) || f->rgba[i * 4 + c] < 0.0f)
                bad++;
    return bad;
}

/* Mean of channel values over a pixel rectangle. */
static void region_mean(const struct frame *f, int x0, int y0, int x1, int y1, double out[3])
{
    double sum[3] = { 0, 0, 0 };
    int n = 0;
    for (int y = y0; y < y1; y++)
        for (int x = x0; x < x1; x++, n++)
            for (int c = 0; c < 3; c++)
                sum[c] += f->rgba[(y * W + x) * 4 + c];
    for (int c = 0; c < 3; c++)
        out[c] = sum[c] / (n ? n : 1);
}

static double luminance(const double rgb[3])
{
    return 0.2126 * rgb[0] + 0.7152 * rgb[1] + 0.0722 * rgb[2];
}

static void test_no_nan_anywhere(struct frame *f)
{
    const char *presets[] = { NULL, "mars" };
    const double elevations[] = { -20, -6, -2, 0, 0.5, 5, 30, 90 };
    const double altitudes[] = { 0, 0.2, 12, 99, 400, 36000 };
    const double pitches[] = { -90, -20, 0, 10, 90 };
    for (int p = 0; p < 2; p++)
        for (size_t e = 0; e < sizeof elevations / sizeof *elevations; e++)
            for (size_t a = 0; a < sizeof altitudes / sizeof *altitudes; a++) {
                struct proto_world_state s;
                state_for(&s, presets[p], elevations[e]);
                s.camera.altitude_km = altitudes[a];
                s.camera.pitch_deg = pitches[(e + a) % 5];
                s.camera.fov_deg = altitudes[a] > 1000 ? 20 : 70;
                render_linear(&s, f);
                int bad = count_non_finite(f);
                if (bad)
                    printf("non-finite or negative values: %d (preset %s, sun %g, alt %g)\n", bad,
                           presets[p] ? presets[p] : "earth", elevations[e], altitudes[a]);
                CHECK(bad == 0);
            }
}

static void test_night_darker_than_day(struct frame *f)
{
    struct proto_world_state s;
    double day[3], night[3], twilight[3];
    state_for(&s, NULL, 45);
    render_linear(&s, f);
    region_mean(f, 0, 0, W, H, day);
    state_for(&s, NULL, -4);
    render_linear(&s, f);
    region_mean(f, 0, 0, W, H, twilight);
    state_for(&s, NULL, -18);
    render_linear(&s, f);
    region_mean(f, 0, 0, W, H, night);
    printf("mean luminance: day %.4g, sun -4 deg %.4g, sun -18 deg %.4g cd/m2\n", luminance(day),
           luminance(twilight), luminance(night));
    CHECK_LE(luminance(twilight) * 100.0, luminance(day));
    CHECK_LE(luminance(night) * 100.0, luminance(twilight));
}

/* Horizon sky facing the sun: R/B at sunset above R/B at noon. */
static void test_sunset_redder_than_noon(struct frame *f)
{
    struct proto_world_state s;
    double noon[3], sunset[3];
    state_for(&s, NULL, 60);
    s.camera.pitch_deg = 5;
    s.camera.yaw_deg = s.sun.azimuth_deg;
    render_linear(&s, f);
    region_mean(f, 0, H / 3, W, H / 2, noon);
    state_for(&s, NULL, 2);
    s.camera.pitch_deg = 5;
    s.camera.yaw_deg = s.sun.azimuth_deg;
    render_linear(&s, f);
    region_mean(f, 0, H / 3, W, H / 2, sunset);
    printf("horizon R/B: noon %.3f, sunset %.3f\n", noon[0] / noon[2], sunset[0] / sunset[2]);
    CHECK_LE(noon[0] / noon[2] * 2.0, sunset[0] / sunset[2]);
}

/* Mars: butterscotch sky away from the sun, blue halo around the setting sun. */
static void test_mars_blue_sunset_halo(struct frame *f)
{
    struct proto_world_state s;
    double halo[3], away[3];
    state_for(&s, "mars", 3);
    s.camera.yaw_deg = s.sun.azimuth_deg;
    s.camera.pitch_deg = 3;
    s.camera.fov_deg = 40;
    render_linear(&s, f);
    /* The sun sits at the image centre; sample a ring just outside its disk. */
    region_mean(f, W / 2 - 12, H / 2 - 12, W / 2 + 12, H / 2 - 4, halo);
    s.camera.yaw_deg = s.sun.azimuth_deg + 180;
    s.camera.pitch_deg = 30;
    render_linear(&s, f);
    region_mean(f, 0, 0, W, H / 2, away);
    printf("mars: halo B/R %.3f, sky away from the sun B/R %.3f\n", halo[2] / halo[0],
           away[2] / away[0]);
    CHECK_LE(1.0, halo[2] / halo[0]);
    CHECK_LE(away[2] / away[0], 0.9);
}

/* From 400 km looking at the horizon: black space above, a bright limb, the lit planet. */
static void test_orbit_shows_planet_and_limb(struct frame *f)
{
    struct proto_world_state s;
    state_for(&s, NULL, 30);
    s.camera.altitude_km = 400;
    s.camera.pitch_deg = -20;
    s.camera.fov_deg = 40;
    s.camera.yaw_deg = s.sun.azimuth_deg + 90;
    render_linear(&s, f);
    double top[3], bottom[3];
    region_mean(f, 0, 0, W, 4, top);
    region_mean(f, 0, H - 4, W, H, bottom);
    /* Find the brightest row: the limb, where the line of sight grazes the atmosphere. */
    int limb_row = 0;
    double limb = 0;
    for (int y = 0; y < H; y++) {
        double row[3];
        region_mean(f, 0, y, W, y + 1, row);
        if (luminance(row) > limb) {
            limb = luminance(row);
            limb_row = y;
        }
    }
    printf("orbit: space %.3g, limb %.3g at row %d, planet %.3g cd/m2\n", luminance(top), limb,
           limb_row, luminance(bottom));
    CHECK_LE(luminance(top), 1e-3);
    CHECK_LE(1000.0, luminance(bottom));
    CHECK(limb_row > 4 && limb_row < H - 4);
}

/* Other LUT sizes change resolution, not the physics: the mean luminance stays within 3%. */
static void test_lut_sizes_are_honoured(struct frame *f)
{
    struct proto_world_state s;
    double base[3], small[3];
    state_for(&s, NULL, 20);
    s.camera.yaw_deg = s.sun.azimuth_deg + 150; /* sky and ground, no sun disk */
    render_linear(&s, f);
    region_mean(f, 0, 0, W, H, base);
    struct sky_render_lut_sizes sizes = {
        .transmittance = { 128, 32 },
        .multiscattering = { 16, 16 },
        .skyview = { 96, 54 },
        .aerial_perspective = { 16, 16, 16 },
    };
    CHECK(sky_renderer_set_lut_sizes(renderer, &sizes) == 0);
    render_linear(&s, f);
    region_mean(f, 0, 0, W, H, small);
    uint32_t size[3] = { 0, 0, 0 };
    float *skyview = sky_renderer_read_lut(renderer, "skyview", size);
    CHECK(skyview && size[0] == 96 && size[1] == 54);
    free(skyview);
    float *ap = sky_renderer_read_lut(renderer, "ap_inscatter", size);
    CHECK(ap && size[0] == 14 && size[1] == 14 && size[2] == 14); /* a power of two, less two */
    free(ap);
    CHECK(sky_renderer_set_lut_sizes(renderer, NULL) == 0); /* back to the defaults */
    printf("mean luminance with default LUTs %.5g, with half-size LUTs %.5g cd/m2\n",
           luminance(base), luminance(small));
    CHECK_NEAR(luminance(small) / luminance(base), 1.0, 0.03);
}

/* Manual exposure at the EV100 the meter chose gives back the auto-exposed image. */
static void test_manual_exposure_matches_metered(void)
{
    static uint8_t auto_px[W * H * 4], manual_px[W * H * 4];
    struct proto_world_state s;
    state_for(&s, NULL, 30);
    struct sky_render_atmosphere atm;
    struct sky_render_view view;
    struct sky_render_stats stats;
    world_to_render_atmosphere(&s, &atm);
    world_to_render_view(&s, W, H, SKY_RENDER_OUTPUT_SRGB8, &view);
    CHECK(sky_renderer_render(renderer, &atm, &view, auto_px, sizeof auto_px, &stats) == 0);
    CHECK(isfinite(stats.metered_ev100));
    view.auto_exposure = false;
    view.ev100 = stats.metered_ev100;
    CHECK(sky_renderer_render(renderer, &atm, &view, manual_px, sizeof manual_px, NULL) == 0);
    int worst = 0;
    for (size_t i = 0; i < sizeof auto_px; i++) {
        int d = abs((int)auto_px[i] - (int)manual_px[i]);
        worst = d > worst ? d : worst;
    }
    printf("metered EV100 %.2f; manual exposure at it differs by at most %d/255\n",
           stats.metered_ev100, worst);
    CHECK(worst <= 1);
    /* One stop more exposure (EV100 one lower) brightens the image. */
    view.ev100 = stats.metered_ev100 - 1.0;
    CHECK(sky_renderer_render(renderer, &atm, &view, manual_px, sizeof manual_px, NULL) == 0);
    long sum_auto = 0, sum_brighter = 0;
    for (size_t i = 0; i < sizeof auto_px; i++) {
        sum_auto += auto_px[i];
        sum_brighter += manual_px[i];
    }
    CHECK(sum_brighter > sum_auto);
}

static void write_review_images(void)
{
    struct proto_world_state s;
    state_for(&s, NULL, 60);
    save_png(&s, "noon");
    state_for(&s, NULL, 1.5);
    s.camera.yaw_deg = s.sun.azimuth_deg;
    s.camera.pitch_deg = 8;
    save_png(&s, "sunset");
    state_for(&s, NULL, -4);
    s.camera.yaw_deg = s.sun.azimuth_deg;
    save_png(&s, "dusk");
    state_for(&s, NULL, 20);
    s.camera.altitude_km = 400;
    s.camera.pitch_deg = -18;
    s.camera.yaw_deg = s.sun.azimuth_deg + 90;
    save_png(&s, "orbit");
    state_for(&s, "mars", 4);
    s.camera.yaw_deg = s.sun.azimuth_deg;
    s.camera.pitch_deg = 8;
    save_png(&s, "mars");
}

/* The tests, in order, with the renderer. */
static void run_tests(void)
{
    struct frame *f = malloc(sizeof *f);
    test_no_nan_anywhere(f);
    test_night_darker_than_day(f);
    test_sunset_redder_than_noon(f);
    test_mars_blue_sunset_halo(f);
    test_orbit_shows_planet_and_limb(f);
    test_lut_sizes_are_honoured(f);
    test_manual_exposure_matches_metered();
    write_review_images();
    free(f);
}

int main(int argc, char **argv)
{
    if (argc > 1)
        out_dir = argv[1];
    return test_run_with_renderer(&renderer, run_tests);
}
