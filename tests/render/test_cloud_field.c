/* Cloud fields against the targets, measured on skyd's renders from 14 km straight down
 * (cloud_field_views.h, cloud_field_metrics.h):
 * - fair cumulus (low coverage 0.25 and 0.45; weather seeds 1 and 7; sun 40 and 65 deg up):
 *   the cloud fraction (within 20 deg of the nadir, over four views) within 0.06 of the
 *   coverage; cloud sizes n(L) ~ L^-b, b 1.6-2.9 over at least 50 clouds (Neggers et al.
 *   2003, JAS 60; Zhao & Di Girolamo 2007, JGR 112; De Vera et al. 2024, ACP 24);
 *   area-perimeter dimension 1.22-1.42 (Lovejoy 1982);
 * - stratocumulus (broken without its cirrus) and stratus (overcast without its cirrus) decks:
 *   the radiance spectrum E(k) ~ k^-beta with beta 1.3-2.0 over 1-8 km (Cahalan & Snider
 *   1989, RSE 28; Davis et al. 1997, JAS 54), and at least 2.5 below 200 m, where radiative
 *   smoothing takes over (Davis et al. 1997).
 * Cumulus from fov 90 deg (512 px over 24 km, 46 m a pixel): sizes and dimension from that
 * view. Its disc within 20 deg of the nadir is 8.6 km across at the layer, and its cloud
 * fraction scatters by about 0.09 from one part of the field to another, a sampling error of
 * the disc: the fraction checked is the disc's averaged over that view and three more of the
 * same configuration 15 km east, north and both over the weather map, at 128 px
 * (FIELD_FRACTION_* in cloud_field_views.h). Decks: 1-8 km from four fov 90 views (two seeds,
 * two parts of the map, the two suns; 48-51 m a pixel), their spectra summed, since one 24 km
 * view scatters beta over 1-8 km by 0.16 alone; 4 px (111-118 m) to 200 m from two fov 60
 * views (28-30 m a pixel, as Landsat's 28.5 m in Davis et al. 1997). The decks are measured
 * without the presets' cirrus, which lies over them and is not the deck. argv[1]: where the
 * renders and masks are written as PNGs; argv[2]: the config directory. */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "check.h"
#include "cloud_field_views.h"
#include "test_support.h"

static struct field_views views;

static void test_cumulus(void)
{
    const int seeds[] = { 1, 7 };
    const double suns[] = { 40.0, 65.0 }, coverages[] = { 0.25, 0.45 };
    for (int i = 0; i < 2; i++)
        for (int j = 0; j < 2; j++) {
            struct field_view view = field_cumulus_view(NAN, seeds[i], suns[j]);
            CHECK(field_render_clear(&views, &view));
            for (int c = 0; c < 2; c++) {
                char name[64];
                snprintf(name, sizeof name, "cumulus_%02.0f_seed%d_sun%02.0f", 100.0 * coverages[c],
                         seeds[i], suns[j]);
                check_case_name = name;
                view.low_coverage = coverages[c];
                struct cumulus_figures f;
                if (!field_measure_cumulus(&views, &view, name, &f, NULL)) {
                    CHECK(false);
                    continue;
                }
                field_print_cumulus(name, &f);
                CHECK_MSG(fabs(f.mean_fraction - f.coverage) <= 0.06,
                          "cloud fraction %.3f over %d views, coverage %.2f", f.mean_fraction,
                          FIELD_FRACTION_VIEWS, f.coverage);
                CHECK_MSG(f.size.used >= 50, "%d clouds above L_min, want >= 50", f.size.used);
                CHECK_MSG(f.size.b >= 1.6 && f.size.b <= 2.9, "b = %.2f, want 1.6..2.9", f.size.b);
                CHECK_MSG(f.dimension >= 1.22 && f.dimension <= 1.42,
                          "D = %.3f, want "
                          "1.22..1.42",
                          f.dimension);
            }
        }
    check_case_name = "";
}

static void view_name(char *name, size_t size, const struct field_view *view, const char *kind)
{
    snprintf(name, size, "%s_%s_seed%d_sun%02.0f", view->preset, kind, view->seed,
             view->sun_elevation_deg);
}

static void test_deck(const char *preset)
{
    static struct field_spectrum wide, narrow;
    memset(&wide, 0, sizeof wide);
    memset(&narrow, 0, sizeof narrow);
    check_case_name = preset;
    for (int i = 0; i < FIELD_DECK_VIEWS; i++) {
        struct field_view view = field_deck_view(preset, i, false);
        struct field_spectrum one;
        memset(&one, 0, sizeof one);
        char name[64];
        view_name(name, sizeof name, &view, "wide");
        CHECK(field_add_spectrum(&views, &view, name, &one));
        CHECK(field_sum_spectra(&wide, &one));
        printf("%s: beta %.2f over 1-8 km\n", name, field_band_slope(&one, 1.0, 8.0, NULL));
    }
    for (int i = 0; i < 2; i++) {
        struct field_view view = field_deck_view(preset, i, true);
        char name[64];
        view_name(name, sizeof name, &view, "narrow");
        CHECK(field_add_spectrum(&views, &view, name, &narrow));
    }
    int used_wide, used_narrow;
    double beta_wide = field_band_slope(&wide, 1.0, 8.0, &used_wide);
    double lambda_min = 4.0 * narrow.pixel_km;
    double beta_narrow = field_band_slope(&narrow, lambda_min, 0.2, &used_narrow);
    field_print_octaves(preset, &wide);
    field_print_octaves(preset, &narrow);
    printf("%s: beta %.2f over 1-8 km (%d views, %.1f m/px, %d rings); beta %.2f over "
           "%.0f-200 m (%d views, %.1f m/px, %d rings)\n",
           preset, beta_wide, wide.views, 1000.0 * wide.pixel_km, used_wide, beta_narrow,
           1000.0 * lambda_min, narrow.views, 1000.0 * narrow.pixel_km, used_narrow);
    CHECK_MSG(beta_wide >= 1.3 && beta_wide <= 2.0, "beta %.2f over 1-8 km, want 1.3..2.0",
              beta_wide);
    CHECK_MSG(beta_narrow >= 2.5, "beta %.2f below 200 m, want >= 2.5", beta_narrow);
    check_case_name = "";
}

static void run_tests(void)
{
    test_cumulus();
    test_deck("broken");
    test_deck("overcast");
}

int main(int argc, char **argv)
{
    views.out_dir = argc > 1 ? argv[1] : ".";
    views.config_dir = argc > 2 ? argv[2] : "config";
    return test_run_with_renderer(&views.renderer, run_tests);
}
