/* Steps shared by the sun and the moon (internal to the ephemeris module). */
#ifndef SKYD_EPHEMERIS_INTERNAL_H
#define SKYD_EPHEMERIS_INTERNAL_H

#include "ephemeris.h"

#define EPH_PI 3.14159265358979323846
#define EPH_RAD (EPH_PI / 180.0)
#define EPH_J2000 2451545.0
#define EPH_AU_KM 149597870.7
#define EPH_EARTH_RADIUS_KM 6378.14 /* the equatorial radius Meeus and SPA use */

double eph_wrap360(double deg);

/* Julian centuries of dynamical time from J2000.0 for Julian Ephemeris Day jde. */
static inline double eph_centuries(double jde)
{
    return (jde - EPH_J2000) / 36525.0;
}

struct eph_nutation {
    double dpsi_deg, deps_deg; /* in longitude and in obliquity */
    double obliquity_deg;      /* true obliquity of the ecliptic, ε0 + Δε */
};
void eph_nutation(double jce, struct eph_nutation *out);

/* Apparent sidereal time at Greenwich for Julian Day jd (UT). */
double eph_apparent_sidereal_deg(double jd, const struct eph_nutation *n);

/* Geocentric apparent equatorial place of the sun at jde. */
struct eph_sun_place {
    double ra_deg, dec_deg, distance_au;
    double mean_longitude_deg; /* for the equation of time */
};
void eph_sun_geocentric(double jde, const struct eph_nutation *n, struct eph_sun_place *out);

void eph_ecliptic_to_equatorial(double lambda_deg, double beta_deg, double obliquity_deg,
                                double *ra_deg, double *dec_deg);

/* ρ cos φ' and ρ sin φ' of the site, in equatorial radii of the Earth. */
void eph_site_geocentric(const struct world_site *site, double *rho_cos, double *rho_sin);

/* Parallax: moves a geocentric place (hour angle, declination) to the site, for a body whose
 * equatorial horizontal parallax has sine sin_parallax. */
void eph_topocentric(double hour_angle_deg, double dec_deg, double sin_parallax,
                     const struct world_site *site, double *topo_hour_angle_deg,
                     double *topo_dec_deg);

/* Hour angle and declination to azimuth (from north through east) and elevation, with
 * refraction added when asked. */
void eph_horizontal(double hour_angle_deg, double dec_deg, const struct world_site *site,
                    bool refraction, double *azimuth_deg, double *elevation_deg);

#endif
