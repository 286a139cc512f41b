/* What the files of test_night share: the image size, the frame of the last render and the
 * fixtures that make and measure it (defined in test_night.c with the prefix night_test_, but
 * the small pure helpers, static inline here), and the tests of each file:
 *   test_night_stars.c  star positions and photometry
 *   test_night_moon.c   the moon's disc: phases, luminance, below the horizon
 *   test_night.c        night lighting, adaptation, no NaN, review images; main
 * All files count into check.h's one set of counters. */
#ifndef SKYD_TEST_NIGHT_H
#define SKYD_TEST_NIGHT_H

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "test_support.h"

#define W 320
#define H 180
#define DEG (3.14159265358979323846 / 180.0)

/* The last linear render (night_test_render): RGBA, cd/m2. */
extern float night_test_frame[W * H * 4];

void night_test_state(struct proto_world_state *s);
void night_test_render(const struct proto_world_state *s, const struct sky_render_night *override);
int night_test_count_bad(void);
double night_test_transmittance_at(const struct proto_world_state *s, double el_deg);

/* Luminance of pixel (x, y) of the last linear render (night_test_render). */
static inline double lum_at(int x, int y)
{
    const float *p = &night_test_frame[(y * W + x) * 4];
    return 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2];
}

static inline void local_dir(double az_deg, double el_deg, double d[3])
{
    d[0] = sin(az_deg * DEG) * cos(el_deg * DEG);
    d[1] = cos(az_deg * DEG) * cos(el_deg * DEG);
    d[2] = sin(el_deg * DEG);
}

static inline double dot3(const double a[3], const double b[3])
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

/* The pinhole camera of sky_uniforms.c / camera.glsl. */
struct camera {
    double f[3], r[3], u[3], tan_half, aspect;
};

static inline struct camera camera_of(const struct proto_world_state *s)
{
    struct camera c;
    local_dir(s->camera.yaw_deg, s->camera.pitch_deg, c.f);
    double yaw = s->camera.yaw_deg * DEG;
    c.r[0] = cos(yaw), c.r[1] = -sin(yaw), c.r[2] = 0;
    c.u[0] = c.r[1] * c.f[2] - c.r[2] * c.f[1];
    c.u[1] = c.r[2] * c.f[0] - c.r[0] * c.f[2];
    c.u[2] = c.r[0] * c.f[1] - c.r[1] * c.f[0];
    c.tan_half = tan(0.5 * s->camera.fov_deg * DEG);
    c.aspect = (double)W / H;
    return c;
}

static inline void pixel_dir(const struct camera *c, double px, double py, double d[3])
{
    double nx = px / W * 2 - 1, ny = 1 - py / H * 2;
    for (int i = 0; i < 3; i++)
        d[i] = c->f[i] + c->r[i] * nx * c->tan_half * c->aspect + c->u[i] * ny * c->tan_half;
    double n = sqrt(dot3(d, d));
    for (int i = 0; i < 3; i++)
        d[i] /= n;
}

static inline double pixel_solid_angle(const struct camera *c, int x, int y)
{
    double d[3];
    pixel_dir(c, x + 0.5, y + 0.5, d);
    double z = dot3(d, c->f), side = 2.0 * c->tan_half / H;
    return side * side * z * z * z; /* a pinhole pixel's solid angle: A cos^3 / f^2 */
}

/* ---- the tests of each file ---- */

void test_star_positions(void);
void test_star_photometry(void);

/* The moon scene of test_night_moon.c: the moon 12 deg up in the south, filling the view. */
void night_test_moon_scene(struct proto_world_state *s, double sun_az, double sun_el);
void test_moon_phases(void);
void test_full_moon_luminance(void);
void test_moon_hidden_below_horizon(void);

#endif
