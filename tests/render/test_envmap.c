/* Equirectangular environment maps on lavapipe with validation: every pixel looks where the
 * documented mapping says (against the renderer's own per-direction probe), the seam is
 * continuous, the sun's disk is whole wherever it falls (centre, seam, around the zenith),
 * auto exposure weighs pixels by their solid angle, and clouds render without NaN. Writes
 * envmap.png and envmap_clouds.png to the directory given as argv[1]. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "png_write.h"
#include "test_support.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif
#define DEG (M_PI / 180.0)

static struct sky_renderer *renderer;
static const char *out_dir = ".";

static void clear_state(struct proto_world_state *s, double sun_azimuth, double sun_elevation)
{
    proto_world_state_defaults(s);
    s->clouds.low.coverage = 0.0;
    s->clouds.high.coverage = 0.0;
    s->camera.yaw_deg = 40.0;
    s->camera.pitch_deg = 25.0; /* a panorama ignores it */
    s->sun.azimuth_deg = sun_azimuth;
    s->sun.elevation_deg = sun_elevation;
}

static void panorama_view(const struct proto_world_state *s, uint32_t width,
                          enum sky_render_output_kind output, struct sky_render_view *view)
{
    world_to_render_view(s, width, width / 2, output, view);
    view->projection = SKY_RENDER_PROJECTION_EQUIRECTANGULAR;
}

/* The documented mapping, independently of the renderer's: azimuth yaw + (u - 0.5) 360,
 * elevation 90 - 180 v at the pixel's centre. */
static void pixel_direction(double yaw_deg, uint32_t width, uint32_t height, uint32_t x, uint32_t y,
                            double out[3])
{
    double azimuth = yaw_deg + ((x + 0.5) / width - 0.5) * 360.0;
    double elevation = 90.0 - 180.0 * (y + 0.5) / height;
    sky_direction_from_angles(azimuth, elevation, out);
}

static float *render_linear(const struct proto_world_state *s, uint32_t width,
                            struct sky_render_stats *stats)
{
    struct sky_render_atmosphere atm;
    struct sky_render_view view;
    world_to_render_atmosphere(s, &atm);
    panorama_view(s, width, SKY_RENDER_OUTPUT_LINEAR, &view);
    size_t bytes = (size_t)view.width * view.height * 16;
    float *px = malloc(bytes);
    CHECK(px && sky_renderer_render(renderer, &atm, &view, px, bytes, stats) == 0);
    return px;
}

static double luma(const float *rgba)
{
    return 0.2126 * rgba[0] + 0.7152 * rgba[1] + 0.0722 * rgba[2];
}

/* Pixels against the probe in the same directions: the probe shades one direction with the
 * frame's own code, so any mismatch is the mapping's. */
static void test_pixels_look_where_documented(void)
{
    enum { W = 128, H = 64, STEP_X = 8, STEP_Y = 4 };
    struct proto_world_state s;
    clear_state(&s, 100.0, 30.0);
    float *px = render_linear(&s, W, NULL);
    struct sky_render_atmosphere atm;
    struct sky_render_view view;
    world_to_render_atmosphere(&s, &atm);
    panorama_view(&s, W, SKY_RENDER_OUTPUT_LINEAR, &view);
    double dirs[(W / STEP_X) * (H / STEP_Y)][3], probe[(W / STEP_X) * (H / STEP_Y)][3];
    uint32_t where[(W / STEP_X) * (H / STEP_Y)][2];
    size_t n = 0;
    for (uint32_t y = STEP_Y / 2; y < H; y += STEP_Y)
        for (uint32_t x = 3; x < W; x += STEP_X) {
            pixel_direction(s.camera.yaw_deg, W, H, x, y, dirs[n]);
            where[n][0] = x, where[n][1] = y;
            n++;
        }
    CHECK(sky_renderer_probe_luminance(renderer, &atm, &view, (const double(*)[3])dirs, n, false,
                                       probe) == 0);
    double worst_sky = 0.0, worst_ground = 0.0;
    for (size_t i = 0; i < n; i++) {
        const float *p = px + ((size_t)where[i][1] * W + where[i][0]) * 4;
        for (int c = 0; c < 3; c++) {
            double rel = fabs(p[c] / probe[i][c] - 1.0);
            if (dirs[i][2] > 0.0)
                worst_sky = fmax(worst_sky, rel);
            else
                worst_ground = fmax(worst_ground, rel);
        }
    }
    printf("%zu pixels against the probe: worst %.3f%% in the sky, %.3f%% on the ground\n", n,
           100 * worst_sky, 100 * worst_ground);
    CHECK_LE(worst_sky, 0.01);
    CHECK_LE(worst_ground, 0.03);

    /* Across the seam (the column before the first is the last) the image changes no more
     * than between neighbours on either side. */
    double worst_ratio = 0.0;
    for (uint32_t y = 4; y < H - 4; y++) {
        const float *row = px + (size_t)y * W * 4;
        double seam = fabs(luma(row) - luma(row + (W - 1) * 4));
        double left = fabs(luma(row + (W - 1) * 4) - luma(row + (W - 2) * 4));
        double right = fabs(luma(row + 4) - luma(row));
        double scale = fmax(fmax(left, right), 1e-4 * luma(row));
        worst_ratio = fmax(worst_ratio, seam / scale);
    }
    printf("seam step / neighbouring step: at most %.2f\n", worst_ratio);
    CHECK_LE(worst_ratio, 2.0);
    free(px);
}

