/* Monte Carlo of the atmosphere reference: path tracing with next-event estimation toward the
 * sun, in threads (atmosphere_reference.h, atmosphere_reference_internal.h). */
#include "atmosphere_reference_internal.h"

#include <math.h>
#include <pthread.h>
#include <stdlib.h>
#include <string.h>

/* ---------------------------------------------------------------- Monte Carlo */

#define PATH_BLOCK 64
#define MAX_THREADS 64
/* Russian roulette keeps a path with probability max(beta) / RR_LEVEL below that level. */
#define RR_LEVEL 0.1

/* Direction at polar cosine cos_t and azimuth phi about unit axis (basis: Duff et al. 2017). */
static void dir_about(const double axis[3], double cos_t, double phi, double out[3])
{
    double sign = copysign(1.0, axis[2]), a = -1.0 / (sign + axis[2]), b = axis[0] * axis[1] * a;
    double t[3] = { 1.0 + sign * axis[0] * axis[0] * a, sign * b, -sign * axis[0] };
    double u[3] = { b, sign + axis[1] * axis[1] * a, -axis[1] };
    double s = sqrt(fmax(0.0, 1.0 - cos_t * cos_t)), cp = cos(phi) * s, sp = sin(phi) * s;
    for (int i = 0; i < 3; ++i)
        out[i] = cp * t[i] + sp * u[i] + cos_t * axis[i];
    normalize3(out, out);
}

/* Distance where channel ch's optical depth reaches target (below the total); col_out gets
 * the columns there. Newton on the piece's quadrature, safeguarded by bisection. */
static double march_sample(const struct ctx *c, const struct march *m, int ch, double target,
                           double col_out[4])
{
    int k = 0, hi_k = m->n - 1;
    while (k < hi_k) {
        int mid = (k + hi_k + 1) / 2;
        if (tau_ch(c, ch, m->col[mid]) <= target)
            k = mid;
        else
            hi_k = mid - 1;
    }
    double a = m->t[k], lo = a, hi = m->t[k + 1], acc[4], dn[4];
    double base = tau_ch(c, ch, m->col[k]), rem = target - base;
    double piece = tau_ch(c, ch, m->col[k + 1]) - base;
    double t = piece > 0 ? a + (hi - a) * fmin(1.0, fmax(0.0, rem / piece)) : 0.5 * (lo + hi);
    for (int it = 0;; ++it) {
        ref_medium_gl5(c, &m->r, a, t, acc);
        double f = tau_ch(c, ch, acc) - rem;
        if (fabs(f) <= 1e-12 * target || it == 100 || hi - lo <= 1e-13 * hi)
            break;
        if (f > 0)
            hi = t;
        else
            lo = t;
        densities(c, ray_radius(&m->r, t), dn);
        double sigma = tau_ch(c, ch, dn), tn = sigma > 0 ? t - f / sigma : lo;
        t = tn > lo && tn < hi ? tn : 0.5 * (lo + hi);
    }
    for (int q = 0; q < 4; ++q)
        col_out[q] = m->col[k][q] + acc[q];
    return t;
}

/* splitmix64 (Steele et al. 2014), one stream per path started from a hash of (seed, path). */
static uint64_t splitmix64(uint64_t *x)
{
    uint64_t z = (*x += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
}

double ref_uniform(uint64_t *g)
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
        double u = ref_uniform(rg), c = 2.0 * u - 1.0;
        if (fabs(g) >= 1e-6) {
            double sq = (1.0 - g * g) / (1.0 - g + 2.0 * g * u);
            c = fmax(-1.0, fmin(1.0, (1.0 + g * g - sq * sq) / (2.0 * g)));
        }
        if (2.0 * ref_uniform(rg) < 1.0 + c * c)
            return c;
    }
}

struct mc_setup {
    struct ctx seg;
    const struct ref_atmosphere *a;
    double sun[3], cam[3], view[3];
    int mode; /* 0 radiance along view; +1/-1 cosine-weighted about +z / -z, times pi */
    int min_order, max_order;
    int estimator;              /* enum ref_mc_estimator */
    long first, count, nblocks; /* the batch being run */
    uint64_t seed;
    double (*blocks)[6];
};

