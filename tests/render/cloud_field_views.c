/* Whole cloud fields from 14 km straight down, rendered and measured (cloud_field_views.h). */
#include "cloud_field_views.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include "field_errors.h"
#include "png_write.h"
#include "presets.h"
#include "test_support.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

#define N_PIXELS (FIELD_SIDE * FIELD_SIDE)
#define N_FRACTION_PIXELS (FIELD_FRACTION_SIDE * FIELD_FRACTION_SIDE)
#define MAX_OBJECTS 16384

static float rgba[N_PIXELS * 4];
static float cloudy[N_PIXELS], clear[N_PIXELS];
static unsigned char mask[N_PIXELS];
/* The moved views' clear renders ([i - 1] for view i), their cloudy render and mask. */
static float moved_clear[FIELD_FRACTION_VIEWS - 1][N_FRACTION_PIXELS];
static float moved_cloudy[N_FRACTION_PIXELS];
static unsigned char moved_mask[N_FRACTION_PIXELS];
static struct cloud_object objects[MAX_OBJECTS];
static uint64_t next_history_key = 1;

struct field_view field_cumulus_view(double coverage, int seed, double sun_elevation_deg)
{
    struct field_view view = { "fair_cumulus",    coverage, true,         seed,
                               sun_elevation_deg, 135.0,    { 0.0, 0.0 }, 90.0 };
    return view;
}

struct field_view field_deck_view(const char *preset, int i, bool narrow)
{
    static const struct {
        int seed;
        double sun, offset_km;
    } views[FIELD_DECK_VIEWS] = {
        { 1, 40.0, 0.0 },
        { 1, 65.0, 30.0 },
        { 7, 65.0, 0.0 },
        { 7, 40.0, 30.0 },
    };
    i %= FIELD_DECK_VIEWS;
    double offset = narrow ? 0.0 : views[i].offset_km;
    struct field_view view = { preset,
                               NAN,
                               false,
                               views[i].seed,
                               views[i].sun,
                               135.0,
                               { offset, offset },
                               narrow ? 60.0 : 90.0 };
    return view;
}

void field_fraction_offset_km(int i, double offset_km[2])
{
    offset_km[0] = (i == 1 || i == 3) ? 15.0 : 0.0;
    offset_km[1] = (i == 2 || i == 3) ? 15.0 : 0.0;
}

bool field_state(const struct field_views *v, const struct field_view *view,
                 struct proto_world_state *s)
{
    proto_world_state_defaults(s);
    struct proto_field_errors errors = { 0 };
    char msg[1024] = "";
    if (!world_preset_apply(v->config_dir, "weather", view->preset, s, &errors, msg, sizeof msg)) {
        printf("weather preset %s: %s\n", view->preset, msg);
        return false;
    }
    if (!isnan(view->low_coverage))
        s->clouds.low.coverage = view->low_coverage;
    if (!view->keep_high)
        s->clouds.high.coverage = 0.0;
    s->weather.seed = view->seed;
    s->weather.offset_east_km = view->offset_km[0];
    s->weather.offset_north_km = view->offset_km[1];
    s->sun.elevation_deg = view->sun_elevation_deg;
    s->sun.azimuth_deg = view->sun_azimuth_deg;
    s->camera.altitude_km = FIELD_CAMERA_KM;
    s->camera.pitch_deg = -90.0;
    s->camera.yaw_deg = 0.0;
    s->camera.fov_deg = view->fov_deg;
    s->clouds.resolution = PROTO_CLOUD_RESOLUTION_FULL;
    for (int i = 0; i < v->set_count; i++) {
        char path[256];
        const char *eq = strchr(v->sets[i], '=');
        size_t len = eq ? (size_t)(eq - v->sets[i]) : 0;
        if (!eq || len >= sizeof path) {
            printf("--set expects PATH=VALUE, got \"%s\"\n", v->sets[i]);
            return false;
        }
        memcpy(path, v->sets[i], len);
        path[len] = '\0';
        if (!proto_world_state_set_path(s, path, eq + 1, &errors)) {
            printf("--set %s rejected\n", v->sets[i]);
            return false;
        }
    }
    return true;
}

/* A pinhole over a level layer: the view's height on the ground at distance d is
 * 2 d tan(fov / 2). The Earth's curvature drops the layer by 13 m at the corners of a 26 km
 * view, a thousandth of the distance: left out. */
