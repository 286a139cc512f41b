/* Night sky tests on lavapipe with validation: the moon's disc (photometry, phase, bright limb,
 * hidden below the horizon), star positions against PyEphem for known stars, times and sites
 * (so also the rotation with sidereal time), star photometry and daylight, the moonlit sky,
 * night against day, no NaN/Inf; review images night_*.png in the directory of argv[1]. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "night_shared.h"
#include "night_sky.h"
#include "night_stars.h"
#include "sky_photometry.h"
#include "png_write.h"
#include "test_support.h"

#define W 320
#define H 180
#define DEG (3.14159265358979323846 / 180.0)

static const char *out_dir = ".";
static struct sky_renderer *renderer;
static float frame[W * H * 4];

static void night_state(struct sky_world_state *s)
{
    sky_world_state_defaults(s);
    s->sun.azimuth_deg = 0;
    s->sun.elevation_deg = -30;
    s->moon.elevation_deg = -40; /* down unless a test raises it */
    s->camera.fov_deg = 60;
}

/* Renders linear luminance with the state's night; `tweak` may edit the night first. */
static void render(const struct sky_world_state *s, const struct sky_render_night *override)
{
    struct sky_render_atmosphere atm;
    struct sky_render_view view;
    struct sky_render_night night;
    world_to_render_atmosphere(s, &atm);
    world_to_render_view(s, W, H, SKY_RENDER_OUTPUT_LINEAR, &view);
    world_to_render_night(s, &night);
    sky_renderer_set_night(renderer, override ? override : &night);
    CHECK(sky_renderer_render(renderer, &atm, &view, frame, sizeof frame, NULL) == 0);
}

/* Renders the state's exposed sRGB8 image of w x h into pixels; stats may be NULL. */
static bool render_srgb8(const struct sky_world_state *s, unsigned w, unsigned h,
                         uint8_t *pixels, struct sky_render_stats *stats)
{
    struct sky_render_atmosphere atm;
    struct sky_render_view view;
    struct sky_render_night night;
    world_to_render_atmosphere(s, &atm);
    world_to_render_view(s, w, h, SKY_RENDER_OUTPUT_SRGB8, &view);
    world_to_render_night(s, &night);
    sky_renderer_set_night(renderer, &night);
    return pixels && sky_renderer_render(renderer, &atm, &view, pixels, (size_t)w * h * 4,
                                         stats) == 0;
}

static void save_png(const struct sky_world_state *s, const char *name, unsigned w, unsigned h)
{
    uint8_t *pixels = malloc((size_t)w * h * 4);
    CHECK(render_srgb8(s, w, h, pixels, NULL));
    char path[1024], err[256];
    snprintf(path, sizeof path, "%s/%s.png", out_dir, name);
    CHECK(pixels && png_write_rgba8_file(path, pixels, w, h, err, sizeof err) == 0);
    printf("wrote %s\n", path);
    free(pixels);
}

static double lum_at(int x, int y)
{
    const float *p = &frame[(y * W + x) * 4];
    return 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2];
}

static void local_dir(double az_deg, double el_deg, double d[3])
{
    d[0] = sin(az_deg * DEG) * cos(el_deg * DEG);
    d[1] = cos(az_deg * DEG) * cos(el_deg * DEG);
    d[2] = sin(el_deg * DEG);
}

static double dot3(const double a[3], const double b[3])
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

/* The pinhole camera of sky_uniforms.c / camera.glsl. */
struct camera {
    double f[3], r[3], u[3], tan_half, aspect;
};

static struct camera camera_of(const struct sky_world_state *s)
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

static void pixel_dir(const struct camera *c, double px, double py, double d[3])
{
    double nx = px / W * 2 - 1, ny = 1 - py / H * 2;
    for (int i = 0; i < 3; i++)
        d[i] = c->f[i] + c->r[i] * nx * c->tan_half * c->aspect + c->u[i] * ny * c->tan_half;
    double n = sqrt(dot3(d, d));
    for (int i = 0; i < 3; i++)
        d[i] /= n;
}

static double pixel_solid_angle(const struct camera *c, int x, int y)
{
    double d[3];
    pixel_dir(c, x + 0.5, y + 0.5, d);
    double z = dot3(d, c->f), side = 2.0 * c->tan_half / H;
    return side * side * z * z * z; /* a pinhole pixel's solid angle: A cos^3 / f^2 */
}

