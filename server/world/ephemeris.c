/* The sun by the NREL Solar Position Algorithm (Reda & Andreas 2004, NREL/TP-560-34302;
 * equations cited as "SPA eq. n"), and the Earth-orientation steps the moon and the stars share
 * with it: nutation, obliquity, sidereal time, parallax, horizontal coordinates, refraction. */
#include "ephemeris_internal.h"

#include <math.h>

#include "ephemeris_terms.h"

/* The Earth's polar to equatorial radius, b/a (SPA eqs. 34-36, Meeus ch. 11). */
#define EARTH_AXIS_RATIO 0.99664719
/* SPA: refraction stops when the sun's upper limb is below the horizon. */
#define SUN_RADIUS_DEG 0.26667
#define HORIZON_REFRACTION_DEG 0.5667

double eph_wrap360(double deg)
{
    double w = fmod(deg, 360.0);
    if (w < 0.0)
        w += 360.0;
    return w >= 360.0 ? 0.0 : w;
}

static double polynomial(const double *c, int n, double x)
{
    double sum = 0.0;
    for (int i = n - 1; i >= 0; i--)
        sum = sum * x + c[i];
    return sum;
}

void eph_nutation(double jce, struct eph_nutation *out)
{
    /* SPA eqs. 15-19: mean elongation of the moon, anomalies of the sun and moon, the moon's
     * argument of latitude and the longitude of its ascending node, in degrees. */
    static const double args[5][4] = {
        { 297.85036, 445267.111480, -0.0019142, 1.0 / 189474.0 },
        { 357.52772, 35999.050340, -0.0001603, -1.0 / 300000.0 },
        { 134.96298, 477198.867398, 0.0086972, 1.0 / 56250.0 },
        { 93.27191, 483202.017538, -0.0036825, 1.0 / 327270.0 },
        { 125.04452, -1934.136261, 0.0020708, 1.0 / 450000.0 },
    };
    double x[5];
    for (int j = 0; j < 5; j++)
        x[j] = polynomial(args[j], 4, jce);

    /* SPA eqs. 20-23 (Meeus 22.A): sums in 0.0001". */
    double dpsi = 0.0, deps = 0.0;
    for (int i = 0; i < EPH_NUTATION_TERMS; i++) {
        const struct eph_nutation_term *t = &eph_nutation_terms[i];
        double arg = 0.0;
        for (int j = 0; j < 5; j++)
            arg += t->multiple[j] * x[j];
        arg *= EPH_RAD;
        dpsi += (t->a + t->b * jce) * sin(arg);
        deps += (t->c + t->d * jce) * cos(arg);
    }
    out->dpsi_deg = dpsi / 36000000.0;
    out->deps_deg = deps / 36000000.0;

    /* Mean obliquity, Laskar 1986 (Meeus 22.3, SPA eq. 24), U in units of 10000 years. */
    static const double laskar[11] = { 84381.448, -4680.93, -1.55, 1999.25, -51.38, -249.67,
                                       -39.05,    7.12,     27.87, 5.79,    2.45 };
    double epsilon0_arcsec = polynomial(laskar, 11, jce / 100.0);
    out->obliquity_deg = epsilon0_arcsec / 3600.0 + out->deps_deg; /* SPA eq. 25 */
}

static double mean_sidereal_deg(double jd)
{
    double t = (jd - EPH_J2000) / 36525.0;
    /* Meeus 12.4 (SPA eq. 28). */
    return eph_wrap360(280.46061837 + 360.98564736629 * (jd - EPH_J2000) +
                       t * t * (0.000387933 - t / 38710000.0));
}

double eph_apparent_sidereal_deg(double jd, const struct eph_nutation *n)
{
    /* Equation of the equinoxes, Meeus ch. 12 (SPA eq. 29). */
    return eph_wrap360(mean_sidereal_deg(jd) + n->dpsi_deg * cos(n->obliquity_deg * EPH_RAD));
}

