/* The ephemeris: ISO 8601 time stamps, the sun against the SPA paper's example and the moon
 * against Meeus's, sidereal time against Meeus 12.a, and both bodies against PyEphem over
 * 1900..2100 at sites on both hemispheres (tests/unit/ephemeris_reference.h). */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "check.h"
#include "ephemeris.h"
#include "ephemeris_reference.h"

#define RAD (3.14159265358979323846 / 180.0)
#define REFERENCE_COUNT (sizeof ephemeris_reference / sizeof ephemeris_reference[0])
/* SPA stops refracting when the sun's centre is below -(0.26667 + 0.5667) deg; PyEphem does
 * not, so refracted places are compared above -0.8 deg only. Below 1 deg the two empirical
 * formulas (Bennett's in SPA, on the true elevation; libastro's, on the apparent one) part by up
 * to 0.015 deg in cold air, so the sun gets 0.02 deg there and 0.01 deg above. */
#define REFRACTION_FLOOR_DEG (-0.8)
#define REFRACTION_LOW_DEG 1.0

/* Angle between two directions given as (azimuth, elevation), degrees (haversine). */
static double separation_deg(double az1, double el1, double az2, double el2)
{
    double s_el = sin((el2 - el1) * RAD / 2.0), s_az = sin((az2 - az1) * RAD / 2.0);
    double h = s_el * s_el + cos(el1 * RAD) * cos(el2 * RAD) * s_az * s_az;
    return 2.0 * asin(sqrt(fmin(1.0, h))) / RAD;
}

static double parse(const char *text)
{
    double t = NAN;
    char err[160] = "";
    if (!proto_time_parse_iso8601(text, &t, err, sizeof err))
        printf("  parse \"%s\": %s\n", text, err);
    return t;
}

static void check_rejected(const char *text, const char *reason_part)
{
    double t = 12345.0;
    char err[160] = "";
    bool ok = proto_time_parse_iso8601(text, &t, err, sizeof err);
    CHECK(!ok);
    CHECK(t == 12345.0);
    if (!ok && !strstr(err, reason_part)) {
        check_failed++;
        printf("FAIL: \"%s\" rejected with \"%s\", expected a reason naming \"%s\"\n", text, err,
               reason_part);
    }
}

static void test_time(void)
{
    char text[64];
    /* Known POSIX times of the range's ends and of a date with an offset. */
    CHECK_NEAR(parse("1900-01-01T00:00:00Z"), -2208988800.0, 0.0);
    CHECK_NEAR(parse("2100-12-31T23:59:59Z"), 4133980799.0, 0.0);
    CHECK_NEAR(parse("1970-01-01T00:00Z"), 0.0, 0.0);
    CHECK_NEAR(parse("2003-10-17T12:30:30-07:00"), parse("2003-10-17T19:30:30Z"), 0.0);
    CHECK_NEAR(parse("2003-10-17 19:30:30+05:45"), parse("2003-10-17T13:45:30Z"), 0.0);
    CHECK_NEAR(parse("2024-02-29t12:00:00.25z"), parse("2024-02-29T12:00:00Z") + 0.25, 1e-6);
    CHECK_NEAR(parse("2000-02-29T00:00Z") + 86400.0, parse("2000-03-01T00:00Z"), 0.0);
    CHECK_NEAR(parse("2100-02-28T00:00Z") + 86400.0, parse("2100-03-01T00:00Z"), 0.0);

    proto_time_format_iso8601(parse("2026-06-21T12:00:00Z"), text, sizeof text);
    CHECK(strcmp(text, "2026-06-21T12:00:00Z") == 0);
    proto_time_format_iso8601(parse("1905-03-04T05:06:07.250+01:00"), text, sizeof text);
    CHECK(strcmp(text, "1905-03-04T04:06:07.250Z") == 0);
    proto_time_format_iso8601(-2208988800.0 - 0.5, text, sizeof text);
    CHECK(strcmp(text, "1899-12-31T23:59:59.500Z") == 0);

    /* Round trips every 3 days and some hours over 1900..2100, and the table's own times (whose
     * POSIX seconds came from Python's calendar module). */
    int mismatches = 0;
    for (double t = -2208988800.0; t < 4133980800.0; t += 3 * 86400.0 + 3671.0) {
        proto_time_format_iso8601(t, text, sizeof text);
        if (parse(text) != t && mismatches++ < 5)
            printf("FAIL: round trip of %.0f through \"%s\"\n", t, text);
    }
    CHECK(mismatches == 0);
    for (size_t i = 0; i < REFERENCE_COUNT; i++) {
        const struct ephemeris_reference *c = &ephemeris_reference[i];
        CHECK_NEAR(parse(c->time), c->unix_seconds, 1e-5);
        proto_time_format_iso8601(c->unix_seconds, text, sizeof text);
        CHECK_NEAR(parse(text), c->unix_seconds, 1e-5);
    }

    check_rejected("", "empty");
    check_rejected("2026-06-21", "time");
    check_rejected("2026-06-21T12:00", "time zone");
    check_rejected("2026-06-21T12:00:00", "time zone");
    check_rejected("26-06-21T12:00Z", "date");
    check_rejected("2026/06/21T12:00Z", "date");
    check_rejected("2026-13-01T00:00Z", "month");
    check_rejected("2026-02-29T00:00Z", "day");
    check_rejected("1900-02-29T00:00Z", "day");
    check_rejected("2026-04-31T00:00Z", "day");
    check_rejected("2026-06-21T24:00Z", "hour");
    check_rejected("2026-06-21T12:60Z", "minute");
    check_rejected("2026-06-21T12:00:60Z", "second");
    check_rejected("2026-06-21T12:00:00.Z", "fractional");
    check_rejected("2026-06-21T12:00+2:00", "offset");
    check_rejected("2026-06-21T12:00+24:00", "offset");
    check_rejected("2026-06-21T12:00Z junk", "unexpected");
    check_rejected("2026-06-21T12:00 UTC", "unexpected");
}

