/* Brute-force double-precision atmosphere reference; see atmosphere_reference.h. */
#include "atmosphere_reference.h"

#include <math.h>
#include <pthread.h>
#include <stdlib.h>
#include <string.h>

#define REF_PI 3.14159265358979323846
#define MAX_SHELLS 400
#define MAX_EXTRA 2
#define MAX_BREAKS (2 * MAX_SHELLS + MAX_EXTRA + 3)
#define MARCH_CAP 640
#define PATH_BLOCK 64
#define MAX_THREADS 64

/* Shell spacing is step_scale * 2 scale heights (see ctx_init); pieces are at most
 * LMAX_PER_Q * step_scale km long. */
#define Q_TRANSMITTANCE 0.5
#define Q_SINGLE 0.5
#define SS_REL_TOL 1e-7
#define Q_MC 3.0
#define LMAX_PER_Q 200.0
/* Russian roulette keeps a path with probability max(beta) / RR_LEVEL below that level. */
#define RR_LEVEL 0.1

static const double gl5_x[5] = {-0.9061798459386640, -0.5384693101056831, 0.0,
                                0.5384693101056831, 0.9061798459386640};
static const double gl5_w[5] = {0.2369268850561891, 0.4786286704993665, 0.5688888888888889,
                                0.4786286704993665, 0.2369268850561891};
/* Kronrod 15 abscissae (positive half, descending) and weights; Gauss 7 weights for the
 * odd-indexed abscissae. */
static const double gk_x[8] = {0.99145537112081264, 0.94910791234275853, 0.86486442335976907,
                               0.74153118559939444, 0.58608723546769113, 0.40584515137739717,
                               0.20778495500789847, 0.0};
static const double gk_w[8] = {0.02293532201052922, 0.06309209262997855, 0.10479001032225018,
                               0.14065325971552592, 0.16900472663926790, 0.19035057806478541,
                               0.20443294007529889, 0.20948214108472783};
static const double g7_w[4] = {0.12948496616886969, 0.27970539148927667, 0.38183005050511894,
                               0.41795918367346939};

static double dot3(const double a[3], const double b[3])
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

static void normalize3(const double in[3], double out[3])
{
    double l = sqrt(dot3(in, in));
    for (int i = 0; i < 3; ++i) out[i] = l > 0 ? in[i] / l : (double)(i == 2);
}

static void along(const double o[3], const double d[3], double t, double out[3])
{
    for (int i = 0; i < 3; ++i) out[i] = o[i] + t * d[i];
}

/* Direction at polar cosine cos_t and azimuth phi about unit axis (basis: Duff et al. 2017). */
static void dir_about(const double axis[3], double cos_t, double phi, double out[3])
{
    double sign = copysign(1.0, axis[2]), a = -1.0 / (sign + axis[2]), b = axis[0] * axis[1] * a;
    double t[3] = {1.0 + sign * axis[0] * axis[0] * a, sign * b, -sign * axis[0]};
    double u[3] = {b, sign + axis[1] * axis[1] * a, -axis[1]};
    double s = sqrt(fmax(0.0, 1.0 - cos_t * cos_t)), cp = cos(phi) * s, sp = sin(phi) * s;
    for (int i = 0; i < 3; ++i) out[i] = cp * t[i] + sp * u[i] + cos_t * axis[i];
    normalize3(out, out);
}