static int count_bad(void)
{
    int bad = 0;
    for (int i = 0; i < W * H * 4; i++)
        if (!isfinite(frame[i]) || frame[i] < 0.0f) {
            if (bad++ < 3)
                printf("bad value %g at pixel (%d, %d)\n", frame[i], (i / 4) % W, (i / 4) / W);
        }
    return bad;
}

/* Transmittance (luminance-weighted) from the ground toward elevation el. */
static double transmittance_at(const struct sky_world_state *s, double el_deg)
{
    struct sky_render_atmosphere atm;
    world_to_render_atmosphere(s, &atm);
    double alt = s->camera.altitude_km, mu = sin(el_deg * DEG), t[1][3];
    CHECK(sky_renderer_probe_transmittance(renderer, &atm, &alt, &mu, 1, t) == 0);
    return sky_rgb_to_luminance(t[0]);
}

/* ---- stars ---- */

struct star_case {
    const char *name;
    double lat, lon, unix_s, az, el; /* PyEphem 4.1.4, pressure 0 (no refraction) */
};

/* The brightest pixel near the centre and the background-subtracted centroid around it. */
static void star_centroid(double *cx, double *cy, double *flux_lum, const struct camera *c)
{
    int bx = W / 2, by = H / 2;
    for (int y = H / 2 - 12; y <= H / 2 + 12; y++)
        for (int x = W / 2 - 12; x <= W / 2 + 12; x++)
            if (lum_at(x, y) > lum_at(bx, by))
                bx = x, by = y;
    double bg = 0;
    int nb = 0;
    for (int k = -6; k <= 6; k++) {
        bg += lum_at(bx + k, by - 6) + lum_at(bx + k, by + 6) + lum_at(bx - 6, by + k) +
              lum_at(bx + 6, by + k);
        nb += 4;
    }
    bg /= nb;
    double sx = 0, sy = 0, sw = 0, flux = 0;
    for (int y = by - 4; y <= by + 4; y++)
        for (int x = bx - 4; x <= bx + 4; x++) {
            double v = fmax(0.0, lum_at(x, y) - bg);
            sx += v * (x + 0.5), sy += v * (y + 0.5), sw += v;
            flux += v * pixel_solid_angle(c, x, y);
        }
    *cx = sw > 0 ? sx / sw : -1;
    *cy = sw > 0 ? sy / sw : -1;
    *flux_lum = flux;
}

static void test_star_positions(void)
{
    static const struct star_case cases[] = {
        { "Sirius", 51.4769, -0.0005, 1768514400, 163.43232932795823, 20.313529006751523 },
        { "Sirius", 51.4769, -0.0005, 1768521600, 194.20047372741143, 20.70193625164076 },
        { "Polaris", 51.4769, -0.0005, 1768514400, 359.3690917839003, 51.95958152588856 },
        { "Sirius", -33.8688, 151.2093, 1768485600, 318.8009373217994, 68.40524612264814 },
        { "Vega", 45.0, 6.0, 1782079200, 92.28684546124681, 64.60865815173987 },
    };
    for (size_t i = 0; i < sizeof cases / sizeof *cases; i++) {
        const struct star_case *k = &cases[i];
        struct sky_world_state s;
        night_state(&s);
        s.location.latitude_deg = k->lat;
        s.location.longitude_deg = k->lon;
        s.clock.utc_unix_s = k->unix_s;
        s.camera.yaw_deg = k->az;
        s.camera.pitch_deg = k->el;
        s.camera.fov_deg = 8; /* 0.044 deg per pixel */
        render(&s, NULL);
        struct camera c = camera_of(&s);
        double cx, cy, flux;
        star_centroid(&cx, &cy, &flux, &c);
        double off = hypot(cx - W / 2.0, cy - H / 2.0);
        printf("%s at %.4f, %.4f (lat %g, t %.0f): centroid %.2f px from the expected pixel "
               "(1 px = %.3f deg)\n", k->name, k->az, k->el, k->lat, k->unix_s, off,
               s.camera.fov_deg / H);
        CHECK_LE(off, 1.5);
    }
    /* Polaris stands at about the latitude; after one sidereal day the sky is where it was. */
    double m0[3][3], m1[3][3], m6[3][3];
    world_star_rotation(1768514400, 51.4769, 0, m0);
    world_star_rotation(1768514400 + 86164.0905, 51.4769, 0, m1);
    world_star_rotation(1768514400 + 86164.0905 / 4, 51.4769, 0, m6);
    double pole_el = asin(m0[2][2]) / DEG, drift = 0;
    for (int a = 0; a < 3; a++)
        for (int b = 0; b < 3; b++)
            drift = fmax(drift, fabs(m0[a][b] - m1[a][b]));
    CHECK_NEAR(pole_el, 51.4769, 0.5); /* the J2000 pole precessed by 26 years */
    CHECK_LE(drift, 1e-4);
    /* A quarter sidereal day turns a star on the equator by 90 deg of hour angle. */
    double eq_x[3] = { m0[0][0], m0[1][0], m0[2][0] }, eq_x6[3] = { m6[0][0], m6[1][0], m6[2][0] };
    double pole[3] = { m0[0][2], m0[1][2], m0[2][2] };
    double cross_pole = pole[0] * (eq_x[1] * eq_x6[2] - eq_x[2] * eq_x6[1]) +
                        pole[1] * (eq_x[2] * eq_x6[0] - eq_x[0] * eq_x6[2]) +
                        pole[2] * (eq_x[0] * eq_x6[1] - eq_x[1] * eq_x6[0]);
    CHECK_NEAR(acos(dot3(eq_x, eq_x6)) / DEG, 90.0, 0.05);
    CHECK(cross_pole < 0); /* westward: clockwise seen from the north pole */
}

