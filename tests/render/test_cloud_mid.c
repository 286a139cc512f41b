/* The middle cloud layer (clouds.mid: altostratus .. altocumulus, WMO's middle etage) on
 * lavapipe with validation: an altostratus sheet dims the sun and the ground; it lies between
 * the low and the high layers (an aircraft above it sees it below and not above, one under it
 * sees it above); altocumulus shows cells of a few hundred metres where altostratus is smooth;
 * seen from above neither repeats and both cover about their coverage; every frame is finite;
 * an empty middle layer changes nothing, whatever its other fields say.
 * Review images go to argv[1]. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "cloud_metrics.h"
#include "png_write.h"
#include "test_support.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

#define W 128
#define H 72

static const char *out_dir = ".";
static struct sky_renderer *renderer;
static float frame_a[W * H * 4], frame_b[W * H * 4];

/* A clear day with the sun at 45 degrees in the south and an empty middle layer at 3.5-4.5 km. */
static void mid_state(struct proto_world_state *s)
{
    proto_world_state_defaults(s);
    s->clouds.resolution = PROTO_CLOUD_RESOLUTION_FULL;
    s->exposure.mode = PROTO_EXPOSURE_MANUAL;
    s->exposure.ev100 = 14.5;
    s->sun.azimuth_deg = 180.0;
    s->sun.elevation_deg = 45.0;
    s->camera.yaw_deg = 180.0;
    s->clouds.mid.coverage = 0.0;
    s->clouds.mid.type = 0.0;
    s->clouds.mid.density = 0.5;
    s->clouds.mid.bottom_km = 3.5;
    s->clouds.mid.thickness_km = 1.0;
}

static void altostratus(struct proto_world_state *s)
{
    s->clouds.mid.coverage = 0.8;
    s->clouds.mid.type = 0.0;
}

static void render(const struct proto_world_state *s, uint64_t key, float *linear)
{
    CHECK(test_render_world(renderer, s, W, H, SKY_RENDER_OUTPUT_LINEAR, key, false, linear,
                            (size_t)W * H * 16) == 0);
    CHECK(test_count_bad(linear, (size_t)W * H) == 0);
}

static void save_png(const struct proto_world_state *s, uint64_t key, const char *name)
{
    static uint8_t pixels[W * H * 4];
    CHECK(test_render_world(renderer, s, W, H, SKY_RENDER_OUTPUT_SRGB8, key, false, pixels,
                            sizeof pixels) == 0);
    char path[1024], err[256];
    snprintf(path, sizeof path, "%s/cloud_mid_%s.png", out_dir, name);
    CHECK(png_write_rgba8_file(path, pixels, W, H, err, sizeof err) == 0);
    printf("wrote %s\n", path);
}

static double mean_luminance(const float *f)
{
    double sum = 0.0;
    for (int i = 0; i < W * H; i++)
        sum += test_pixel_luminance(f + 4 * i);
    return sum / (W * H);
}

static double max_luminance(const float *f)
{
    double m = 0.0;
    for (int i = 0; i < W * H; i++)
        m = fmax(m, test_pixel_luminance(f + 4 * i));
    return m;
}

/* Mean blue over mean red: a clear sky's is well above 1, a white cloud's near 1. */
static double blue_over_red(const float *f)
{
    double r = 0.0, b = 0.0;
    for (int i = 0; i < W * H; i++) {
        r += f[4 * i];
        b += f[4 * i + 2];
    }
    return b / fmax(r, 1e-30);
}

/* An altostratus sheet (coverage 0.8, optical depth of several where it is whole) hides the
 * sun's disk, which a clear sky shows at full strength, and darkens the sunlit ground. Over
 * eight sun azimuths, so that the sheet's thinner fifth (coverage 0.8) decides no result
 * alone: the sun's ray crosses the sheet 4 km from the camera, and the pattern moves 8 km
 * (its wind offset) from one azimuth to the next, so that each crossing and each patch of
 * ground falls on another part of the sheet, whose breaks come in patches kilometres wide. */