static void test_spa_example(void)
{
    /* Reda & Andreas 2004, table A5.1: 2003-10-17 12:30:30 at UTC-7, ΔT = 67 s. */
    double t = parse("2003-10-17T12:30:30-07:00");
    struct world_site site = { 39.742476, -105.1786, 1830.14, 820.0, 11.0 };
    struct world_body_position p;
    world_sun_position_delta_t(t, 67.0, &site, true, &p);
    CHECK_NEAR(90.0 - p.elevation_deg, 50.11162, 0.00001);
    CHECK_NEAR(p.azimuth_deg, 194.34024, 0.00001);
    CHECK_NEAR(p.distance_km / 149597870.7, 0.9965422974, 1e-9);
    /* The same through the ΔT polynomial, which differs by a few seconds in 2003. */
    world_sun_position(t, &site, true, &p);
    CHECK_NEAR(90.0 - p.elevation_deg, 50.11162, 0.001);
    CHECK_NEAR(p.azimuth_deg, 194.34024, 0.001);
    CHECK_NEAR(world_equation_of_time_min(t), 14.641503, 1e-4);
}

static void test_moon_example(void)
{
    /* Meeus example 47.a: 1992-04-12 0h TD. */
    double lambda, beta, distance, ra, dec;
    world_moon_geocentric(2448724.5, &lambda, &beta, &distance);
    CHECK_NEAR(lambda, 133.162655, 1e-6);
    CHECK_NEAR(beta, -3.229126, 1e-6);
    CHECK_NEAR(distance, 368409.7, 0.1);
    world_moon_geocentric_equatorial(2448724.5, &ra, &dec);
    CHECK_NEAR(ra, 134.688470, 3e-6);
    CHECK_NEAR(dec, 13.768368, 3e-6);
}

static void test_sidereal_time(void)
{
    /* Meeus example 12.a: 1987-04-10 0h UT, mean 13h10m46.3668s, apparent 13h10m46.1351s. */
    double t = parse("1987-04-10T00:00:00Z");
    double hms = (13.0 + 10.0 / 60.0) * 15.0;
    CHECK_NEAR(world_greenwich_mean_sidereal_time_deg(t), hms + 46.3668 / 240.0, 0.0001 / 240.0);
    CHECK_NEAR(world_greenwich_sidereal_time_deg(t), hms + 46.1351 / 240.0, 0.001 / 240.0);
    CHECK_NEAR(world_local_sidereal_time_deg(t, -77.0), hms + 46.1351 / 240.0 - 77.0,
               0.001 / 240.0);
    CHECK_NEAR(world_local_sidereal_time_deg(t, 170.0), hms + 46.1351 / 240.0 + 170.0 - 360.0,
               0.001 / 240.0);

    /* Stars: the celestial pole stands at the latitude due north; a star on the meridian at
     * declination 0 culminates at 90 - latitude due south. */
    struct world_site site = { 48.0, 11.0, 500.0, 1010.0, 10.0 };
    double az, el;
    world_equatorial_to_horizontal(123.0, 90.0, t, &site, &az, &el);
    CHECK_NEAR(el, 48.0, 1e-9);
    CHECK(fabs(remainder(az, 360.0)) < 1e-6);
    world_equatorial_to_horizontal(world_local_sidereal_time_deg(t, 11.0), 0.0, t, &site, &az, &el);
    CHECK_NEAR(el, 42.0, 1e-9);
    CHECK_NEAR(az, 180.0, 1e-6);
    /* Six sidereal hours later the same star sets due west. */
    world_equatorial_to_horizontal(world_local_sidereal_time_deg(t, 11.0) - 90.0, 0.0, t, &site,
                                   &az, &el);
    CHECK_NEAR(el, 0.0, 1e-9);
    CHECK_NEAR(az, 270.0, 1e-6);
}