static void test_star_photometry(void)
{
    struct sky_world_state s;
    night_state(&s);
    s.location.latitude_deg = 51.4769;
    s.location.longitude_deg = -0.0005;
    s.clock.utc_unix_s = 1768514400;
    s.camera.yaw_deg = 163.43232932795823;
    s.camera.pitch_deg = 20.313529006751523;
    s.camera.fov_deg = 8;
    struct camera c = camera_of(&s);
    double cx, cy, flux, flux2;
    render(&s, NULL);
    star_centroid(&cx, &cy, &flux, &c);
    double expected = night_star_illuminance_lux(-1.44) * transmittance_at(&s, 20.31);
    printf("Sirius: %.3g lux through the atmosphere in the frame, %.3g expected\n", flux,
           expected);
    CHECK_NEAR(flux / expected, 1.0, 0.1);
    s.night.star_brightness = 2;
    render(&s, NULL);
    star_centroid(&cx, &cy, &flux2, &c);
    CHECK_NEAR(flux2 / flux, 2.0, 0.05);
    CHECK(count_bad() == 0);

    /* By day the same star adds under 0.1 % of the sky: physically invisible. */
    s.night.star_brightness = 1;
    s.sun.azimuth_deg = 200, s.sun.elevation_deg = 30;
    render(&s, NULL);
    double centre = lum_at(W / 2, H / 2), around = 0.25 * (lum_at(W / 2 - 8, H / 2) +
                                                            lum_at(W / 2 + 8, H / 2) +
                                                            lum_at(W / 2, H / 2 - 8) +
                                                            lum_at(W / 2, H / 2 + 8));
    printf("Sirius by day: centre %.6g cd/m2, around %.6g cd/m2\n", centre, around);
    CHECK_LE(fabs(centre / around - 1.0), 0.01);

    /* Whole-frame: a wide daylight view needs no night sky; a narrow one on a bright star, or
     * any view with the sun low, does. */
    struct sky_render_view view;
    struct sky_render_night night;
    world_to_render_view(&s, W, H, SKY_RENDER_OUTPUT_LINEAR, &view);
    world_to_render_night(&s, &night);
    double brightest = night_star_illuminance_lux(-1.44);
    CHECK(!night_sky_visible(&night, &view, brightest)); /* 8 deg: Sirius peaks at ~7 cd/m2 */
    view.camera_fov_deg = 2; /* about 100 cd/m2 */
    CHECK(night_sky_visible(&night, &view, brightest));
    view.camera_fov_deg = 60;
    CHECK(!night_sky_visible(&night, &view, brightest));
    view.sun_elevation_deg = 5;
    CHECK(night_sky_visible(&night, &view, brightest));

    /* The field: about 8000 stars to magnitude 6.5, starlight of order 1e-4 lux (seed 001 4.3
     * quotes 3e-2 W/m2 for all starlight, most of it from stars below naked-eye limits and in
     * the infrared). */
    struct night_stars *field = night_stars_create();
    CHECK(field != NULL);
    if (field) {
        printf("star field: %zu stars, %.3g lux in all outside the atmosphere\n",
               night_stars_count(field), night_stars_total_lux(field));
        CHECK(night_stars_count(field) > 7000 && night_stars_count(field) < 10000);
        CHECK(night_stars_total_lux(field) > 3e-5 && night_stars_total_lux(field) < 1e-3);
        night_stars_destroy(&field);
    }
    /* Colours from temperature: hot stars blue, cool stars red, unit luminance. */
    double hot[3], cool[3];
    night_blackbody_rgb(20000, hot);
    night_blackbody_rgb(3000, cool);
    CHECK(hot[2] > hot[0] && cool[0] > cool[2]);
    CHECK_NEAR(sky_rgb_to_luminance(hot), 1.0, 1e-9);
}