static void test_dims_sun_and_ground(void)
{
    double sun_clear = 0.0, sun_mid = 0.0, ground_clear = 0.0, ground_mid = 0.0;
    int dimmed = 0;
    for (int k = 0; k < 8; k++) {
        struct proto_world_state s;
        mid_state(&s);
        s.sun.azimuth_deg = 45.0 * k;
        s.camera.yaw_deg = s.sun.azimuth_deg;
        s.weather.offset_east_km = 7.3 * k;
        s.weather.offset_north_km = 4.1 * k;
        s.camera.altitude_km = 0.2;
        s.camera.pitch_deg = 45.0;
        s.camera.fov_deg = 10.0;
        render(&s, 100 + 4 * k, frame_a);
        altostratus(&s);
        render(&s, 101 + 4 * k, frame_b);
        double clear = max_luminance(frame_a), mid = max_luminance(frame_b);
        CHECK(clear > 1e9); /* the disk is in the frame */
        sun_clear += clear / 8.0;
        sun_mid += mid / 8.0;
        dimmed += mid < 0.01 * clear;
        if (k == 4)
            save_png(&s, 150, "toward_sun");

        mid_state(&s);
        s.sun.azimuth_deg = 45.0 * k;
        s.weather.offset_east_km = 7.3 * k;
        s.weather.offset_north_km = 4.1 * k;
        s.camera.altitude_km = 0.2;
        s.camera.pitch_deg = -60.0;
        render(&s, 102 + 4 * k, frame_a);
        altostratus(&s);
        render(&s, 103 + 4 * k, frame_b);
        ground_clear += mean_luminance(frame_a) / 8.0;
        ground_mid += mean_luminance(frame_b) / 8.0;
    }
    printf("sun: clear peak %.4g, under altostratus %.4g cd/m2 (hidden at %d of 8 azimuths)\n",
           sun_clear, sun_mid, dimmed);
    printf("ground: clear %.5g, under altostratus %.5g cd/m2\n", ground_clear, ground_mid);
    CHECK_LE(sun_mid, 0.3 * sun_clear);
    CHECK(dimmed >= 5);
    CHECK_LE(ground_mid, 0.7 * ground_clear);
    CHECK(ground_mid > 0.02 * ground_clear); /* the sky's diffuse light still comes through */
}

/* From an aircraft at 5.5 km, above the sheet, the sheet fills the view down and none of the
 * view up; from 3 km, between the low layer's tops (2.5 km) and the sheet's base, it fills the
 * view up, white where the sky was blue. */
static void test_between_layers(void)
{
    static const struct {
        const char *name;
        double altitude, pitch;
        bool sees_mid;
    } views[] = {
        { "above_up", 5.5, 60.0, false },
        { "above_down", 5.5, -60.0, true },
        { "under_up", 3.0, 60.0, true },
    };
    for (size_t v = 0; v < sizeof views / sizeof views[0]; v++) {
        struct proto_world_state s;
        mid_state(&s);
        s.clouds.low.coverage = 0.4;
        s.clouds.low.bottom_km = 1.0;
        s.clouds.low.thickness_km = 1.5;
        s.camera.altitude_km = views[v].altitude;
        s.camera.pitch_deg = views[v].pitch;
        render(&s, 200 + 2 * v, frame_a);
        altostratus(&s);
        render(&s, 201 + 2 * v, frame_b);
        double diff = test_relative_difference(frame_b, frame_a, (size_t)W * H);
        double tint_without = blue_over_red(frame_a), tint_with = blue_over_red(frame_b);
        printf("%s: mean %.5g -> %.5g cd/m2, relative difference %.3f, blue/red %.3f -> %.3f\n",
               views[v].name, mean_luminance(frame_a), mean_luminance(frame_b), diff, tint_without,
               tint_with);
        if (views[v].sees_mid) {
            CHECK(diff > 0.2);
        } else {
            CHECK(diff < 0.03);
        }
        if (strcmp(views[v].name, "under_up") == 0)
            CHECK(tint_with < tint_without - 0.2); /* grey-white overhead instead of blue */
        save_png(&s, 210 + v, views[v].name);
    }
}

