/* Night sky tests on lavapipe with validation: the moon's disc (photometry, phase, bright limb,
 * hidden below the horizon), star positions against PyEphem for known stars, times and sites
 * (so also the rotation with sidereal time), star photometry and daylight, the moonlit sky,
 * night against day, no NaN/Inf; review images night_*.png in the directory of argv[1]. */
#include "test_night.h"

#include "night_shared.h"
#include "night_sky.h"
#include "night_stars.h"
#include "sky_photometry.h"
#include "png_write.h"

static const char *out_dir = ".";
static struct sky_renderer *renderer;
float night_test_frame[W * H * 4];

void night_test_state(struct proto_world_state *s)
{
    proto_world_state_defaults(s);
    s->sun.azimuth_deg = 0;
    s->sun.elevation_deg = -30;
    s->moon.elevation_deg = -40; /* down unless a test raises it */
    s->camera.fov_deg = 60;
}

/* Renders linear luminance with the state's night; `tweak` may edit the night first. */
void night_test_render(const struct proto_world_state *s, const struct sky_render_night *override)
{
    struct sky_render_atmosphere atm;
    struct sky_render_view view;
    struct sky_render_night night;
    world_to_render_atmosphere(s, &atm);
    world_to_render_view(s, W, H, SKY_RENDER_OUTPUT_LINEAR, &view);
    world_to_render_night(s, &night);
    sky_renderer_set_night(renderer, override ? override : &night);
    CHECK(sky_renderer_render(renderer, &atm, &view, night_test_frame, sizeof night_test_frame,
                              NULL) == 0);
}

/* Renders the state's exposed sRGB8 image of w x h into pixels; stats may be NULL. */
static bool render_srgb8(const struct proto_world_state *s, unsigned w, unsigned h, uint8_t *pixels,
                         struct sky_render_stats *stats)
{
    struct sky_render_atmosphere atm;
    struct sky_render_view view;
    struct sky_render_night night;
    world_to_render_atmosphere(s, &atm);
    world_to_render_view(s, w, h, SKY_RENDER_OUTPUT_SRGB8, &view);
    world_to_render_night(s, &night);
    sky_renderer_set_night(renderer, &night);
    return pixels &&
           sky_renderer_render(renderer, &atm, &view, pixels, (size_t)w * h * 4, stats) == 0;
}

static void save_png(const struct proto_world_state *s, const char *name, unsigned w, unsigned h)
{
    uint8_t *pixels = malloc((size_t)w * h * 4);
    CHECK(render_srgb8(s, w, h, pixels, NULL));
    char path[1024], err[256];
    snprintf(path, sizeof path, "%s/%s.png", out_dir, name);
    CHECK(pixels && png_write_rgba8_file(path, pixels, w, h, err, sizeof err) == 0);
    printf("wrote %s\n", path);
    free(pixels);
}

int night_test_count_bad(void)
{
    int bad = 0;
    for (int i = 0; i < W * H * 4; i++)
        if (!isfinite(night_test_frame[i]) || night_test_frame[i] < 0.0f) {
            if (bad++ < 3)
                printf("bad value %g at pixel (%d, %d)\n", night_test_frame[i], (i / 4) % W,
                       (i / 4) / W);
        }
    return bad;
}

/* Transmittance (luminance-weighted) from the ground toward elevation el. */
double night_test_transmittance_at(const struct proto_world_state *s, double el_deg)
{
    struct sky_render_atmosphere atm;
    world_to_render_atmosphere(s, &atm);
    double alt = s->camera.altitude_km, mu = sin(el_deg * DEG), t[1][3];
    CHECK(sky_renderer_probe_transmittance(renderer, &atm, &alt, &mu, 1, t) == 0);
    return sky_rgb_to_luminance(t[0]);
}

/* ---- night lighting ---- */

static double mean_sky(void)
{
    double sum = 0;
    for (int y = 0; y < H / 2; y++)
        for (int x = 0; x < W; x++)
            sum += lum_at(x, y);
    return sum / (W * H / 2);
}