/* ---- moon ---- */

struct disc_stats {
    int pixels, lit;
    double flux;         /* sum of (L - sky) x pixel solid angle over the disc, lux */
    double centroid[3];  /* mean direction of the lit pixels */
};

/* background: the same frame without the moon (NULL: none). */
static void measure_disc(const struct sky_world_state *s, const double *background,
                         double threshold, struct disc_stats *d)
{
    struct camera c = camera_of(s);
    double moon[3];
    local_dir(s->moon.azimuth_deg, s->moon.elevation_deg, moon);
    double cos_r = cos(0.5 * s->moon.angular_diameter_deg * DEG);
    memset(d, 0, sizeof *d);
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
            double dir[3];
            pixel_dir(&c, x + 0.5, y + 0.5, dir);
            double excess = lum_at(x, y) - (background ? background[y * W + x] : 0.0);
            if (dot3(dir, moon) >= cos(0.5 * 1.04 * s->moon.angular_diameter_deg * DEG))
                d->flux += excess * pixel_solid_angle(&c, x, y); /* with the edge pixels */
            if (dot3(dir, moon) < cos_r)
                continue;
            d->pixels++;
            if (excess > threshold) {
                d->lit++;
                for (int i = 0; i < 3; i++)
                    d->centroid[i] += dir[i];
            }
        }
}

static void moon_scene(struct sky_world_state *s, double sun_az, double sun_el)
{
    night_state(s);
    s->moon.azimuth_deg = 180;
    s->moon.elevation_deg = 12;
    s->moon.angular_diameter_deg = 0.518;
    s->sun.azimuth_deg = sun_az;
    s->sun.elevation_deg = sun_el;
    s->camera.yaw_deg = 180;
    s->camera.pitch_deg = 12;
    s->camera.fov_deg = 0.6; /* the disc is 155 pixels across */
    s->night.star_brightness = 0;
}

static double max_lum(void)
{
    double m = 0;
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++)
            m = fmax(m, lum_at(x, y));
    return m;
}

