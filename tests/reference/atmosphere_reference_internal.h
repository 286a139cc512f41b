/* Internals shared by the files of the atmosphere reference (atmosphere_reference.h is the
 * public header):
 *   atmosphere_reference.c         the medium, quadrature of optical depths, transmittance
 *   atmosphere_reference_single.c  single scattering (adaptive Gauss-Kronrod)
 *   atmosphere_reference_mc.c      Monte Carlo radiance and irradiance
 * The small helpers called in the inner loops are static inline here; the rest, defined in
 * atmosphere_reference.c, carry the prefix ref_medium_. */
#ifndef SKYD_ATMOSPHERE_REFERENCE_INTERNAL_H
#define SKYD_ATMOSPHERE_REFERENCE_INTERNAL_H

#include "atmosphere_reference.h"

#include <math.h>
#include <string.h>

#define REF_PI 3.14159265358979323846
#define MAX_SHELLS 400
#define MAX_EXTRA 2
#define MAX_BREAKS (2 * MAX_SHELLS + MAX_EXTRA + 3)
#define MARCH_CAP 640

/* Shell spacing is step_scale * 2 scale heights (see ref_medium_ctx_init); pieces are at most
 * LMAX_PER_Q * step_scale km long. */
#define Q_TRANSMITTANCE 0.5
#define Q_SINGLE 0.5
#define SS_REL_TOL 1e-7
#define Q_MC 3.0
#define LMAX_PER_Q 200.0

static inline double dot3(const double a[3], const double b[3])
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

static inline void normalize3(const double in[3], double out[3])
{
    double l = sqrt(dot3(in, in));
    for (int i = 0; i < 3; ++i)
        out[i] = l > 0 ? in[i] / l : (double)(i == 2);
}

static inline void along(const double o[3], const double d[3], double t, double out[3])
{
    for (int i = 0; i < 3; ++i)
        out[i] = o[i] + t * d[i];
}

/* ---------------------------------------------------------------- medium and quadrature */

/* Density components: 0 Rayleigh, 1 Mie, 2 fog, 3 ozone. */
struct ctx {
    const struct ref_atmosphere *a;
    double R, top, inv_h[3], lmax;
    int active[4], nshell;
    double ext[3][4]; /* extinction per channel per unit density of each component */
    double shell_r[MAX_SHELLS];
};

struct ray {
    double o[3], d[3], ro2, b;
};

static inline void ray_set(struct ray *r, const double o[3], const double d[3])
{
    memcpy(r->o, o, sizeof r->o);
    memcpy(r->d, d, sizeof r->d);
    r->ro2 = dot3(o, o), r->b = dot3(o, d);
}

static inline double ray_radius(const struct ray *r, double t)
{
    double s = r->ro2 + t * (2.0 * r->b + t);
    return s > 0 ? sqrt(s) : 0.0;
}

static inline void densities(const struct ctx *c, double radius, double dn[4])
{
    double h = fmax(radius - c->R, 0.0);
    dn[0] = c->active[0] ? exp(-h * c->inv_h[0]) : 0.0;
    dn[1] = c->active[1] ? exp(-h * c->inv_h[1]) : 0.0;
    dn[2] = c->active[2] ? exp(-h * c->inv_h[2]) : 0.0;
    dn[3] = c->active[3]
                ? fmax(0.0, 1.0 - fabs(h - c->a->ozone_peak_altitude) / (0.5 * c->a->ozone_width))
                : 0.0;
}

static inline double tau_ch(const struct ctx *c, int ch, const double col[4])
{
    return c->ext[ch][0] * col[0] + c->ext[ch][1] * col[1] + c->ext[ch][2] * col[2] +
           c->ext[ch][3] * col[3];
}

/* Extinction, Rayleigh scattering and Mie-phase scattering (Mie + fog) at a radius. */
static inline void local_coefs(const struct ctx *c, double radius, double st[3], double sr[3],
                               double sm[3])
{
    double dn[4];
    densities(c, radius, dn);
    for (int ch = 0; ch < 3; ++ch) {
        st[ch] = tau_ch(c, ch, dn);
        sr[ch] = c->a->rayleigh_scattering[ch] * dn[0];
        sm[ch] = c->a->mie_scattering[ch] * dn[1] + c->a->fog_density * dn[2];
    }
}

/* A ray's pieces inside the medium with the cumulative columns at their ends. */
struct march {
    struct ray r;
    int in_medium, ground, n; /* n pieces */
    double t[MARCH_CAP + 1];
    double col[MARCH_CAP + 1][4];
};

/* atmosphere_reference.c: see there. */
void ref_medium_ctx_init(struct ctx *c, const struct ref_atmosphere *a, double q);
void ref_medium_gl5(const struct ctx *c, const struct ray *r, double ta, double tb, double acc[4]);
void ref_medium_march_ray(const struct ctx *c, const struct ray *r, double tmax,
                          const double *extra, int nextra, int stop_on_ground, struct march *m);
void ref_medium_transmittance_to_top(const struct ctx *c, const double x[3], const double s[3],
                                     struct march *m, double T[3]);

#endif
