/* Validates the Monte Carlo cloud-slab reference (reference/cloud_mc_reference.c) against
 *   - an independent doubling-adding solution written here (van de Hulst 1980; Hansen &
 *     Travis 1974 sec. 3.3) of the azimuth-averaged transfer equation, exact up to
 *     quadrature, for the isotropic and the dual-lobe phases;
 *   - Chandrasekhar's H-function for a semi-infinite isotropic medium (plane albedo
 *     1 - H(mu0) sqrt(1 - omega), reflection (omega/4) H(mu) H(mu0) / (mu + mu0)), with
 *     H(1) = 2.9078 for omega = 1 (Chandrasekhar 1960, table XI) checked first;
 *   - single scattering for a thin slab, the thick-slab diffusion limit, conservation,
 *     monotonicity, 1/sqrt(N) noise and thread-count invariance.
 * Prints the table of R, T_diffuse, T_direct for the renderer's default cloud phase. */
#include "check.h"
#include "cloud_mc_reference.h"
#include "world_state.h"

#include <stdio.h>
#include <string.h>
#include <time.h>

#define PI 3.14159265358979323846
#define THREADS 2
#define NB CLOUD_MC_BINS
/* Doubling resolution: going to 14 Gauss points per bin, 600 azimuth panels or a 1e-9
 * starting layer changes R and T by < 2e-5 for the default phase at tau 1..64. */
#define NG 6 /* Gauss points per radiance bin */
#define NQ (NB * NG)
#define NN (NQ + 1) /* + the sun's direction as a zero-weight node */
#define NPHI 240    /* trapezoid panels in azimuth over [0, pi] */
#define DELTA 1e-7  /* optical depth of the starting layer */

struct phase {
    double g0, g1, w;
};

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* Azimuth average of the phase at cos Theta = a + b cos(phi) (trapezoid, periodic). */
static double phase_avg(const struct phase *ph, double a, double b)
{
    double s = 0.0;
    for (int k = 0; k <= NPHI; ++k) {
        double f = cloud_mc_phase(a + b * cos(PI * k / NPHI), ph->g0, ph->g1, ph->w);
        s += (k == 0 || k == NPHI) ? 0.5 * f : f;
    }
    return s / NPHI;
}

/* ------------------------------------------------------------ doubling-adding reference */

struct da_result {
    double R, T, reflect[NB], transmit[NB];
    double norm_error; /* max |sum over directions of the phase kernel - omega| */
};

static double x[NN], c[NN], e[NN];
static double Pb[NN][NN], Pf[NN][NN], r[NN][NN], t[NN][NN], A[NN][NN], Q[NN][NN], d[NN][NN],
    u[NN][NN], tmp[NN][NN];

/* out = a W b + p + q E (W = diag(c), the quadrature, in which the sun node has weight 0;
 * E = diag(e); p, q may be NULL). */
static void mul(double (*out)[NN], double (*a)[NN], double (*b)[NN], double (*p)[NN],
                double (*q)[NN])
{
    for (int i = 0; i < NN; ++i)
        for (int j = 0; j < NN; ++j) {
            double s = (p ? p[i][j] : 0.0) + (q ? q[i][j] * e[j] : 0.0);
            for (int k = 0; k < NQ; ++k)
                s += a[i][k] * c[k] * b[k][j];
            tmp[i][j] = s;
        }
    memcpy(out, tmp, sizeof tmp);
}

