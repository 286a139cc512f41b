/* Whole cloud fields seen from 14 km straight down, rendered with the renderer library and
 * measured with cloud_field_metrics.h: shared by test_cloud_field (the targets) and
 * tools/cloud_field_probe (the same figures for one configuration, without verdicts).
 *
 * A view is FIELD_SIDE^2 pixels of linear luminance (cd/m2) from a pinhole (those that measure
 * the cloud fraction alone FIELD_FRACTION_SIDE^2), so one pixel covers the same ground
 * everywhere on a level surface: field_pixel_km() at the low layer's middle altitude. The
 * weather map is tileable over weather.map_extent_km (60 km by default) and centred on the
 * camera; a view must stay narrower than it, or the spectrum sees the map repeat: fov 90 deg
 * from 14 km spans 24-26 km at the low layer. */
#ifndef SKYD_TEST_CLOUD_FIELD_VIEWS_H
#define SKYD_TEST_CLOUD_FIELD_VIEWS_H

#include <stdbool.h>

#include "cloud_field_metrics.h"
#include "sky_renderer.h"
#include "world_state.h"

#define FIELD_SIDE 512
#define FIELD_CAMERA_KM 14.0
/* L_min: 4 pixels across, the smallest cloud that the mask resolves as more than a speck. */
#define FIELD_MIN_AREA_PX 13
/* Cloud fraction: the part of the sky that clouds cover seen from straight above (as the
 * weather map's coverage means it). Off the nadir a camera also sees the clouds' sides: a
 * cylinder h tall and w wide seen theta off the nadir covers 1 + (4 / pi) (h / w) tan(theta)
 * times its footprint, 1.6 times for h = w / 2 at 45 deg. Within 20 deg of the nadir (a disc
 * of 4.3 km radius at the layer from 14 km, 27000 pixels at fov 90) that is 1.15 on average
 * over the disc. */
#define FIELD_NADIR_DEG 20.0
/* That disc is 8.6 km across at the layer, five or six cells of cumulus (about 1.6 km apart):
 * its fraction scatters by about 0.09 from one part of the field to another even where the
 * field's mean fraction is right, a sampling error of the measurement, not of the field. The
 * cloud fraction of a configuration is the disc's fraction averaged over FIELD_FRACTION_VIEWS
 * nadir views of it: the view itself, and the same view moved by field_fraction_offset_km()
 * over the weather map (which tiles every 60 km), 15 km east, north and both (the discs
 * 15-21 km apart). The fraction needs no fine pixels, as a coarser grid samples the same field
 * more sparsely, without a bias (a view's fraction at 128 and at 256 pixels a side differs by
 * 0.01 at most): the moved views are FIELD_FRACTION_SIDE pixels a side (184 m at the layer,
 * 1700 pixels in the disc, a sixth of the render time of 256), each with its own clear
 * render. */
#define FIELD_FRACTION_VIEWS 4
#define FIELD_FRACTION_SIDE 128
/* Objects smaller than this are pixel noise for the area-perimeter fit (cloud_metrics.h). */
#define FIELD_D_MIN_AREA_PX 30

/* What every view shares: the renderer, where presets are read and PNGs written (NULL: none),
 * and PATH=VALUE assignments applied after the preset and the view (world_fields.c paths). */
struct field_views {
    struct sky_renderer *renderer;
    const char *config_dir;
    const char *out_dir;
    const char *const *sets;
    int set_count;
};

struct field_view {
    const char *preset;  /* config/weather/<preset>.json */
    double low_coverage; /* clouds.low.coverage; NAN: the preset's */
    bool keep_high;      /* false: clouds.high.coverage 0, the low layer alone */
    int seed;            /* weather.seed */
    double sun_elevation_deg, sun_azimuth_deg;
    double offset_km[2]; /* weather.offset_east_km, _north_km: which part of the map */
    double fov_deg;
};

