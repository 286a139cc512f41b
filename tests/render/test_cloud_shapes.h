/* What the files of test_cloud_shapes share (see test_cloud_shapes.c): the image size, the
 * renderer and the images, and the fixtures that render, label and save them, defined in
 * test_cloud_shapes.c with the prefix shapes_; and the tests of each file:
 *   test_cloud_shapes_outlines.c  fair cumulus from above and edge-on, smooth outlines
 *   test_cloud_shapes_storm.c     a storm cell's tower and rain shaft
 *   test_cloud_shapes_light.c     silver lining, sky ambient, the sun through clouds
 * All files count into check.h's one set of counters. */
#ifndef SKYD_TEST_CLOUD_SHAPES_H
#define SKYD_TEST_CLOUD_SHAPES_H

#include <math.h>
#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "cloud_metrics.h"
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

extern struct sky_renderer *shapes_renderer;
/* Luminance of the last renders (shapes_render), the mask labelled on them and its objects
 * (shapes_label). */
extern float shapes_cloudy[W * H], shapes_clear[W * H];
extern unsigned char shapes_mask[W * H];
extern struct cloud_object shapes_objects[MAX_OBJECTS];

/* How shapes_label() tells cloud from background below the horizon. */
enum below_horizon {
    BELOW_BRIGHTER, /* only where brighter: the background is the ground and the air over it,
                       and what clouds darken there is their shadow, not cloud */
    BELOW_NONE,     /* nothing below 2 deg over the camera's horizontal: clouds seen from the
                       side stand above the band that the far ones merge into there */
    BRIGHTER_ABOVE, /* as BELOW_NONE, and only where brighter: clouds lit from behind the
                       camera, not the air their shadows darken */
};

bool shapes_weather_state(const char *name, struct proto_world_state *s);
void shapes_render(const struct proto_world_state *s, float *luma);
void shapes_save_render(const char *name);
bool shapes_measured(const struct cloud_object *o, int min_area, int min_width);
void shapes_save_mask(const char *name, int count, int min_area, int min_width);
double shapes_camera_basis(const struct proto_world_state *s, double f[3], double r[3],
                           double u[3]);
void shapes_pixel_direction(const double f[3], const double r[3], const double u[3],
                            double tan_half, int x, int y, double d[3]);
void shapes_render_pair(struct proto_world_state *s, const char *name);
int shapes_label(const struct proto_world_state *s, enum below_horizon below, double *cover);
void shapes_set_cell_map(const struct proto_world_state *s, double radius, double north,
                         uint8_t type, uint8_t rain);

/* ---- the tests of each file ---- */

void test_from_above(const char *name, int seed, double sun_azimuth_deg, double altitude_km,
                     double fov_deg);
void test_edge_on(void);
void test_smooth_outlines(void);

void test_storm_tower(void);
void test_rain_shaft(void);

void test_silver_lining(void);
void test_powder(void);
void test_storm_steps(void);
void test_sky_ambient(void);
void test_sun_through_clouds(void);

#endif
