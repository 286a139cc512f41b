/* Astronomy for the world simulation: UTC time stamps, the sun (NREL SPA, Reda & Andreas 2004)
 * and the moon (Meeus, Astronomical Algorithms 2nd ed., ch. 47/48) as seen from a site, and
 * sidereal time for the stars. Pure functions in double precision, valid for 1900..2100.
 *
 * Time scales: unix_seconds is UTC (POSIX, no leap seconds) and is taken as UT1 (|UT1-UTC| <
 * 0.9 s, below these algorithms' accuracy); dynamical time is UT + ΔT from the Espenak & Meeus
 * polynomials. Angles are degrees; azimuth runs from north through east in [0, 360). */
#ifndef SKYD_EPHEMERIS_H
#define SKYD_EPHEMERIS_H

#include <stdbool.h>
#include <stddef.h>

#include "utc_time.h" /* ISO 8601 time stamps */

struct world_site {
    double latitude_deg, longitude_deg /* east positive */, altitude_m;
    double pressure_mbar /* 1010 */, temperature_c /* 10 */; /* for refraction only */
};

struct world_body_position {
    double azimuth_deg;   /* from north through east, [0, 360) */
    double elevation_deg; /* topocentric, refracted when asked */
    double distance_km;   /* sun: geocentric; moon: from the site */
};

#define WORLD_SITE_PRESSURE_MBAR 1010.0
#define WORLD_SITE_TEMPERATURE_C 10.0

/* Apparent topocentric sun. Refraction is applied only while the sun's centre is above
 * -(0.26667 + 0.5667) deg, the SPA convention (below that the upper limb has set). */
void world_sun_position(double unix_seconds, const struct world_site *site, bool refraction,
                        struct world_body_position *out);

/* Apparent topocentric moon, refracted as the sun is; the illuminated fraction (0..1) and the
 * phase angle (deg, 0 = full) are geocentric (Meeus 48.1-48.3). Either may be NULL. */
void world_moon_position(double unix_seconds, const struct world_site *site, bool refraction,
                         struct world_body_position *out, double *illuminated_fraction,
                         double *phase_angle_deg);

/* Moonlight on a surface facing the moon, at the top of the atmosphere, in lux. */
double world_moon_illuminance_lux(double phase_angle_deg, double distance_km);

/* Apparent (true equinox) and mean sidereal time at Greenwich, [0, 360). */
double world_greenwich_sidereal_time_deg(double unix_seconds);
double world_greenwich_mean_sidereal_time_deg(double unix_seconds);
double world_local_sidereal_time_deg(double unix_seconds, double longitude_deg);

/* Right ascension and declination of date (no parallax: stars) to azimuth and elevation. */
void world_equatorial_to_horizontal(double ra_deg, double dec_deg, double unix_seconds,
                                    const struct world_site *site, double *azimuth_deg,
                                    double *elevation_deg);

/* The steps underneath, for tests and diagnostics. */
double world_julian_day(double unix_seconds);
double world_delta_t_seconds(double unix_seconds); /* TT - UT */
/* Apparent solar time minus mean solar time, minutes. */
double world_equation_of_time_min(double unix_seconds);
/* world_sun_position with an explicit ΔT instead of the polynomial. */
void world_sun_position_delta_t(double unix_seconds, double delta_t_s,
                                const struct world_site *site, bool refraction,
                                struct world_body_position *out);
/* Geocentric ecliptic longitude and latitude (mean equinox of date, without nutation) and
 * distance of the moon's centre at Julian Ephemeris Day jde. */
void world_moon_geocentric(double jde, double *lambda_deg, double *beta_deg, double *distance_km);
/* Geocentric apparent right ascension and declination of the moon at jde. */
void world_moon_geocentric_equatorial(double jde, double *ra_deg, double *dec_deg);
/* How much refraction lifts a body whose true elevation is true_elevation_deg. */
double world_refraction_deg(double true_elevation_deg, double pressure_mbar, double temperature_c);

#endif