/* Adds w * T_sun(x) to out (next-event estimation toward the sun). */
static void nee(const struct mc_setup *S, const double x[3], const double w[3], struct march *m,
                double out[3])
{
    double Ts[3];
    if (!(w[0] > 0 || w[1] > 0 || w[2] > 0))
        return;
    ref_medium_transmittance_to_top(&S->seg, x, S->sun, m, Ts);
    for (int ch = 0; ch < 3; ++ch)
        out[ch] += w[ch] * Ts[ch];
}

/* sigma_s * phase for channel ch (1/km/sr). */
static double kernel(const struct ref_atmosphere *a, int ch, const double sr[3], const double sm[3],
                     double c)
{
    return sr[ch] * ref_phase_rayleigh(c) + sm[ch] * ref_phase_mie(c, a->mie_g[ch]);
}

/* The planet's shadow on the line o + t d (d unit length): the points y with y.s < 0 and
 * |y|^2 - (y.s)^2 < R^2, i.e. those whose ray toward the sun s meets the planet. It is one
 * interval (t0, t1), possibly unbounded; returns 0 when the line does not cross it. */
static int shadow_interval(const double o[3], const double d[3], const double s[3], double R,
                           double *t0, double *t1)
{
    double os = dot3(o, s), ds = dot3(d, s);
    /* |y|^2 - (y.s)^2 - R^2 = qa t^2 + 2 qb t + qc */
    double qa = 1.0 - ds * ds, qb = dot3(o, d) - os * ds, qc = dot3(o, o) - os * os - R * R;
    double lo = -HUGE_VAL, hi = HUGE_VAL;
    if (qa > 1e-15) {
        double disc = qb * qb - qa * qc;
        if (disc <= 0)
            return 0;
        double q = -(qb + copysign(sqrt(disc), qb)); /* the roots without cancellation */
        double r1 = q / qa, r2 = q != 0 ? qc / q : r1;
        lo = fmin(r1, r2), hi = fmax(r1, r2);
    } else if (qc >= 0) {
        return 0;
    }
    if (ds > 0)
        hi = fmin(hi, -os / ds);
    else if (ds < 0)
        lo = fmax(lo, -os / ds);
    else if (os >= 0)
        return 0;
    if (!(lo < hi))
        return 0;
    *t0 = lo, *t1 = hi;
    return 1;
}

/* Columns from the start of m's ray to distance t (within its pieces). */
static void march_column_at(const struct ctx *c, const struct march *m, double t, double col[4])
{
    int k = 0, hi_k = m->n - 1;
    while (k < hi_k) {
        int mid = (k + hi_k + 1) / 2;
        if (m->t[mid] <= t)
            k = mid;
        else
            hi_k = mid - 1;
    }
    double acc[4];
    ref_medium_gl5(c, &m->r, m->t[k], fmin(fmax(t, m->t[k]), m->t[k + 1]), acc);
    for (int q = 0; q < 4; ++q)
        col[q] = m->col[k][q] + acc[q];
}

/* Next-event estimation over a whole segment whose line crosses the planet's shadow: its
 * expected value beta * integral of T(0, t) sigma_s(t) p(d.s) T_sun(t) dt is estimated from
 * SUNLIT_SAMPLES points per channel drawn, stratified, from that channel's free-flight
 * density restricted to the sunlit parts of the segment, combined by the balance heuristic
 * (Veach 1997, eq. 9.13). In twilight the sunlit part is a thin, far stretch of the segment
 * that a collision drawn from the whole segment rarely reaches; here every path gets it.
 * Returns 0, adding nothing, when the segment does not meet the shadow: the caller then keeps
 * its estimate at the path's own collision, which is as good there and costs nothing more. */
