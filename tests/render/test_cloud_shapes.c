/* Cloud shapes against the targets, measured on skyd's renders (tests/common/cloud_metrics.h)
 * with the weather presets applied as `skyd render --weather NAME` applies them:
 * - seen from above, fair cumulus outlines have an area-perimeter fractal dimension of
 *   1.25-1.45 over at least 30 whole clouds (Lovejoy 1982: 1.35), and at coverage 0.3 they
 *   are many small cumuli, not ten blobs (three weather seeds and sun azimuths; from 14 km with
 *   a 90 deg field of view and from 40 km with 40 deg, nearer the vertical everywhere);
 * - seen from the side (from the ground toward the horizon, the field thinned so that clouds
 *   stand apart), fair cumulus have a median height / width of at least 0.35 over at least 10
 *   whole clouds;
 * - a storm cell (the storm preset's layer, one cumulonimbus footprint on a client weather
 *   map) is a tower taller than it is wide, and its rain makes a shaft under its base;
 * - a cumulus backlit by a low sun has a silver lining: its outline outshines its core;
 * - overcast and storm decks hide the sun's disk; thin cirrus dims it and leaves it visible.
 * argv[1]: where the renders and the masks measured on them are written as PNGs (boxes: green
 * the objects measured, red those cut by the image's border); argv[2]: the config directory. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "cloud_metrics.h"
#include "png_write.h"
#include "presets.h"
#include "test_support.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

#define W 640
#define H 360
#define MAX_OBJECTS 8192
#define DEG (M_PI / 180.0)

/* Objects smaller than this are pixel noise for the area-perimeter fit (cloud_metrics.h). */
#define D_MIN_AREA 30

static const char *out_dir = ".";
static const char *config_dir = "config";
static struct sky_renderer *renderer;
static float rgba[W * H * 4];
static float cloudy[W * H], clear[W * H];
static unsigned char mask[W * H];
static struct cloud_object objects[MAX_OBJECTS];
static uint64_t next_history_key = 1;

/* The defaults with config/weather/<name>.json applied, as `skyd render --weather NAME`
 * does (server/cli/cli_args.c); clouds traced at every pixel. */
static bool weather_state(const char *name, struct sky_world_state *s)
{
    sky_world_state_defaults(s);
    struct sky_field_errors errors = { 0 };
    char msg[1024] = "";
    bool ok = sky_preset_apply(config_dir, "weather", name, s, &errors, msg, sizeof msg);
    CHECK_MSG(ok, "weather preset %s: %s", name, msg);
    s->clouds.resolution = SKY_CLOUD_RESOLUTION_FULL;
    return ok;
}

/* Renders linear RGBA (cd/m2) into rgba[] and its luminance into luma[]. */
static void render(const struct sky_world_state *s, float *luma)
{
    /* A one-off view, converged from scratch. */
    CHECK(test_render_world(renderer, s, W, H, SKY_RENDER_OUTPUT_LINEAR, next_history_key++,
                            false, rgba, sizeof rgba) == 0);
    CHECK(test_count_bad(rgba, (size_t)W * H) == 0);
    cloud_metrics_luma(rgba, W, H, luma);
}

static uint8_t srgb8(double v)
{
    v = v <= 0.0031308 ? 12.92 * v : 1.055 * pow(v, 1.0 / 2.4) - 0.055;
    return (uint8_t)lround(fmin(fmax(v, 0.0), 1.0) * 255.0);
}

static void write_png(const char *name, const uint8_t *pixels)
{
    char path[1024], err[256];
    snprintf(path, sizeof path, "%s/cloud_shapes_%s.png", out_dir, name);
    CHECK(png_write_rgba8_file(path, pixels, W, H, err, sizeof err) == 0);
}

/* The render in rgba[], exposed for its mean luminance and tone mapped (Reinhard). */
static void save_render(const char *name)
{
    static uint8_t pixels[W * H * 4];
    double mean = 0.0;
    for (int i = 0; i < W * H; i++)
        mean += test_pixel_luminance(rgba + 4 * i);
    double k = 0.25 / fmax(mean / (W * H), 1e-9);
    for (int i = 0; i < W * H; i++) {
        for (int c = 0; c < 3; c++) {
            double v = rgba[4 * i + c] * k;
            pixels[4 * i + c] = srgb8(v / (1.0 + v));
        }
        pixels[4 * i + 3] = 255;
    }
    write_png(name, pixels);
}