void eph_ecliptic_to_equatorial(double lambda_deg, double beta_deg, double obliquity_deg,
                                double *ra_deg, double *dec_deg)
{
    double l = lambda_deg * EPH_RAD, b = beta_deg * EPH_RAD, e = obliquity_deg * EPH_RAD;
    /* Meeus 13.3 and 13.4 (SPA eqs. 30 and 31). */
    *ra_deg = eph_wrap360(atan2(sin(l) * cos(e) - tan(b) * sin(e), cos(l)) / EPH_RAD);
    *dec_deg = asin(sin(b) * cos(e) + cos(b) * sin(e) * sin(l)) / EPH_RAD;
}

static double vsop_sum(const struct eph_vsop_series *series, int count, double tau)
{
    /* SPA eqs. 9-11: Σ_i tau^i Σ_k a cos(b + c tau), in 1e-8 units. */
    double sum = 0.0, power = 1.0;
    for (int i = 0; i < count; i++) {
        double s = 0.0;
        for (int k = 0; k < series[i].count; k++) {
            const struct eph_vsop_term *t = &series[i].terms[k];
            s += t->a * cos(t->b + t->c * tau);
        }
        sum += s * power;
        power *= tau;
    }
    return sum / 1e8;
}

void eph_sun_geocentric(double jde, const struct eph_nutation *n, struct eph_sun_place *out)
{
    double jme = (jde - EPH_J2000) / 365250.0;
    double earth_l = vsop_sum(eph_earth_l, 6, jme) / EPH_RAD;
    double earth_b = vsop_sum(eph_earth_b, 2, jme) / EPH_RAD;
    double r = vsop_sum(eph_earth_r, 5, jme);
    /* Geocentric longitude and latitude (SPA eqs. 13-14), aberration (eq. 26), apparent
     * longitude (eq. 27). */
    double theta = eph_wrap360(earth_l + 180.0), beta = -earth_b;
    double aberration = -20.4898 / (3600.0 * r);
    double lambda = theta + n->dpsi_deg + aberration;
    eph_ecliptic_to_equatorial(lambda, beta, n->obliquity_deg, &out->ra_deg, &out->dec_deg);
    out->distance_au = r;
    /* The sun's mean longitude, SPA eq. A2. */
    static const double mean_longitude[6] = { 280.4664567,   360007.6982779, 0.03032028,
                                              1.0 / 49931.0, -1.0 / 15300.0, -1.0 / 2000000.0 };
    out->mean_longitude_deg = eph_wrap360(polynomial(mean_longitude, 6, jme));
}

void eph_site_geocentric(const struct world_site *site, double *rho_cos, double *rho_sin)
{
    double phi = site->latitude_deg * EPH_RAD;
    double height = site->altitude_m / (EPH_EARTH_RADIUS_KM * 1000.0);
    /* Meeus ch. 11 (SPA eqs. 34-36); atan2 keeps the poles finite. */
    double u = atan2(EARTH_AXIS_RATIO * sin(phi), cos(phi));
    *rho_cos = cos(u) + height * cos(phi);
    *rho_sin = EARTH_AXIS_RATIO * sin(u) + height * sin(phi);
}

void eph_topocentric(double hour_angle_deg, double dec_deg, double sin_parallax,
                     const struct world_site *site, double *topo_hour_angle_deg,
                     double *topo_dec_deg)
{
    double h = hour_angle_deg * EPH_RAD, dec = dec_deg * EPH_RAD, x, y;
    eph_site_geocentric(site, &x, &y);
    /* Meeus 40.2-40.3 (SPA eqs. 37 and 39). */
    double denominator = cos(dec) - x * sin_parallax * cos(h);
    double dalpha = atan2(-x * sin_parallax * sin(h), denominator);
    *topo_dec_deg = atan2((sin(dec) - y * sin_parallax) * cos(dalpha), denominator) / EPH_RAD;
    *topo_hour_angle_deg = hour_angle_deg - dalpha / EPH_RAD; /* SPA eq. 40 */
}

double world_refraction_deg(double true_elevation_deg, double pressure_mbar, double temperature_c)
{
    double e0 = true_elevation_deg;
    if (pressure_mbar <= 0.0 || e0 < -(SUN_RADIUS_DEG + HORIZON_REFRACTION_DEG))
        return 0.0;
    /* Bennett 1982 as SPA eq. 42 writes it. */
    return pressure_mbar / 1010.0 * 283.0 / (273.0 + temperature_c) * 1.02 /
           (60.0 * tan((e0 + 10.3 / (e0 + 5.11)) * EPH_RAD));
}