static void test_moon_phases(void)
{
    static double background[W * H];
    /* Sun below the horizon at several elongations from the moon. */
    const double sun_az[] = { 200, 240, 290, 330, 0 };
    for (size_t i = 0; i < sizeof sun_az / sizeof *sun_az; i++) {
        struct sky_world_state s;
        moon_scene(&s, sun_az[i], -8);
        struct sky_render_night night;
        world_to_render_night(&s, &night);
        night.moon_illuminance_lux = 0;
        render(&s, &night);
        for (int p = 0; p < W * H; p++)
            background[p] = lum_at(p % W, p / W);
        render(&s, NULL);
        CHECK(count_bad() == 0);
        double peak = max_lum();
        struct disc_stats d;
        measure_disc(&s, background, 0.005 * (peak - background[0]), &d);
        double sun[3], moon[3];
        local_dir(s.sun.azimuth_deg, s.sun.elevation_deg, sun);
        local_dir(s.moon.azimuth_deg, s.moon.elevation_deg, moon);
        double distance = 1737.4 / sin(0.5 * s.moon.angular_diameter_deg * DEG);
        double phase = world_moon_phase_angle_deg(sun, moon, distance);
        double k = 0.5 * (1.0 + cos(phase * DEG)), lit = (double)d.lit / d.pixels;
        /* The bright limb faces the sun: the lit pixels' centroid lies toward it. */
        double off[3], toward[3], along = dot3(sun, moon);
        for (int j = 0; j < 3; j++) {
            off[j] = d.centroid[j] / (d.lit ? d.lit : 1) - moon[j];
            toward[j] = sun[j] - along * moon[j];
        }
        double cos_limb = dot3(off, toward) / (sqrt(dot3(off, off) * dot3(toward, toward)) + 1e-30);
        printf("moon phase angle %.1f deg: lit fraction of the disc %.3f, illuminated fraction "
               "%.3f, bright limb %.1f deg from the sun's direction\n", phase, lit, k,
               acos(fmin(1.0, cos_limb)) / DEG);
        CHECK_NEAR(lit, k, 0.03);
        if (phase > 5)
            CHECK(cos_limb > cos(3 * DEG));
        /* Illuminance: the disc delivers the phase law's illuminance through the atmosphere. */
        world_to_render_night(&s, &night);
        double expected = night.moon_illuminance_lux * transmittance_at(&s, s.moon.elevation_deg);
        printf("    disc %.4g lux, expected %.4g lux\n", d.flux, expected);
        CHECK_NEAR(d.flux / expected, 1.0, 0.03);
    }
}

static void test_full_moon_luminance(void)
{
    /* Seed 001 4.2: a 0.568 deg full moon of 0.26 lux has a mean luminance of about 3658
     * cd/m2 (E / solid angle gives 3368; the two agree to 10 %). Outside the atmosphere: a
     * camera at 200 km. */
    struct sky_world_state s;
    moon_scene(&s, 0, -12);
    s.moon.angular_diameter_deg = 0.568;
    s.camera.altitude_km = 200;
    struct sky_render_night night;
    world_to_render_night(&s, &night);
    night.moon_illuminance_lux = 0.26;
    render(&s, &night);
    double background = lum_at(2, 2), sum = 0;
    int n = 0;
    struct camera c = camera_of(&s);
    double moon[3];
    local_dir(s.moon.azimuth_deg, s.moon.elevation_deg, moon);
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
            double dir[3];
            pixel_dir(&c, x + 0.5, y + 0.5, dir);
            if (dot3(dir, moon) >= cos(0.5 * 0.568 * DEG * 0.95))
                sum += lum_at(x, y) - background, n++;
        }
    double mean = sum / (n ? n : 1);
    printf("full moon from 200 km: mean disc luminance %.0f cd/m2 (seed 001: 3658)\n", mean);
    CHECK_NEAR(mean / 3658.0, 1.0, 0.1);
    CHECK(count_bad() == 0);
}

static void test_moon_hidden_below_horizon(void)
{
    struct sky_world_state s;
    moon_scene(&s, 0, -20);
    s.moon.elevation_deg = -1.0;
    s.camera.pitch_deg = -1.0;
    render(&s, NULL);
    struct disc_stats d;
    measure_disc(&s, NULL, 0.0, &d);
    double lo = 1e30, hi = 0;
    struct camera c = camera_of(&s);
    double moon[3];
    local_dir(s.moon.azimuth_deg, s.moon.elevation_deg, moon);
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
            double dir[3];
            pixel_dir(&c, x + 0.5, y + 0.5, dir);
            if (dot3(dir, moon) >= cos(0.5 * s.moon.angular_diameter_deg * DEG))
                lo = fmin(lo, lum_at(x, y)), hi = fmax(hi, lum_at(x, y));
        }
    printf("moon below the horizon: disc area luminance %.3g..%.3g cd/m2\n", lo, hi);
    CHECK(d.pixels > 100);
    CHECK_LE(hi, 1.5 * lo); /* the ground, no disc */
}

/* ---- night lighting ---- */

static double mean_sky(void)
{
    double sum = 0;
    for (int y = 0; y < H / 2; y++)
        for (int x = 0; x < W; x++)
            sum += lum_at(x, y);
    return sum / (W * H / 2);
}