static void test_delta_t(void)
{
    /* Observed ΔT (Meeus table 10.A) at the start of some years, within a second. */
    static const struct {
        const char *time;
        double delta_t;
    } observed[] = {
        { "1900-01-01T00:00Z", -2.7 }, { "1920-01-01T00:00Z", 21.2 }, { "1940-01-01T00:00Z", 24.3 },
        { "1960-01-01T00:00Z", 33.2 }, { "1980-01-01T00:00Z", 50.5 }, { "2000-01-01T00:00Z", 63.8 },
    };
    for (size_t i = 0; i < sizeof observed / sizeof observed[0]; i++)
        CHECK_NEAR(world_delta_t_seconds(parse(observed[i].time)), observed[i].delta_t, 1.0);
    /* The polynomials join without jumps of more than a second over 1900..2100. */
    double previous = world_delta_t_seconds(parse("1900-01-01T00:00Z"));
    double largest_step = 0.0;
    for (double t = parse("1900-01-01T00:00Z"); t < 4133980800.0; t += 86400.0 * 30) {
        double dt = world_delta_t_seconds(t);
        largest_step = fmax(largest_step, fabs(dt - previous));
        previous = dt;
    }
    CHECK_LE(largest_step, 1.0);
}

struct error_stats {
    double max, sum;
    int count;
};

static void add_error(struct error_stats *s, double error)
{
    s->max = fmax(s->max, error);
    s->sum += error;
    s->count++;
}

static void check_case(const struct ephemeris_reference *c, const char *what, double error,
                       double tolerance)
{
    if (error <= tolerance) {
        check_passed++;
        return;
    }
    check_failed++;
    printf("FAIL %s %s (%.4f, %.4f): %s error %.5f deg > %.3f\n", c->site, c->time, c->latitude_deg,
           c->longitude_deg, what, error, tolerance);
}

