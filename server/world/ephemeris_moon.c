/* The moon: Meeus, Astronomical Algorithms 2nd ed., ch. 47 (the truncated ELP-2000/82 of
 * tables 47.A and 47.B) for the geocentric place, ch. 40 for the parallax, ch. 48 for the
 * phase; and its brightness (Krisciunas & Schaefer 1991). */
#include "ephemeris_internal.h"

#include <math.h>
#include <stdlib.h>

#include "ephemeris_terms.h"

#define MOON_MEAN_DISTANCE_KM 384400.0

void world_moon_geocentric(double jde, double *lambda_deg, double *beta_deg, double *distance_km)
{
    double t = eph_centuries(jde), t2 = t * t, t3 = t2 * t, t4 = t3 * t;
    /* Mean longitude, elongation, sun's and moon's anomalies, argument of latitude: Meeus
     * 47.1-47.5. */
    double lp = eph_wrap360(218.3164477 + 481267.88123421 * t - 0.0015786 * t2 + t3 / 538841.0 -
                            t4 / 65194000.0);
    double d = eph_wrap360(297.8501921 + 445267.1114034 * t - 0.0018819 * t2 + t3 / 545868.0 -
                           t4 / 113065000.0);
    double m = eph_wrap360(357.5291092 + 35999.0502909 * t - 0.0001536 * t2 + t3 / 24490000.0);
    double mp = eph_wrap360(134.9633964 + 477198.8675055 * t + 0.0087414 * t2 + t3 / 69699.0 -
                            t4 / 14712000.0);
    double f = eph_wrap360(93.2720950 + 483202.0175233 * t - 0.0036539 * t2 - t3 / 3526000.0 +
                           t4 / 863310000.0);
    /* Venus, Jupiter and flattening arguments, and the eccentricity factor: Meeus p. 338. */
    double a1 = eph_wrap360(119.75 + 131.849 * t) * EPH_RAD;
    double a2 = eph_wrap360(53.09 + 479264.290 * t) * EPH_RAD;
    double a3 = eph_wrap360(313.45 + 481266.484 * t) * EPH_RAD;
    double e = 1.0 - 0.002516 * t - 0.0000074 * t2; /* Meeus 47.6 */
    double e_power[3] = { 1.0, e, e * e };
    double args[4] = { d * EPH_RAD, m * EPH_RAD, mp * EPH_RAD, f * EPH_RAD };

    double sum_l = 0.0, sum_r = 0.0, sum_b = 0.0;
    for (int i = 0; i < EPH_MOON_TERMS; i++) {
        const struct eph_moon_lr_term *lr = &eph_moon_lr_terms[i];
        double arg = 0.0;
        for (int j = 0; j < 4; j++)
            arg += lr->multiple[j] * args[j];
        double scale = e_power[abs(lr->multiple[1])];
        sum_l += lr->sigma_l * scale * sin(arg);
        sum_r += lr->sigma_r * scale * cos(arg);

        const struct eph_moon_b_term *b = &eph_moon_b_terms[i];
        arg = 0.0;
        for (int j = 0; j < 4; j++)
            arg += b->multiple[j] * args[j];
        sum_b += b->sigma_b * e_power[abs(b->multiple[1])] * sin(arg);
    }
    double lpr = lp * EPH_RAD, fr = args[3], mpr = args[2];
    /* Additive terms, Meeus p. 342. */
    sum_l += 3958.0 * sin(a1) + 1962.0 * sin(lpr - fr) + 318.0 * sin(a2);
    sum_b += -2235.0 * sin(lpr) + 382.0 * sin(a3) + 175.0 * sin(a1 - fr) + 175.0 * sin(a1 + fr) +
             127.0 * sin(lpr - mpr) - 115.0 * sin(lpr + mpr);

    *lambda_deg = eph_wrap360(lp + sum_l / 1e6);
    *beta_deg = sum_b / 1e6;
    *distance_km = 385000.56 + sum_r / 1000.0;
}