#define SUNLIT_SAMPLES 2
static int sunlit_segment_nee(const struct mc_setup *S, const struct march *m, const int act[3],
                              int nact, const double beta[3], uint64_t *g, struct march *ms,
                              double out[3])
{
    const struct ctx *c = &S->seg;
    double t0, t1, ta = m->t[0], tb = m->t[m->n];
    if (!shadow_interval(m->r.o, m->r.d, S->sun, c->R, &t0, &t1) || t1 <= ta || t0 >= tb)
        return 0;
    double iv[2][2], mass[3][2], top[3][2], width[3][2], total[3] = { 0, 0, 0 };
    int ni = 0;
    if (t0 > ta)
        iv[ni][0] = ta, iv[ni][1] = t0, ++ni;
    if (t1 < tb)
        iv[ni][0] = t1, iv[ni][1] = tb, ++ni;
    for (int i = 0; i < ni; ++i) {
        double ca[4], cb[4];
        march_column_at(c, m, iv[i][0], ca);
        march_column_at(c, m, iv[i][1], cb);
        for (int ch = 0; ch < 3; ++ch) {
            double tau_a = tau_ch(c, ch, ca), tau_b = tau_ch(c, ch, cb);
            top[ch][i] = tau_a;
            width[ch][i] = -expm1(-(tau_b - tau_a));
            mass[ch][i] = exp(-tau_a) * width[ch][i]; /* integral of sigma_t T over the part */
            total[ch] += mass[ch][i];
        }
    }
    int lit[3], nlit = 0;
    for (int i = 0; i < nact; ++i)
        if (total[act[i]] > 0)
            lit[nlit++] = act[i];
    double cos_sun = dot3(m->r.d, S->sun);
    for (int i = 0; i < nlit; ++i) {
        int j = lit[i];
        for (int k = 0; k < SUNLIT_SAMPLES; ++k) {
            double u = (k + ref_uniform(g)) / SUNLIT_SAMPLES * total[j];
            int p = ni > 1 && u >= mass[j][0];
            double f = fmin(1.0, (p ? u - mass[j][0] : u) / fmax(mass[j][p], 1e-300));
            double col[4], st[3], sr[3], sm[3], x[3], Ts[3], pdf = 0.0;
            double t = march_sample(c, m, j, top[j][p] - log1p(-f * width[j][p]), col);
            along(m->r.o, m->r.d, t, x);
            local_coefs(c, ray_radius(&m->r, t), st, sr, sm);
            for (int q = 0; q < nlit; ++q) /* the balance heuristic's summed densities */
                pdf += SUNLIT_SAMPLES * st[lit[q]] * exp(-tau_ch(c, lit[q], col)) / total[lit[q]];
            if (!(pdf > 0))
                continue;
            ref_medium_transmittance_to_top(c, x, S->sun, ms, Ts);
            for (int ch = 0; ch < 3; ++ch)
                out[ch] += beta[ch] * exp(-tau_ch(c, ch, col)) * kernel(S->a, ch, sr, sm, cos_sun) *
                           Ts[ch] / pdf;
        }
    }
    return 1;
}

/* Whether the sun s is hidden by the planet from x (see shadow_interval). */
static int in_shadow(const double x[3], const double s[3], double R)
{
    double xs = dot3(x, s);
    return xs < 0 && dot3(x, x) - xs * xs < R * R;
}

/* Directions from a shadowed point: a share GUIDE_SHARE drawn from a Henyey-Greenstein lobe
 * of asymmetry GUIDE_G about the sun, the rest as before (phase function or cosine), and
 * weighted by the mixture's density, so the estimate stays unbiased and never costs more
 * than 1 / (1 - GUIDE_SHARE) times the variance of before (a defensive mixture, Hesterberg
 * 1995). The twilight sky seen from the shadow is brightest toward the sun just above the
 * horizon, a small part of the sphere that phase or cosine sampling rarely visits. */
#define GUIDE_SHARE 0.5
#define GUIDE_G 0.8
static double guide_pdf(const double s[3], const double w[3])
{
    double den = 1.0 + GUIDE_G * GUIDE_G - 2.0 * GUIDE_G * dot3(s, w);
    return (1.0 - GUIDE_G * GUIDE_G) / (4.0 * REF_PI * den * sqrt(den));
}

