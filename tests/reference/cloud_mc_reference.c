/* Monte Carlo photon tracer for a homogeneous plane-parallel slab: the standard weighted
 * Monte Carlo radiative-transfer scheme (Witt 1977, ApJS 35, 1) with the renderer's
 * dual-lobe Henyey-Greenstein phase (seed 000 eq. 14.17). See cloud_mc_reference.h. */
#include "cloud_mc_reference.h"

#include <math.h>
#include <pthread.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#define PI 3.14159265358979323846
#define CHUNK 4096 /* photons per RNG stream / partial sum */
#define MAX_THREADS 64
#define RR_LEVEL 1e-2  /* Russian roulette below this fraction of the starting weight */
#define RR_SURVIVE 0.1 /* survival probability in the roulette */

/* ------------------------------------------------------------------ random numbers */

/* splitmix64 (Steele, Lea & Flood 2014): seeds the streams. */
static uint64_t splitmix64(uint64_t *x)
{
    uint64_t z = (*x += 0x9e3779b97f4a7c15ull);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return z ^ (z >> 31);
}

/* xoshiro256** 1.0 (Blackman & Vigna 2018). */
struct rng {
    uint64_t s[4];
};

static uint64_t rotl(uint64_t x, int k)
{
    return (x << k) | (x >> (64 - k));
}

static uint64_t rng_next(struct rng *r)
{
    uint64_t *s = r->s;
    const uint64_t result = rotl(s[1] * 5, 7) * 9;
    const uint64_t t = s[1] << 17;
    s[2] ^= s[0];
    s[3] ^= s[1];
    s[1] ^= s[2];
    s[0] ^= s[3];
    s[2] ^= t;
    s[3] = rotl(s[3], 45);
    return result;
}

/* Uniform in [0, 1) with 53 random bits. */
static double rng_uniform(struct rng *r)
{
    return (double)(rng_next(r) >> 11) * 0x1.0p-53;
}

static void rng_seed(struct rng *r, uint64_t seed, uint64_t stream)
{
    uint64_t x = seed;
    uint64_t h = splitmix64(&x) ^ (stream * 0xd1b54a32d192ed03ull);
    for (int i = 0; i < 4; ++i)
        r->s[i] = splitmix64(&h);
    if (!(r->s[0] | r->s[1] | r->s[2] | r->s[3]))
        r->s[0] = 1; /* the all-zero state is the one forbidden state */
}

/* ------------------------------------------------------------------ phase function */

static double hg(double c, double g)
{
    double d = 1.0 + g * g - 2.0 * g * c;
    return (1.0 - g * g) / (4.0 * PI * d * sqrt(d));
}

double cloud_mc_phase(double c, double g0, double g1, double w)
{
    double p0 = hg(c, g0);
    return p0 + w * (hg(c, g1) - p0);
}

/* Inverse of the HG cumulative distribution in the scattering-angle cosine. */
static double hg_sample(double g, double u)
{
    if (fabs(g) < 1e-6)
        return 2.0 * u - 1.0;
    double s = (1.0 - g * g) / (1.0 - g + 2.0 * g * u);
    double c = (1.0 + g * g - s * s) / (2.0 * g);
    return c < -1.0 ? -1.0 : c > 1.0 ? 1.0 : c;
}

void cloud_gauss_legendre(int n, double lo, double hi, double *xs, double *ws)
{
    for (int i = 0; i < n; ++i) {
        double z = cos(PI * (i + 0.75) / (n + 0.5)), dp = 1.0;
        for (int it = 0; it < 100; ++it) { /* Newton's method on the Legendre polynomial */
            double p0 = 1.0, p1 = 0.0;
            for (int k = 1; k <= n; ++k) {
                double p2 = p1;
                p1 = p0;
                p0 = ((2.0 * k - 1.0) * z * p1 - (k - 1.0) * p2) / k;
            }
            dp = n * (z * p0 - p1) / (z * z - 1.0);
            double dz = p0 / dp;
            z -= dz;
            if (fabs(dz) < 1e-15)
                break;
        }
        xs[i] = 0.5 * (lo + hi) - 0.5 * (hi - lo) * z;
        ws[i] = (hi - lo) / ((1.0 - z * z) * dp * dp);
    }
}

void cloud_mc_bin_edges(int b, double *mu_lo, double *mu_hi)
{
    *mu_lo = (double)b / CLOUD_MC_BINS;
    *mu_hi = (double)(b + 1) / CLOUD_MC_BINS;
}

/* ------------------------------------------------------------------ the tracer */

/* Sums over one chunk of photons: first and second moments of each photon's contribution. */
struct tally {
    double r, r2, t, t2, a, a2;
    double rb[CLOUD_MC_BINS], rb2[CLOUD_MC_BINS], tb[CLOUD_MC_BINS], tb2[CLOUD_MC_BINS];
    double scatterings;
};

struct job {
    const struct cloud_mc_slab *slab;
    struct tally *chunks;
    long n_chunks;
    int first, stride; /* this worker's chunks: first, first + stride, ... */
};

static int bin_of(double mu)
{
    int b = (int)(mu * CLOUD_MC_BINS);
    return b < 0 ? 0 : b >= CLOUD_MC_BINS ? CLOUD_MC_BINS - 1 : b;
}

/* One photon: adds its contributions to *t. The position is the optical depth z below the
 * top, the direction the cosine u to the downward normal (u > 0 heads down). */