double field_pixel_km(const struct proto_world_state *s)
{
    double mid = s->clouds.low.bottom_km + 0.5 * s->clouds.low.thickness_km;
    double d = s->camera.altitude_km - mid;
    return 2.0 * d * tan(0.5 * s->camera.fov_deg * M_PI / 180.0) / FIELD_SIDE;
}

/* Frames show the converged multiple scattering only once it has been built over frames for
 * the atmosphere and faded in over wall time (render/sky/ms_refine.h), and a weather preset's
 * humidity changes the atmosphere. A probe that asks for the converged table builds it at once
 * and shows it fully: then a view's figures do not depend on what was rendered before it (the
 * test's order, or the probe tool's first frame). */
static bool settle_atmosphere(const struct field_views *v, const struct proto_world_state *s)
{
    enum { SMALL = 8 };
    static float small[SMALL * SMALL * 4];
    const double up[1][3] = { { 0.0, 0.0, 1.0 } };
    double rgb[1][3];
    struct sky_render_atmosphere atm;
    struct sky_render_view view;
    struct sky_render_stats stats;
    world_to_render_atmosphere(s, &atm);
    world_to_render_view(s, SMALL, SMALL, SKY_RENDER_OUTPUT_LINEAR, &view);
    sky_renderer_set_probe_multiple_scattering(v->renderer, SKY_RENDER_PROBE_MS_CONVERGED);
    int probed = sky_renderer_probe_luminance(v->renderer, &atm, &view, up, 1, false, rgb);
    sky_renderer_set_probe_multiple_scattering(v->renderer, SKY_RENDER_PROBE_MS_CURRENT);
    if (probed != 0 ||
        sky_renderer_render(v->renderer, &atm, &view, small, sizeof small, &stats) != 0)
        return false;
    if (stats.multiple_scattering.weight < 1.0) {
        printf("the converged multiple scattering shows at %.3f, not 1\n",
               stats.multiple_scattering.weight);
        return false;
    }
    return true;
}

/* A side x side render (side <= FIELD_SIDE) into rgba[] and its luminance into luma. */
static bool render(const struct field_views *v, const struct proto_world_state *s, int side,
                   float *luma)
{
    if (!settle_atmosphere(v, s))
        return false;
    /* A one-off view, converged from scratch. */
    size_t pixels = (size_t)side * (size_t)side;
    if (test_render_world(v->renderer, s, (uint32_t)side, (uint32_t)side, SKY_RENDER_OUTPUT_LINEAR,
                          next_history_key++, false, rgba, pixels * 4 * sizeof rgba[0]) != 0) {
        printf("render failed\n");
        return false;
    }
    if (test_count_bad(rgba, pixels) != 0) {
        printf("render has NaN, infinite or negative pixels\n");
        return false;
    }
    cloud_metrics_luma(rgba, side, side, luma);
    return true;
}

static void write_png(const struct field_views *v, const char *name, const uint8_t *pixels,
                      int side)
{
    char path[1024], err[256];
    snprintf(path, sizeof path, "%s/cloud_field_%s.png", v->out_dir, name);
    if (png_write_rgba8_file(path, pixels, side, side, err, sizeof err) != 0)
        printf("%s: %s\n", path, err);
}

/* The side x side render in rgba[], exposed and tone mapped (cloud_metrics_picture). */
static void save_render(const struct field_views *v, const char *name, int side)
{
    static uint8_t pixels[N_PIXELS * 4];
    if (!v->out_dir)
        return;
    cloud_metrics_picture(rgba, side, side, pixels);
    write_png(v, name, pixels, side);
}

static bool measured_field_object(const struct cloud_object *o, const void *ctx)
{
    (void)ctx;
    return !o->touches_border && o->area >= FIELD_MIN_AREA_PX;
}

/* A side x side mask, with the boxes of objects[0, count) when side is FIELD_SIDE. */
static void save_mask(const struct field_views *v, const char *name, const unsigned char *m,
                      int side, int count)
{
    static uint8_t pixels[N_PIXELS * 4];
    if (!v->out_dir)
        return;
    int boxed = side == FIELD_SIDE ? (count < MAX_OBJECTS ? count : MAX_OBJECTS) : 0;
    cloud_metrics_mask_picture(m, side, side, objects, boxed, measured_field_object, NULL, pixels);
    char mask_name[256];
    snprintf(mask_name, sizeof mask_name, "%s_mask", name);
    write_png(v, mask_name, pixels, side);
}