static void test_night_lighting(void)
{
    struct sky_world_state s;
    night_state(&s);
    s.camera.pitch_deg = 30;
    s.camera.yaw_deg = 90;
    render(&s, NULL);
    CHECK(count_bad() == 0);
    double moonless = mean_sky(), darkest = 1e30;
    for (int i = 0; i < W * H; i++)
        darkest = fmin(darkest, lum_at(i % W, i / W));
    /* Full moon high in the south (the sun opposite, below the horizon). */
    s.moon.azimuth_deg = 180, s.moon.elevation_deg = 40;
    s.sun.azimuth_deg = 0, s.sun.elevation_deg = -40;
    render(&s, NULL);
    CHECK(count_bad() == 0);
    double moonlit = mean_sky();
    double centre[3];
    float *p = &frame[((H / 4) * W + W / 2) * 4];
    centre[0] = p[0], centre[1] = p[1], centre[2] = p[2];
    /* Day. */
    night_state(&s);
    s.camera.pitch_deg = 30;
    s.camera.yaw_deg = 90;
    s.sun.azimuth_deg = 200, s.sun.elevation_deg = 45;
    render(&s, NULL);
    double day = mean_sky();
    printf("mean sky luminance: moonless %.3g, full moon %.3g, day %.3g cd/m2; darkest moonless "
           "pixel %.3g cd/m2; moonlit sky rgb %.3g %.3g %.3g\n", moonless, moonlit, day, darkest,
           centre[0], centre[1], centre[2]);
    CHECK(moonlit > 5.0 * moonless);
    CHECK(centre[2] > centre[0]);               /* the moonlit sky is blue (Rayleigh) */
    CHECK(day > 1e6 * moonless);                /* night darker than day by orders */
    CHECK(day > 1e4 * moonlit);
    CHECK(darkest > 1e-5);                      /* never black: airglow and starlight */
    CHECK(moonless > 0.5 * s.night.airglow_luminance_cd_m2);

    /* Probes see the moonlit sky and, with the bodies, the disc. */
    struct sky_render_atmosphere atm;
    struct sky_render_view view;
    struct sky_render_night night;
    night_state(&s);
    s.moon.azimuth_deg = 180, s.moon.elevation_deg = 40;
    s.sun.azimuth_deg = 0, s.sun.elevation_deg = -40;
    world_to_render_atmosphere(&s, &atm);
    world_to_render_view(&s, 1, 1, SKY_RENDER_OUTPUT_LINEAR, &view);
    world_to_render_night(&s, &night);
    sky_renderer_set_night(renderer, &night);
    double dirs[2][3], out[2][3], sky[2][3];
    local_dir(180, 40, dirs[0]);
    local_dir(0, 90, dirs[1]);
    CHECK(sky_renderer_probe_luminance(renderer, &atm, &view, (const double (*)[3])dirs, 2, true,
                                       out) == 0);
    CHECK(sky_renderer_probe_luminance(renderer, &atm, &view, (const double (*)[3])dirs, 2, false,
                                       sky) == 0);
    printf("probe: moon direction %.4g cd/m2 (sky only %.4g), zenith %.4g cd/m2\n",
           sky_rgb_to_luminance(out[0]), sky_rgb_to_luminance(sky[0]),
           sky_rgb_to_luminance(out[1]));
    CHECK(sky_rgb_to_luminance(out[0]) > 1000.0);
    CHECK(sky_rgb_to_luminance(sky[1]) > 5.0 * s.night.airglow_luminance_cd_m2);
}

/* Mean of the upper half of an sRGB8 frame with auto exposure, and the metered EV100. */
static double exposed_mean(const struct sky_world_state *s, double *ev100)
{
    static uint8_t pixels[W * H * 4];
    struct sky_render_stats stats;
    CHECK(render_srgb8(s, W, H, pixels, &stats));
    *ev100 = stats.metered_ev100;
    double sum = 0;
    for (int i = 0; i < W * H / 2; i++)
        sum += (pixels[4 * i] + pixels[4 * i + 1] + pixels[4 * i + 2]) / 3.0;
    return sum / (W * H / 2);
}

/* Krawczyk, Myszkowski & Seidel 2005, eq. 11: the key value for a log-average luminance. */
static double key_value(double l_avg)
{
    return 1.03 - 2.0 / (2.0 + log10(l_avg + 1.0));
}

/* exposure.night_adaptation: daylight as metered; a night darker than a camera would show it,
 * by the EV the key value gives for the metered luminance. */