/* Variation at the scale of b x b pixel blocks: the root mean square of each block's mean
 * about the mean of the B x B block around it, relative to the frame's mean. Variation on
 * scales larger than B (a sheet's thick and thin parts, its breaks) does not count. */
static double fine_variation(const float *f, int b, int big)
{
    double sum2 = 0.0, total = 0.0;
    int n = 0;
    for (int gy = 0; gy + big <= H; gy += big)
        for (int gx = 0; gx + big <= W; gx += big) {
            double blocks[64];
            int count = 0;
            double big_mean = 0.0;
            for (int by = gy; by < gy + big; by += b)
                for (int bx = gx; bx < gx + big; bx += b) {
                    double m = 0.0;
                    for (int y = by; y < by + b; y++)
                        for (int x = bx; x < bx + b; x++)
                            m += test_pixel_luminance(f + 4 * (y * W + x));
                    blocks[count++] = m / (b * b);
                    big_mean += m / (b * b);
                }
            big_mean /= count;
            for (int i = 0; i < count; i++) {
                sum2 += (blocks[i] - big_mean) * (blocks[i] - big_mean);
                n++;
            }
            total += big_mean;
        }
    double mean = total / (n / ((big / b) * (big / b)));
    return sqrt(sum2 / n) / fmax(mean, 1e-30);
}

/* Pixels between the edges of cloud and gap along the rows: with hysteresis about the frame's
 * mean luminance (cloud above 1.2 times it, gap below 0.8 times it), the pixels per crossing. */
static double pixels_per_crossing(const float *f)
{
    double mean = mean_luminance(f);
    int crossings = 0;
    for (int y = 0; y < H; y++) {
        int state = 0; /* 1 cloud, -1 gap, 0 not yet known */
        for (int x = 0; x < W; x++) {
            double l = test_pixel_luminance(f + 4 * (y * W + x));
            int now = l > 1.2 * mean ? 1 : l < 0.8 * mean ? -1 : state;
            crossings += state != 0 && now != state;
            state = now;
        }
    }
    return (double)(W * H) / fmax(crossings, 1);
}

/* Looking up from the ground at a 40-degree field, 4 km up: about 23 m a pixel. Altocumulus
 * varies between blocks of 4 pixels (90 m) within each block of 24 (550 m), and its cells
 * and gaps alternate every few hundred metres; altostratus of the same coverage is a sheet
 * with breaks kilometres apart. */
static void test_altocumulus_cells(void)
{
    struct proto_world_state s;
    mid_state(&s);
    s.camera.altitude_km = 0.2;
    s.camera.pitch_deg = 89.0;
    s.camera.fov_deg = 40.0;
    s.clouds.mid.coverage = 0.6;
    s.clouds.mid.bottom_km = 4.0;
    s.clouds.mid.thickness_km = 0.5;
    s.clouds.mid.density = 0.6;
    s.clouds.mid.type = 1.0;
    render(&s, 300, frame_a);
    s.clouds.mid.type = 0.0;
    render(&s, 301, frame_b);
    const double km_per_pixel = 2.0 * 3.8 * tan(20.0 * M_PI / 180.0) / H;
    double cells = fine_variation(frame_a, 4, 24);
    double cell_km = km_per_pixel * pixels_per_crossing(frame_a);
    double sheet_km = km_per_pixel * pixels_per_crossing(frame_b);
    printf("altocumulus: variation of 90 m blocks within 550 m %.3f, cloud/gap edges every "
           "%.3g km; altostratus: every %.3g km\n",
           cells, cell_km, sheet_km);
    CHECK(cells > 0.15);
    CHECK(cell_km > 0.1 && cell_km < 1.0);
    CHECK(sheet_km > 3.0 * cell_km);
    s.clouds.mid.type = 1.0;
    save_png(&s, 302, "altocumulus");
}