static bool measured(const struct cloud_object *o, int min_area, int min_width)
{
    return !o->touches_border && o->area >= min_area && o->x1 - o->x0 + 1 >= min_width;
}

/* The mask (white) with boxes around its objects: green the measured ones, red those cut by
 * the border; the others (specks, narrow ones) unboxed. */
static void save_mask(const char *name, int count, int min_area, int min_width)
{
    static uint8_t pixels[W * H * 4];
    for (int i = 0; i < W * H; i++) {
        uint8_t v = mask[i] ? 200 : 0;
        pixels[4 * i] = pixels[4 * i + 1] = pixels[4 * i + 2] = v;
        pixels[4 * i + 3] = 255;
    }
    for (int k = 0; k < count; k++) {
        const struct cloud_object *o = &objects[k];
        bool used = measured(o, min_area, min_width);
        if (!used && !o->touches_border)
            continue;
        for (int y = o->y0; y <= o->y1; y++)
            for (int x = o->x0; x <= o->x1; x++) {
                if (y != o->y0 && y != o->y1 && x != o->x0 && x != o->x1)
                    continue;
                uint8_t *p = pixels + 4 * ((size_t)y * W + (size_t)x);
                p[0] = used ? 0 : 255;
                p[1] = used ? 255 : 0;
                p[2] = 0;
            }
    }
    write_png(name, pixels);
}

/* The camera's basis as render/sky/sky_uniforms.c builds it, and tan(fov / 2). */
static double camera_basis(const struct sky_world_state *s, double f[3], double r[3],
                           double u[3])
{
    double yaw = s->camera.yaw_deg * DEG;
    sky_direction_from_angles(s->camera.yaw_deg, s->camera.pitch_deg, f);
    r[0] = cos(yaw);
    r[1] = -sin(yaw);
    r[2] = 0.0;
    u[0] = r[1] * f[2] - r[2] * f[1];
    u[1] = r[2] * f[0] - r[0] * f[2];
    u[2] = r[0] * f[1] - r[1] * f[0];
    return tan(0.5 * s->camera.fov_deg * DEG);
}

/* Pixel (x, y)'s direction in the pinhole of shaders/include/camera.glsl, unit length. */
static void pixel_direction(const double f[3], const double r[3], const double u[3],
                            double tan_half, int x, int y, double d[3])
{
    double nx = 2.0 * ((x + 0.5) / W) - 1.0, ny = 1.0 - 2.0 * ((y + 0.5) / H), len = 0.0;
    for (int c = 0; c < 3; c++) {
        d[c] = f[c] + r[c] * nx * tan_half * W / H + u[c] * ny * tan_half;
        len += d[c] * d[c];
    }
    for (int c = 0; c < 3; c++)
        d[c] /= sqrt(len);
}

/* Renders the cloudy state `s`, then `s` without its low layer (its cirrus stays in both: the
 * shapes measured are the cumulus'), both over a black ground so that no shadow on it makes an
 * object; saves the cloudy render as <name>.png. */
static void render_pair(struct sky_world_state *s, const char *name)
{
    for (int c = 0; c < 3; c++)
        s->atmosphere.ground_albedo[c] = 0.0;
    render(s, cloudy);
    save_render(name);
    double coverage = s->clouds.low.coverage;
    s->clouds.low.coverage = 0.0;
    render(s, clear);
    s->clouds.low.coverage = coverage;
}

/* How label() tells cloud from background below the horizon. */
enum below_horizon {
    BELOW_BRIGHTER, /* only where brighter: the background is the ground and the air over it,
                       and what clouds darken there is their shadow, not cloud */
    BELOW_NONE,     /* nothing below 2 deg over the camera's horizontal: clouds seen from the
                       side stand above the band that the far ones merge into there */
    BRIGHTER_ABOVE, /* as BELOW_NONE, and only where brighter: clouds lit from behind the
                       camera, not the air their shadows darken */
};

/* mask: where the cloudy render differs from the clear one by more than 10 % of the clear one,
 * below the horizon as `below` says. Then its objects into objects[]: returns how many, and
 * the masked fraction of the image in *cover. */