static void test_night_adaptation(void)
{
    struct sky_world_state s;
    const double sun_elevations[3] = {45, -30, -8}; /* day, night, nautical twilight */
    double adapted[3], camera[3];
    for (int k = 0; k < 3; k++) {
        night_state(&s);
        s.camera.pitch_deg = 30;
        s.camera.yaw_deg = 90;
        s.sun.azimuth_deg = 200, s.sun.elevation_deg = sun_elevations[k];
        double ev_on, ev_off;
        s.exposure.night_adaptation = SKY_SWITCH_ON;
        adapted[k] = exposed_mean(&s, &ev_on);
        s.exposure.night_adaptation = SKY_SWITCH_OFF;
        camera[k] = exposed_mean(&s, &ev_off);
        /* EV100 = log2(L * 100 / 12.5) when metered like a camera. */
        double l_avg = exp2(ev_off) * 12.5 / 100.0;
        double expected = fmax(0.0, -log2(key_value(l_avg) / key_value(1000.0)));
        printf("night adaptation, sun at %g deg: metered %.3g cd/m2, EV100 %.2f -> %.2f "
               "(expected +%.2f), mean sRGB %.1f -> %.1f\n", sun_elevations[k], l_avg, ev_off,
               ev_on, expected, camera[k], adapted[k]);
        CHECK_NEAR(ev_on - ev_off, expected, 0.02);
    }
    CHECK_NEAR(adapted[0], camera[0], 2.0);  /* daylight: as metered */
    CHECK(camera[1] > 40.0);                 /* a camera lifts the night to mid grey ... */
    CHECK(adapted[1] < 0.35 * camera[1]);    /* ... a dark-adapted eye does not */
    CHECK(adapted[1] < adapted[2] && adapted[2] < adapted[0]); /* night < twilight < day */
}

static void test_no_nan(void)
{
    const double altitudes[] = { 0, 12, 400 };
    const double moon_el[] = { -5, 2, 60 };
    const double pitch[] = { -30, 5, 60 };
    for (int a = 0; a < 3; a++)
        for (int m = 0; m < 3; m++) {
            struct sky_world_state s;
            night_state(&s);
            s.camera.altitude_km = altitudes[a];
            s.moon.elevation_deg = moon_el[m];
            s.moon.azimuth_deg = 120;
            s.camera.yaw_deg = 120;
            s.camera.pitch_deg = pitch[(a + m) % 3];
            s.sun.elevation_deg = m == 2 ? 10 : -15;
            render(&s, NULL);
            int bad = count_bad();
            if (bad)
                printf("non-finite: %d (alt %g, moon %g)\n", bad, altitudes[a], moon_el[m]);
            CHECK(bad == 0);
        }
}

static void write_review_images(void)
{
    struct sky_world_state s;
    night_state(&s);
    s.clock.utc_unix_s = 1768514400; /* 2026-01-15 22:00 UTC, Greenwich: Orion and Sirius */
    s.location.latitude_deg = 51.4769;
    s.location.longitude_deg = 0;
    s.sun.azimuth_deg = 0, s.sun.elevation_deg = -40;
    s.moon.azimuth_deg = 215, s.moon.elevation_deg = 28;
    s.camera.yaw_deg = 185, s.camera.pitch_deg = 18, s.camera.fov_deg = 75;
    save_png(&s, "night_moon_stars", 640, 360);
    s.moon.elevation_deg = -30;
    save_png(&s, "night_moonless", 640, 360);
    moon_scene(&s, 250, -8);
    s.camera.fov_deg = 1.0;
    save_png(&s, "night_crescent", 320, 180);
    moon_scene(&s, 310, -8);
    s.camera.fov_deg = 1.0;
    save_png(&s, "night_gibbous", 320, 180);
}

/* The tests, in order, with the renderer. */
static void run_tests(void)
{
    test_star_positions();
    test_star_photometry();
    test_moon_phases();
    test_full_moon_luminance();
    test_moon_hidden_below_horizon();
    test_night_lighting();
    test_night_adaptation();
    test_no_nan();
    write_review_images();
}

int main(int argc, char **argv)
{
    if (argc > 1)
        out_dir = argv[1];
    return test_run_with_renderer(&renderer, run_tests);
}