/* Straight down from 14 km over 60 degrees, 160 x 160 pixels: about 70 m a pixel at the
 * layer (4-4.5 km), over a black ground, so that the light that comes back is the layer's and
 * the air's, and the layer's shadows do not repeat it. */
#define AW 160
#define AH 160
static const double above_altitude_km = 14.0, above_fov_deg = 60.0;
static float frame_above[AW * AH * 4], luma_above[AW * AH], luma_clear[AW * AH],
    luma_white[AW * AH];

static void above_state(struct proto_world_state *s, double coverage, double type)
{
    mid_state(s);
    s->sun.azimuth_deg = 135.0;
    s->sun.elevation_deg = 60.0;
    s->camera.yaw_deg = 0.0;
    s->camera.altitude_km = above_altitude_km;
    s->camera.pitch_deg = -90.0;
    s->camera.fov_deg = above_fov_deg;
    s->clouds.mid.coverage = coverage;
    s->clouds.mid.type = type;
    s->clouds.mid.bottom_km = 4.0;
    s->clouds.mid.thickness_km = 0.5;
    s->clouds.mid.density = 0.6;
    for (int c = 0; c < 3; c++)
        s->atmosphere.ground_albedo[c] = 0.0;
}

static void render_above(const struct proto_world_state *s, uint64_t key, float *luma)
{
    CHECK(test_render_world(renderer, s, AW, AH, SKY_RENDER_OUTPUT_LINEAR, key, false, frame_above,
                            sizeof frame_above) == 0);
    CHECK(test_count_bad(frame_above, (size_t)AW * AH) == 0);
    cloud_metrics_luma(frame_above, AW, AH, luma);
}

/* The largest autocorrelation along either image axis within 2 pixels of `shift` (the
 * perspective of the layer's 0.5 km depth spreads a period over about 3 pixels). */
static double autocorrelation_near(const float *luma, double shift)
{
    double best = -1.0;
    int s0 = (int)lround(shift);
    for (int d = s0 - 2; d <= s0 + 2; d++)
        for (int across = -2; across <= 2; across++) {
            best = fmax(best, cloud_metrics_autocorrelation(luma, AW, AH, d, across));
            best = fmax(best, cloud_metrics_autocorrelation(luma, AW, AH, across, d));
        }
    return best;
}

/* The fraction of the pixels where the layer reflects at least a tenth of what a white ground
 * would: its light beyond the clear view's, over a white ground's beyond the same (both seen
 * through the same air), is an apparent reflectance, which a satellite's cloud mask
 * thresholds. Cloud of optical depth above about 1.5 counts; a thin edge or wisp does not. */
static double covered_fraction(const float *luma, const float *clear, const float *white)
{
    int n = 0;
    for (int i = 0; i < AW * AH; i++)
        n += luma[i] - clear[i] > 0.1 * (white[i] - clear[i]);
    return (double)n / (AW * AH);
}

/* Seen from above the layer does not tile: its luminance hardly correlates with itself one
 * period over along the image's axes, at twice and half the base tile (2.5 km over the default
 * 60 km weather extent, render/clouds/cloud_params.c), the periods of the noise read at those
 * scales unrotated, where a pattern that repeats correlates fully. And its covered fraction is
 * about its coverage. */
