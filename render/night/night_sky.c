#include "night_sky.h"

#include <math.h>
#include <pthread.h>
#include <string.h>

#include "night_shared.h"
#include "sky_photometry.h"
#include "sky_uniforms.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif
#define DEG (M_PI / 180.0)
#define V4(x_, y_, z_, w_) ((sky_vec4){ (float)(x_), (float)(y_), (float)(z_), (float)(w_) })

/* Seeing and the eye's resolution blur a star over about one arc minute. */
#define STAR_SEEING_SIGMA_RAD (1.0 / 60.0 * DEG)
/* Moonlight is sunlight reddened by the lunar regolith: reflectance ratios at 650, 550 and
 * 450 nm of about 1.08 : 1 : 0.85 (Lane & Irvine 1973). */
static const double moon_reddening[3] = { 1.08, 1.0, 0.85 };
/* Earthshine on the dark side at new moon is about 1e-4 of the full moon's luminance (Danjon's
 * measurements; Goode et al. 2001 for the Earth's albedo), scaled by the Earth's phase. */
#define EARTHSHINE_OF_FULL 1.0e-4
/* Full moon at mean distance outside the atmosphere, lux (server/ephemeris: V = -12.73). */
#define FULL_MOON_LUX 0.2606

static double dot3(const double a[3], const double b[3])
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

static void cross3(const double a[3], const double b[3], double out[3])
{
    out[0] = a[1] * b[2] - a[2] * b[1];
    out[1] = a[2] * b[0] - a[0] * b[2];
    out[2] = a[0] * b[1] - a[1] * b[0];
}

static void normalize3(double v[3])
{
    double n = sqrt(dot3(v, v));
    if (n > 0.0)
        for (int i = 0; i < 3; i++)
            v[i] /= n;
}

static double mare(const double p[3], double lat_deg, double lon_deg, double radius_deg)
{
    double lat = lat_deg * DEG, lon = lon_deg * DEG;
    double c[3] = { cos(lat) * sin(lon), sin(lat), cos(lat) * cos(lon) };
    double angle = acos(fmin(1.0, fmax(-1.0, dot3(p, c)))) / DEG;
    double t = fmin(1.0, fmax(0.0, (angle - (radius_deg - 1.5)) / 3.0));
    double smooth = t * t * (3.0 - 2.0 * t);
    return NIGHT_MARE_ALBEDO + (1.0 - NIGHT_MARE_ALBEDO) * smooth;
}

double night_moon_albedo(double qx, double qy)
{
    double p[3] = { qx, qy, sqrt(fmax(0.0, 1.0 - qx * qx - qy * qy)) };
    double a = 1.0;
#define MARE_TERM(lat, lon, r) a = fmin(a, mare(p, lat, lon, r));
    NIGHT_MARIA(MARE_TERM)
#undef MARE_TERM
    return a;
}

double night_moon_reflectance(double qx, double qy, const double sun[3])
{
    /* Disc frame: x right, y up, z toward the observer; the normal is (q, z). */
    double z = sqrt(fmax(0.0, 1.0 - qx * qx - qy * qy));
    double mu0 = qx * sun[0] + qy * sun[1] + z * sun[2];
    return mu0 > 0.0 ? mu0 / (mu0 + z) : 0.0;
}

/* The disc's basis: right and up as seen (up toward the celestial pole), z toward us. */
static void disc_basis(const double moon[3], const double pole[3], double right[3], double up[3])
{
    double along = dot3(pole, moon);
    for (int i = 0; i < 3; i++)
        up[i] = pole[i] - along * moon[i];
    if (dot3(up, up) < 1e-12) {
        double fallback[3] = { 0, 1, 0 };
        along = dot3(fallback, moon);
        for (int i = 0; i < 3; i++)
            up[i] = fallback[i] - along * moon[i];
    }
    normalize3(up);
    cross3(moon, up, right);
}

/* Integral over the disc of albedo x reflectance, in steradians (the disc's solid angle times
 * the mean): a midpoint rule in polar coordinates with q = sin(t), so that samples crowd
 * toward the limb where a crescent's light is (dA = sin t cos t dt dphi). */
