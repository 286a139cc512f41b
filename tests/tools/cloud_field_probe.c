/* The figures of test_cloud_field for one configuration, without verdicts, for working on the
 * cloud density model: a weather preset seen from 14 km straight down (cloud_field_views.h).
 *
 *   cloud_field_probe PRESET [--coverage C] [--seed S] [--sun-elev E] [--sun-az A]
 *                     [--keep-high | --no-high] [--views N] [--what all|sizes|spectra]
 *                     [--set PATH=VALUE]... [--out DIR] [--config-dir DIR]
 *
 * sizes: the cloudy/clear pair over a black ground at fov 90: size distribution and
 * area-perimeter dimension, and the cloud fraction within 20 deg of the nadir, that view's and
 * its mean over the view and three more 15 km east, north and both over the weather map, at
 * 128 px (a disc 8.6 km across scatters by about 0.09 from one part of the field to another),
 * as for fair cumulus in the test. spectra: N views at fov 90 (beta over 1-8 km) and up to 2
 * at fov 60 (beta from 4 px to 200 m) over the preset's ground, the test's deck views (seeds 1
 * and 7, two parts of the map, suns 40 and 65 deg) unless --seed or --sun-elev fix them; with
 * --views 4 the decks' pooled figures are the test's. The preset's high layer stays in the
 * sizes' pairs and is left out of the spectra, as in the test, unless --keep-high or --no-high
 * says otherwise for both. SKYD_VALIDATION=1 turns the validation layer on (off by default
 * here). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cloud_field_views.h"

#define MAX_SETS 32

struct options {
    const char *preset, *what;
    double coverage, sun_elevation, sun_azimuth;
    int seed, views;
    int high; /* -1: as the test's view; 0: left out; 1: kept */
};

static int usage(void)
{
    fprintf(stderr, "usage: cloud_field_probe PRESET [--coverage C] [--seed S] [--sun-elev E] "
                    "[--sun-az A] [--keep-high | --no-high] [--views N] [--what all|sizes|spectra] "
                    "[--set PATH=VALUE]... [--out DIR] [--config-dir DIR]\n");
    return 2;
}

/* The option's settings applied to one of the test's views. */
static struct field_view customised(const struct options *o, struct field_view view)
{
    view.preset = o->preset;
    view.low_coverage = o->coverage;
    if (o->high >= 0)
        view.keep_high = o->high == 1;
    if (o->seed >= 0)
        view.seed = o->seed;
    if (!isnan(o->sun_elevation))
        view.sun_elevation_deg = o->sun_elevation;
    view.sun_azimuth_deg = o->sun_azimuth;
    return view;
}

static bool probe_sizes(const struct field_views *v, const struct options *o)
{
    struct field_view view = customised(o, field_cumulus_view(NAN, 1, 40.0));
    struct cumulus_figures f;
    if (!field_render_clear(v, &view) || !field_measure_cumulus(v, &view, "probe_sizes", &f, NULL))
        return false;
    field_print_cumulus("sizes (fov 90, black ground)", &f);
    return true;
}

static bool probe_spectra(const struct field_views *v, const struct options *o)
{
    static struct field_spectrum wide, narrow;
    for (int i = 0; i < o->views; i++) {
        struct field_view view = customised(o, field_deck_view(o->preset, i, false));
        struct field_spectrum one;
        memset(&one, 0, sizeof one);
        char name[64];
        snprintf(name, sizeof name, "probe_wide_%d", i);
        if (!field_add_spectrum(v, &view, name, &one) || !field_sum_spectra(&wide, &one))
            return false;
        printf("wide view %d (seed %d, sun %.0f deg, map offset %.0f km): beta %.2f over 1-8 "
               "km\n",
               i, view.seed, view.sun_elevation_deg, view.offset_km[0],
               field_band_slope(&one, 1.0, 8.0, NULL));
    }
    for (int i = 0; i < o->views && i < 2; i++) {
        struct field_view view = customised(o, field_deck_view(o->preset, i, true));
        char name[64];
        snprintf(name, sizeof name, "probe_narrow_%d", i);
        if (!field_add_spectrum(v, &view, name, &narrow))
            return false;
    }
    field_print_octaves("wide", &wide);
    field_print_octaves("narrow", &narrow);
    int used_wide, used_narrow;
    double lambda_min = 4.0 * narrow.pixel_km;
    double beta_wide = field_band_slope(&wide, 1.0, 8.0, &used_wide);
    double beta_narrow = field_band_slope(&narrow, lambda_min, 0.2, &used_narrow);
    printf("spectra: beta %.2f over 1-8 km (%d views, %.1f m/px, %d rings); beta %.2f over "
           "%.0f-200 m (%d views, %.1f m/px, %d rings)\n",
           beta_wide, wide.views, 1000.0 * wide.pixel_km, used_wide, beta_narrow,
           1000.0 * lambda_min, narrow.views, 1000.0 * narrow.pixel_km, used_narrow);
    return true;
}

int main(int argc, char **argv)
{
    struct options o = { NULL, "all", NAN, NAN, 135.0, -1, 1, -1 };
    static const char *sets[MAX_SETS];
    struct field_views v = { NULL, "config", NULL, sets, 0 };
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i], *value = i + 1 < argc ? argv[i + 1] : NULL;
        bool flag = strcmp(a, "--keep-high") == 0 || strcmp(a, "--no-high") == 0;
        bool takes_value = !flag && strncmp(a, "--", 2) == 0;
        if (takes_value && !value)
            return usage();
        if (strcmp(a, "--coverage") == 0)
            o.coverage = atof(value);
        else if (strcmp(a, "--seed") == 0)
            o.seed = atoi(value);
        else if (strcmp(a, "--sun-elev") == 0)
            o.sun_elevation = atof(value);
        else if (strcmp(a, "--sun-az") == 0)
            o.sun_azimuth = atof(value);
        else if (strcmp(a, "--views") == 0)
            o.views = atoi(value);
        else if (strcmp(a, "--what") == 0)
            o.what = value;
        else if (strcmp(a, "--out") == 0)
            v.out_dir = value;
        else if (strcmp(a, "--config-dir") == 0)
            v.config_dir = value;
        else if (strcmp(a, "--set") == 0 && v.set_count < MAX_SETS)
            sets[v.set_count++] = value;
        else if (flag)
            o.high = strcmp(a, "--keep-high") == 0;
        else if (a[0] != '-' && !o.preset)
            o.preset = a;
        else
            return usage();
        i += takes_value;
    }
    bool sizes = strcmp(o.what, "all") == 0 || strcmp(o.what, "sizes") == 0;
    bool spectra = strcmp(o.what, "all") == 0 || strcmp(o.what, "spectra") == 0;
    if (!o.preset || o.views < 1 || (!sizes && !spectra))
        return usage();

    const char *validation = getenv("SKYD_VALIDATION");
    struct sky_renderer_params params = { .validation = validation &&
                                                        strcmp(validation, "1") == 0 };
    v.renderer = sky_renderer_create(&params);
    if (!v.renderer) {
        fprintf(stderr, "cloud_field_probe: no renderer\n");
        return 1;
    }
    bool ok = (!sizes || probe_sizes(&v, &o)) && (!spectra || probe_spectra(&v, &o));
    sky_renderer_destroy(&v.renderer);
    return ok ? 0 : 1;
}