bool field_sum_spectra(struct field_spectrum *sum, const struct field_spectrum *one)
{
    if (sum->views > 0 && fabs(sum->pixel_km - one->pixel_km) > 1e-9 * one->pixel_km) {
        printf("views of different pixel sizes (%.5f, %.5f km) in one spectrum\n", sum->pixel_km,
               one->pixel_km);
        return false;
    }
    for (int r = 0; r < one->rings; r++) {
        sum->k[r] = one->k[r];
        sum->e[r] += one->e[r];
    }
    sum->rings = one->rings;
    sum->pixel_km = one->pixel_km;
    sum->views += one->views;
    return true;
}

static bool add_spectrum(const float *luma, double pixel_km, struct field_spectrum *spectrum)
{
    static struct field_spectrum one;
    one.rings = cloud_field_spectrum(luma, FIELD_SIDE, FIELD_SIDE, pixel_km, one.k, one.e,
                                     FIELD_SIDE / 2);
    one.views = 1;
    one.pixel_km = pixel_km;
    return one.rings > 0 && field_sum_spectra(spectrum, &one);
}

static void black_ground(struct proto_world_state *s)
{
    for (int c = 0; c < 3; c++)
        s->atmosphere.ground_albedo[c] = 0.0;
}

/* Cloud where the cloudy render is brighter than the clear one by more than 10 % of it.
 * Brighter only: what a cloud darkens below it is its shadow on the air, not cloud. */
static void mask_clouds(const float *cloudy_luma, const float *clear_luma, int n, unsigned char *m)
{
    for (int i = 0; i < n; i++)
        m[i] = cloudy_luma[i] - clear_luma[i] > 0.10f * clear_luma[i];
}

/* The part of a side x side mask within FIELD_NADIR_DEG of the nadir (a pinhole straight
 * down). */
static double nadir_fraction(const unsigned char *m, int side, double fov_deg)
{
    double tan_half = tan(0.5 * fov_deg * M_PI / 180.0);
    double limit = tan(FIELD_NADIR_DEG * M_PI / 180.0);
    long on = 0, all = 0;
    for (int y = 0; y < side; y++)
        for (int x = 0; x < side; x++) {
            double nx = 2.0 * (x + 0.5) / side - 1.0;
            double ny = 2.0 * (y + 0.5) / side - 1.0;
            if (tan_half * hypot(nx, ny) > limit)
                continue;
            all++;
            on += m[(size_t)y * (size_t)side + (size_t)x] != 0;
        }
    return all > 0 ? (double)on / all : NAN;
}

/* The state of the view moved by field_fraction_offset_km(i) over a black ground. The offset
 * is added after field_state(), so to offsets that v->sets give too. */
static bool moved_state(const struct field_views *v, const struct field_view *view, int i,
                        struct proto_world_state *s)
{
    double offset_km[2];
    if (!field_state(v, view, s))
        return false;
    field_fraction_offset_km(i, offset_km);
    s->weather.offset_east_km += offset_km[0];
    s->weather.offset_north_km += offset_km[1];
    black_ground(s);
    return true;
}

bool field_render_clear(const struct field_views *v, const struct field_view *view)
{
    for (int i = 0; i < FIELD_FRACTION_VIEWS; i++) {
        struct proto_world_state s;
        if (!moved_state(v, view, i, &s))
            return false;
        s.clouds.low.coverage = 0.0;
        if (i == 0 ? !render(v, &s, FIELD_SIDE, clear)
                   : !render(v, &s, FIELD_FRACTION_SIDE, moved_clear[i - 1]))
            return false;
    }
    return true;
}

/* The disc's fraction in the moved view i (1 ..) over moved_clear[i - 1]. */
static bool moved_fraction(const struct field_views *v, const struct field_view *view,
                           const char *name, int i, double *fraction)
{
    struct proto_world_state s;
    if (!moved_state(v, view, i, &s) || !render(v, &s, FIELD_FRACTION_SIDE, moved_cloudy))
        return false;
    double offset_km[2];
    field_fraction_offset_km(i, offset_km);
    char moved_name[256];
    snprintf(moved_name, sizeof moved_name, "%s_at%.0f_%.0f", name, offset_km[0], offset_km[1]);
    save_render(v, moved_name, FIELD_FRACTION_SIDE);
    mask_clouds(moved_cloudy, moved_clear[i - 1], N_FRACTION_PIXELS, moved_mask);
    save_mask(v, moved_name, moved_mask, FIELD_FRACTION_SIDE, 0);
    *fraction = nadir_fraction(moved_mask, FIELD_FRACTION_SIDE, s.camera.fov_deg);
    return true;
}