#define DISC_NT 48
#define DISC_NPHI 96
/* The sample points and their weight x albedo, which do not depend on the sun: built once. */
static struct {
    double qx, qy, weight;
} disc_samples[DISC_NT * DISC_NPHI];
static double disc_area;
static pthread_once_t disc_once = PTHREAD_ONCE_INIT;

static void build_disc_samples(void)
{
    for (int i = 0; i < DISC_NT; i++) {
        double t = (i + 0.5) / DISC_NT * 0.5 * M_PI, w = sin(t) * cos(t);
        for (int j = 0; j < DISC_NPHI; j++) {
            double phi = (j + 0.5) / DISC_NPHI * 2.0 * M_PI;
            double qx = sin(t) * cos(phi), qy = sin(t) * sin(phi);
            disc_samples[i * DISC_NPHI + j].qx = qx;
            disc_samples[i * DISC_NPHI + j].qy = qy;
            disc_samples[i * DISC_NPHI + j].weight = w * night_moon_albedo(qx, qy);
            disc_area += w;
        }
    }
}

static double disc_integral(const double sun_in_disc[3], double angular_diameter_deg)
{
    pthread_once(&disc_once, build_disc_samples);
    double sum = 0.0;
    for (int k = 0; k < DISC_NT * DISC_NPHI; k++)
        sum += disc_samples[k].weight *
               night_moon_reflectance(disc_samples[k].qx, disc_samples[k].qy, sun_in_disc);
    return sky_disk_solid_angle(angular_diameter_deg) * sum / disc_area;
}

static bool moon_drawn(const struct sky_render_night *n)
{
    return n->moon_illuminance_lux > 0.0 && n->moon_angular_diameter_deg > 0.0;
}

bool night_moon_rect(const struct sky_render_night *n, const struct sky_render_view *v,
                     int32_t rect[4])
{
    if (!moon_drawn(n))
        return false;
    double moon[3];
    sky_direction_from_angles(n->moon_azimuth_deg, n->moon_elevation_deg, moon);
    return sky_uniforms_disk_rect(v, moon, n->moon_angular_diameter_deg, rect);
}

static sky_vec4 horizontal(const double d[3])
{
    double h = hypot(d[0], d[1]);
    return h > 1e-7 ? V4(d[0] / h, d[1] / h, 0, 1) : V4(0, 0, 0, 0);
}

static void fill_moon(const struct sky_render_night *n, const struct sky_render_view *v,
                      struct sky_frame_uniforms *u)
{
    double moon[3], sun[3], pole[3], right[3], up[3];
    sky_direction_from_angles(n->moon_azimuth_deg, n->moon_elevation_deg, moon);
    sky_direction_from_angles(v->sun_azimuth_deg, v->sun_elevation_deg, sun);
    for (int i = 0; i < 3; i++)
        pole[i] = n->star_rotation[i][2]; /* the J2000 pole in local axes */
    disc_basis(moon, pole, right, up);
    double radius = 0.5 * n->moon_angular_diameter_deg * DEG;
    /* The sun lights the moon from its own direction (the sun is 400 times farther). */
    double sun_in_disc[3] = { dot3(sun, right), dot3(sun, up), -dot3(sun, moon) };
    double integral = disc_integral(sun_in_disc, n->moon_angular_diameter_deg);
    /* The sun's spectrum outside the atmosphere, reddened, at unit luminance. */
    double e_sun[3] = { u->sun_illuminance.x, u->sun_illuminance.y, u->sun_illuminance.z };
    double colour[3];
    for (int c = 0; c < 3; c++)
        colour[c] = e_sun[c] * moon_reddening[c];
    double lum = sky_rgb_to_luminance(colour);
    for (int c = 0; c < 3; c++)
        colour[c] = lum > 0.0 ? colour[c] / lum : 1.0;
    double e = n->moon_illuminance_lux;
    u->moon_direction = V4(moon[0], moon[1], moon[2], cos(radius));
    /* Moonlight lights the sky while the sun is down; with the sun up the moonlit sky is below
     * 1e-4 of the sunlit one (0.26 lx against 1e5 lx) and its LUT is not computed. Below -10
     * deg the moon lights the sky no more than the sun at -10 deg scaled by 2e-6. */
    bool sky_lit = e > 0.0 && v->sun_elevation_deg < 0.0 && n->moon_elevation_deg > -10.0;
    u->moon_illuminance = V4(e * colour[0], e * colour[1], e * colour[2], sky_lit ? 1 : 0);
    u->moon_disk = V4(integral > 0.0 ? 1.0 / integral : 0.0, sin(radius), moon_drawn(n), 0);
    /* Earthshine: the Earth seen from the moon is full when the moon is new; phase angle of the
     * moon i = 180 deg - elongation, the Earth's lit fraction (1 - cos i) / 2. */
    double earth_lit = 0.5 * (1.0 + dot3(sun, moon));
    double full_luminance = FULL_MOON_LUX / sky_disk_solid_angle(n->moon_angular_diameter_deg);
    double es = EARTHSHINE_OF_FULL * full_luminance * earth_lit;
    u->moon_earthshine = V4(es * colour[0], es * colour[1], es * colour[2], 0);
    double mu = moon[2];
    u->moon_local = V4(sqrt(fmax(0.0, 1.0 - mu * mu)), 0, mu, 0);
    u->moon_horizontal = horizontal(moon);
    u->moon_up = V4(up[0], up[1], up[2], 0);
}