static void test_night_lighting(void)
{
    struct proto_world_state s;
    night_test_state(&s);
    s.camera.pitch_deg = 30;
    s.camera.yaw_deg = 90;
    night_test_render(&s, NULL);
    CHECK(night_test_count_bad() == 0);
    double moonless = mean_sky(), darkest = 1e30;
    for (int i = 0; i < W * H; i++)
        darkest = fmin(darkest, lum_at(i % W, i / W));
    /* Full moon high in the south (the sun opposite, below the horizon). */
    s.moon.azimuth_deg = 180, s.moon.elevation_deg = 40;
    s.sun.azimuth_deg = 0, s.sun.elevation_deg = -40;
    night_test_render(&s, NULL);
    CHECK(night_test_count_bad() == 0);
    double moonlit = mean_sky();
    double centre[3];
    float *p = &night_test_frame[((H / 4) * W + W / 2) * 4];
    centre[0] = p[0], centre[1] = p[1], centre[2] = p[2];
    /* Day. */
    night_test_state(&s);
    s.camera.pitch_deg = 30;
    s.camera.yaw_deg = 90;
    s.sun.azimuth_deg = 200, s.sun.elevation_deg = 45;
    night_test_render(&s, NULL);
    double day = mean_sky();
    printf("mean sky luminance: moonless %.3g, full moon %.3g, day %.3g cd/m2; darkest moonless "
           "pixel %.3g cd/m2; moonlit sky rgb %.3g %.3g %.3g\n",
           moonless, moonlit, day, darkest, centre[0], centre[1], centre[2]);
    CHECK(moonlit > 5.0 * moonless);
    CHECK(centre[2] > centre[0]); /* the moonlit sky is blue (Rayleigh) */
    CHECK(day > 1e6 * moonless);  /* night darker than day by orders */
    CHECK(day > 1e4 * moonlit);
    CHECK(darkest > 1e-5); /* never black: airglow and starlight */
    CHECK(moonless > 0.5 * s.night.airglow_luminance_cd_m2);

    /* Probes see the moonlit sky and, with the bodies, the disc. */
    struct sky_render_atmosphere atm;
    struct sky_render_view view;
    struct sky_render_night night;
    night_test_state(&s);
    s.moon.azimuth_deg = 180, s.moon.elevation_deg = 40;
    s.sun.azimuth_deg = 0, s.sun.elevation_deg = -40;
    world_to_render_atmosphere(&s, &atm);
    world_to_render_view(&s, 1, 1, SKY_RENDER_OUTPUT_LINEAR, &view);
    world_to_render_night(&s, &night);
    sky_renderer_set_night(renderer, &night);
    double dirs[2][3], out[2][3], sky[2][3];
    local_dir(180, 40, dirs[0]);
    local_dir(0, 90, dirs[1]);
    CHECK(sky_renderer_probe_luminance(renderer, &atm, &view, (const double(*)[3])dirs, 2, true,
                                       out) == 0);
    CHECK(sky_renderer_probe_luminance(renderer, &atm, &view, (const double(*)[3])dirs, 2, false,
                                       sky) == 0);
    printf("probe: moon direction %.4g cd/m2 (sky only %.4g), zenith %.4g cd/m2\n",
           sky_rgb_to_luminance(out[0]), sky_rgb_to_luminance(sky[0]),
           sky_rgb_to_luminance(out[1]));
    CHECK(sky_rgb_to_luminance(out[0]) > 1000.0);
    CHECK(sky_rgb_to_luminance(sky[1]) > 5.0 * s.night.airglow_luminance_cd_m2);
}

/* Mean of the upper half of an sRGB8 frame with auto exposure, and the metered EV100. */
static double exposed_mean(const struct proto_world_state *s, double *ev100)
{
    static uint8_t pixels[W * H * 4];
    struct sky_render_stats stats;
    CHECK(render_srgb8(s, W, H, pixels, &stats));
    *ev100 = stats.metered_ev100;
    double sum = 0;
    for (int i = 0; i < W * H / 2; i++)
        sum += (pixels[4 * i] + pixels[4 * i + 1] + pixels[4 * i + 2]) / 3.0;
    return sum / (W * H / 2);
}

/* Krawczyk, Myszkowski & Seidel 2005, eq. 11: the key value for a log-average luminance. */
static double key_value(double l_avg)
{
    return 1.03 - 2.0 / (2.0 + log10(l_avg + 1.0));
}

/* exposure.night_adaptation: daylight as metered; a night darker than a camera would show it,
 * by the EV the key value gives for the metered luminance. */
