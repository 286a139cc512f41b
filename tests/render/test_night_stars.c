/* test_night's stars: positions against PyEphem for known stars, times and sites, the
 * rotation with sidereal time, photometry, daylight, the field (test_night.h). */
#include "test_night.h"

#include "night_shared.h"
#include "night_sky.h"
#include "night_stars.h"
#include "sky_photometry.h"

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

void test_star_positions(void)
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
        struct proto_world_state s;
        night_test_state(&s);
        s.location.latitude_deg = k->lat;
        s.location.longitude_deg = k->lon;
        s.clock.utc_unix_s = k->unix_s;
        s.camera.yaw_deg = k->az;
        s.camera.pitch_deg = k->el;
        s.camera.fov_deg = 8; /* 0.044 deg per pixel */
        night_test_render(&s, NULL);
        struct camera c = camera_of(&s);
        double cx, cy, flux;
        star_centroid(&cx, &cy, &flux, &c);
        double off = hypot(cx - W / 2.0, cy - H / 2.0);
        printf("%s at %.4f, %.4f (lat %g, t %.0f): centroid %.2f px from the expected pixel "
               "(1 px = %.3f deg)\n",
               k->name, k->az, k->el, k->lat, k->unix_s, off, s.camera.fov_deg / H);
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

void test_star_photometry(void)
{
    struct proto_world_state s;
    night_test_state(&s);
    s.location.latitude_deg = 51.4769;
    s.location.longitude_deg = -0.0005;
    s.clock.utc_unix_s = 1768514400;
    s.camera.yaw_deg = 163.43232932795823;
    s.camera.pitch_deg = 20.313529006751523;
    s.camera.fov_deg = 8;
    struct camera c = camera_of(&s);
    double cx, cy, flux, flux2;
    night_test_render(&s, NULL);
    star_centroid(&cx, &cy, &flux, &c);
    double expected = night_star_illuminance_lux(-1.44) * night_test_transmittance_at(&s, 20.31);
    printf("Sirius: %.3g lux through the atmosphere in the frame, %.3g expected\n", flux, expected);
    CHECK_NEAR(flux / expected, 1.0, 0.1);
    s.night.star_brightness = 2;
    night_test_render(&s, NULL);
    star_centroid(&cx, &cy, &flux2, &c);
    CHECK_NEAR(flux2 / flux, 2.0, 0.05);
    CHECK(night_test_count_bad() == 0);

    /* By day the same star adds under 0.1 % of the sky: physically invisible. */
    s.night.star_brightness = 1;
    s.sun.azimuth_deg = 200, s.sun.elevation_deg = 30;
    night_test_render(&s, NULL);
    double centre = lum_at(W / 2, H / 2),
           around = 0.25 * (lum_at(W / 2 - 8, H / 2) + lum_at(W / 2 + 8, H / 2) +
                            lum_at(W / 2, H / 2 - 8) + lum_at(W / 2, H / 2 + 8));
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
    view.camera_fov_deg = 2;                             /* about 100 cd/m2 */
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