bool field_measure_cumulus(const struct field_views *v, const struct field_view *view,
                           const char *name, struct cumulus_figures *out,
                           struct field_spectrum *spectrum)
{
    struct proto_world_state s;
    if (!moved_state(v, view, 0, &s) || !render(v, &s, FIELD_SIDE, cloudy))
        return false;
    save_render(v, name, FIELD_SIDE);
    mask_clouds(cloudy, clear, N_PIXELS, mask);
    int count = cloud_metrics_objects(mask, FIELD_SIDE, FIELD_SIDE, objects, MAX_OBJECTS);
    if (count < 0 || count > MAX_OBJECTS) {
        printf("%s: %d objects, more than the %d kept\n", name, count, MAX_OBJECTS);
        return false;
    }
    save_mask(v, name, mask, FIELD_SIDE, count);
    out->pixel_km = field_pixel_km(&s);
    out->coverage = s.clouds.low.coverage;
    out->fraction = nadir_fraction(mask, FIELD_SIDE, s.camera.fov_deg);
    out->image_fraction = cloud_field_fraction(mask, FIELD_SIDE, FIELD_SIDE);
    out->objects = count;
    out->size = cloud_field_size_distribution(objects, count, out->pixel_km, FIELD_MIN_AREA_PX);
    out->dimension = cloud_metrics_fractal_dimension(objects, count, FIELD_D_MIN_AREA_PX,
                                                     &out->dimension_used);
    if (spectrum && !add_spectrum(cloudy, out->pixel_km, spectrum))
        return false;
    /* The configuration's cloud fraction: the disc's over the view and the moved ones. */
    out->view_fractions[0] = out->fraction;
    out->mean_fraction = out->fraction;
    for (int i = 1; i < FIELD_FRACTION_VIEWS; i++) {
        if (!moved_fraction(v, view, name, i, &out->view_fractions[i]))
            return false;
        out->mean_fraction += out->view_fractions[i];
    }
    out->mean_fraction /= FIELD_FRACTION_VIEWS;
    return true;
}

bool field_add_spectrum(const struct field_views *v, const struct field_view *view,
                        const char *name, struct field_spectrum *spectrum)
{
    struct proto_world_state s;
    if (!field_state(v, view, &s) || !render(v, &s, FIELD_SIDE, cloudy))
        return false;
    save_render(v, name, FIELD_SIDE);
    return add_spectrum(cloudy, field_pixel_km(&s), spectrum);
}

double field_band_slope(const struct field_spectrum *spectrum, double lambda_min_km,
                        double lambda_max_km, int *used)
{
    return cloud_field_spectral_slope(spectrum->k, spectrum->e, spectrum->rings, lambda_min_km,
                                      lambda_max_km, used);
}

void field_print_cumulus(const char *name, const struct cumulus_figures *f)
{
    const struct cloud_size_fit *z = &f->size;
    printf("%s: %.1f m/px; cloud fraction within %.0f deg of the nadir %.3f over %d views "
           "(coverage %.2f, %+.3f; views",
           name, 1000.0 * f->pixel_km, FIELD_NADIR_DEG, f->mean_fraction, FIELD_FRACTION_VIEWS,
           f->coverage, f->mean_fraction - f->coverage);
    for (int i = 0; i < FIELD_FRACTION_VIEWS; i++)
        printf(" %.3f", f->view_fractions[i]);
    printf("), %.3f in this view (%+.3f), %.3f of its image; %d objects, %d whole, %d >= L_min "
           "%.0f m (largest %.2f km): b %.2f +- %.2f (untruncated %.2f, binned %.2f, KS %.3f); "
           "D %.3f over %d >= %d px\n",
           f->fraction, f->fraction - f->coverage, f->image_fraction, f->objects, z->whole, z->used,
           1000.0 * z->l_min_km, z->l_max_km, z->b, z->b_sigma, z->b_clauset, z->b_binned, z->ks,
           f->dimension, f->dimension_used, FIELD_D_MIN_AREA_PX);
}

void field_print_octaves(const char *name, const struct field_spectrum *spectrum)
{
    double lo = 4.0 * spectrum->pixel_km, top = FIELD_SIDE * spectrum->pixel_km / 4.0;
    printf("%s: beta by octave (%d views, %.1f m/px):", name, spectrum->views,
           1000.0 * spectrum->pixel_km);
    for (; lo < top; lo *= 2.0) {
        double hi = fmin(2.0 * lo, top);
        printf(" %.2f-%.2f km %.2f;", lo, hi, field_band_slope(spectrum, lo, hi, NULL));
    }
    printf("\n");
}