static void test_night_adaptation(void)
{
    struct proto_world_state s;
    const double sun_elevations[3] = { 45, -30, -8 }; /* day, night, nautical twilight */
    double adapted[3], camera[3];
    for (int k = 0; k < 3; k++) {
        night_test_state(&s);
        s.camera.pitch_deg = 30;
        s.camera.yaw_deg = 90;
        s.sun.azimuth_deg = 200, s.sun.elevation_deg = sun_elevations[k];
        double ev_on, ev_off;
        s.exposure.night_adaptation = PROTO_SWITCH_ON;
        adapted[k] = exposed_mean(&s, &ev_on);
        s.exposure.night_adaptation = PROTO_SWITCH_OFF;
        camera[k] = exposed_mean(&s, &ev_off);
        /* EV100 = log2(L * 100 / 12.5) when metered like a camera. */
        double l_avg = exp2(ev_off) * 12.5 / 100.0;
        double expected = fmax(0.0, -log2(key_value(l_avg) / key_value(1000.0)));
        printf("night adaptation, sun at %g deg: metered %.3g cd/m2, EV100 %.2f -> %.2f "
               "(expected +%.2f), mean sRGB %.1f -> %.1f\n",
               sun_elevations[k], l_avg, ev_off, ev_on, expected, camera[k], adapted[k]);
        CHECK_NEAR(ev_on - ev_off, expected, 0.02);
    }
    CHECK_NEAR(adapted[0], camera[0], 2.0); /* daylight: as metered */
    CHECK(camera[1] > 40.0);                /* a camera lifts the night to mid grey ... */
    CHECK(adapted[1] < 0.35 * camera[1]);   /* ... a dark-adapted eye does not */
    CHECK(adapted[1] < adapted[2] && adapted[2] < adapted[0]); /* night < twilight < day */
}

static void test_no_nan(void)
{
    const double altitudes[] = { 0, 12, 400 };
    const double moon_el[] = { -5, 2, 60 };
    const double pitch[] = { -30, 5, 60 };
    for (int a = 0; a < 3; a++)
        for (int m = 0; m < 3; m++) {
            struct proto_world_state s;
            night_test_state(&s);
            s.camera.altitude_km = altitudes[a];
            s.moon.elevation_deg = moon_el[m];
            s.moon.azimuth_deg = 120;
            s.camera.yaw_deg = 120;
            s.camera.pitch_deg = pitch[(a + m) % 3];
            s.sun.elevation_deg = m == 2 ? 10 : -15;
            night_test_render(&s, NULL);
            int bad = night_test_count_bad();
            if (bad)
                printf("non-finite: %d (alt %g, moon %g)\n", bad, altitudes[a], moon_el[m]);
            CHECK(bad == 0);
        }
}

static void write_review_images(void)
{
    struct proto_world_state s;
    night_test_state(&s);
    s.clock.utc_unix_s = 1768514400; /* 2026-01-15 22:00 UTC, Greenwich: Orion and Sirius */
    s.location.latitude_deg = 51.4769;
    s.location.longitude_deg = 0;
    s.sun.azimuth_deg = 0, s.sun.elevation_deg = -40;
    s.moon.azimuth_deg = 215, s.moon.elevation_deg = 28;
    s.camera.yaw_deg = 185, s.camera.pitch_deg = 18, s.camera.fov_deg = 75;
    save_png(&s, "night_moon_stars", 640, 360);
    s.moon.elevation_deg = -30;
    save_png(&s, "night_moonless", 640, 360);
    night_test_moon_scene(&s, 250, -8);
    s.camera.fov_deg = 1.0;
    save_png(&s, "night_crescent", 320, 180);
    night_test_moon_scene(&s, 310, -8);
    s.camera.fov_deg = 1.0;
    save_png(&s, "night_gibbous", 320, 180);
}

/* The tests, in order, with the renderer. */
static void run_tests(void)
{
    test_star_positions();
    test_star_photometry();
    test_moon_phases();
    test_full_moon_luminance();
    test_moon_hidden_below_horizon();
    test_night_lighting();
    test_night_adaptation();
    test_no_nan();
    write_review_images();
}

int main(int argc, char **argv)
{
    if (argc > 1)
        out_dir = argv[1];
    return test_run_with_renderer(&renderer, run_tests);
}