static int label(const struct sky_world_state *s, enum below_horizon below, double *cover)
{
    double f[3], r[3], u[3], d[3], tan_half = camera_basis(s, f, r, u);
    double radius = s->atmosphere.bottom_radius_km;
    double dip = -sqrt(1.0 - pow(radius / (radius + s->camera.altitude_km), 2.0));
    long on = 0;
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
            size_t i = (size_t)y * W + (size_t)x;
            double change = (double)cloudy[i] - clear[i];
            pixel_direction(f, r, u, tan_half, x, y, d);
            if (below != BELOW_BRIGHTER && d[2] < sin(2.0 * DEG))
                change = 0.0;
            else if (below == BELOW_NONE || d[2] >= dip)
                change = fabs(change);
            mask[i] = change > 0.10 * clear[i];
            on += mask[i];
        }
    *cover = (double)on / (W * H);
    int n = cloud_metrics_objects(mask, W, H, objects, MAX_OBJECTS);
    CHECK(n >= 0 && n <= MAX_OBJECTS);
    return n < 0 ? 0 : n > MAX_OBJECTS ? MAX_OBJECTS : n;
}

static int compare_int(const void *a, const void *b)
{
    int x = *(const int *)a, y = *(const int *)b;
    return (x > y) - (x < y);
}

/* Fair cumulus (coverage 0.3) seen from above, cloud = brighter than the black ground and the
 * air over it by more than 10 %: the area-perimeter dimension of the whole clouds' outlines,
 * and many small clouds (ten blobs covering 0.3 of the view would be 3 % of the image each;
 * the median cloud must be a tenth of that or less). */
static void test_from_above(const char *name, int seed, double sun_azimuth_deg,
                            double altitude_km, double fov_deg)
{
    struct sky_world_state s;
    if (!weather_state("fair_cumulus", &s))
        return;
    s.weather.seed = seed;
    s.sun.azimuth_deg = sun_azimuth_deg;
    s.camera.altitude_km = altitude_km;
    s.camera.pitch_deg = -90.0;
    s.camera.fov_deg = fov_deg;
    render_pair(&s, name);
    double cover;
    int n = label(&s, BELOW_BRIGHTER, &cover);
    char mask_name[64];
    snprintf(mask_name, sizeof mask_name, "%s_mask", name);
    save_mask(mask_name, n, D_MIN_AREA, 1);

    int used = 0, whole = 0;
    double d = cloud_metrics_fractal_dimension(objects, n, D_MIN_AREA, &used);
    static int areas[MAX_OBJECTS];
    for (int k = 0; k < n; k++)
        if (measured(&objects[k], D_MIN_AREA, 1))
            areas[whole++] = objects[k].area;
    qsort(areas, (size_t)whole, sizeof areas[0], compare_int);
    double median_fraction = whole ? (double)areas[whole / 2] / (W * H) : NAN;
    printf("from above (%s: %.0f km, fov %.0f, seed %d, sun azimuth %.0f): cloud cover %.3f of "
           "the image, %d objects, %d whole of >= %d px (%d..%d px, median %.3f %% of the "
           "image); D = %.3f over %d\n",
           name, altitude_km, fov_deg, seed, sun_azimuth_deg, cover, n, whole, D_MIN_AREA,
           whole ? areas[0] : 0, whole ? areas[whole - 1] : 0, 100.0 * median_fraction, d,
           used);
    CHECK_MSG(used >= 30, "%s: %d whole clouds in the fit, want >= 30", name, used);
    CHECK_MSG(d >= 1.25 && d <= 1.45, "%s: D = %.3f, want 1.25..1.45", name, d);
    CHECK_MSG(median_fraction <= 0.003, "%s: median cloud %.3f %% of the image, want <= 0.3 %%",
              name, 100.0 * median_fraction);
}

/* Fair cumulus seen from the ground toward the horizon, in eight directions, against the sky
 * above the camera's horizontal. At the preset's coverage (0.3) every ray near the horizon
 * crosses several clouds, which merge into one band, so the field is thinned to a coverage of
 * 0.12 (the same clouds, fewer of them): separate clouds then stand against the sky, seen from
 * the side. The whole clouds at least 8 px wide, pooled; their median height / width. */
