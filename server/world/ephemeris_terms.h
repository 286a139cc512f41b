/* Periodic-term tables of the ephemeris (internal): the Earth's heliocentric position (VSOP87
 * as truncated by Reda & Andreas 2004, table A4.2), nutation (IAU 1980 as truncated in Meeus
 * table 22.A and SPA table A4.3) and the moon (Meeus tables 47.A and 47.B). */
#ifndef SKYD_EPHEMERIS_TERMS_H
#define SKYD_EPHEMERIS_TERMS_H

/* One VSOP87 term: a cos(b + c tau), tau in Julian millennia from J2000.0. */
struct eph_vsop_term {
    double a, b, c;
};

struct eph_vsop_series {
    const struct eph_vsop_term *terms;
    int count;
};

/* Earth's heliocentric longitude L0..L5, latitude B0..B1, radius R0..R4 (units of 1e-8 rad
 * and 1e-8 au). */
extern const struct eph_vsop_series eph_earth_l[6];
extern const struct eph_vsop_series eph_earth_b[2];
extern const struct eph_vsop_series eph_earth_r[5];

/* Multiples of D, M, M', F, Omega; (a + b T) sin(arg) in Δψ and (c + d T) cos(arg) in Δε, in
 * units of 0.0001 arcsecond. */
#define EPH_NUTATION_TERMS 63
struct eph_nutation_term {
    signed char multiple[5];
    double a, b, c, d;
};
extern const struct eph_nutation_term eph_nutation_terms[EPH_NUTATION_TERMS];

/* Multiples of D, M, M', F; Σl in 1e-6 deg (sine), Σr in 1e-3 km (cosine), Σb in 1e-6 deg. */
#define EPH_MOON_TERMS 60
struct eph_moon_lr_term {
    signed char multiple[4];
    int sigma_l, sigma_r;
};
struct eph_moon_b_term {
    signed char multiple[4];
    int sigma_b;
};
extern const struct eph_moon_lr_term eph_moon_lr_terms[EPH_MOON_TERMS];
extern const struct eph_moon_b_term eph_moon_b_terms[EPH_MOON_TERMS];

#endif
