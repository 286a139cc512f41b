/* test_cloud_shapes' outlines: fair cumulus from above (fractal dimension, many small clouds)
 * and from the side (height / width), and outlines without stair steps (test_cloud_shapes.h). */
#include "test_cloud_shapes.h"

static int compare_int(const void *a, const void *b)
{
    int x = *(const int *)a, y = *(const int *)b;
    return (x > y) - (x < y);
}

/* Fair cumulus (coverage 0.3, without the preset's thin high layer, whose veil would join the
 * clouds under it into one outline) seen from above, cloud = brighter than the black ground
 * and the air over it by more than 10 %: the area-perimeter dimension of the whole clouds'
 * outlines (test_cloud_field holds it to the observed 1.22-1.42 over more fields),
 * and many small clouds (ten blobs covering 0.3 of the view would be 3 % of the image each;
 * the median cloud must be a tenth of that or less). */
void test_from_above(const char *name, int seed, double sun_azimuth_deg, double altitude_km,
                     double fov_deg)
{
    struct proto_world_state s;
    if (!shapes_weather_state("fair_cumulus", &s))
        return;
    s.weather.seed = seed;
    s.clouds.high.coverage = 0.0;
    s.sun.azimuth_deg = sun_azimuth_deg;
    s.camera.altitude_km = altitude_km;
    s.camera.pitch_deg = -90.0;
    s.camera.fov_deg = fov_deg;
    shapes_render_pair(&s, name);
    double cover;
    int n = shapes_label(&s, BELOW_BRIGHTER, &cover);
    char mask_name[64];
    snprintf(mask_name, sizeof mask_name, "%s_mask", name);
    shapes_save_mask(mask_name, n, D_MIN_AREA, 1);

    int used = 0, whole = 0;
    double d = cloud_metrics_fractal_dimension(shapes_objects, n, D_MIN_AREA, &used);
    static int areas[MAX_OBJECTS];
    for (int k = 0; k < n; k++)
        if (shapes_measured(&shapes_objects[k], D_MIN_AREA, 1))
            areas[whole++] = shapes_objects[k].area;
    qsort(areas, (size_t)whole, sizeof areas[0], compare_int);
    double median_fraction = whole ? (double)areas[whole / 2] / (W * H) : NAN;
    printf("from above (%s: %.0f km, fov %.0f, seed %d, sun azimuth %.0f): cloud cover %.3f of "
           "the image, %d objects, %d whole of >= %d px (%d..%d px, median %.3f %% of the "
           "image); D = %.3f over %d\n",
           name, altitude_km, fov_deg, seed, sun_azimuth_deg, cover, n, whole, D_MIN_AREA,
           whole ? areas[0] : 0, whole ? areas[whole - 1] : 0, 100.0 * median_fraction, d, used);
    CHECK_MSG(used >= 30, "%s: %d whole clouds in the fit, want >= 30", name, used);
    /* A regression bound, not the target: the rebuilt clouds read 1.49-1.57 by this mask (the
     * old ones 1.25) and 1.34-1.42 by test_cloud_field's, which holds the observed 1.22-1.42
     * but is not in ctest until the fields meet all its targets (docs/ACCURACY.md). */
    CHECK_MSG(d >= 1.25 && d <= 1.60, "%s: D = %.3f, want 1.25..1.60", name, d);
    CHECK_MSG(median_fraction <= 0.003, "%s: median cloud %.3f %% of the image, want <= 0.3 %%",
              name, 100.0 * median_fraction);
}

/* Fair cumulus seen from the ground toward the horizon, in eight directions, against the sky
 * above the camera's horizontal. At the preset's coverage (0.3) every ray near the horizon
 * crosses several clouds, which merge into one band, so the field is thinned to a coverage of
 * 0.12 (the same clouds, fewer of them): separate clouds then stand against the sky, seen from
 * the side. The whole clouds at least 8 px wide, pooled; their median height / width. */
void test_edge_on(void)
{
    static struct cloud_object pooled[MAX_OBJECTS];
    int count = 0;
    for (int k = 0; k < 8; k++) {
        struct proto_world_state s;
        if (!shapes_weather_state("fair_cumulus", &s))
            return;
        s.clouds.low.coverage = 0.12;
        s.camera.pitch_deg = 12.0;
        s.camera.fov_deg = 50.0;
        s.camera.yaw_deg = 45.0 * k;
        char name[64];
        snprintf(name, sizeof name, "edge_on_%d", 45 * k);
        shapes_render_pair(&s, name);
        double cover, largest;
        int n = shapes_label(&s, BELOW_NONE, &cover), used = 0;
        strcat(name, "_mask");
        shapes_save_mask(name, n, 1, 8);
        double median = cloud_metrics_median_aspect(shapes_objects, n, 8, &used, &largest);
        printf("edge-on (camera at %.2f km, yaw %.0f): cloud cover %.3f, %d objects, %d whole "
               ">= 8 px wide (height/width median %.3f, largest %.3f)\n",
               s.camera.altitude_km, s.camera.yaw_deg, cover, n, used, median, largest);
        for (int i = 0; i < n && count < MAX_OBJECTS; i++)
            pooled[count++] = shapes_objects[i];
    }
    double largest;
    int used = 0;
    double median = cloud_metrics_median_aspect(pooled, count, 8, &used, &largest);
    printf("edge-on, pooled: %d whole clouds >= 8 px wide; height/width median %.3f, largest "
           "%.3f\n",
           used, median, largest);
    CHECK_MSG(used >= 10, "edge-on: %d whole clouds, want >= 10", used);
    CHECK_MSG(median >= 0.35, "edge-on: median height/width %.3f, want >= 0.35", median);
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
void test_smooth_outlines(void)
{
    double aligned[4];
    for (int k = 0; k < 4; k++) {
        struct proto_world_state s;
        if (!shapes_weather_state("broken", &s))
            return;
        s.clouds.high.coverage = 0.0;
        s.camera.yaw_deg = 45.0 * k;
        s.camera.pitch_deg = 89.0;
        s.camera.fov_deg = 120.0;
        shapes_render(&s, shapes_cloudy);
        if (k == 0)
            shapes_save_render("outlines_overhead");
        aligned[k] = axis_aligned_edges(shapes_cloudy);
    }
    double along = 0.5 * (aligned[0] + aligned[2]), across = 0.5 * (aligned[1] + aligned[3]);
    printf("outlines overhead: edges within 10 deg of the image axes %.3f with the map's axes "
           "there, %.3f with them diagonal (%.3f)\n",
           along, across, along / across);
    CHECK_MSG(along < 1.4 * across,
              "stair-stepped outlines: %.3f along the map's axes, %.3f "
              "across",
              along, across);
}