static void test_edge_on(void)
{
    static struct cloud_object pooled[MAX_OBJECTS];
    int count = 0;
    for (int k = 0; k < 8; k++) {
        struct sky_world_state s;
        if (!weather_state("fair_cumulus", &s))
            return;
        s.clouds.low.coverage = 0.12;
        s.camera.pitch_deg = 12.0;
        s.camera.fov_deg = 50.0;
        s.camera.yaw_deg = 45.0 * k;
        char name[64];
        snprintf(name, sizeof name, "edge_on_%d", 45 * k);
        render_pair(&s, name);
        double cover, largest;
        int n = label(&s, BELOW_NONE, &cover), used = 0;
        strcat(name, "_mask");
        save_mask(name, n, 1, 8);
        double median = cloud_metrics_median_aspect(objects, n, 8, &used, &largest);
        printf("edge-on (camera at %.2f km, yaw %.0f): cloud cover %.3f, %d objects, %d whole "
               ">= 8 px wide (height/width median %.3f, largest %.3f)\n",
               s.camera.altitude_km, s.camera.yaw_deg, cover, n, used, median, largest);
        for (int i = 0; i < n && count < MAX_OBJECTS; i++)
            pooled[count++] = objects[i];
    }
    double largest;
    int used = 0;
    double median = cloud_metrics_median_aspect(pooled, count, 8, &used, &largest);
    printf("edge-on, pooled: %d whole clouds >= 8 px wide; height/width median %.3f, largest "
           "%.3f\n", used, median, largest);
    CHECK_MSG(used >= 10, "edge-on: %d whole clouds, want >= 10", used);
    CHECK_MSG(median >= 0.35, "edge-on: median height/width %.3f, want >= 0.35", median);
}

/* A client weather map with one footprint of `radius` km (coverage 1 at its centre falling to 0
 * at its rim; cloud type `type`, 255 cumulonimbus; precipitation `rain` inside it) `north` km
 * north of the camera. */
static void set_cell_map(const struct sky_world_state *s, double radius, double north,
                         uint8_t type, uint8_t rain)
{
    enum { MAP = 128 };
    static uint8_t map[MAP * MAP * 4];
    double extent = s->weather.map_extent_km;
    for (int y = 0; y < MAP; y++)
        for (int x = 0; x < MAP; x++) {
            double east_km = ((x + 0.5) / MAP - 0.5) * extent;
            double north_km = (0.5 - (y + 0.5) / MAP) * extent;
            double r = hypot(east_km, north_km - north) / radius;
            uint8_t *t = map + 4 * (y * MAP + x);
            t[0] = (uint8_t)lround(255.0 * fmax(0.0, 1.0 - r * r));
            t[1] = 0;
            t[2] = type;
            t[3] = r < 1.0 ? rain : 0;
        }
    CHECK(sky_renderer_set_weather_map(renderer, map, MAP, MAP) == 0);
}

/* The storm preset from the ground with the sun behind the camera, on a client map (by
 * set_cell_map) and without the high layer. */
static bool storm_cell_state(struct sky_world_state *s)
{
    if (!weather_state("storm", s))
        return false;
    s->weather.map_source = SKY_WEATHER_MAP_CLIENT;
    s->clouds.high.coverage = 0.0;
    s->camera.altitude_km = 0.2;
    s->camera.yaw_deg = 0.0;
    s->camera.pitch_deg = 12.0;
    s->camera.fov_deg = 60.0;
    s->sun.azimuth_deg = 180.0;
    s->sun.elevation_deg = 30.0;
    return true;
}

/* One storm cell, alone: a single cumulonimbus footprint 6 km across, 25 km north of the camera,
 * whose repeats lie outside the view or behind the cell. Seen from the ground, lit from behind
 * the camera (cloud = brighter than the clear sky: the air its shadow darkens is not), the cell
 * is a whole object taller than it is wide: a tower, not a pancake or a dome. */