static void test_from_above(void)
{
    static const double base_tile_km = 2.5;
    static const double periods_km[] = { 2.0 * base_tile_km, 0.5 * base_tile_km };
    static const struct {
        const char *name;
        double coverage, type;
    } layers[] = {
        { "altocumulus", 0.6, 1.0 },
        { "altocumulus_sparse", 0.3, 1.0 },
        { "altostratus", 0.8, 0.0 },
        { "altostratus_broken", 0.5, 0.0 },
    };
    struct proto_world_state s;
    above_state(&s, 0.0, 0.0);
    render_above(&s, 600, luma_clear);
    for (int c = 0; c < 3; c++)
        s.atmosphere.ground_albedo[c] = 1.0;
    render_above(&s, 599, luma_white);
    /* Pixels per km where the cells are, the upper half of the layer. */
    const double cells_km = 4.0 + 0.35;
    const double pixels_per_km =
        AH / (2.0 * (above_altitude_km - cells_km) * tan(0.5 * above_fov_deg * M_PI / 180.0));
    for (size_t k = 0; k < sizeof layers / sizeof layers[0]; k++) {
        above_state(&s, layers[k].coverage, layers[k].type);
        render_above(&s, 601 + k, luma_above);
        double covered = covered_fraction(luma_above, luma_clear, luma_white);
        printf("%s from above: coverage %.2f, covered %.3f; autocorrelation", layers[k].name,
               layers[k].coverage, covered);
        for (size_t p = 0; p < sizeof periods_km / sizeof periods_km[0]; p++) {
            double shift = periods_km[p] * pixels_per_km;
            double r = autocorrelation_near(luma_above, shift);
            printf(" %.3f at %.2f km (%.1f pixels)", r, periods_km[p], shift);
            CHECK(r < 0.35);
        }
        printf("\n");
        CHECK_NEAR(covered, layers[k].coverage, 0.08);
        static uint8_t pixels[AW * AH * 4];
        cloud_metrics_picture(frame_above, AW, AH, pixels);
        char path[1024], err[256];
        snprintf(path, sizeof path, "%s/cloud_mid_above_%s.png", out_dir, layers[k].name);
        CHECK(png_write_rgba8_file(path, pixels, AW, AH, err, sizeof err) == 0);
        printf("wrote %s\n", path);
    }
}

/* The pattern tiles the weather extent (60 km), so the wind's offset, kept within it
 * (render/clouds/cloud_params.c), wraps without a seam: a layer moved 10 m short of the extent
 * east and north looks as one moved 10 m back. */
static void test_wraps_with_extent(void)
{
    for (int type = 0; type <= 1; type++) {
        struct proto_world_state s;
        above_state(&s, 0.6, type);
        s.camera.fov_deg = 40.0;
        s.weather.offset_east_km = s.weather.offset_north_km = 60.0 - 0.01;
        render(&s, 650 + 2 * type, frame_a);
        s.weather.offset_east_km = s.weather.offset_north_km = -0.01;
        render(&s, 651 + 2 * type, frame_b);
        double diff = test_relative_difference(frame_a, frame_b, (size_t)W * H);
        printf("%s across the extent's wrap: relative difference %.2g\n",
               type ? "altocumulus" : "altostratus", diff);
        CHECK(diff < 0.01);
    }
}

/* An empty middle layer is no layer: with coverage 0 (or density 0) its other fields change no
 * pixel. */
static void test_empty_is_nothing(void)
{
    struct proto_world_state s;
    mid_state(&s);
    s.clouds.low.coverage = 0.5;
    s.clouds.high.coverage = 0.3;
    s.camera.altitude_km = 0.2;
    s.camera.pitch_deg = 20.0;
    render(&s, 400, frame_a);
    s.clouds.mid.type = 1.0;
    s.clouds.mid.bottom_km = 2.2;
    s.clouds.mid.thickness_km = 3.0;
    s.clouds.mid.density = 3.0;
    render(&s, 401, frame_b);
    CHECK(memcmp(frame_a, frame_b, sizeof frame_a) == 0);
    s.clouds.mid.coverage = 0.7;
    s.clouds.mid.density = 0.0;
    render(&s, 402, frame_b);
    CHECK(memcmp(frame_a, frame_b, sizeof frame_a) == 0);
    /* ... and the layer, once there, does change them. */
    s.clouds.mid.density = 0.5;
    render(&s, 403, frame_b);
    CHECK(memcmp(frame_a, frame_b, sizeof frame_a) != 0);
}