static void test_reference_table(void)
{
    struct error_stats sun = { 0 }, sun_refracted = { 0 }, sun_refracted_low = { 0 };
    struct error_stats moon = { 0 }, moon_refracted = { 0 }, fraction = { 0 }, distance = { 0 };
    int refracted_near_horizon = 0;
    CHECK(REFERENCE_COUNT >= 60);
    for (size_t i = 0; i < REFERENCE_COUNT; i++) {
        const struct ephemeris_reference *c = &ephemeris_reference[i];
        struct world_site site = { c->latitude_deg, c->longitude_deg, c->altitude_m,
                                   c->pressure_mbar, c->temperature_c };
        struct world_body_position p, pr;
        double e;

        world_sun_position(c->unix_seconds, &site, false, &p);
        world_sun_position(c->unix_seconds, &site, true, &pr);
        e = separation_deg(p.azimuth_deg, p.elevation_deg, c->sun_azimuth_deg,
                           c->sun_elevation_deg);
        add_error(&sun, e);
        check_case(c, "sun", e, 0.01);
        CHECK(p.azimuth_deg >= 0.0 && p.azimuth_deg < 360.0);
        if (c->sun_elevation_deg >= REFRACTION_FLOOR_DEG) {
            bool low = c->sun_elevation_deg < REFRACTION_LOW_DEG;
            e = separation_deg(pr.azimuth_deg, pr.elevation_deg, c->sun_azimuth_deg,
                               c->sun_elevation_refracted_deg);
            add_error(low ? &sun_refracted_low : &sun_refracted, e);
            check_case(c, "refracted sun", e, low ? 0.02 : 0.01);
            refracted_near_horizon += !low && c->sun_elevation_deg < 5.0;
        } else if (c->sun_elevation_deg < -0.9) {
            CHECK(pr.elevation_deg == p.elevation_deg);
        }

        double k, phase_angle;
        world_moon_position(c->unix_seconds, &site, false, &p, &k, &phase_angle);
        world_moon_position(c->unix_seconds, &site, true, &pr, NULL, NULL);
        e = separation_deg(p.azimuth_deg, p.elevation_deg, c->moon_azimuth_deg,
                           c->moon_elevation_deg);
        add_error(&moon, e);
        check_case(c, "moon", e, 0.3);
        if (c->moon_elevation_deg >= REFRACTION_FLOOR_DEG) {
            e = separation_deg(pr.azimuth_deg, pr.elevation_deg, c->moon_azimuth_deg,
                               c->moon_elevation_refracted_deg);
            add_error(&moon_refracted, e);
            check_case(c, "refracted moon", e, 0.3);
        }
        e = fabs(k - c->moon_illuminated_fraction);
        add_error(&fraction, e);
        check_case(c, "moon illuminated fraction", e, 0.02);
        CHECK_NEAR(k, (1.0 + cos(phase_angle * RAD)) / 2.0, 1e-12);

        /* PyEphem's earth_distance of the moon is from the site when computed for one. */
        e = fabs(p.distance_km - c->moon_distance_km);
        add_error(&distance, e);
        check_case(c, "moon distance (km, not deg)", e, 30.0);
    }
    CHECK(refracted_near_horizon >= 5 && sun_refracted_low.count >= 5);
    printf("against PyEphem (%d cases), separation on the sky in degrees, max / mean:\n",
           (int)REFERENCE_COUNT);
    printf("  sun            %.5f / %.5f\n", sun.max, sun.sum / sun.count);
    printf("  sun refracted  %.5f / %.5f (%d cases above %g deg, %d of them below 5 deg)\n",
           sun_refracted.max, sun_refracted.sum / sun_refracted.count, sun_refracted.count,
           REFRACTION_LOW_DEG, refracted_near_horizon);
    printf("  sun refracted  %.5f / %.5f (%d cases from %g to %g deg)\n", sun_refracted_low.max,
           sun_refracted_low.sum / sun_refracted_low.count, sun_refracted_low.count,
           REFRACTION_FLOOR_DEG, REFRACTION_LOW_DEG);
    printf("  moon           %.5f / %.5f\n", moon.max, moon.sum / moon.count);
    printf("  moon refracted %.5f / %.5f (%d cases)\n", moon_refracted.max,
           moon_refracted.sum / moon_refracted.count, moon_refracted.count);
    printf("  moon illuminated fraction %.5f / %.5f, distance %.1f / %.1f km\n", fraction.max,
           fraction.sum / fraction.count, distance.max, distance.sum / distance.count);
}

static void test_refraction(void)
{
    /* Bennett: about 29' at the horizon at 1010 mbar and 10 C, nearly 0 at the zenith. */
    CHECK_NEAR(world_refraction_deg(0.0, 1010.0, 10.0), 0.483, 0.005);
    CHECK_LE(world_refraction_deg(89.9, 1010.0, 10.0), 0.0001);
    CHECK(world_refraction_deg(5.0, 1010.0, 10.0) > world_refraction_deg(10.0, 1010.0, 10.0));
    CHECK(world_refraction_deg(5.0, 820.0, 10.0) < world_refraction_deg(5.0, 1010.0, 10.0));
    CHECK(world_refraction_deg(5.0, 1010.0, -20.0) > world_refraction_deg(5.0, 1010.0, 30.0));
    CHECK(world_refraction_deg(-0.8, 1010.0, 10.0) > 0.5);
    CHECK(world_refraction_deg(-0.9, 1010.0, 10.0) == 0.0);
    CHECK(world_refraction_deg(10.0, 0.0, 10.0) == 0.0);
}

static void test_moon_illuminance(void)
{
    double full = world_moon_illuminance_lux(0.0, 384400.0);
    CHECK(full >= 0.2 && full <= 0.35);
    CHECK_NEAR(world_moon_illuminance_lux(0.0, 384400.0 / 1.1), full * 1.21, 1e-12);
    double previous = full;
    bool decreasing = true;
    for (double a = 1.0; a <= 180.0; a += 1.0) {
        double e = world_moon_illuminance_lux(a, 384400.0);
        decreasing = decreasing && e < previous && e > 0.0;
        previous = e;
    }
    CHECK(decreasing);
    /* A quarter moon gives roughly a tenth of the full moon's light (opposition surge). */
    double quarter = world_moon_illuminance_lux(90.0, 384400.0) / full;
    CHECK(quarter > 0.07 && quarter < 0.12);
    CHECK_NEAR(world_moon_illuminance_lux(-60.0, 384400.0),
               world_moon_illuminance_lux(60.0, 384400.0), 0.0);
}

int main(void)
{
    test_time();
    test_spa_example();
    test_moon_example();
    test_sidereal_time();
    test_delta_t();
    test_refraction();
    test_moon_illuminance();
    test_reference_table();
    return check_summary();
}