static void test_storm_tower(void)
{
    struct sky_world_state s;
    if (!storm_cell_state(&s))
        return;
    set_cell_map(&s, 3.0, 25.0, 255, 230);
    for (int c = 0; c < 3; c++)
        s.atmosphere.ground_albedo[c] = 0.0;
    render(&s, cloudy);
    save_render("storm_cell");
    s.weather.map_source = SKY_WEATHER_MAP_PROCEDURAL; /* the clear sky: no low layer */
    s.clouds.low.coverage = 0.0;
    render(&s, clear);
    double cover;
    int n = label(&s, BRIGHTER_ABOVE, &cover), largest = -1;
    save_mask("storm_cell_mask", n, 1, 8);
    for (int i = 0; i < n; i++)
        if (largest < 0 || objects[i].area > objects[largest].area)
            largest = i;
    CHECK_MSG(largest >= 0, "storm cell: no cloud in view");
    if (largest < 0)
        return;
    const struct cloud_object *o = &objects[largest];
    double width = o->x1 - o->x0 + 1, height = o->y1 - o->y0 + 1;
    printf("storm cell: cloud cover %.3f, %d objects; the largest %d px, %.0f x %.0f px "
           "(height/width %.2f)%s\n", cover, n, o->area, width, height, height / width,
           o->touches_border ? ", touches the border" : "");
    CHECK_MSG(!o->touches_border, "storm cell: the tower leaves the view");
    CHECK_MSG(height > width, "storm cell: %.0f px tall, %.0f px wide", height, width);
    CHECK(sky_renderer_set_weather_map(renderer, NULL, 0, 0) == 0);
}

/* Rain shafts: the same cell with its base at 1.5 km, raining and not. Between the horizon and
 * the base (0.5-2.5 deg up) the air under the cell changes by more than 10 % with its rain;
 * beside it (15 deg and more off the cell's azimuth) by under 1 %. */
static void test_rain_shaft(void)
{
    struct sky_world_state s;
    if (!storm_cell_state(&s))
        return;
    s.clouds.low.bottom_km = 1.5;
    s.clouds.low.thickness_km = 8.0;
    s.camera.pitch_deg = 5.0;
    double f[3], r[3], u[3], d[3], tan_half = camera_basis(&s, f, r, u);
    set_cell_map(&s, 3.0, 25.0, 255, 230);
    render(&s, cloudy);
    save_render("rain_shaft");
    set_cell_map(&s, 3.0, 25.0, 255, 0);
    render(&s, clear);
    double under[2] = { 0 }, beside[2] = { 0 };
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
            pixel_direction(f, r, u, tan_half, x, y, d);
            double up = asin(d[2]) / DEG, off = fabs(atan2(d[0], d[1])) / DEG;
            if (up < 0.5 || up > 2.5)
                continue;
            size_t i = (size_t)y * W + (size_t)x;
            double *sum = off < 2.0 ? under : off > 15.0 ? beside : NULL;
            if (sum) {
                sum[0] += fabs((double)cloudy[i] - clear[i]);
                sum[1] += clear[i];
            }
        }
    double change_under = under[0] / fmax(under[1], 1e-9);
    double change_beside = beside[0] / fmax(beside[1], 1e-9);
    printf("rain shaft: the air under the cell changes by %.3f with its rain, beside it by %.4f\n",
           change_under, change_beside);
    CHECK_MSG(change_under > 0.10, "rain shaft: %.3f under the cell", change_under);
    CHECK_MSG(change_beside < 0.01, "rain shaft: %.4f beside the cell", change_beside);
    CHECK(sky_renderer_set_weather_map(renderer, NULL, 0, 0) == 0);
}

/* Mean luminance of the masked pixels on the outline (a 4-neighbour outside the mask) over
 * that of those at least 3 px inside it. */
static double rim_over_core(const float *luma)
{
    double rim = 0.0, core = 0.0;
    long rims = 0, cores = 0;
    for (int y = 3; y < H - 3; y++)
        for (int x = 3; x < W - 3; x++) {
            size_t i = (size_t)y * W + (size_t)x;
            if (!mask[i])
                continue;
            bool edge = !mask[i - 1] || !mask[i + 1] || !mask[i - W] || !mask[i + W];
            bool inner = true;
            for (int dy = -3; dy <= 3 && inner; dy++)
                for (int dx = -3; dx <= 3 && inner; dx++)
                    inner = mask[i + (size_t)(dy * W + dx)] != 0;
            if (edge) {
                rim += luma[i];
                rims++;
            } else if (inner) {
                core += luma[i];
                cores++;
            }
        }
    return rims > 0 && cores > 0 ? (rim / rims) / (core / cores) : NAN;
}