/* The sun disk's illuminance sum(L - L_sky) dOmega over the pixels around it, with a
 * pixel's solid angle (2 pi / W)(pi / H) cos(elevation). */
static double disk_illuminance(const struct proto_world_state *s, uint32_t width)
{
    uint32_t height = width / 2;
    float *px = render_linear(s, width, NULL);
    struct sky_render_atmosphere atm;
    struct sky_render_view view;
    world_to_render_atmosphere(s, &atm);
    panorama_view(s, width, SKY_RENDER_OUTPUT_LINEAR, &view);
    double sun[3];
    sky_direction_from_angles(s->sun.azimuth_deg, s->sun.elevation_deg, sun);
    double reach = cos(1.5 * s->sun.angular_diameter_deg * DEG);
    enum { MAX_NEAR = 32768 };
    static double dirs[MAX_NEAR][3], sky[MAX_NEAR][3];
    static uint32_t where[MAX_NEAR][2];
    size_t n = 0;
    for (uint32_t y = 0; y < height; y++)
        for (uint32_t x = 0; x < width && n < MAX_NEAR; x++) {
            pixel_direction(s->camera.yaw_deg, width, height, x, y, dirs[n]);
            if (dirs[n][0] * sun[0] + dirs[n][1] * sun[1] + dirs[n][2] * sun[2] >= reach) {
                where[n][0] = x, where[n][1] = y;
                n++;
            }
        }
    CHECK(n > 0 && n < MAX_NEAR);
    CHECK(sky_renderer_probe_luminance(renderer, &atm, &view, (const double(*)[3])dirs, n, false,
                                       sky) == 0);
    double e = 0.0;
    for (size_t i = 0; i < n; i++) {
        const float *p = px + ((size_t)where[i][1] * width + where[i][0]) * 4;
        double l_sky = 0.2126 * sky[i][0] + 0.7152 * sky[i][1] + 0.0722 * sky[i][2];
        double elevation = asin(dirs[i][2]);
        e += (luma(p) - l_sky) * (2.0 * M_PI / width) * (M_PI / height) * cos(elevation);
    }
    free(px);
    return e;
}

static void test_sun_disk_whole_anywhere(void)
{
    enum { W = 512 };
    struct proto_world_state s;
    clear_state(&s, 0.0, 30.0);
    s.sun.angular_diameter_deg = 8.0; /* about 11 pixels across */
    s.sun.azimuth_deg = s.camera.yaw_deg;
    double centre = disk_illuminance(&s, W);
    s.sun.azimuth_deg = s.camera.yaw_deg + 180.0 - 0.3; /* split by the seam */
    double seam = disk_illuminance(&s, W);
    s.sun.elevation_deg = 83.0;
    double high = disk_illuminance(&s, W);
    s.sun.elevation_deg = 89.0; /* the disk covers the zenith: whole rows */
    double zenith = disk_illuminance(&s, W);
    printf("sun disk illuminance: centre %.5g, across the seam %.5g lux (30 deg); "
           "83 deg %.5g, around the zenith %.5g lux\n",
           centre, seam, high, zenith);
    CHECK(centre > 0.0);
    CHECK_NEAR(seam / centre, 1.0, 0.03);
    CHECK_NEAR(zenith / high, 1.0, 0.03);
    /* Higher sun, less air: more light, by the transmittance ratio (about 10 %). */
    CHECK(high > centre);
}

/* Auto exposure meters the sphere by solid angle: the log-average it chose matches the
 * cos(elevation)-weighted log-average of the frame's own luminance. */