/* Q = (I - A W)^-1 A by Gaussian elimination with partial pivoting. */
static void solve(void)
{
    static double m[NN][NN];
    for (int i = 0; i < NN; ++i)
        for (int j = 0; j < NN; ++j)
            m[i][j] = (i == j) - A[i][j] * c[j], Q[i][j] = A[i][j];
    for (int k = 0; k < NN; ++k) {
        int p = k;
        for (int i = k + 1; i < NN; ++i)
            if (fabs(m[i][k]) > fabs(m[p][k]))
                p = i;
        for (int j = 0; j < NN; ++j) {
            double s = m[k][j];
            m[k][j] = m[p][j];
            m[p][j] = s;
            s = Q[k][j];
            Q[k][j] = Q[p][j];
            Q[p][j] = s;
        }
        for (int i = 0; i < NN; ++i) {
            if (i == k || m[i][k] == 0.0)
                continue;
            double f = m[i][k] / m[k][k];
            for (int j = 0; j < NN; ++j)
                m[i][j] -= f * m[k][j], Q[i][j] -= f * Q[k][j];
        }
    }
    for (int i = 0; i < NN; ++i)
        for (int j = 0; j < NN; ++j)
            Q[i][j] /= m[i][i];
}

static double phi1(double y) /* (1 - exp(-y)) / y */
{
    return fabs(y) < 1e-12 ? 1.0 - 0.5 * y : -expm1(-y) / y;
}

/* Kernels act on azimuth-averaged radiance: L_out(mu) = sum_k K(mu, mu_k) c_k L_in(mu_k),
 * with the direct beam e(mu) = exp(-delta / mu) kept apart. A beam E at mu0 reflects
 * L(mu) = E r(mu, mu0) / (2 pi), so rho(mu) = r(mu, mu0) / (2 mu0). */
static void doubling(double tau, double omega, double mu0, const struct phase *ph,
                     struct da_result *o)
{
    for (int b = 0; b < NB; ++b)
        cloud_gauss_legendre(NG, (double)b / NB, (double)(b + 1) / NB, x + b * NG, c + b * NG);
    x[NQ] = mu0, c[NQ] = 0.0;
    o->norm_error = 0.0;
    for (int i = 0; i < NN; ++i) {
        double sum = 0.0;
        for (int j = 0; j < NN; ++j) {
            double s = sqrt((1.0 - x[i] * x[i]) * (1.0 - x[j] * x[j]));
            Pb[i][j] = 2.0 * PI * omega * phase_avg(ph, -x[i] * x[j], s);
            Pf[i][j] = 2.0 * PI * omega * phase_avg(ph, x[i] * x[j], s);
            sum += c[j] * (Pb[i][j] + Pf[i][j]);
        }
        o->norm_error = fmax(o->norm_error, fabs(sum - omega));
    }
    int doublings = 0;
    double dl = tau;
    while (dl > DELTA)
        dl *= 0.5, ++doublings;
    for (int i = 0; i < NN; ++i) { /* single scattering in the thin layer */
        e[i] = exp(-dl / x[i]);
        for (int j = 0; j < NN; ++j) {
            r[i][j] = Pb[i][j] * dl / x[i] * phi1(dl * (1.0 / x[i] + 1.0 / x[j]));
            t[i][j] = Pf[i][j] * dl / x[i] * e[i] * phi1(dl * (1.0 / x[j] - 1.0 / x[i]));
        }
    }
    for (int n = 0; n < doublings; ++n) { /* two equal halves: top and bottom */
        mul(A, r, r, NULL, NULL);
        solve();               /* Q: all the round trips between the halves */
        mul(d, Q, t, t, Q);    /* d = t + Q E + Q W t: diffuse light down at the interface */
        mul(u, r, d, NULL, r); /* u = r E + r W d: light up at the interface */
        mul(A, t, u, NULL, NULL);
        mul(Q, t, d, NULL, t);
        for (int i = 0; i < NN; ++i)
            for (int j = 0; j < NN; ++j) {
                r[i][j] += e[i] * u[i][j] + A[i][j]; /* r + E u + t W u */
                t[i][j] = e[i] * d[i][j] + Q[i][j];  /* E d + t E + t W d */
            }
        for (int i = 0; i < NN; ++i)
            e[i] *= e[i];
    }
    o->R = o->T = 0.0;
    for (int b = 0; b < NB; ++b) {
        double lo, hi, sr = 0.0, st = 0.0;
        cloud_mc_bin_edges(b, &lo, &hi);
        for (int k = b * NG; k < (b + 1) * NG; ++k)
            sr += c[k] * x[k] * r[k][NQ] / mu0, st += c[k] * x[k] * t[k][NQ] / mu0;
        o->R += sr, o->T += st;
        o->reflect[b] = sr / (hi * hi - lo * lo);
        o->transmit[b] = st / (hi * hi - lo * lo);
    }
}