/* Silver lining: one cumulus 8 km away, seen from the ground against a sun 6 deg up just beside
 * it. With the renderer's forward-peaked phase its thin outline outshines its thick core, by
 * far more than with an isotropic phase (the same cloud, the same light otherwise). */
static void test_silver_lining(void)
{
    double ratio[2];
    for (int k = 0; k < 2; k++) {
        struct sky_world_state s;
        if (!weather_state("fair_cumulus", &s))
            return;
        s.weather.map_source = SKY_WEATHER_MAP_CLIENT;
        s.clouds.high.coverage = 0.0;
        s.camera.altitude_km = 0.2;
        s.camera.yaw_deg = 0.0;
        s.camera.pitch_deg = 12.0;
        s.camera.fov_deg = 40.0;
        s.sun.azimuth_deg = 8.0;
        s.sun.elevation_deg = 6.0;
        if (k == 1)
            s.clouds.phase_g0 = s.clouds.phase_g1 = 0.0;
        set_cell_map(&s, 1.5, 8.0, 168, 0);
        render(&s, cloudy);
        save_render(k == 0 ? "silver_lining" : "silver_lining_isotropic");
        s.weather.map_source = SKY_WEATHER_MAP_PROCEDURAL;
        s.clouds.low.coverage = 0.0;
        render(&s, clear);
        double cover;
        label(&s, BELOW_NONE, &cover);
        ratio[k] = rim_over_core(cloudy);
        printf("silver lining (%s phase): cloud cover %.3f, outline / core luminance %.3f\n",
               k == 0 ? "the renderer's" : "an isotropic", cover, ratio[k]);
    }
    CHECK(sky_renderer_set_weather_map(renderer, NULL, 0, 0) == 0);
    CHECK_MSG(ratio[0] > 1.2, "silver lining: outline / core %.3f", ratio[0]);
    CHECK_MSG(ratio[0] > 1.5 * ratio[1], "silver lining: %.3f, isotropic %.3f", ratio[0],
              ratio[1]);
}

static int compare_float(const void *a, const void *b)
{
    float x = *(const float *)a, y = *(const float *)b;
    return (x > y) - (x < y);
}

/* Fraction of the luminance gradient (Sobel, weighted by its magnitude, over the strongest
 * 10 % of pixels) whose direction lies within 10 deg of the image's axes. */
static double axis_aligned_edges(const float *luma)
{
    static float mag[W * H], sorted[W * H];
    static bool along_axis[W * H];
    size_t n = 0;
    for (int y = 1; y < H - 1; y++)
        for (int x = 1; x < W - 1; x++) {
            size_t i = (size_t)y * W + (size_t)x;
            double gx = (luma[i - W + 1] + 2.0 * luma[i + 1] + luma[i + W + 1]) -
                        (luma[i - W - 1] + 2.0 * luma[i - 1] + luma[i + W - 1]);
            double gy = (luma[i + W - 1] + 2.0 * luma[i + W] + luma[i + W + 1]) -
                        (luma[i - W - 1] + 2.0 * luma[i - W] + luma[i - W + 1]);
            double angle = atan2(fabs(gy), fabs(gx)) / DEG; /* 0..90 */
            mag[i] = (float)hypot(gx, gy);
            along_axis[i] = angle < 10.0 || angle > 80.0;
            sorted[n++] = mag[i];
        }
    qsort(sorted, n, sizeof *sorted, compare_float);
    float threshold = sorted[n * 9 / 10];
    double aligned = 0.0, total = 0.0;
    for (int y = 1; y < H - 1; y++)
        for (int x = 1; x < W - 1; x++) {
            size_t i = (size_t)y * W + (size_t)x;
            if (mag[i] <= threshold)
                continue;
            total += mag[i];
            aligned += along_axis[i] ? mag[i] : 0.0;
        }
    return total > 0.0 ? aligned / total : NAN;
}

/* Outlines without stair steps: broken clouds seen straight up from the ground, their weather
 * map's texels about 40 px wide. Outlines that follow the texels are runs along the map's
 * axes: with the camera turned so that those are the image's axes (yaw 0 and 90 deg), more of
 * the edges lie along the image's axes than with them diagonal (45 and 135 deg). A clamped
 * footprint (every texel's square, cloud_weather.comp) gives 1.84 times as many; the signed
 * one 1.23. */