struct cumulus_figures {
    double pixel_km;
    double coverage; /* the low layer's, as set */
    double fraction; /* the view's: of its pixels within FIELD_NADIR_DEG of the nadir
                              * in the mask */
    double view_fractions[FIELD_FRACTION_VIEWS]; /* the same, view by view: [0] the view's */
    double mean_fraction;  /* their mean: the configuration's cloud fraction */
    double image_fraction; /* of the whole image */
    int objects;           /* in the mask, all */
    struct cloud_size_fit size;
    double dimension; /* area-perimeter, whole objects >= FIELD_D_MIN_AREA_PX */
    int dimension_used;
};

/* Spectra of views with the same pixel size, summed ring by ring. */
struct field_spectrum {
    int views, rings;
    double pixel_km;
    double k[FIELD_SIDE / 2], e[FIELD_SIDE / 2];
};

/* The test's views. Fair cumulus: fov 90, the sun at azimuth 135 deg, the preset's cirrus kept
 * (in both renders of the pair, so not in the mask). Decks (FIELD_DECK_VIEWS of them, fov 90
 * wide, 60 narrow): seeds 1 and 7, the map's part under the camera and the one 30 km east and
 * north (half the map away), suns 40 and 65 deg up; the narrow ones all under the camera. */
#define FIELD_DECK_VIEWS 4
struct field_view field_cumulus_view(double coverage, int seed, double sun_elevation_deg);
struct field_view field_deck_view(const char *preset, int i, bool narrow);

/* How far view i of the cloud fraction is moved over the weather map, east and north, in km:
 * (0, 0) for i = 0, then (15, 0), (0, 15), (15, 15); added to the view's own offsets. */
void field_fraction_offset_km(int i, double offset_km[2]);

/* The world state of a view: defaults, the weather preset, the view's fields, the camera
 * (FIELD_CAMERA_KM, straight down), clouds traced at every pixel, then v->sets. */
bool field_state(const struct field_views *v, const struct field_view *view,
                 struct proto_world_state *s);

/* Side of a pixel in km at the low layer's middle altitude. */
double field_pixel_km(const struct proto_world_state *s);

/* Renders the view without its low layer over a black ground, and the same for the view moved
 * by field_fraction_offset_km() at FIELD_FRACTION_SIDE: the clear halves of the pairs that
 * field_measure_cumulus() compares with, kept until the next call. */
bool field_render_clear(const struct field_views *v, const struct field_view *view);

/* Renders the view over a black ground (saved as cloud_field_<name>.png), masks what is
 * brighter than the clear render by more than 10 % of it (saved as <name>_mask.png: green
 * boxes the clouds in the size fit, red those cut by the border) and measures the mask. Then
 * renders and masks the moved views alike (cloud_field_<name>_at<east>_<north>.png and its
 * _mask.png) for their disc's fractions alone. When spectrum is not NULL, adds the view's
 * render's spectrum to it. */
bool field_measure_cumulus(const struct field_views *v, const struct field_view *view,
                           const char *name, struct cumulus_figures *out,
                           struct field_spectrum *spectrum);

/* Renders the view over the preset's ground (saved as cloud_field_<name>.png) and adds its
 * spectrum to *spectrum (which starts zeroed). */
bool field_add_spectrum(const struct field_views *v, const struct field_view *view,
                        const char *name, struct field_spectrum *spectrum);

/* Adds *one's views to *sum (which starts zeroed); false when their pixels differ. */
bool field_sum_spectra(struct field_spectrum *sum, const struct field_spectrum *one);

/* beta over [lambda_min_km, lambda_max_km] of the summed spectrum; *used the rings. */
double field_band_slope(const struct field_spectrum *spectrum, double lambda_min_km,
                        double lambda_max_km, int *used);

void field_print_cumulus(const char *name, const struct cumulus_figures *f);

/* The slopes over octaves from 4 pixels to a quarter of the view, one line. */
void field_print_octaves(const char *name, const struct field_spectrum *spectrum);

#endif