/* One path from the camera along dir; out gets its estimate of orders min..max. On every
 * segment the volume vertex is a forced collision (density sigma_t T / (1 - T(L)) per
 * channel, mixed evenly over the channels); a segment that ends on the ground also yields
 * the ground vertex with weight T(L). Both get next-event estimation toward the sun, and
 * the path continues from one of them, chosen by its expected throughput. */
static void trace(const struct mc_setup *S, const double dir[3], uint64_t *g, struct march *m,
                  struct march *ms, double out[3])
{
    const struct ctx *c = &S->seg;
    const struct ref_atmosphere *a = S->a;
    double x[3], d[3], beta[3] = { 1, 1, 1 };
    memcpy(x, S->cam, sizeof x);
    memcpy(d, dir, sizeof d);
    out[0] = out[1] = out[2] = 0.0;
    for (int k = 1; k <= S->max_order; ++k) {
        double col[4], st[3], sr[3], sm[3], tau[3], pe[3], bg[3] = { 0, 0, 0 }, bv[3] = { 0, 0, 0 };
        double xg[3], xv[3], ng[3] = { 0, 0, 1 }, w[3], wg = 0.0, wv = 0.0, nd[3];
        int act[3], nact = 0, has_v = 0;
        struct ray r;
        ray_set(&r, x, d);
        ref_medium_march_ray(c, &r, HUGE_VAL, NULL, 0, 0, m);
        if (!m->in_medium)
            break;
        for (int ch = 0; ch < 3; ++ch) {
            tau[ch] = tau_ch(c, ch, m->col[m->n]);
            pe[ch] = -expm1(-tau[ch]);
            if (pe[ch] > 0)
                act[nact++] = ch;
            bg[ch] = m->ground ? beta[ch] * exp(-tau[ch]) : 0.0;
        }
        if (m->ground) {
            along(r.o, r.d, m->t[m->n], xg);
            normalize3(xg, ng);
            for (int i = 0; i < 3; ++i)
                xg[i] = a->bottom_radius * ng[i];
        }
        if (nact > 0) {
            int j = act[(int)(ref_uniform(g) * nact)];
            double t = march_sample(c, m, j, -log1p(-ref_uniform(g) * pe[j]), col), p = 0.0;
            along(r.o, r.d, t, xv);
            local_coefs(c, ray_radius(&r, t), st, sr, sm);
            for (int i = 0; i < nact; ++i)
                p += st[act[i]] * exp(-tau_ch(c, act[i], col)) / pe[act[i]] / nact;
            for (int ch = 0; ch < 3 && p > 0; ++ch) /* sigma_s enters through the kernel */
                bv[ch] = beta[ch] * exp(-tau_ch(c, ch, col)) / p, has_v = 1;
        }
        if (!has_v && !m->ground)
            break;
        if (k >= S->min_order) {
            /* its own random stream, so that the path itself is drawn as without it */
            uint64_t h = *g ^ 0x5851F42D4C957F2Dull, gn = splitmix64(&h);
            int segment_done = S->estimator == REF_MC_SUNLIT_SEGMENTS && nact > 0 &&
                               sunlit_segment_nee(S, m, act, nact, beta, &gn, ms, out);
            // ground: albedo/pi * cos * T_sun; volume: sigma_s * phase * T_sun
            for (int ch = 0; ch < 3; ++ch)
                w[ch] = bg[ch] * a->ground_albedo[ch] / REF_PI * fmax(0.0, dot3(ng, S->sun));
            nee(S, xg, w, ms, out);
            for (int ch = 0; ch < 3; ++ch)
                w[ch] = has_v && !segment_done ? bv[ch] * kernel(a, ch, sr, sm, dot3(d, S->sun))
                                               : 0.0;
            nee(S, xv, w, ms, out);
        }
        if (k == S->max_order)
            break;
        for (int ch = 0; ch < 3; ++ch)
            wg += bg[ch] * a->ground_albedo[ch], wv += has_v ? bv[ch] * (sr[ch] + sm[ch]) : 0.0;
        if (!(wg + wv > 0))
            break;
        double pg = wg / (wg + wv);
        int on_ground = pg > 0 && (pg >= 1 || ref_uniform(g) < pg);
        const double *xn = on_ground ? xg : xv;
        /* From a point in the planet's shadow, part of the directions go to a lobe about the
         * sun: the twilight glow it sees is brightest there (see guide_pdf). */
        int guided = S->estimator == REF_MC_SUNLIT_SEGMENTS && in_shadow(xn, S->sun, c->R);
        int to_guide = guided && ref_uniform(g) < GUIDE_SHARE;
        if (to_guide) {
            double u = ref_uniform(g),
                   sq = (1.0 - GUIDE_G * GUIDE_G) / (1.0 - GUIDE_G + 2.0 * GUIDE_G * u);
            dir_about(S->sun, (1.0 + GUIDE_G * GUIDE_G - sq * sq) / (2.0 * GUIDE_G),
                      2.0 * REF_PI * ref_uniform(g), nd);
        }
        if (on_ground) {
            if (!to_guide) {
                double u1 = ref_uniform(g), u2 = ref_uniform(g);
                dir_about(ng, sqrt(1.0 - u1), 2.0 * REF_PI * u2, nd); /* cosine-weighted */
            }
            double cos_n = fmax(0.0, dot3(ng, nd)), pdf = cos_n / REF_PI;
            if (guided)
                pdf = (1.0 - GUIDE_SHARE) * pdf + GUIDE_SHARE * guide_pdf(S->sun, nd);
            for (int ch = 0; ch < 3; ++ch) /* albedo/pi * cos / pdf: the albedo without guiding */
                beta[ch] = cos_n > 0 ? bg[ch] * a->ground_albedo[ch] / REF_PI * cos_n / pdf / pg
                                     : 0.0;
            memcpy(x, xg, sizeof x);
        } else {
            /* phase mixture: a channel evenly among the scattering ones, then Rayleigh or
             * Mie by their share of that channel's scattering */
            int sc[3], ns = 0;
            for (int ch = 0; ch < 3; ++ch)
                if (sr[ch] + sm[ch] > 0)
                    sc[ns++] = ch;
            if (!to_guide) {
                int j = sc[(int)(ref_uniform(g) * ns)];
                double ct = ref_uniform(g) * (sr[j] + sm[j]) < sr[j]
                                ? sample_rayleigh(ref_uniform(g))
                                : sample_cs(a->mie_g[j], g);
                dir_about(d, ct, 2.0 * REF_PI * ref_uniform(g), nd);
            }
            double ct = fmax(-1.0, fmin(1.0, dot3(d, nd))), pdf = 0.0;
            for (int i = 0; i < ns; ++i)
                pdf += kernel(a, sc[i], sr, sm, ct) / (sr[sc[i]] + sm[sc[i]]) / ns;
            if (guided)
                pdf = (1.0 - GUIDE_SHARE) * pdf + GUIDE_SHARE * guide_pdf(S->sun, nd);
            for (int ch = 0; ch < 3; ++ch)
                beta[ch] = bv[ch] / (1.0 - pg) * kernel(a, ch, sr, sm, ct) / pdf;
            memcpy(x, xv, sizeof x);
        }
        double mb = fmax(beta[0], fmax(beta[1], beta[2]));
        if (!(mb > 0) || (k >= 2 && mb < RR_LEVEL && ref_uniform(g) * RR_LEVEL >= mb))
            break;
        for (int ch = 0; ch < 3 && k >= 2 && mb < RR_LEVEL; ++ch)
            beta[ch] *= RR_LEVEL / mb;
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
    struct march *m = malloc(2 * sizeof *m), *ms = m ? m + 1 : NULL;
    for (long b = w->id; m && b < S->nblocks; b += w->nthreads) {
        double sums[6] = { 0, 0, 0, 0, 0, 0 };
        long begin = S->first + b * PATH_BLOCK, end = begin + PATH_BLOCK;
        for (long i = begin; i < end && i < S->first + S->count; ++i) {
            uint64_t h = (uint64_t)i ^ 0xD1B54A32D192ED03ull;
            uint64_t g = S->seed ^ splitmix64(&h);
            double dir[3], v[3], scale = 1.0, axis[3] = { 0, 0, S->mode > 0 ? 1.0 : -1.0 };
            if (S->mode == 0) {
                memcpy(dir, S->view, sizeof dir);
            } else {
                double u1 = ref_uniform(&g), u2 = ref_uniform(&g);
                dir_about(axis, sqrt(1.0 - u1), 2.0 * REF_PI * u2, dir);
                scale = REF_PI; // E = pi * E[L] for cosine-weighted directions
            }
            trace(S, dir, &g, m, ms, v);
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
    int started[MAX_THREADS] = { 0 };
    struct worker w[MAX_THREADS];
    if (count <= 0 || S->max_order < S->min_order)
        return;
    S->first = first, S->count = count, S->nblocks = (count + PATH_BLOCK - 1) / PATH_BLOCK;
    S->blocks = malloc((size_t)S->nblocks * sizeof *S->blocks);
    if (!S->blocks) {
        sums[0] = sums[1] = sums[2] = NAN;
        return;
    }
    for (long b = 0; b < S->nblocks; ++b)
        for (int q = 0; q < 6; ++q)
            S->blocks[b][q] = NAN;
    threads = threads < 1 ? 1 : threads > MAX_THREADS ? MAX_THREADS : threads;
    threads = threads > S->nblocks ? (int)S->nblocks : threads;
    for (int i = 0; i < threads; ++i) {
        w[i] = (struct worker){ S, i, threads };
        if (i > 0)
            started[i] = pthread_create(&tid[i], NULL, worker_main, &w[i]) == 0;
    }
    worker_main(&w[0]);
    for (int i = 1; i < threads; ++i)
        if (started[i])
            pthread_join(tid[i], NULL);
        else
            worker_main(&w[i]);
    for (long b = 0; b < S->nblocks; ++b) /* fixed order: independent of scheduling */
        for (int q = 0; q < 6; ++q)
            sums[q] += S->blocks[b][q];
    free(S->blocks);
    S->blocks = NULL;
}

static void mc_finish(const double sums[6], double N, double out[3], double se[3])
{
    for (int ch = 0; ch < 3; ++ch) {
        out[ch] = N > 0 ? sums[ch] / N : 0.0;
        double var = N > 1 ? (sums[3 + ch] - N * out[ch] * out[ch]) / (N - 1.0) : 0.0;
        if (se)
            se[ch] = N > 0 ? sqrt(fmax(var, 0.0) / N) : 0.0;
    }
}

static struct mc_setup *mc_setup_new(const struct ref_atmosphere *a, double altitude,
                                     const double sun_dir[3], int min_order, int max_order,
                                     uint64_t seed)
{
    struct mc_setup *S = calloc(1, sizeof *S);
    if (!S)
        return NULL;
    ref_medium_ctx_init(&S->seg, a, Q_MC);
    S->a = a, S->cam[2] = a->bottom_radius + altitude, S->seed = seed;
    S->min_order = min_order < 1 ? 1 : min_order, S->max_order = max_order;
    normalize3(sun_dir, S->sun);
    return S;
}

static void mc_run(struct mc_setup *S, int paths, int threads, double out[3], double se[3])
{
    double sums[6] = { 0, 0, 0, 0, 0, 0 };
    if (!S) {
        out[0] = out[1] = out[2] = NAN;
        return;
    }
    mc_batch(S, threads, 0, paths, sums);
    mc_finish(sums, S->max_order >= S->min_order && paths > 0 ? paths : 0, out, se);
    free(S);
}

void ref_radiance_mc_estimator(const struct ref_atmosphere *a, double altitude,
                               const double view_dir[3], const double sun_dir[3], int min_order,
                               int max_order, int paths, uint64_t seed, int threads,
                               enum ref_mc_estimator estimator, double out[3], double std_error[3])
{
    struct mc_setup *S = mc_setup_new(a, altitude, sun_dir, min_order, max_order, seed);
    if (S)
        normalize3(view_dir, S->view), S->estimator = estimator;
    mc_run(S, paths, threads, out, std_error);
}

void ref_radiance_mc(const struct ref_atmosphere *a, double altitude, const double view_dir[3],
                     const double sun_dir[3], int min_order, int max_order, int paths,
                     uint64_t seed, int threads, double out[3], double std_error[3])
{
    ref_radiance_mc_estimator(a, altitude, view_dir, sun_dir, min_order, max_order, paths, seed,
                              threads, REF_MC_SUNLIT_SEGMENTS, out, std_error);
}

void ref_radiance_adaptive(const struct ref_atmosphere *a, double altitude,
                           const double view_dir[3], const double sun_dir[3], int max_order,
                           double rel_error, int min_paths, int max_paths, uint64_t seed,
                           int threads, double out[3], double std_error[3], int *paths_used)
{
    double ss[3] = { 0, 0, 0 }, ms[3] = { 0, 0, 0 }, se[3] = { 0, 0, 0 }, sums[6] = { 0 };
    long n = 0, batch = min_paths > PATH_BLOCK ? min_paths : PATH_BLOCK;
    struct mc_setup *S = mc_setup_new(a, altitude, sun_dir, 2, max_order, seed);
    if (max_order >= 1)
        ref_single_scattering(a, altitude, view_dir, sun_dir, ss);
    if (!S)
        ss[0] = ss[1] = ss[2] = NAN;
    else
        normalize3(view_dir, S->view);
    while (S && max_order >= 2 && n < max_paths) {
        batch = batch < max_paths - n ? batch : max_paths - n;
        mc_batch(S, threads, n, batch, sums);
        n += batch;
        mc_finish(sums, (double)n, ms, se);
        double worst = 0.0;
        for (int ch = 0; ch < 3; ++ch)
            worst = fmax(worst, ss[ch] + ms[ch] > 0 ? se[ch] / (ss[ch] + ms[ch]) : 0.0);
        if (!(worst > rel_error))
            break;
        /* SE ~ 1/sqrt(n): aim 10% past the paths the target needs, but at most 4 times the
         * paths so far: in twilight one rare path can inflate the measured error for a while */
        batch = (long)fmin(1.1 * (double)n * (worst / rel_error) * (worst / rel_error),
                           fmin(4.0 * (double)n, 1e9)) -
                n + PATH_BLOCK;
    }
    free(S);
    for (int ch = 0; ch < 3; ++ch) {
        out[ch] = ss[ch] + ms[ch];
        if (std_error)
            std_error[ch] = se[ch];
    }
    if (paths_used)
        *paths_used = (int)n;
}

void ref_radiance(const struct ref_atmosphere *a, double altitude, const double view_dir[3],
                  const double sun_dir[3], int max_order, int paths, uint64_t seed, int threads,
                  double out[3], double std_error[3])
{
    ref_radiance_adaptive(a, altitude, view_dir, sun_dir, max_order, 0.0, paths, paths, seed,
                          threads, out, std_error, NULL);
}

void ref_irradiance(const struct ref_atmosphere *a, double altitude, int facing_up,
                    const double sun_dir[3], int max_order, int paths, uint64_t seed, int threads,
                    double out[3], double std_error[3])
{
    struct mc_setup *S = mc_setup_new(a, altitude, sun_dir, 1, max_order, seed);
    if (S)
        S->mode = facing_up ? 1 : -1;
    mc_run(S, paths, threads, out, std_error);
}

void ref_sky_irradiance(const struct ref_atmosphere *a, const double sun_dir[3], int max_order,
                        int paths, uint64_t seed, int threads, double out[3], double std_error[3])
{
    ref_irradiance(a, 0.0, 1, sun_dir, max_order, paths, seed, threads, out, std_error);
}
