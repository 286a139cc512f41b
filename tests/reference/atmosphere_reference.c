/* Brute-force double-precision atmosphere reference; see atmosphere_reference.h. The medium
 * and the optical depths through it, transmittance; single scattering and Monte Carlo in
 * atmosphere_reference_single.c and atmosphere_reference_mc.c. */
#include "atmosphere_reference_internal.h"

#include <math.h>
#include <string.h>

static const double gl5_x[5] = { -0.9061798459386640, -0.5384693101056831, 0.0, 0.5384693101056831,
                                 0.9061798459386640 };
static const double gl5_w[5] = { 0.2369268850561891, 0.4786286704993665, 0.5688888888888889,
                                 0.4786286704993665, 0.2369268850561891 };

void ref_atmosphere_earth(struct ref_atmosphere *a)
{
    static const struct ref_atmosphere earth = {
        .bottom_radius = 6360.0,
        .top_radius = 6460.0,
        .rayleigh_scattering = { 5.802e-3, 13.558e-3, 33.1e-3 },
        .rayleigh_scale_height = 8.0,
        .mie_scattering = { 3.996e-3, 3.996e-3, 3.996e-3 },
        .mie_absorption = { 0.444e-3, 0.444e-3, 0.444e-3 },
        .mie_scale_height = 1.2,
        .mie_g = { 0.8, 0.8, 0.8 },
        .ozone_absorption = { 0.650e-3, 1.881e-3, 0.085e-3 },
        .ozone_peak_altitude = 25.0,
        .ozone_width = 30.0,
        .ground_albedo = { 0.3, 0.3, 0.3 },
        .fog_density = 0.0,
        .fog_scale_height = 1.0,
    };
    *a = earth;
}

// Rayleigh phase 3/(16 pi) (1 + c^2)
double ref_phase_rayleigh(double c)
{
    return 3.0 / (16.0 * REF_PI) * (1.0 + c * c);
}

// Cornette-Shanks phase, normalized over the sphere
double ref_phase_mie(double c, double g)
{
    double k = 1.0 + g * g - 2.0 * g * c;
    return 3.0 / (8.0 * REF_PI) * (1.0 - g * g) * (1.0 + c * c) / ((2.0 + g * g) * k * sqrt(k));
}

int ref_ray_sphere(const double o[3], const double d[3], double radius, double *t_near,
                   double *t_far)
{
    double b = dot3(o, d), ro = sqrt(dot3(o, o)), c = (ro - radius) * (ro + radius);
    double disc = b * b - c;
    if (disc < 0)
        return 0;
    double q = b > 0 ? -(b + sqrt(disc)) : -(b - sqrt(disc)); /* no cancellation in -b +- s */
    double r1 = q != 0 ? c / q : 0.0;
    *t_near = fmin(q, r1), *t_far = fmax(q, r1);
    return 1;
}

/* ---------------------------------------------------------------- medium and quadrature */

static void sort_doubles(double *v, int n)
{
    for (int i = 1; i < n; ++i)
        for (int j = i; j > 0 && v[j - 1] > v[j]; --j) {
            double tmp = v[j];
            v[j] = v[j - 1], v[j - 1] = tmp;
        }
}

/* Shells split every ray into pieces whose altitude span is at most step_scale * 2 scale
 * heights of the thinnest component still non-negligible there (density > e^-25), and at
 * the ozone kinks; 5-point Gauss-Legendre is then accurate to ~1e-9 per piece. */
void ref_medium_ctx_init(struct ctx *c, const struct ref_atmosphere *a, double q)
{
    memset(c, 0, sizeof *c);
    c->a = a, c->R = a->bottom_radius, c->top = a->top_radius, c->lmax = LMAX_PER_Q * q;
    const double H[3] = { a->rayleigh_scale_height, a->mie_scale_height, a->fog_scale_height };
    for (int ch = 0; ch < 3; ++ch) {
        c->ext[ch][0] = a->rayleigh_scattering[ch];
        c->ext[ch][1] = a->mie_scattering[ch] + a->mie_absorption[ch];
        c->ext[ch][2] = a->fog_density;
        c->ext[ch][3] = a->ozone_width > 0 ? a->ozone_absorption[ch] : 0.0;
        for (int k = 0; k < 4; ++k)
            c->active[k] |= c->ext[ch][k] != 0;
    }
    for (int k = 0; k < 3; ++k)
        c->inv_h[k] = c->active[k] && H[k] > 0 ? 1.0 / H[k] : 0.0;
    double thick = c->top - c->R, hs[MAX_SHELLS], h = 0;
    int n = 0;
    while (n < MAX_SHELLS - 3) {
        double step = HUGE_VAL;
        for (int k = 0; k < 3; ++k)
            if (c->active[k] && h < 25.0 * H[k])
                step = fmin(step, 2.0 * q * H[k]);
        if (step == HUGE_VAL || h + step >= thick)
            break;
        hs[n++] = h += step;
    }
    for (int i = -1; i <= 1 && c->active[3]; ++i) {
        double kink = a->ozone_peak_altitude + 0.5 * i * a->ozone_width;
        if (kink > 0 && kink < thick)
            hs[n++] = kink;
    }
    sort_doubles(hs, n);
    for (int i = 0; i < n; ++i)
        if (c->nshell == 0 || hs[i] - (c->shell_r[c->nshell - 1] - c->R) > 1e-9)
            c->shell_r[c->nshell++] = c->R + hs[i];
}

/* Sorted breakpoints of r inside the medium, clipped to t <= tmax: entry, shell crossings,
 * perigee, extra points, exit. Returns their count (0 if the ray misses the medium);
 * *ground tells whether the ray ends on the planet before tmax. */