static void test_smooth_outlines(void)
{
    double aligned[4];
    for (int k = 0; k < 4; k++) {
        struct sky_world_state s;
        if (!weather_state("broken", &s))
            return;
        s.clouds.high.coverage = 0.0;
        s.camera.yaw_deg = 45.0 * k;
        s.camera.pitch_deg = 89.0;
        s.camera.fov_deg = 120.0;
        render(&s, cloudy);
        if (k == 0)
            save_render("outlines_overhead");
        aligned[k] = axis_aligned_edges(cloudy);
    }
    double along = 0.5 * (aligned[0] + aligned[2]), across = 0.5 * (aligned[1] + aligned[3]);
    printf("outlines overhead: edges within 10 deg of the image axes %.3f with the map's axes "
           "there, %.3f with them diagonal (%.3f)\n", along, across, along / across);
    CHECK_MSG(along < 1.4 * across, "stair-stepped outlines: %.3f along the map's axes, %.3f "
              "across", along, across);
}

/* Sky ambient from the sky-view LUT: an overcast deck seen from 200 m over its top in the
 * twilight (sun 4 deg down: no sunlight reaches the deck), looking down toward the glow and away
 * from it. The deck scatters the sky behind it forward, so the side toward the glow is
 * brighter; with an isotropic phase the ambient is isotropic too and both sides match. */
static double deck_toward_over_away(bool isotropic)
{
    double mean[2];
    for (int k = 0; k < 2; k++) {
        struct sky_world_state s;
        if (!weather_state("overcast", &s))
            return NAN;
        s.clouds.high.coverage = 0.0;
        s.clouds.precipitation = 0.0;
        s.camera.altitude_km = s.clouds.low.bottom_km + s.clouds.low.thickness_km + 0.2;
        s.camera.yaw_deg = k == 0 ? 0.0 : 180.0;
        s.camera.pitch_deg = -30.0;
        s.camera.fov_deg = 30.0;
        s.sun.azimuth_deg = 0.0;
        s.sun.elevation_deg = -4.0;
        if (isotropic)
            s.clouds.phase_g0 = s.clouds.phase_g1 = 0.0;
        render(&s, cloudy);
        if (!isotropic)
            save_render(k == 0 ? "deck_twilight_toward" : "deck_twilight_away");
        double sum = 0.0;
        for (size_t i = 0; i < (size_t)W * H; i++)
            sum += cloudy[i];
        mean[k] = sum / ((double)W * H);
    }
    printf("twilight deck (%s phase): toward the glow %.4g, away %.4g cd/m2 (%.3f)\n",
           isotropic ? "an isotropic" : "the renderer's", mean[0], mean[1], mean[0] / mean[1]);
    return mean[0] / mean[1];
}

static void test_sky_ambient(void)
{
    double shaped = deck_toward_over_away(false), flat = deck_toward_over_away(true);
    CHECK_MSG(shaped > 1.12 && shaped > flat + 0.08, "sky ambient: toward / away %.3f, "
              "isotropic %.3f", shaped, flat);
    CHECK_MSG(shaped < 2.0, "sky ambient: toward / away %.3f", shaped);
}

/* The brightest pixel whose centre lies within disk_deg of the sun (the pinhole of
 * shaders/include/camera.glsl, as cloud_metrics_sun_contrast measures it). */
static double sun_peak(const struct sky_world_state *s, const double sun[3], double disk_deg)
{
    double f[3], r[3], u[3], d[3], tan_half = camera_basis(s, f, r, u), peak = 0.0;
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
            pixel_direction(f, r, u, tan_half, x, y, d);
            if (d[0] * sun[0] + d[1] * sun[1] + d[2] * sun[2] >= cos(disk_deg * DEG))
                peak = fmax(peak, cloudy[(size_t)y * W + (size_t)x]);
        }
    return peak;
}

/* Looks at the sun (30 deg up) through the clouds of `s`: its contrast against the sky 3-6 deg
 * away (cloud_metrics_sun_contrast, disk 0.5 deg) and the brightest pixel of its disk. */
