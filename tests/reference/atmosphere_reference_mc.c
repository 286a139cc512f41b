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
    double t[3] = {1.0 + sign * axis[0] * axis[0] * a, sign * b, -sign * axis[0]};
    double u[3] = {b, sign + axis[1] * axis[1] * a, -axis[1]};
    double s = sqrt(fmax(0.0, 1.0 - cos_t * cos_t)), cp = cos(phi) * s, sp = sin(phi) * s;
    for (int i = 0; i < 3; ++i) out[i] = cp * t[i] + sp * u[i] + cos_t * axis[i];
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
        if (tau_ch(c, ch, m->col[mid]) <= target) k = mid;
        else hi_k = mid - 1;
    }
    double a = m->t[k], lo = a, hi = m->t[k + 1], acc[4], dn[4];
    double base = tau_ch(c, ch, m->col[k]), rem = target - base;
    double piece = tau_ch(c, ch, m->col[k + 1]) - base;
    double t = piece > 0 ? a + (hi - a) * fmin(1.0, fmax(0.0, rem / piece)) : 0.5 * (lo + hi);
    for (int it = 0;; ++it) {
        ref_medium_gl5(c, &m->r, a, t, acc);
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
    ref_medium_transmittance_to_top(&S->seg, x, S->sun, m, Ts);
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
        ref_medium_march_ray(c, &r, HUGE_VAL, NULL, 0, 0, m);
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
    ref_medium_ctx_init(&S->seg, a, Q_MC);
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