static int ray_breaks(const struct ctx *c, const struct ray *r, double tmax, const double *extra,
                      int nextra, double *br, int *ground)
{
    double tn, tf, gn, gf;
    *ground = 0;
    if (!ref_ray_sphere(r->o, r->d, c->top, &tn, &tf) || tf <= 0)
        return 0;
    double t_in = fmax(tn, 0.0), t_out = fmin(tf, tmax);
    if (r->b < 0 && ref_ray_sphere(r->o, r->d, c->R, &gn, &gf) && gf > 0 && fmax(gn, 0.0) <= t_out)
        *ground = 1, t_out = fmax(gn, 0.0);
    if (t_out < t_in && !*ground)
        return 0;
    t_out = fmax(t_out, t_in);
    int n = 0;
    br[n++] = t_in;
    for (int k = 0; k < c->nshell; ++k) {
        if (!ref_ray_sphere(r->o, r->d, c->shell_r[k], &tn, &tf))
            continue;
        if (tn > t_in && tn < t_out)
            br[n++] = tn;
        if (tf > t_in && tf < t_out && tf != tn)
            br[n++] = tf;
    }
    if (-r->b > t_in && -r->b < t_out)
        br[n++] = -r->b;
    for (int i = 0; i < nextra && i < MAX_EXTRA; ++i)
        if (extra[i] > t_in && extra[i] < t_out)
            br[n++] = extra[i];
    br[n++] = t_out;
    sort_doubles(br + 1, n - 2);
    return n;
}

void ref_medium_gl5(const struct ctx *c, const struct ray *r, double ta, double tb, double acc[4])
{
    double mid = 0.5 * (ta + tb), half = 0.5 * (tb - ta), dn[4];
    acc[0] = acc[1] = acc[2] = acc[3] = 0.0;
    for (int i = 0; i < 5; ++i) {
        densities(c, ray_radius(r, mid + half * gl5_x[i]), dn);
        for (int k = 0; k < 4; ++k)
            acc[k] += half * gl5_w[i] * dn[k];
    }
}

/* With stop_on_ground, a ray that hits the planet gets no pieces. */
void ref_medium_march_ray(const struct ctx *c, const struct ray *r, double tmax,
                          const double *extra, int nextra, int stop_on_ground, struct march *m)
{
    double br[MAX_BREAKS], acc[4], lmax = c->lmax;
    int nb = ray_breaks(c, r, tmax, extra, nextra, br, &m->ground);
    m->r = *r, m->n = 0, m->in_medium = nb > 0, m->t[0] = nb > 0 ? br[0] : 0.0;
    memset(m->col[0], 0, sizeof m->col[0]);
    if (nb == 0 || (m->ground && stop_on_ground))
        return;
    for (;; lmax *= 2.0) {
        long total = 0;
        for (int i = 0; i + 1 < nb; ++i)
            total += (long)ceil((br[i + 1] - br[i]) / lmax);
        if (total <= MARCH_CAP)
            break;
    }
    for (int i = 0; i + 1 < nb; ++i) {
        double len = br[i + 1] - br[i];
        int pieces = (int)ceil(len / lmax);
        for (int j = 0; j < pieces; ++j, ++m->n) {
            double tb = j + 1 == pieces ? br[i + 1] : br[i] + len * (j + 1) / pieces;
            ref_medium_gl5(c, r, m->t[m->n], tb, acc);
            m->t[m->n + 1] = tb;
            for (int k = 0; k < 4; ++k)
                m->col[m->n + 1][k] = m->col[m->n][k] + acc[k];
        }
    }
}

/* Transmittance from x toward s to the top of the atmosphere; 0 in the planet's shadow. */
void ref_medium_transmittance_to_top(const struct ctx *c, const double x[3], const double s[3],
                                     struct march *m, double T[3])
{
    struct ray r;
    ray_set(&r, x, s);
    ref_medium_march_ray(c, &r, HUGE_VAL, NULL, 0, 1, m);
    for (int ch = 0; ch < 3; ++ch)
        T[ch] = m->ground ? 0.0 : exp(-tau_ch(c, ch, m->col[m->n]));
}

void ref_transmittance_ex(const struct ref_atmosphere *a, double altitude, double mu,
                          double step_scale, double out[3])
{
    struct ctx c;
    struct march m;
    mu = fmax(-1.0, fmin(1.0, mu));
    double o[3] = { 0, 0, a->bottom_radius + altitude }, d[3] = { sqrt(1.0 - mu * mu), 0, mu };
    ref_medium_ctx_init(&c, a, step_scale);
    ref_medium_transmittance_to_top(&c, o, d, &m, out);
}

void ref_transmittance(const struct ref_atmosphere *a, double altitude, double mu, double out[3])
{
    ref_transmittance_ex(a, altitude, mu, Q_TRANSMITTANCE, out);
}

void ref_transmittance_segment(const struct ref_atmosphere *a, const double p0[3],
                               const double p1[3], double out[3])
{
    double v[3] = { p1[0] - p0[0], p1[1] - p0[1], p1[2] - p0[2] }, d[3], len = sqrt(dot3(v, v));
    struct ctx c;
    struct ray r;
    struct march m;
    normalize3(v, d);
    ray_set(&r, p0, d);
    ref_medium_ctx_init(&c, a, Q_TRANSMITTANCE);
    ref_medium_march_ray(&c, &r, len * (1.0 + 1e-15), NULL, 0, 0, &m);
    int blocked = ray_radius(&r, fmin(fmax(-r.b, 0.0), len)) < c.R * (1.0 - 1e-12);
    for (int ch = 0; ch < 3; ++ch)
        out[ch] = blocked ? 0.0 : exp(-tau_ch(&c, ch, m.col[m.n]));
}