static double sun_view(struct sky_world_state *s, const char *name, double *peak)
{
    s->sun.elevation_deg = 30.0;
    s->camera.yaw_deg = s->sun.azimuth_deg;
    s->camera.pitch_deg = s->sun.elevation_deg;
    s->camera.fov_deg = 30.0;
    render(s, cloudy);
    save_render(name);
    double f[3], r[3], u[3], sun[3], tan_half = camera_basis(s, f, r, u);
    sky_direction_from_angles(s->sun.azimuth_deg, s->sun.elevation_deg, sun);
    const double ring[2] = { 3.0, 6.0 };
    *peak = sun_peak(s, sun, 0.5);
    return cloud_metrics_sun_contrast(cloudy, W, H, f, r, u, tan_half, sun, 0.5, ring);
}

/* Nominal optical depth of a layer along the sun's ray: extinction x density x thickness /
 * sin(elevation), at full density throughout (the noise thins it). */
static double nominal_tau(const struct sky_world_state *s, const struct sky_cloud_layer_state *l)
{
    return s->clouds.extinction_per_km * l->density * l->thickness_km /
           sin(s->sun.elevation_deg * DEG);
}

/* Overcast and storm decks (optical depth along the sun's ray far above 5) show no disk: its
 * brightest pixel under twice the sky 3-6 deg away. Thin cirrus (optical depth ~1) dims the
 * disk and leaves it plainly visible (over ten times the sky around it). */
static void test_sun_through_clouds(void)
{
    struct sky_world_state s;
    double clear_peak, peak;
    weather_state("clear", &s);
    s.clouds.low.coverage = s.clouds.high.coverage = 0.0;
    double clear_contrast = sun_view(&s, "sun_clear", &clear_peak);
    printf("sun, clear sky: contrast %.4g, disk peak %.4g cd/m2\n", clear_contrast, clear_peak);
    CHECK(clear_contrast > 100.0);

    static const char *decks[] = { "overcast", "storm" };
    for (int k = 0; k < 2; k++) {
        if (!weather_state(decks[k], &s))
            continue;
        s.sun.elevation_deg = 30.0;
        double tau = nominal_tau(&s, &s.clouds.low);
        char name[64];
        snprintf(name, sizeof name, "sun_%s", decks[k]);
        double contrast = sun_view(&s, name, &peak);
        printf("sun, %s (low layer's nominal optical depth along the sun's ray %.0f): "
               "contrast %.4g, disk peak %.4g cd/m2 (%.3g of the clear sky's)\n",
               decks[k], tau, contrast, peak, peak / clear_peak);
        CHECK_MSG(contrast < 2.0, "%s: sun contrast %.4g, want < 2 (no disk)", decks[k],
                  contrast);
    }

    /* Cirrus alone, its density set for a nominal optical depth of 3 along the sun's ray: the
     * profile and the noise thin a layer to about a third of that, ~1. */
    weather_state("clear", &s);
    s.sun.elevation_deg = 30.0;
    s.clouds.low.coverage = 0.0;
    s.clouds.high.coverage = 1.0;
    s.clouds.high.density = 1.0;
    s.clouds.high.density = 3.0 / nominal_tau(&s, &s.clouds.high);
    double contrast = sun_view(&s, "sun_cirrus", &peak);
    printf("sun, thin cirrus (density %.4f, nominal optical depth 3): contrast %.4g, disk peak "
           "%.4g cd/m2 (%.3g of the clear sky's: optical depth %.2f)\n",
           s.clouds.high.density, contrast, peak, peak / clear_peak, -log(peak / clear_peak));
    CHECK_MSG(contrast > 10.0, "cirrus: sun contrast %.4g, want > 10 (a visible disk)",
              contrast);
    CHECK_MSG(peak < 0.9 * clear_peak, "cirrus: disk peak %.4g of the clear sky's, want < 0.9",
              peak / clear_peak);
}

/* The tests, in order, with the renderer. */
static void run_tests(void)
{
    test_from_above("above_seed1", 1, 180.0, 14.0, 90.0);
    test_from_above("above_seed7", 7, 100.0, 14.0, 90.0);
    test_from_above("nadir_seed3", 3, 250.0, 40.0, 40.0);
    test_edge_on();
    test_storm_tower();
    test_rain_shaft();
    test_silver_lining();
    test_sky_ambient();
    test_smooth_outlines();
    test_sun_through_clouds();
}

int main(int argc, char **argv)
{
    if (argc > 1)
        out_dir = argv[1];
    if (argc > 2)
        config_dir = argv[2];
    return test_run_with_renderer(&renderer, run_tests);
}