static void trace_photon(const struct cloud_mc_slab *s, struct rng *g, struct tally *t)
{
    const double tau = s->tau, omega = s->omega;
    /* Forced first collision: the path along the beam is drawn from exp(-l) truncated to
     * the slab, l < tau / mu0, and the weight carries the probability to interact. */
    const double w0 = -expm1(-tau / s->mu0);
    double z = -log1p(-rng_uniform(g) * w0) * s->mu0;
    if (z > tau)
        z = tau;
    double u = s->mu0, weight = w0, absorbed = 0.0, n = 0.0;
    for (;;) {
        /* Scatter at z. */
        n += 1.0;
        absorbed += weight * (1.0 - omega);
        weight *= omega;
        if (weight < RR_LEVEL * w0) {
            if (rng_uniform(g) >= RR_SURVIVE)
                break;
            weight /= RR_SURVIVE;
        }
        double lobe = rng_uniform(g) < s->w ? s->g1 : s->g0;
        double c = hg_sample(lobe, rng_uniform(g));
        double sin_t = sqrt(fmax(0.0, 1.0 - c * c));
        double cos_p = cos(2.0 * PI * rng_uniform(g));
        u = u * c + sqrt(fmax(0.0, 1.0 - u * u)) * sin_t * cos_p;
        u = u < -1.0 ? -1.0 : u > 1.0 ? 1.0 : u;
        /* Fly: optical path -log(1 - U) along u. */
        z += -log1p(-rng_uniform(g)) * u;
        if (z < 0.0) {
            int b = bin_of(-u);
            t->r += weight;
            t->r2 += weight * weight;
            t->rb[b] += weight;
            t->rb2[b] += weight * weight;
            break;
        }
        if (z > tau) {
            int b = bin_of(u);
            t->t += weight;
            t->t2 += weight * weight;
            t->tb[b] += weight;
            t->tb2[b] += weight * weight;
            break;
        }
    }
    t->a += absorbed;
    t->a2 += absorbed * absorbed;
    t->scatterings += n;
}

static void *worker(void *arg)
{
    const struct job *j = arg;
    const long photons = j->slab->photons;
    for (long c = j->first; c < j->n_chunks; c += j->stride) {
        struct rng g;
        rng_seed(&g, j->slab->seed, (uint64_t)c);
        long begin = c * CHUNK, end = begin + CHUNK < photons ? begin + CHUNK : photons;
        for (long i = begin; i < end; ++i)
            trace_photon(j->slab, &g, &j->chunks[c]);
    }
    return NULL;
}

/* Mean and standard error of n samples from their sum and sum of squares. */
static double std_error(double sum, double sum2, double n)
{
    double mean = sum / n;
    double var = (sum2 - n * mean * mean) / (n - 1.0);
    return var > 0.0 ? sqrt(var / n) : 0.0;
}

static int valid(const struct cloud_mc_slab *s)
{
    return isfinite(s->tau) && s->tau > 0.0 && s->omega > 0.0 && s->omega <= 1.0 && s->mu0 > 0.0 &&
           s->mu0 <= 1.0 && fabs(s->g0) < 1.0 && fabs(s->g1) < 1.0 && s->w >= 0.0 && s->w <= 1.0 &&
           s->photons >= 2 && s->threads >= 1;
}

int cloud_mc_slab_run(const struct cloud_mc_slab *in, struct cloud_mc_result *out)
{
    memset(out, 0, sizeof *out);
    if (!valid(in))
        return -1;
    long n_chunks = (in->photons + CHUNK - 1) / CHUNK;
    struct tally *chunks = calloc((size_t)n_chunks, sizeof *chunks);
    if (!chunks)
        return -1;
    int threads = in->threads < MAX_THREADS ? in->threads : MAX_THREADS;
    if (threads > n_chunks)
        threads = (int)n_chunks;
    struct job jobs[MAX_THREADS];
    pthread_t tid[MAX_THREADS];
    int started[MAX_THREADS] = { 0 };
    for (int i = 0; i < threads; ++i) {
        jobs[i] = (struct job){ in, chunks, n_chunks, i, threads };
        if (i > 0)
            started[i] = pthread_create(&tid[i], NULL, worker, &jobs[i]) == 0;
    }
    worker(&jobs[0]);
    for (int i = 1; i < threads; ++i) {
        if (started[i])
            pthread_join(tid[i], NULL);
        else
            worker(&jobs[i]);
    }

    struct tally sum = { 0 };
    for (long c = 0; c < n_chunks; ++c) {
        const struct tally *t = &chunks[c];
        sum.r += t->r, sum.r2 += t->r2, sum.t += t->t, sum.t2 += t->t2;
        sum.a += t->a, sum.a2 += t->a2, sum.scatterings += t->scatterings;
        for (int b = 0; b < CLOUD_MC_BINS; ++b) {
            sum.rb[b] += t->rb[b], sum.rb2[b] += t->rb2[b];
            sum.tb[b] += t->tb[b], sum.tb2[b] += t->tb2[b];
        }
    }
    free(chunks);

    const double n = (double)in->photons;
    out->R = sum.r / n;
    out->T_diffuse = sum.t / n;
    out->T_direct = exp(-in->tau / in->mu0);
    out->absorbed = sum.a / n;
    out->R_stderr = std_error(sum.r, sum.r2, n);
    out->T_stderr = std_error(sum.t, sum.t2, n);
    out->absorbed_stderr = std_error(sum.a, sum.a2, n);
    out->mean_scatterings = sum.scatterings / n;
    for (int b = 0; b < CLOUD_MC_BINS; ++b) {
        double lo, hi;
        cloud_mc_bin_edges(b, &lo, &hi);
        double solid = hi * hi - lo * lo; /* projected solid angle / pi */
        out->reflect_factor[b] = sum.rb[b] / n / solid;
        out->transmit_factor[b] = sum.tb[b] / n / solid;
        out->reflect_factor_stderr[b] = std_error(sum.rb[b], sum.rb2[b], n) / solid;
        out->transmit_factor_stderr[b] = std_error(sum.tb[b], sum.tb2[b], n) / solid;
    }
    return 0;
}