/* A star is a Gaussian of the seeing convolved with about half a pixel, so that it keeps its
 * illuminance whatever the resolution; the grid's support bounds it. */
static double star_sigma(const struct sky_render_view *v)
{
    double span = v->projection == SKY_RENDER_PROJECTION_EQUIRECTANGULAR
                      ? M_PI /* a panorama's rows span 180 deg */
                      : 2.0 * tan(0.5 * v->camera_fov_deg * DEG);
    double pixel = span / (v->height ? v->height : 1);
    double sigma = sqrt(STAR_SEEING_SIGMA_RAD * STAR_SEEING_SIGMA_RAD + 0.25 * pixel * pixel);
    return fmin(sigma, NIGHT_STAR_MAX_SIGMA_DEG * DEG);
}

static double star_peak_luminance(const struct sky_render_night *n, const struct sky_render_view *v,
                                  double brightest_star_lux)
{
    double sigma = star_sigma(v);
    return n->star_brightness * brightest_star_lux / (2.0 * M_PI * sigma * sigma);
}

bool night_sky_visible(const struct sky_render_night *n, const struct sky_render_view *v,
                       double brightest_star_lux)
{
    /* With the sun 10 deg or more above the horizon the darkest part of a clear sky is about
     * 1000 cd/m2 or more (CIE clear sky, 90 deg from the sun; Earth and Mars alike): the night
     * sky adds under 0.1 % while its sources stay under 1 cd/m2 (airglow 2e-4; the moonlit
     * sky is not lit then; stars unless a narrow view concentrates one). */
    /* A star is let in by day only when it would add 1 % to that darkest sky (10 cd/m2):
     * less changes no 8-bit pixel (a step near mid grey is about 1.6 % of the luminance), and
     * the star lookup makes the composite 2-4x dearer (a 1280x720 view at 70 deg, where Sirius
     * peaks at 1.4 cd/m2, paid that for 0.14 %). */
    return v->sun_elevation_deg < 10.0 || n->airglow_luminance_cd_m2 > 1.0 ||
           star_peak_luminance(n, v, brightest_star_lux) > 10.0;
}

bool night_fill_uniforms(const struct sky_render_night *n, const struct sky_render_view *v,
                         double brightest_star_lux, struct sky_frame_uniforms *u)
{
    if (moon_drawn(n))
        fill_moon(n, v, u);
    for (int i = 0; i < 3; i++)
        u->star_rotation[i] = V4(n->star_rotation[i][0], n->star_rotation[i][1],
                                 n->star_rotation[i][2], 0);
    double peak = star_peak_luminance(n, v, brightest_star_lux);
    u->night = V4(n->airglow_luminance_cd_m2, n->star_brightness, star_sigma(v), 1e3 * peak);
    return u->moon_illuminance.w > 0.5f;
}