static void moon_apparent(double jde, const struct eph_nutation *n, double *ra_deg, double *dec_deg,
                          double *distance_km)
{
    double lambda, beta;
    world_moon_geocentric(jde, &lambda, &beta, distance_km);
    /* Apparent longitude: add the nutation in longitude (Meeus ch. 47). */
    eph_ecliptic_to_equatorial(lambda + n->dpsi_deg, beta, n->obliquity_deg, ra_deg, dec_deg);
}

void world_moon_geocentric_equatorial(double jde, double *ra_deg, double *dec_deg)
{
    struct eph_nutation n;
    eph_nutation(eph_centuries(jde), &n);
    double distance;
    moon_apparent(jde, &n, ra_deg, dec_deg, &distance);
}

/* Distance from the site to a body at geocentric distance r_km in (hour angle, declination):
 * the length of the difference of the two vectors in the equatorial frame of the meridian. */
static double topocentric_distance_km(double hour_angle_deg, double dec_deg, double r_km,
                                      const struct world_site *site)
{
    double h = hour_angle_deg * EPH_RAD, dec = dec_deg * EPH_RAD, rho_cos, rho_sin;
    eph_site_geocentric(site, &rho_cos, &rho_sin);
    double dx = r_km * cos(dec) * cos(h) - rho_cos * EPH_EARTH_RADIUS_KM;
    double dy = r_km * cos(dec) * sin(h);
    double dz = r_km * sin(dec) - rho_sin * EPH_EARTH_RADIUS_KM;
    return sqrt(dx * dx + dy * dy + dz * dz);
}

void world_moon_position(double unix_seconds, const struct world_site *site, bool refraction,
                         struct world_body_position *out, double *illuminated_fraction,
                         double *phase_angle_deg)
{
    double jd = world_julian_day(unix_seconds);
    double jde = jd + world_delta_t_seconds(unix_seconds) / 86400.0;
    struct eph_nutation n;
    eph_nutation(eph_centuries(jde), &n);
    double ra, dec, distance;
    moon_apparent(jde, &n, &ra, &dec, &distance);

    if (out) {
        /* Hour angle from apparent sidereal time; sin π = a / Δ (Meeus ch. 40). */
        double h = eph_apparent_sidereal_deg(jd, &n) + site->longitude_deg - ra;
        double topo_h, topo_dec;
        eph_topocentric(h, dec, EPH_EARTH_RADIUS_KM / distance, site, &topo_h, &topo_dec);
        eph_horizontal(topo_h, topo_dec, site, refraction, &out->azimuth_deg, &out->elevation_deg);
        out->distance_km = topocentric_distance_km(h, dec, distance, site);
    }
    if (illuminated_fraction || phase_angle_deg) {
        struct eph_sun_place sun;
        eph_sun_geocentric(jde, &n, &sun);
        double r = sun.distance_au * EPH_AU_KM;
        double d0 = sun.dec_deg * EPH_RAD, d1 = dec * EPH_RAD;
        /* Geocentric elongation (Meeus 48.2), phase angle (48.3), illuminated fraction (48.1). */
        double cos_psi = sin(d0) * sin(d1) + cos(d0) * cos(d1) * cos((sun.ra_deg - ra) * EPH_RAD);
        double psi = acos(fmax(-1.0, fmin(1.0, cos_psi)));
        double i = atan2(r * sin(psi), distance - r * cos(psi));
        if (illuminated_fraction)
            *illuminated_fraction = (1.0 + cos(i)) / 2.0;
        if (phase_angle_deg)
            *phase_angle_deg = i / EPH_RAD;
    }
}

double world_moon_illuminance_lux(double phase_angle_deg, double distance_km)
{
    double a = fmin(fabs(phase_angle_deg), 180.0);
    /* The moon's V magnitude at phase angle a: Krisciunas & Schaefer 1991, eq. 9 (after Allen
     * 1973), at the mean distance. */
    double v = -12.73 + 0.026 * a + 4e-9 * a * a * a * a;
    /* V = -14.18 - 2.5 log10(E / 1 lx), the zero point that gives the usual 0.26 lx full moon;
     * inverse square of the distance from the mean. */
    double scale = MOON_MEAN_DISTANCE_KM / distance_km;
    return pow(10.0, -0.4 * (v + 14.18)) * scale * scale;
}