/* ------------------------------------------------------------ Chandrasekhar's H-function */

#define NH 96
static double hx[NH], hw[NH], hv[NH];

/* 1/H(mu) = sqrt(1 - omega) + omega/2 int_0^1 mu' H(mu') / (mu + mu') dmu' (Nystrom). */
static double h_eval(double omega, double mu)
{
    double s = 0.0;
    for (int k = 0; k < NH; ++k)
        s += hw[k] * hx[k] * hv[k] / (mu + hx[k]);
    return 1.0 / (sqrt(1.0 - omega) + 0.5 * omega * s);
}

static void h_solve(double omega)
{
    static const double edges[7] = { 0, 1e-4, 1e-3, 1e-2, 0.1, 0.5, 1 };
    for (int p = 0; p < 6; ++p)
        cloud_gauss_legendre(NH / 6, edges[p], edges[p + 1], hx + p * NH / 6, hw + p * NH / 6);
    double next[NH];
    for (int k = 0; k < NH; ++k)
        hv[k] = 1.0;
    for (int it = 0; it < 20000; ++it) {
        double change = 0.0;
        for (int k = 0; k < NH; ++k)
            next[k] = sqrt(hv[k] * h_eval(omega, hx[k])); /* damps the H -> 1/H mode */
        for (int k = 0; k < NH; ++k)
            change = fmax(change, fabs(next[k] - hv[k]));
        memcpy(hv, next, sizeof next);
        if (change < 1e-14)
            break;
    }
}

/* ------------------------------------------------------------ closed forms per bin */

struct closed {
    double tau, omega, mu0;
    const struct phase *ph; /* NULL: isotropic */
};

/* Semi-infinite isotropic slab: rho(mu) = omega/4 H(mu) H(mu0) / (mu + mu0). */
static double rho_semi(double mu, const struct closed *f)
{
    return f->omega / 4.0 * h_eval(f->omega, mu) * h_eval(f->omega, f->mu0) / (mu + f->mu0);
}

/* Single scattering: rho1(mu) = pi omega p(mu, mu0) (1 - exp(-tau (1/mu + 1/mu0))) /
 * (mu + mu0), p averaged over azimuth (1/(4 pi) if isotropic). */
static double rho_single(double mu, const struct closed *f)
{
    double s = sqrt((1 - mu * mu) * (1 - f->mu0 * f->mu0));
    double p = f->ph ? phase_avg(f->ph, -mu * f->mu0, s) : 1.0 / (4.0 * PI);
    return PI * f->omega * p * -expm1(-f->tau * (1.0 / mu + 1.0 / f->mu0)) / (mu + f->mu0);
}

/* The bin average of rho weighted by mu dmu, which is what the tracer's bins estimate. */
static double bin_average(int b, double (*rho)(double, const struct closed *),
                          const struct closed *f)
{
    double lo, hi, gx[8], gw[8], s = 0.0;
    cloud_mc_bin_edges(b, &lo, &hi);
    cloud_gauss_legendre(8, lo, hi, gx, gw);
    for (int k = 0; k < 8; ++k)
        s += gw[k] * 2.0 * gx[k] * rho(gx[k], f);
    return s / (hi * hi - lo * lo);
}

/* ------------------------------------------------------------ comparisons */

static struct cloud_mc_result mc(double tau, double omega, double mu0, const struct phase *ph,
                                 long photons, unsigned long long seed)
{
    struct cloud_mc_slab s = { tau, omega, mu0, ph->g0, ph->g1, ph->w, photons, seed, THREADS };
    struct cloud_mc_result res;
    CHECK(cloud_mc_slab_run(&s, &res) == 0);
    return res;
}