static void test_metering_weighs_solid_angle(void)
{
    enum { W = 256, H = W / 2 };
    struct proto_world_state s;
    clear_state(&s, 200.0, 12.0);
    s.exposure.night_adaptation = PROTO_SWITCH_OFF;
    s.exposure.compensation_ev = 0.0;
    struct sky_render_stats stats;
    float *px = render_linear(&s, W, &stats);
    double sum = 0.0, weight = 0.0, flat = 0.0;
    for (uint32_t y = 0; y < H; y++) {
        double w = cos((90.0 - 180.0 * (y + 0.5) / H) * DEG);
        for (uint32_t x = 0; x < W; x++) {
            double l = log2(luma(px + ((size_t)y * W + x) * 4));
            sum += w * l, weight += w, flat += l;
        }
    }
    double expected = sum / weight + log2(100.0 / 12.5); /* EV100 = log2(L S / K) */
    double unweighted = flat / (W * H) + log2(100.0 / 12.5);
    printf("metered EV100 %.3f; weighted log-average of the frame %.3f, unweighted %.3f\n",
           stats.metered_ev100, expected, unweighted);
    CHECK_NEAR(stats.metered_ev100, expected, 0.1);
    CHECK_NEAR(stats.exposure, 1.0 / (1.2 * exp2(stats.metered_ev100)), 1e-6 * stats.exposure);
    free(px);
}

static void save_srgb(const struct proto_world_state *s, uint32_t width, const char *name,
                      bool live, int frames)
{
    struct sky_render_atmosphere atm;
    struct sky_render_view view;
    world_to_render_atmosphere(s, &atm);
    panorama_view(s, width, SKY_RENDER_OUTPUT_SRGB8, &view);
    view.live = live;
    view.history_key = 7;
    size_t bytes = (size_t)view.width * view.height * 4;
    uint8_t *px = malloc(bytes);
    for (int k = 0; k < frames; k++)
        CHECK(px && sky_renderer_render(renderer, &atm, &view, px, bytes, NULL) == 0);
    char path[1024], err[256];
    snprintf(path, sizeof path, "%s/%s.png", out_dir, name);
    CHECK(px && png_write_rgba8_file(path, px, view.width, view.height, err, sizeof err) == 0);
    free(px);
}

/* Clouds in a panorama: finite everywhere, and a cloud deck changes the sky overhead. */
static void test_clouds_in_panorama(void)
{
    enum { W = 256, H = W / 2 };
    struct proto_world_state s;
    clear_state(&s, 135.0, 25.0);
    float *clear = render_linear(&s, W, NULL);
    s.clouds.low.coverage = 0.6;
    s.clouds.low.type = 0.67;
    struct sky_render_clouds clouds;
    world_to_render_clouds(&s, &clouds);
    CHECK(sky_renderer_set_clouds(renderer, &clouds) == 0);
    float *cloudy = render_linear(&s, W, NULL);
    int non_finite = 0;
    double upper_clear = 0.0, upper_cloudy = 0.0, changed = 0.0;
    for (size_t i = 0; i < (size_t)W * H; i++) {
        for (int c = 0; c < 4; c++)
            non_finite += !isfinite(cloudy[i * 4 + (size_t)c]);
        if (i < (size_t)W * H / 2) {
            double a = luma(clear + i * 4), b = luma(cloudy + i * 4);
            upper_clear += a, upper_cloudy += b;
            changed += fabs(b - a) > 0.05 * a;
        }
    }
    printf("clouds: %d non-finite values; %.0f%% of the sky changed, mean sky luminance %.4g -> "
           "%.4g cd/m2\n",
           non_finite, 100.0 * changed / (W * H / 2), upper_clear / (W * H / 2),
           upper_cloudy / (W * H / 2));
    CHECK(non_finite == 0);
    CHECK(changed > 0.2 * (W * H / 2));
    save_srgb(&s, 512, "envmap_clouds", false, 1);
    save_srgb(&s, 512, "envmap_clouds_live", true, 4); /* a stream reuses its history */
    s.clouds.low.coverage = 0.0;
    world_to_render_clouds(&s, &clouds);
    CHECK(sky_renderer_set_clouds(renderer, &clouds) == 0);
    save_srgb(&s, 512, "envmap", false, 1);
    free(clear);
    free(cloudy);
}

/* The tests, in order, with the renderer. */
static void run_tests(void)
{
    test_pixels_look_where_documented();
    test_sun_disk_whole_anywhere();
    test_metering_weighs_solid_angle();
    test_clouds_in_panorama();
}

int main(int argc, char **argv)
{
    if (argc > 1)
        out_dir = argv[1];
    return test_run_with_renderer(&renderer, run_tests);
}