/* The path-traced reference (`skyd render --reference`) traces the middle layer too: no density
 * sample above its majorant (the bound of cloud_pathtrace.glsl's pt_bound_mid), finite, and
 * the renderer's mean luminance near it: cells over a few cumulus within 15 % (measured +2.9 %),
 * and a sheet of optical depth 5-10 seen from below, away from the sun, within 15 % (measured
 * +3.2 %). Both were further (+7 % and +21 %) when four samples shared a dispatch: lavapipe's
 * loop limit cut their long paths short (cloud_pathtrace.glsl, pt_loops_intact), and still cuts
 * some (printed), so the reference is a little dark yet. The sheet's base is lit by the ground
 * in the shadow the map knows (cloud_march.glsl's ground_transmission); lit by half the sun and
 * the clear sky, it was +29.5 % (+14.6 % against 16 samples). */
static const double mid_reference_tolerance[2] = { 0.15, 0.15 }; /* altostratus, altocumulus */
static void render_reference(const struct proto_world_state *s, uint32_t spp, uint64_t key,
                             float *rgba)
{
    struct sky_render_atmosphere atm;
    struct sky_render_view view;
    struct sky_render_clouds clouds;
    struct sky_render_night night;
    world_to_render_atmosphere(s, &atm);
    world_to_render_view(s, W, H, SKY_RENDER_OUTPUT_LINEAR, &view);
    view.history_key = key;
    world_to_render_clouds(s, &clouds);
    clouds.reference_spp = spp;
    clouds.reference_seed = 7;
    CHECK(sky_renderer_set_clouds(renderer, &clouds) == 0);
    world_to_render_night(s, &night);
    sky_renderer_set_night(renderer, &night);
    CHECK(sky_renderer_render(renderer, &atm, &view, rgba, (size_t)W * H * 16, NULL) == 0);
    CHECK(test_count_bad(rgba, (size_t)W * H) == 0);
}

static void test_reference(void)
{
    for (int k = 0; k < 2; k++) {
        struct proto_world_state s;
        mid_state(&s);
        s.camera.altitude_km = 0.2;
        s.camera.yaw_deg = 0.0;
        s.camera.pitch_deg = 30.0;
        s.camera.fov_deg = 60.0;
        s.sun.elevation_deg = 40.0;
        if (k == 0) {
            altostratus(&s);
        } else {
            s.clouds.mid.coverage = 0.6;
            s.clouds.mid.type = 1.0;
            s.clouds.mid.thickness_km = 0.5;
            s.clouds.low.coverage = 0.2;
            s.clouds.low.bottom_km = 1.0;
            s.clouds.low.thickness_km = 1.5;
        }
        render_reference(&s, 0, 500 + 2 * k, frame_a);
        render_reference(&s, 4, 501 + 2 * k, frame_b);
        struct sky_render_reference_stats st;
        CHECK(sky_renderer_cloud_reference_stats(renderer, &st) == 0);
        double fast = mean_luminance(frame_a), reference = mean_luminance(frame_b);
        printf("%s: renderer %.5g, reference %.5g cd/m2 (%+.1f %%); %.3g density samples, %u "
               "above the majorant, %u cut short by the device's loop limit\n",
               k == 0 ? "altostratus" : "altocumulus over cumulus", fast, reference,
               100.0 * (fast - reference) / reference, st.density_samples, st.bound_violations,
               st.truncated);
        CHECK(st.bound_violations == 0);
        CHECK(st.density_samples > 0);
        CHECK_NEAR(fast / reference, 1.0, mid_reference_tolerance[k]);
    }
}

static void run_tests(void)
{
    test_dims_sun_and_ground();
    test_between_layers();
    test_altocumulus_cells();
    test_from_above();
    test_wraps_with_extent();
    test_empty_is_nothing();
    test_reference();
}

int main(int argc, char **argv)
{
    if (argc > 1)
        out_dir = argv[1];
    return test_run_with_renderer(&renderer, run_tests);
}