/* MC within 4.5 sigma (+ a small allowance for the quadrature) of the doubling. */
static void compare_da(const char *what, const struct cloud_mc_result *m, const struct da_result *a)
{
    CHECK_MSG(fabs(m->R - a->R) <= 4.5 * m->R_stderr + 2e-4, "%s: R MC %.5f DA %.5f", what, m->R,
              a->R);
    CHECK_MSG(fabs(m->T_diffuse - a->T) <= 4.5 * m->T_stderr + 2e-4,
              "%s: T_diffuse MC %.5f DA %.5f", what, m->T_diffuse, a->T);
    for (int k = 0; k < 2 * NB; ++k) {
        int up = k < NB, b = k % NB;
        double v = up ? m->reflect_factor[b] : m->transmit_factor[b];
        double se = up ? m->reflect_factor_stderr[b] : m->transmit_factor_stderr[b];
        double ref = up ? a->reflect[b] : a->transmit[b];
        CHECK_MSG(fabs(v - ref) <= 4.5 * se + 2e-3 * ref,
                  "%s: rho_%c bin %d MC %.5f +- %.5f "
                  "DA %.5f",
                  what, up ? 'R' : 'T', b, v, se, ref);
    }
}

static void print_bins(const char *label, const double *v)
{
    printf("  %-18s", label);
    for (int b = 0; b < NB; ++b)
        printf(" %7.4f", v[b]);
    printf("\n");
}