void ref_atmosphere_earth(struct ref_atmosphere *a)
{
    static const struct ref_atmosphere earth = {
        .bottom_radius = 6360.0, .top_radius = 6460.0,
        .rayleigh_scattering = {5.802e-3, 13.558e-3, 33.1e-3}, .rayleigh_scale_height = 8.0,
        .mie_scattering = {3.996e-3, 3.996e-3, 3.996e-3},
        .mie_absorption = {0.444e-3, 0.444e-3, 0.444e-3}, .mie_scale_height = 1.2,
        .mie_g = {0.8, 0.8, 0.8}, .ozone_absorption = {0.650e-3, 1.881e-3, 0.085e-3},
        .ozone_peak_altitude = 25.0, .ozone_width = 30.0, .ground_albedo = {0.3, 0.3, 0.3},
        .fog_density = 0.0, .fog_scale_height = 1.0,
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
    if (disc < 0) return 0;
    double q = b > 0 ? -(b + sqrt(disc)) : -(b - sqrt(disc)); /* no cancellation in -b +- s */
    double r1 = q != 0 ? c / q : 0.0;
    *t_near = fmin(q, r1), *t_far = fmax(q, r1);
    return 1;
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

static void ray_set(struct ray *r, const double o[3], const double d[3])
{
    memcpy(r->o, o, sizeof r->o);
    memcpy(r->d, d, sizeof r->d);
    r->ro2 = dot3(o, o), r->b = dot3(o, d);
}

static double ray_radius(const struct ray *r, double t)
{
    double s = r->ro2 + t * (2.0 * r->b + t);
    return s > 0 ? sqrt(s) : 0.0;
}

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
static void ctx_init(struct ctx *c, const struct ref_atmosphere *a, double q)
{
    memset(c, 0, sizeof *c);
    c->a = a, c->R = a->bottom_radius, c->top = a->top_radius, c->lmax = LMAX_PER_Q * q;
    const double H[3] = {a->rayleigh_scale_height, a->mie_scale_height, a->fog_scale_height};
    for (int ch = 0; ch < 3; ++ch) {
        c->ext[ch][0] = a->rayleigh_scattering[ch];
        c->ext[ch][1] = a->mie_scattering[ch] + a->mie_absorption[ch];
        c->ext[ch][2] = a->fog_density;
        c->ext[ch][3] = a->ozone_width > 0 ? a->ozone_absorption[ch] : 0.0;
        for (int k = 0; k < 4; ++k) c->active[k] |= c->ext[ch][k] != 0;
    }
    for (int k = 0; k < 3; ++k) c->inv_h[k] = c->active[k] && H[k] > 0 ? 1.0 / H[k] : 0.0;
    double thick = c->top - c->R, hs[MAX_SHELLS], h = 0;
    int n = 0;
    while (n < MAX_SHELLS - 3) {
        double step = HUGE_VAL;
        for (int k = 0; k < 3; ++k)
            if (c->active[k] && h < 25.0 * H[k]) step = fmin(step, 2.0 * q * H[k]);
        if (step == HUGE_VAL || h + step >= thick) break;
        hs[n++] = h += step;
    }
    for (int i = -1; i <= 1 && c->active[3]; ++i) {
        double kink = a->ozone_peak_altitude + 0.5 * i * a->ozone_width;
        if (kink > 0 && kink < thick) hs[n++] = kink;
    }
    sort_doubles(hs, n);
    for (int i = 0; i < n; ++i)
        if (c->nshell == 0 || hs[i] - (c->shell_r[c->nshell - 1] - c->R) > 1e-9)
            c->shell_r[c->nshell++] = c->R + hs[i];
}

static void densities(const struct ctx *c, double radius, double dn[4])
{
    double h = fmax(radius - c->R, 0.0);
    dn[0] = c->active[0] ? exp(-h * c->inv_h[0]) : 0.0;
    dn[1] = c->active[1] ? exp(-h * c->inv_h[1]) : 0.0;
    dn[2] = c->active[2] ? exp(-h * c->inv_h[2]) : 0.0;
    dn[3] = c->active[3] ? fmax(0.0, 1.0 - fabs(h - c->a->ozone_peak_altitude) /
                                               (0.5 * c->a->ozone_width))
                         : 0.0;
}

static double tau_ch(const struct ctx *c, int ch, const double col[4])
{
    return c->ext[ch][0] * col[0] + c->ext[ch][1] * col[1] + c->ext[ch][2] * col[2] +
           c->ext[ch][3] * col[3];
}

/* Extinction, Rayleigh scattering and Mie-phase scattering (Mie + fog) at a radius. */
static void local_coefs(const struct ctx *c, double radius, double st[3], double sr[3],
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

/* Sorted breakpoints of r inside the medium, clipped to t <= tmax: entry, shell crossings,
 * perigee, extra points, exit. Returns their count (0 if the ray misses the medium);
 * *ground tells whether the ray ends on the planet before tmax. */
static int ray_breaks(const struct ctx *c, const struct ray *r, double tmax, const double *extra,
                      int nextra, double *br, int *ground)
{
    double tn, tf, gn, gf;
    *ground = 0;
    if (!ref_ray_sphere(r->o, r->d, c->top, &tn, &tf) || tf <= 0) return 0;
    double t_in = fmax(tn, 0.0), t_out = fmin(tf, tmax);
    if (r->b < 0 && ref_ray_sphere(r->o, r->d, c->R, &gn, &gf) && gf > 0 &&
        fmax(gn, 0.0) <= t_out)
        *ground = 1, t_out = fmax(gn, 0.0);
    if (t_out < t_in && !*ground) return 0;
    t_out = fmax(t_out, t_in);
    int n = 0;
    br[n++] = t_in;
    for (int k = 0; k < c->nshell; ++k) {
        if (!ref_ray_sphere(r->o, r->d, c->shell_r[k], &tn, &tf)) continue;
        if (tn > t_in && tn < t_out) br[n++] = tn;
        if (tf > t_in && tf < t_out && tf != tn) br[n++] = tf;
    }
    if (-r->b > t_in && -r->b < t_out) br[n++] = -r->b;
    for (int i = 0; i < nextra && i < MAX_EXTRA; ++i)
        if (extra[i] > t_in && extra[i] < t_out) br[n++] = extra[i];
    br[n++] = t_out;
    sort_doubles(br + 1, n - 2);
    return n;
}

static void gl5(const struct ctx *c, const struct ray *r, double ta, double tb, double acc[4])
{
    double mid = 0.5 * (ta + tb), half = 0.5 * (tb - ta), dn[4];
    acc[0] = acc[1] = acc[2] = acc[3] = 0.0;
    for (int i = 0; i < 5; ++i) {
        densities(c, ray_radius(r, mid + half * gl5_x[i]), dn);
        for (int k = 0; k < 4; ++k) acc[k] += half * gl5_w[i] * dn[k];
    }
}

/* A ray's pieces inside the medium with the cumulative columns at their ends. */
struct march {
    struct ray r;
    int in_medium, ground, n; /* n pieces */
    double t[MARCH_CAP + 1];
    double col[MARCH_CAP + 1][4];
};

/* With stop_on_ground, a ray that hits the planet gets no pieces. */
static void march_ray(const struct ctx *c, const struct ray *r, double tmax, const double *extra,
                      int nextra, int stop_on_ground, struct march *m)
{
    double br[MAX_BREAKS], acc[4], lmax = c->lmax;
    int nb = ray_breaks(c, r, tmax, extra, nextra, br, &m->ground);
    m->r = *r, m->n = 0, m->in_medium = nb > 0, m->t[0] = nb > 0 ? br[0] : 0.0;
    memset(m->col[0], 0, sizeof m->col[0]);
    if (nb == 0 || (m->ground && stop_on_ground)) return;
    for (;; lmax *= 2.0) {
        long total = 0;
        for (int i = 0; i + 1 < nb; ++i) total += (long)ceil((br[i + 1] - br[i]) / lmax);
        if (total <= MARCH_CAP) break;
    }
    for (int i = 0; i + 1 < nb; ++i) {
        double len = br[i + 1] - br[i];
        int pieces = (int)ceil(len / lmax);
        for (int j = 0; j < pieces; ++j, ++m->n) {
            double tb = j + 1 == pieces ? br[i + 1] : br[i] + len * (j + 1) / pieces;
            gl5(c, r, m->t[m->n], tb, acc);
            m->t[m->n + 1] = tb;
            for (int k = 0; k < 4; ++k) m->col[m->n + 1][k] = m->col[m->n][k] + acc[k];
        }
    }
}

/* Transmittance from x toward s to the top of the atmosphere; 0 in the planet's shadow. */
static void transmittance_to_top(const struct ctx *c, const double x[3], const double s[3],
                                 struct march *m, double T[3])
{
    struct ray r;
    ray_set(&r, x, s);
    march_ray(c, &r, HUGE_VAL, NULL, 0, 1, m);
    for (int ch = 0; ch < 3; ++ch) T[ch] = m->ground ? 0.0 : exp(-tau_ch(c, ch, m->col[m->n]));
}

void ref_transmittance_ex(const struct ref_atmosphere *a, double altitude, double mu,
                          double step_scale, double out[3])
{
    struct ctx c;
    struct march m;
    mu = fmax(-1.0, fmin(1.0, mu));
    double o[3] = {0, 0, a->bottom_radius + altitude}, d[3] = {sqrt(1.0 - mu * mu), 0, mu};
    ctx_init(&c, a, step_scale);
    transmittance_to_top(&c, o, d, &m, out);
}

void ref_transmittance(const struct ref_atmosphere *a, double altitude, double mu, double out[3])
{
    ref_transmittance_ex(a, altitude, mu, Q_TRANSMITTANCE, out);
}

void ref_transmittance_segment(const struct ref_atmosphere *a, const double p0[3],
                               const double p1[3], double out[3])
{
    double v[3] = {p1[0] - p0[0], p1[1] - p0[1], p1[2] - p0[2]}, d[3], len = sqrt(dot3(v, v));
    struct ctx c;
    struct ray r;
    struct march m;
    normalize3(v, d);
    ray_set(&r, p0, d);
    ctx_init(&c, a, Q_TRANSMITTANCE);
    march_ray(&c, &r, len * (1.0 + 1e-15), NULL, 0, 0, &m);
    int blocked = ray_radius(&r, fmin(fmax(-r.b, 0.0), len)) < c.R * (1.0 - 1e-12);
    for (int ch = 0; ch < 3; ++ch) out[ch] = blocked ? 0.0 : exp(-tau_ch(&c, ch, m.col[m.n]));
}

/* Distance where channel ch's optical depth reaches target (below the total); col_out gets
 * the columns there. Newton on the piece's quadrature, safeguarded by bisection. */
static double march_sample(const struct ctx *c, const struct march *m, int ch, double target,
                           double col_out[4])
{
    int k = 0, hi_k = m->n - 1;
    while (k < hi_k) {
        int mid = (k + hi_k + 1) / 2;
        if (tau_ch(c, ch, m->col[mid]) <= target) k = mid;
        else hi_k = mid - 1;
    }
    double a = m->t[k], lo = a, hi = m->t[k + 1], acc[4], dn[4];
    double base = tau_ch(c, ch, m->col[k]), rem = target - base;
    double piece = tau_ch(c, ch, m->col[k + 1]) - base;
    double t = piece > 0 ? a + (hi - a) * fmin(1.0, fmax(0.0, rem / piece)) : 0.5 * (lo + hi);
    for (int it = 0;; ++it) {
        gl5(c, &m->r, a, t, acc);
        double f = tau_ch(c, ch, acc) - rem;
        if (fabs(f) <= 1e-12 * target || it == 100 || hi - lo <= 1e-13 * hi) break;
        if (f > 0) hi = t;
        else lo = t;
        densities(c, ray_radius(&m->r, t), dn);
        double sigma = tau_ch(c, ch, dn), tn = sigma > 0 ? t - f / sigma : lo;
        t = tn > lo && tn < hi ? tn : 0.5 * (lo + hi);
    }
    for (int q = 0; q < 4; ++q) col_out[q] = m->col[k][q] + acc[q];
    return t;
}

/* ---------------------------------------------------------------- single scattering */

struct ss_state {
    struct ctx view, sun;
    double s[3], p_r, p_m[3]; /* phase values: the scattering angle is fixed along the ray */
    struct march m, shadow;
    double K[MARCH_CAP][3], G[MARCH_CAP][3]; /* first pass per piece */
};

static void ss_integrand(struct ss_state *S, int k, double t, double f[3])
{
    double acc[4], col[4], x[3], st[3], sr[3], sm[3], Ts[3];
    gl5(&S->view, &S->m.r, S->m.t[k], t, acc);
    for (int q = 0; q < 4; ++q) col[q] = S->m.col[k][q] + acc[q];
    along(S->m.r.o, S->m.r.d, t, x);
    local_coefs(&S->view, ray_radius(&S->m.r, t), st, sr, sm);
    transmittance_to_top(&S->sun, x, S->s, &S->shadow, Ts);
    // dL = T_view sigma_s p T_sun dt
    for (int ch = 0; ch < 3; ++ch)
        f[ch] = exp(-tau_ch(&S->view, ch, col)) * (sr[ch] * S->p_r + sm[ch] * S->p_m[ch]) * Ts[ch];
}

/* Gauss-Kronrod 7-15 on [a, b] inside piece k: K (15 points) and G (7 points). */
static void gk15(struct ss_state *S, int k, double a, double b, double K[3], double G[3])
{
    double mid = 0.5 * (a + b), half = 0.5 * (b - a), f1[3], f2[3];
    ss_integrand(S, k, mid, f1);
    for (int ch = 0; ch < 3; ++ch) K[ch] = half * gk_w[7] * f1[ch], G[ch] = half * g7_w[3] * f1[ch];
    for (int i = 0; i < 7; ++i) {
        ss_integrand(S, k, mid - half * gk_x[i], f1);
        ss_integrand(S, k, mid + half * gk_x[i], f2);
        for (int ch = 0; ch < 3; ++ch) {
            K[ch] += half * gk_w[i] * (f1[ch] + f2[ch]);
            G[ch] += (i & 1) ? half * g7_w[i / 2] * (f1[ch] + f2[ch]) : 0.0;
        }
    }
}

static void gk_adapt(struct ss_state *S, int k, double a, double b, const double K[3],
                     const double G[3], const double tol[3], int depth, double sum[3])
{
    double mid = 0.5 * (a + b), K1[3], G1[3], K2[3], G2[3], half_tol[3];
    int conv = 1;
    for (int ch = 0; ch < 3; ++ch)
        conv &= fabs(K[ch] - G[ch]) <= fmax(tol[ch], 1e-14 * fabs(K[ch]));
    if (conv || depth >= 40 || b - a <= 1e-12 * (1.0 + fabs(a))) {
        for (int ch = 0; ch < 3; ++ch) sum[ch] += K[ch];
        return;
    }
    for (int ch = 0; ch < 3; ++ch) half_tol[ch] = 0.5 * tol[ch];
    gk15(S, k, a, mid, K1, G1);
    gk15(S, k, mid, b, K2, G2);
    gk_adapt(S, k, a, mid, K1, G1, half_tol, depth + 1, sum);
    gk_adapt(S, k, mid, b, K2, G2, half_tol, depth + 1, sum);
}

/* Ray parameters where r crosses the boundary of the planet's shadow cylinder. */
static int shadow_breaks(const struct ray *r, const double s[3], double R, double out[2])
{
    double ds = dot3(r->d, s), os = dot3(r->o, s);
    double A = 1.0 - ds * ds, B = r->b - os * ds, C = r->ro2 - os * os - R * R;
    double disc = B * B - A * C;
    int n = 0;
    for (int sign = -1; sign <= 1 && A >= 1e-14 && disc >= 0; sign += 2) {
        double t = (-B + sign * sqrt(disc)) / A;
        if (t > 0 && os + t * ds < 0) out[n++] = t;
    }
    return n;
}

void ref_single_scattering_ex(const struct ref_atmosphere *a, double altitude,
                              const double view_dir[3], const double sun_dir[3],
                              double step_scale, double rel_tol, double out[3])
{
    struct ss_state *S = malloc(sizeof *S);
    double o[3] = {0, 0, a->bottom_radius + altitude}, d[3], extra[2];
    out[0] = out[1] = out[2] = S ? 0.0 : NAN;
    if (!S) return;
    ctx_init(&S->view, a, step_scale);
    ctx_init(&S->sun, a, step_scale);
    normalize3(view_dir, d);
    normalize3(sun_dir, S->s);
    S->p_r = ref_phase_rayleigh(dot3(d, S->s));
    for (int ch = 0; ch < 3; ++ch) S->p_m[ch] = ref_phase_mie(dot3(d, S->s), a->mie_g[ch]);
    struct ray r;
    ray_set(&r, o, d);
    int ne = shadow_breaks(&r, S->s, a->bottom_radius, extra);
    march_ray(&S->view, &r, HUGE_VAL, extra, ne, 0, &S->m);
    double total[3] = {0, 0, 0}, tol[3], x[3], n[3], Ts[3];
    for (int k = 0; k < S->m.n; ++k) {
        gk15(S, k, S->m.t[k], S->m.t[k + 1], S->K[k], S->G[k]);
        for (int ch = 0; ch < 3; ++ch) total[ch] += S->K[k][ch];
    }
    for (int ch = 0; ch < 3; ++ch) tol[ch] = rel_tol * fabs(total[ch]) / sqrt(fmax(1.0, S->m.n));
    for (int k = 0; k < S->m.n; ++k)
        gk_adapt(S, k, S->m.t[k], S->m.t[k + 1], S->K[k], S->G[k], tol, 0, out);
    if (S->m.in_medium && S->m.ground) {
        along(o, d, S->m.t[S->m.n], x);
        normalize3(x, n);
        transmittance_to_top(&S->sun, x, S->s, &S->shadow, Ts);
        // Lambertian ground: albedo/pi * cos * E_sun, attenuated to the camera
        for (int ch = 0; ch < 3; ++ch)
            out[ch] += a->ground_albedo[ch] / REF_PI * fmax(0.0, dot3(n, S->s)) * Ts[ch] *
                       exp(-tau_ch(&S->view, ch, S->m.col[S->m.n]));
    }
    free(S);
}

void ref_single_scattering(const struct ref_atmosphere *a, double altitude,
                           const double view_dir[3], const double sun_dir[3], double out[3])
{
    ref_single_scattering_ex(a, altitude, view_dir, sun_dir, Q_SINGLE, SS_REL_TOL, out);
}

/* ---------------------------------------------------------------- Monte Carlo */

/* splitmix64 (Steele et al. 2014), one stream per path started from a hash of (seed, path). */
static uint64_t splitmix64(uint64_t *x)
{
    uint64_t z = (*x += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
}

static double rng_u(uint64_t *g)
{
    return (double)(splitmix64(g) >> 11) * 0x1.0p-53;
}

// inverse CDF of the Rayleigh phase in cos(theta): c^3 + 3c = 8u - 4 (Cardano)
static double sample_rayleigh(double u)
{
    double z = 4.0 * u - 2.0, s = sqrt(z * z + 1.0);
    return fmax(-1.0, fmin(1.0, cbrt(z + s) + cbrt(z - s)));
}

/* Cornette-Shanks = Henyey-Greenstein * 3(1 + c^2) / (2(2 + g^2)): rejection sampling from
 * Henyey-Greenstein with acceptance (1 + c^2) / 2. */
static double sample_cs(double g, uint64_t *rg)
{
    for (;;) {
        double u = rng_u(rg), c = 2.0 * u - 1.0;
        if (fabs(g) >= 1e-6) {
            double sq = (1.0 - g * g) / (1.0 - g + 2.0 * g * u);
            c = fmax(-1.0, fmin(1.0, (1.0 + g * g - sq * sq) / (2.0 * g)));
        }
        if (2.0 * rng_u(rg) < 1.0 + c * c) return c;
    }
}

struct mc_setup {
    struct ctx seg;
    const struct ref_atmosphere *a;
    double sun[3], cam[3], view[3];
    int mode; /* 0 radiance along view; +1/-1 cosine-weighted about +z / -z, times pi */
    int min_order, max_order;
    long first, count, nblocks; /* the batch being run */
    uint64_t seed;
    double (*blocks)[6];
};

/* Adds w * T_sun(x) to out (next-event estimation toward the sun). */
static void nee(const struct mc_setup *S, const double x[3], const double w[3], struct march *m,
                double out[3])
{
    double Ts[3];
    if (!(w[0] > 0 || w[1] > 0 || w[2] > 0)) return;
    transmittance_to_top(&S->seg, x, S->sun, m, Ts);
    for (int ch = 0; ch < 3; ++ch) out[ch] += w[ch] * Ts[ch];
}

/* sigma_s * phase for channel ch (1/km/sr). */
static double kernel(const struct ref_atmosphere *a, int ch, const double sr[3],
                     const double sm[3], double c)
{
    return sr[ch] * ref_phase_rayleigh(c) + sm[ch] * ref_phase_mie(c, a->mie_g[ch]);
}

/* One path from the camera along dir; out gets its estimate of orders min..max. On every
 * segment the volume vertex is a forced collision (density sigma_t T / (1 - T(L)) per
 * channel, mixed evenly over the channels); a segment that ends on the ground also yields
 * the ground vertex with weight T(L). Both get next-event estimation toward the sun, and
 * the path continues from one of them, chosen by its expected throughput. */
static void trace(const struct mc_setup *S, const double dir[3], uint64_t *g, struct march *m,
                  double out[3])
{
    const struct ctx *c = &S->seg;
    const struct ref_atmosphere *a = S->a;
    double x[3], d[3], beta[3] = {1, 1, 1};
    memcpy(x, S->cam, sizeof x);
    memcpy(d, dir, sizeof d);
    out[0] = out[1] = out[2] = 0.0;
    for (int k = 1; k <= S->max_order; ++k) {
        double col[4], st[3], sr[3], sm[3], tau[3], pe[3], bg[3] = {0, 0, 0}, bv[3] = {0, 0, 0};
        double xg[3], xv[3], ng[3] = {0, 0, 1}, w[3], wg = 0.0, wv = 0.0, nd[3];
        int act[3], nact = 0, has_v = 0;
        struct ray r;
        ray_set(&r, x, d);
        march_ray(c, &r, HUGE_VAL, NULL, 0, 0, m);
        if (!m->in_medium) break;
        for (int ch = 0; ch < 3; ++ch) {
            tau[ch] = tau_ch(c, ch, m->col[m->n]);
            pe[ch] = -expm1(-tau[ch]);
            if (pe[ch] > 0) act[nact++] = ch;
            bg[ch] = m->ground ? beta[ch] * exp(-tau[ch]) : 0.0;
        }
        if (m->ground) {
            along(r.o, r.d, m->t[m->n], xg);
            normalize3(xg, ng);
            for (int i = 0; i < 3; ++i) xg[i] = a->bottom_radius * ng[i];
        }
        if (nact > 0) {
            int j = act[(int)(rng_u(g) * nact)];
            double t = march_sample(c, m, j, -log1p(-rng_u(g) * pe[j]), col), p = 0.0;
            along(r.o, r.d, t, xv);
            local_coefs(c, ray_radius(&r, t), st, sr, sm);
            for (int i = 0; i < nact; ++i)
                p += st[act[i]] * exp(-tau_ch(c, act[i], col)) / pe[act[i]] / nact;
            for (int ch = 0; ch < 3 && p > 0; ++ch) /* sigma_s enters through the kernel */
                bv[ch] = beta[ch] * exp(-tau_ch(c, ch, col)) / p, has_v = 1;
        }
        if (!has_v && !m->ground) break;
        if (k >= S->min_order) {
            // ground: albedo/pi * cos * T_sun; volume: sigma_s * phase * T_sun
            for (int ch = 0; ch < 3; ++ch)
                w[ch] = bg[ch] * a->ground_albedo[ch] / REF_PI * fmax(0.0, dot3(ng, S->sun));
            nee(S, xg, w, m, out);
            for (int ch = 0; ch < 3; ++ch)
                w[ch] = has_v ? bv[ch] * kernel(a, ch, sr, sm, dot3(d, S->sun)) : 0.0;
            nee(S, xv, w, m, out);
        }
        if (k == S->max_order) break;
        for (int ch = 0; ch < 3; ++ch)
            wg += bg[ch] * a->ground_albedo[ch], wv += has_v ? bv[ch] * (sr[ch] + sm[ch]) : 0.0;
        if (!(wg + wv > 0)) break;
        double pg = wg / (wg + wv);
        if (pg > 0 && (pg >= 1 || rng_u(g) < pg)) {
            double u1 = rng_u(g), u2 = rng_u(g);
            dir_about(ng, sqrt(1.0 - u1), 2.0 * REF_PI * u2, nd); /* cosine-weighted */
            for (int ch = 0; ch < 3; ++ch) beta[ch] = bg[ch] * a->ground_albedo[ch] / pg;
            memcpy(x, xg, sizeof x);
        } else {
            /* phase mixture: a channel evenly among the scattering ones, then Rayleigh or
             * Mie by their share of that channel's scattering */
            int sc[3], ns = 0;
            for (int ch = 0; ch < 3; ++ch)
                if (sr[ch] + sm[ch] > 0) sc[ns++] = ch;
            int j = sc[(int)(rng_u(g) * ns)];
            double ct = rng_u(g) * (sr[j] + sm[j]) < sr[j] ? sample_rayleigh(rng_u(g))
                                                           : sample_cs(a->mie_g[j], g);
            dir_about(d, ct, 2.0 * REF_PI * rng_u(g), nd);
            double pdf = 0.0;
            for (int i = 0; i < ns; ++i)
                pdf += kernel(a, sc[i], sr, sm, ct) / (sr[sc[i]] + sm[sc[i]]) / ns;
            for (int ch = 0; ch < 3; ++ch)
                beta[ch] = bv[ch] / (1.0 - pg) * kernel(a, ch, sr, sm, ct) / pdf;
            memcpy(x, xv, sizeof x);
        }
        double mb = fmax(beta[0], fmax(beta[1], beta[2]));
        if (!(mb > 0) || (k >= 2 && mb < RR_LEVEL && rng_u(g) * RR_LEVEL >= mb)) break;
        for (int ch = 0; ch < 3 && k >= 2 && mb < RR_LEVEL; ++ch) beta[ch] *= RR_LEVEL / mb;
        memcpy(d, nd, sizeof d);
    }
}

struct worker {
    const struct mc_setup *S;
    int id, nthreads;
};

static void *worker_main(void *arg)
{
    const struct worker *w = arg;
    const struct mc_setup *S = w->S;
    struct march *m = malloc(sizeof *m);
    for (long b = w->id; m && b < S->nblocks; b += w->nthreads) {
        double sums[6] = {0, 0, 0, 0, 0, 0};
        long begin = S->first + b * PATH_BLOCK, end = begin + PATH_BLOCK;
        for (long i = begin; i < end && i < S->first + S->count; ++i) {
            uint64_t h = (uint64_t)i ^ 0xD1B54A32D192ED03ull;
            uint64_t g = S->seed ^ splitmix64(&h);
            double dir[3], v[3], scale = 1.0, axis[3] = {0, 0, S->mode > 0 ? 1.0 : -1.0};
            if (S->mode == 0) {
                memcpy(dir, S->view, sizeof dir);
            } else {
                double u1 = rng_u(&g), u2 = rng_u(&g);
                dir_about(axis, sqrt(1.0 - u1), 2.0 * REF_PI * u2, dir);
                scale = REF_PI; // E = pi * E[L] for cosine-weighted directions
            }
            trace(S, dir, &g, m, v);
            for (int ch = 0; ch < 3; ++ch)
                sums[ch] += scale * v[ch], sums[3 + ch] += scale * v[ch] * scale * v[ch];
        }
        memcpy(S->blocks[b], sums, sizeof sums);
    }
    free(m); /* without memory its blocks stay NaN */
    return NULL;
}

/* Adds the sums and sums of squares of paths [first, first + count) to sums[6]. */
static void mc_batch(struct mc_setup *S, int threads, long first, long count, double sums[6])
{
    pthread_t tid[MAX_THREADS];
    int started[MAX_THREADS] = {0};
    struct worker w[MAX_THREADS];
    if (count <= 0 || S->max_order < S->min_order) return;
    S->first = first, S->count = count, S->nblocks = (count + PATH_BLOCK - 1) / PATH_BLOCK;
    S->blocks = malloc((size_t)S->nblocks * sizeof *S->blocks);
    if (!S->blocks) {
        sums[0] = sums[1] = sums[2] = NAN;
        return;
    }
    for (long b = 0; b < S->nblocks; ++b)
        for (int q = 0; q < 6; ++q) S->blocks[b][q] = NAN;
    threads = threads < 1 ? 1 : threads > MAX_THREADS ? MAX_THREADS : threads;
    threads = threads > S->nblocks ? (int)S->nblocks : threads;
    for (int i = 0; i < threads; ++i) {
        w[i] = (struct worker){S, i, threads};
        if (i > 0) started[i] = pthread_create(&tid[i], NULL, worker_main, &w[i]) == 0;
    }
    worker_main(&w[0]);
    for (int i = 1; i < threads; ++i)
        if (started[i]) pthread_join(tid[i], NULL);
        else worker_main(&w[i]);
    for (long b = 0; b < S->nblocks; ++b) /* fixed order: independent of scheduling */
        for (int q = 0; q < 6; ++q) sums[q] += S->blocks[b][q];
    free(S->blocks);
    S->blocks = NULL;
}

static void mc_finish(const double sums[6], double N, double out[3], double se[3])
{
    for (int ch = 0; ch < 3; ++ch) {
        out[ch] = N > 0 ? sums[ch] / N : 0.0;
        double var = N > 1 ? (sums[3 + ch] - N * out[ch] * out[ch]) / (N - 1.0) : 0.0;
        if (se) se[ch] = N > 0 ? sqrt(fmax(var, 0.0) / N) : 0.0;
    }
}

static struct mc_setup *mc_setup_new(const struct ref_atmosphere *a, double altitude,
                                     const double sun_dir[3], int min_order, int max_order,
                                     uint64_t seed)
{
    struct mc_setup *S = calloc(1, sizeof *S);
    if (!S) return NULL;
    ctx_init(&S->seg, a, Q_MC);
    S->a = a, S->cam[2] = a->bottom_radius + altitude, S->seed = seed;
    S->min_order = min_order < 1 ? 1 : min_order, S->max_order = max_order;
    normalize3(sun_dir, S->sun);
    return S;
}

static void mc_run(struct mc_setup *S, int paths, int threads, double out[3], double se[3])
{
    double sums[6] = {0, 0, 0, 0, 0, 0};
    if (!S) {
        out[0] = out[1] = out[2] = NAN;
        return;
    }
    mc_batch(S, threads, 0, paths, sums);
    mc_finish(sums, S->max_order >= S->min_order && paths > 0 ? paths : 0, out, se);
    free(S);
}

void ref_radiance_mc(const struct ref_atmosphere *a, double altitude, const double view_dir[3],
                     const double sun_dir[3], int min_order, int max_order, int paths,
                     uint64_t seed, int threads, double out[3], double std_error[3])
{
    struct mc_setup *S = mc_setup_new(a, altitude, sun_dir, min_order, max_order, seed);
    if (S) normalize3(view_dir, S->view);
    mc_run(S, paths, threads, out, std_error);
}

void ref_radiance_adaptive(const struct ref_atmosphere *a, double altitude,
                           const double view_dir[3], const double sun_dir[3], int max_order,
                           double rel_error, int min_paths, int max_paths, uint64_t seed,
                           int threads, double out[3], double std_error[3], int *paths_used)
{
    double ss[3] = {0, 0, 0}, ms[3] = {0, 0, 0}, se[3] = {0, 0, 0}, sums[6] = {0};
    long n = 0, batch = min_paths > PATH_BLOCK ? min_paths : PATH_BLOCK;
    struct mc_setup *S = mc_setup_new(a, altitude, sun_dir, 2, max_order, seed);
    if (max_order >= 1) ref_single_scattering(a, altitude, view_dir, sun_dir, ss);
    if (!S) ss[0] = ss[1] = ss[2] = NAN;
    else normalize3(view_dir, S->view);
    while (S && max_order >= 2 && n < max_paths) {
        batch = batch < max_paths - n ? batch : max_paths - n;
        mc_batch(S, threads, n, batch, sums);
        n += batch;
        mc_finish(sums, (double)n, ms, se);
        double worst = 0.0;
        for (int ch = 0; ch < 3; ++ch)
            worst = fmax(worst, ss[ch] + ms[ch] > 0 ? se[ch] / (ss[ch] + ms[ch]) : 0.0);
        if (!(worst > rel_error)) break;
        /* SE ~ 1/sqrt(n): aim 10% past the paths the target needs */
        batch = (long)fmin(1.1 * (double)n * (worst / rel_error) * (worst / rel_error), 1e9) - n +
                PATH_BLOCK;
    }
    free(S);
    for (int ch = 0; ch < 3; ++ch) {
        out[ch] = ss[ch] + ms[ch];
        if (std_error) std_error[ch] = se[ch];
    }
    if (paths_used) *paths_used = (int)n;
}

void ref_radiance(const struct ref_atmosphere *a, double altitude, const double view_dir[3],
                  const double sun_dir[3], int max_order, int paths, uint64_t seed,
                  int threads, double out[3], double std_error[3])
{
    ref_radiance_adaptive(a, altitude, view_dir, sun_dir, max_order, 0.0, paths, paths, seed,
                          threads, out, std_error, NULL);
}

void ref_irradiance(const struct ref_atmosphere *a, double altitude, int facing_up,
                    const double sun_dir[3], int max_order, int paths, uint64_t seed,
                    int threads, double out[3], double std_error[3])
{
    struct mc_setup *S = mc_setup_new(a, altitude, sun_dir, 1, max_order, seed);
    if (S) S->mode = facing_up ? 1 : -1;
    mc_run(S, paths, threads, out, std_error);
}

void ref_sky_irradiance(const struct ref_atmosphere *a, const double sun_dir[3], int max_order,
                        int paths, uint64_t seed, int threads, double out[3],
                        double std_error[3])
{
    ref_irradiance(a, 0.0, 1, sun_dir, max_order, paths, seed, threads, out, std_error);
}