void eph_horizontal(double hour_angle_deg, double dec_deg, const struct world_site *site,
                    bool refraction, double *azimuth_deg, double *elevation_deg)
{
    double phi = site->latitude_deg * EPH_RAD, h = hour_angle_deg * EPH_RAD;
    double dec = dec_deg * EPH_RAD;
    /* SPA eq. 41 (Meeus 13.6); the azimuth of SPA eqs. 45-46 with both arguments times
     * cos δ, which keeps the poles finite. */
    double sin_e = sin(phi) * sin(dec) + cos(phi) * cos(dec) * cos(h);
    double e0 = asin(fmax(-1.0, fmin(1.0, sin_e))) / EPH_RAD;
    double gamma = atan2(sin(h) * cos(dec), cos(h) * sin(phi) * cos(dec) - sin(dec) * cos(phi));
    *azimuth_deg = eph_wrap360(gamma / EPH_RAD + 180.0);
    *elevation_deg = e0;
    if (refraction)
        *elevation_deg += world_refraction_deg(e0, site->pressure_mbar, site->temperature_c);
}

void world_sun_position_delta_t(double unix_seconds, double delta_t_s,
                                const struct world_site *site, bool refraction,
                                struct world_body_position *out)
{
    double jd = world_julian_day(unix_seconds), jde = jd + delta_t_s / 86400.0;
    struct eph_nutation n;
    eph_nutation(eph_centuries(jde), &n);
    struct eph_sun_place sun;
    eph_sun_geocentric(jde, &n, &sun);
    /* Local hour angle (SPA eq. 32); equatorial horizontal parallax 8.794" at 1 au (eq. 33). */
    double h = eph_apparent_sidereal_deg(jd, &n) + site->longitude_deg - sun.ra_deg;
    double xi = 8.794 / (3600.0 * sun.distance_au) * EPH_RAD;
    double topo_h, topo_dec;
    eph_topocentric(h, sun.dec_deg, sin(xi), site, &topo_h, &topo_dec);
    eph_horizontal(topo_h, topo_dec, site, refraction, &out->azimuth_deg, &out->elevation_deg);
    out->distance_km = sun.distance_au * EPH_AU_KM;
}

void world_sun_position(double unix_seconds, const struct world_site *site, bool refraction,
                        struct world_body_position *out)
{
    world_sun_position_delta_t(unix_seconds, world_delta_t_seconds(unix_seconds), site, refraction,
                               out);
}

double world_equation_of_time_min(double unix_seconds)
{
    double jde = world_julian_day(unix_seconds) + world_delta_t_seconds(unix_seconds) / 86400.0;
    struct eph_nutation n;
    eph_nutation(eph_centuries(jde), &n);
    struct eph_sun_place sun;
    eph_sun_geocentric(jde, &n, &sun);
    /* SPA eq. A1, reduced to (-180, 180] deg (the ±20 minutes limit), 4 minutes per degree. */
    double e = sun.mean_longitude_deg - 0.0057183 - sun.ra_deg +
               n.dpsi_deg * cos(n.obliquity_deg * EPH_RAD);
    return 4.0 * remainder(e, 360.0);
}

double world_greenwich_mean_sidereal_time_deg(double unix_seconds)
{
    return mean_sidereal_deg(world_julian_day(unix_seconds));
}

double world_greenwich_sidereal_time_deg(double unix_seconds)
{
    double jd = world_julian_day(unix_seconds);
    struct eph_nutation n;
    eph_nutation(eph_centuries(jd + world_delta_t_seconds(unix_seconds) / 86400.0), &n);
    return eph_apparent_sidereal_deg(jd, &n);
}

double world_local_sidereal_time_deg(double unix_seconds, double longitude_deg)
{
    return eph_wrap360(world_greenwich_sidereal_time_deg(unix_seconds) + longitude_deg);
}

void world_equatorial_to_horizontal(double ra_deg, double dec_deg, double unix_seconds,
                                    const struct world_site *site, double *azimuth_deg,
                                    double *elevation_deg)
{
    double h = world_local_sidereal_time_deg(unix_seconds, site->longitude_deg) - ra_deg;
    eph_horizontal(h, dec_deg, site, false, azimuth_deg, elevation_deg);
}