int main(void)
{
    double t_start = now();
    const struct phase iso = { 0.0, 0.0, 0.0 }, forward = { 0.8, -0.5, 0.2 };
    struct proto_world_state ws;
    proto_world_state_defaults(&ws);
    const struct phase cloud = { ws.clouds.phase_g0, ws.clouds.phase_g1, ws.clouds.phase_w };
    const double albedo = ws.clouds.albedo;
    const double g_cloud = (1.0 - cloud.w) * cloud.g0 + cloud.w * cloud.g1;
    printf("renderer defaults: clouds.phase.g0 %.3f g1 %.3f w %.3f (mean cosine %.3f), "
           "clouds.albedo %.3f\n",
           cloud.g0, cloud.g1, cloud.w, g_cloud, albedo);

    /* Arguments, determinism, bookkeeping. */
    struct cloud_mc_slab bad = { 1, 1, 0, 0, 0, 0, 100, 1, 1 };
    struct cloud_mc_result res, res1, res2;
    struct da_result da;
    CHECK(cloud_mc_slab_run(&bad, &res) == -1);
    struct cloud_mc_slab s = { 4, 0.9, 0.6, cloud.g0, cloud.g1, cloud.w, 30000, 7, 1 };
    CHECK(cloud_mc_slab_run(&s, &res1) == 0);
    s.threads = 2;
    CHECK(cloud_mc_slab_run(&s, &res2) == 0);
    CHECK_MSG(memcmp(&res1, &res2, sizeof res1) == 0, "1 and 2 threads differ");
    double sum = 0.0; /* bin b spans mu^2 from (b/NB)^2 to ((b+1)/NB)^2 */
    for (int b = 0; b < NB; ++b)
        sum += res2.reflect_factor[b] * (2 * b + 1) / (double)(NB * NB);
    CHECK_NEAR(sum, res2.R, 1e-12);
    CHECK_NEAR(res2.R + res2.T_diffuse + res2.T_direct + res2.absorbed, 1.0, 1e-3);
    res = mc(4, 1.0, 0.6, &cloud, 30000, 8);
    CHECK_NEAR(res.R + res.T_diffuse + res.T_direct + res.absorbed, 1.0, 1e-9);
    CHECK(res.absorbed == 0.0);
    res = mc(64, 0.99, 0.5, &cloud, 20000, 9); /* roulette active */
    CHECK_NEAR(res.R + res.T_diffuse + res.T_direct + res.absorbed, 1.0, 1e-3);
    CHECK_NEAR(res.T_direct, exp(-128.0), 1e-60);
    res1 = mc(4, 0.9, 0.6, &cloud, 20000, 10);
    res2 = mc(4, 0.9, 0.6, &cloud, 80000, 11);
    printf("stderr(R) 20k %.5f 80k %.5f ratio %.3f (expect 2)\n", res1.R_stderr, res2.R_stderr,
           res1.R_stderr / res2.R_stderr);
    CHECK_NEAR(res1.R_stderr / res2.R_stderr, 2.0, 0.15);
    CHECK_NEAR(res1.T_stderr / res2.T_stderr, 2.0, 0.15);

    /* Chandrasekhar's H-function (conservative, isotropic), then a semi-infinite slab. */
    h_solve(1.0);
    double alpha0 = 0.0;
    for (int k = 0; k < NH; ++k)
        alpha0 += hw[k] * hv[k];
    printf("H(1) omega=1: %.5f (Chandrasekhar 2.9078), int H = %.6f (exact 2)\n", h_eval(1.0, 1.0),
           alpha0);
    CHECK_NEAR(h_eval(1.0, 1.0), 2.9078, 2e-4);
    CHECK_NEAR(alpha0, 2.0, 1e-4);
    const double om = 0.9;
    h_solve(om);
    for (int m = 0; m < 2; ++m) {
        const struct closed f = { 64, om, m ? 0.5 : 1.0, NULL };
        double rho[NB], R_h = 1.0 - h_eval(om, f.mu0) * sqrt(1.0 - om);
        res = mc(64, om, f.mu0, &iso, 100000, 20 + m);
        doubling(64, om, f.mu0, &iso, &da);
        printf("semi-infinite isotropic omega %.1f mu0 %.1f: R MC %.5f +- %.5f, DA %.5f, "
               "1 - H sqrt(1-omega) %.5f\n",
               om, f.mu0, res.R, res.R_stderr, da.R, R_h);
        CHECK_NEAR(res.R, R_h, 4.5 * res.R_stderr);
        CHECK_NEAR(da.R, R_h, 1e-4);
        for (int b = 0; b < NB; ++b) {
            rho[b] = bin_average(b, rho_semi, &f);
            CHECK_NEAR(res.reflect_factor[b], rho[b], 4.5 * res.reflect_factor_stderr[b]);
            CHECK_NEAR(da.reflect[b], rho[b], 2e-4 * rho[b]);
        }
        print_bins("rho_R MC", res.reflect_factor);
        print_bins("rho_R H-function", rho);
    }

    /* Thin slab: single scattering (rho_single), isotropic and the cloud phase. */
    for (int m = 0; m < 2; ++m) {
        const struct closed f = { 0.01, 0.8, 0.5, m ? &cloud : NULL };
        double rho1[NB];
        res = mc(f.tau, f.omega, f.mu0, m ? &cloud : &iso, 400000, 30 + m);
        for (int b = 0; b < NB; ++b) {
            rho1[b] = bin_average(b, rho_single, &f);
            if (b >= NB / 4) /* mu >= 0.25: double scattering grows toward grazing exits */
                CHECK_NEAR(res.reflect_factor[b], rho1[b],
                           4.5 * res.reflect_factor_stderr[b] + 0.02 * rho1[b]);
        }
        printf("tau 0.01 omega 0.8 mu0 0.5, %s phase:\n", m ? "cloud" : "isotropic");
        print_bins("rho_R MC", res.reflect_factor);
        print_bins("rho_R single scat.", rho1);
    }

    /* Doubling-adding against the tracer: isotropic, strongly forward, and the defaults. */
    struct {
        double tau, omega, mu0;
        const struct phase *ph;
        const char *name;
    } cases[] = {
        { 1, 1.0, 1.0, &iso, "isotropic tau 1 mu0 1" },
        { 4, 0.9, 0.3, &iso, "isotropic tau 4 omega .9 mu0 .3" },
        { 16, 1.0, 0.2, &forward, "g .8/-.5 w .2 tau 16 mu0 .2" },
        { 8, albedo, 0.7, &cloud, "defaults tau 8 mu0 .7" },
    };
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; ++k) {
        doubling(cases[k].tau, cases[k].omega, cases[k].mu0, cases[k].ph, &da);
        res = mc(cases[k].tau, cases[k].omega, cases[k].mu0, cases[k].ph, 100000, 40 + k);
        printf("%s: R MC %.5f +- %.5f DA %.5f, T_diffuse MC %.5f +- %.5f DA %.5f "
               "(phase quadrature %.1e)\n",
               cases[k].name, res.R, res.R_stderr, da.R, res.T_diffuse, res.T_stderr, da.T,
               da.norm_error);
        CHECK_LE(da.norm_error, 1e-4);
        compare_da(cases[k].name, &res, &da);
        if (k == 0) { /* conservative: the doubling conserves energy too */
            CHECK_NEAR(da.R + da.T + exp(-1.0), 1.0, 1e-5);
            print_bins("rho_R MC", res.reflect_factor);
            print_bins("rho_R doubling", da.reflect);
        }
    }

    /* Conservative slabs, default phase: R rises with tau; thick-slab diffusion limit
     * T_total ~ K(mu0) (4/3) / ((1 - g) tau + 4/3), Eddington escape function
     * K(mu0) = 3/7 (1 + 2 mu0), within 12 % at tau 64: the similarity (1 - g) tau is only 30
     * for the forward-dominated default phase (g 0.53), and diffusion's error falls like
     * 1 / ((1 - g) tau) (8 % held for the old phase, g 0.03). */
    double prev = 0.0;
    for (int k = 0; k < 7; ++k) {
        double tau = (double)(1 << k);
        res = mc(tau, 1.0, 0.5, &cloud, 20000, 50 + k);
        CHECK_MSG(res.R > prev, "R(tau %g) %.5f <= R(tau/2) %.5f", tau, res.R, prev);
        prev = res.R;
    }
    for (int m = 0; m < 2; ++m) {
        double mu0 = m ? 0.5 : 1.0;
        res = mc(64, 1.0, mu0, &cloud, 20000, 60 + m);
        double diff = 3.0 / 7.0 * (1 + 2 * mu0) * (4.0 / 3.0) / ((1 - g_cloud) * 64 + 4.0 / 3.0);
        printf("omega 1 tau 64 mu0 %.1f: T MC %.5f +- %.5f, diffusion %.5f\n", mu0,
               res.T_diffuse + res.T_direct, res.T_stderr, diff);
        CHECK_NEAR(res.T_diffuse + res.T_direct, diff, 0.12 * diff);
    }

    /* The table for the renderer's defaults, each entry checked against the doubling. */
    printf("\nclouds defaults: g0 %.2f g1 %.2f w %.2f, omega %.2f; MC 40000 photons; DA = "
           "doubling\n",
           cloud.g0, cloud.g1, cloud.w, albedo);
    printf("  tau  mu0   R (MC)   +-       R (DA)   T_diff   +-       T_d (DA) T_direct  "
           "absorbed scatt.\n");
    const double mus[3] = { 1.0, 0.5, 0.2 };
    for (int k = 0; k < 7; ++k)
        for (int m = 0; m < 3; ++m) {
            double tau = (double)(1 << k);
            res = mc(tau, albedo, mus[m], &cloud, 40000, 100 + 3 * k + m);
            doubling(tau, albedo, mus[m], &cloud, &da);
            printf("  %3.0f  %.1f  %.5f  %.5f  %.5f  %.5f  %.5f  %.5f  %.2e %.5f  %5.1f\n", tau,
                   mus[m], res.R, res.R_stderr, da.R, res.T_diffuse, res.T_stderr, da.T,
                   res.T_direct, res.absorbed, res.mean_scatterings);
            CHECK_NEAR(res.R, da.R, 4.5 * res.R_stderr + 2e-4);
            CHECK_NEAR(res.T_diffuse, da.T, 4.5 * res.T_stderr + 2e-4);
        }
    printf("total %.2f s\n", now() - t_start);
    return check_summary();
}
