/* Validates the CPU atmosphere reference against closed forms, independent brute-force
 * quadrature and conservation laws. Prints one line per check; exits non-zero on failure. */
#include "atmosphere_reference.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <string.h>
#include <time.h>

#define PI 3.14159265358979323846
#define DEG (PI / 180.0)
#define THREADS 2

static int failures;

static void check(int ok, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    printf("%s ", ok ? "PASS" : "FAIL");
    vprintf(fmt, ap);
    printf("\n");
    va_end(ap);
    if (!ok)
        ++failures;
}

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static double max_rel(const double x[3], const double ref[3])
{
    double e = 0;
    for (int c = 0; c < 3; ++c)
        e = fmax(e, fabs(x[c] - ref[c]) / fabs(ref[c]));
    return e;
}

static void dir_from(double elevation_deg, double azimuth_deg, double d[3])
{
    d[0] = cos(elevation_deg * DEG) * sin(azimuth_deg * DEG); /* east */
    d[1] = cos(elevation_deg * DEG) * cos(azimuth_deg * DEG); /* north */
    d[2] = sin(elevation_deg * DEG);
}

/* ------------------------------------------------ independent brute-force helpers */

static double tent(const struct ref_atmosphere *a, double h)
{
    return fmax(0.0, 1.0 - fabs(h - a->ozone_peak_altitude) / (0.5 * a->ozone_width));
}

static void bf_extinction(const struct ref_atmosphere *a, double h, double e[3])
{
    for (int c = 0; c < 3; ++c)
        e[c] = a->rayleigh_scattering[c] * exp(-h / a->rayleigh_scale_height) +
               (a->mie_scattering[c] + a->mie_absorption[c]) * exp(-h / a->mie_scale_height) +
               a->fog_density * exp(-h / a->fog_scale_height) + a->ozone_absorption[c] * tent(a, h);
}

static double bf_altitude(const struct ref_atmosphere *a, const double p[3], const double d[3],
                          double t)
{
    double q[3] = { p[0] + t * d[0], p[1] + t * d[1], p[2] + t * d[2] };
    return sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2]) - a->bottom_radius;
}

/* Distance from p (inside the top sphere) to the top of the atmosphere along unit d. */
static double bf_exit(const struct ref_atmosphere *a, const double p[3], const double d[3])
{
    double b = p[0] * d[0] + p[1] * d[1] + p[2] * d[2];
    double c = p[0] * p[0] + p[1] * p[1] + p[2] * p[2] - a->top_radius * a->top_radius;
    return -b + sqrt(b * b - c);
}

/* Composite Simpson optical depth over [0, L] with n (even) intervals. */
static void bf_tau(const struct ref_atmosphere *a, const double p[3], const double d[3], double L,
                   int n, double tau[3])
{
    double h = L / n, e[3];
    tau[0] = tau[1] = tau[2] = 0;
    for (int i = 0; i <= n; ++i) {
        double w = (i == 0 || i == n) ? 1.0 : (i & 1) ? 4.0 : 2.0;
        bf_extinction(a, bf_altitude(a, p, d, i * h), e);
        for (int c = 0; c < 3; ++c)
            tau[c] += w * e[c];
    }
    for (int c = 0; c < 3; ++c)
        tau[c] *= h / 3.0;
}

/* Column of the tent profile between altitudes z0 < z1 (exact, piecewise quadratic). */
static double tent_column(const struct ref_atmosphere *a, double z0, double z1)
{
    double p = a->ozone_peak_altitude, hw = 0.5 * a->ozone_width;
    double F[2], z[2] = { z0, z1 };
    for (int i = 0; i < 2; ++i) {
        double x = z[i];
        if (x <= p - hw)
            F[i] = 0;
        else if (x <= p)
            F[i] = (x - (p - hw)) * (x - (p - hw)) / (2 * hw);
        else if (x <= p + hw)
            F[i] = hw - (p + hw - x) * (p + hw - x) / (2 * hw);
        else
            F[i] = hw;
    }
    return F[1] - F[0];
}

/* Plane-parallel-like homogeneous slab: huge planet, huge scale heights. */
static struct ref_atmosphere slab(double thickness)
{
    struct ref_atmosphere a;
    memset(&a, 0, sizeof a);
    a.bottom_radius = 1e7;
    a.top_radius = 1e7 + thickness;
    a.rayleigh_scale_height = a.mie_scale_height = a.fog_scale_height = 1e12;
    a.ozone_peak_altitude = 0.5 * thickness;
    a.ozone_width = 1e9;
    return a;
}

/* ------------------------------------------------ phase functions */

static void test_phase(void)
{
    const double gs[] = { 0.0, 0.5, 0.8, 0.95, -0.6 };
    const int n = 1 << 18; /* Simpson intervals in cos(theta) */
    double h = 2.0 / n, norm = 0, first = 0;
    for (int i = 0; i <= n; ++i) {
        double c = -1 + i * h, w = (i == 0 || i == n) ? 1 : (i & 1) ? 4 : 2;
        norm += w * ref_phase_rayleigh(c), first += w * c * ref_phase_rayleigh(c);
    }
    norm *= 2 * PI * h / 3, first *= 2 * PI * h / 3;
    check(fabs(norm - 1) < 1e-9 && fabs(first) < 1e-12,
          "Rayleigh phase: integral over sphere %.12f, mean cosine %.1e", norm, first);
    for (int k = 0; k < 5; ++k) {
        double g = gs[k];
        norm = first = 0;
        for (int i = 0; i <= n; ++i) {
            double c = -1 + i * h, w = (i == 0 || i == n) ? 1 : (i & 1) ? 4 : 2;
            norm += w * ref_phase_mie(c, g), first += w * c * ref_phase_mie(c, g);
        }
        norm *= 2 * PI * h / 3, first *= 2 * PI * h / 3;
        // Cornette-Shanks asymmetry: <cos> = 3g(4 + g^2) / (5(2 + g^2))
        double want = 3 * g * (4 + g * g) / (5 * (2 + g * g));
        check(fabs(norm - 1) < 1e-6 && fabs(first - want) < 1e-6,
              "Cornette-Shanks g=%+.2f: integral %.9f, mean cosine %.9f (closed form %.9f)", g,
              norm, first, want);
    }
}

/* ------------------------------------------------ transmittance */

static void test_transmittance(void)
{
    struct ref_atmosphere a = slab(0), e;
    ref_atmosphere_earth(&e);
    /* pure exponential Rayleigh atmosphere, vertical: closed form */
    a.bottom_radius = 6360, a.top_radius = 6460, a.rayleigh_scale_height = 8;
    a.rayleigh_scattering[0] = 5.802e-3, a.rayleigh_scattering[1] = 13.558e-3;
    a.rayleigh_scattering[2] = 33.1e-3;
    const double hs[] = { 0.0, 5.0, 60.0 };
    for (int i = 0; i < 3; ++i) {
        double T[3], want[3];
        ref_transmittance(&a, hs[i], 1.0, T);
        for (int c = 0; c < 3; ++c)
            want[c] = exp(-a.rayleigh_scattering[c] * 8 * (exp(-hs[i] / 8) - exp(-100.0 / 8)));
        check(max_rel(T, want) < 1e-10,
              "exponential atmosphere, vertical from h=%g: T=(%.9f %.9f %.9f), rel err %.1e vs "
              "exp(-sigma H (e^-h/H - e^-100/H))",
              hs[i], T[0], T[1], T[2], max_rel(T, want));
    }
    /* Earth, vertical: Rayleigh + Mie exponentials and the ozone tent in closed form */
    for (int i = 0; i < 3; ++i) {
        double T[3], want[3], h = hs[i] == 60.0 ? 20.0 : hs[i];
        ref_transmittance(&e, h, 1.0, T);
        for (int c = 0; c < 3; ++c)
            want[c] = exp(-e.rayleigh_scattering[c] * 8 * (exp(-h / 8) - exp(-100.0 / 8)) -
                          (e.mie_scattering[c] + e.mie_absorption[c]) * 1.2 *
                              (exp(-h / 1.2) - exp(-100.0 / 1.2)) -
                          e.ozone_absorption[c] * tent_column(&e, h, 100.0));
        check(max_rel(T, want) < 1e-9,
              "Earth zenith transmittance from h=%g: (%.6f %.6f %.6f), rel err %.1e", h, T[0], T[1],
              T[2], max_rel(T, want));
    }
    /* slanted paths: independent composite Simpson with 2^20 intervals */
    const double alts[] = { 0.0, 10.0 };
    const double mus[] = { 0.5, 0.1, 0.02, 0.0, -0.03 };
    double worst = 0;
    for (int i = 0; i < 2; ++i)
        for (int j = 0; j < 5; ++j) {
            double T[3], tau[3], want[3], p[3] = { 0, 0, e.bottom_radius + alts[i] };
            if (alts[i] == 0 && mus[j] < 0)
                continue;
            double d[3] = { sqrt(1 - mus[j] * mus[j]), 0, mus[j] };
            ref_transmittance(&e, alts[i], mus[j], T);
            bf_tau(&e, p, d, bf_exit(&e, p, d), 1 << 20, tau);
            for (int c = 0; c < 3; ++c)
                want[c] = exp(-tau[c]);
            worst = fmax(worst, max_rel(T, want));
        }
    check(worst < 1e-8,
          "slanted transmittance (h 0/10 km, mu 0.5..-0.03) vs brute-force "
          "Simpson: max rel err %.1e",
          worst);
    /* convergence under shell refinement */
    const double qs[] = { 3.0, 2.0, 1.0, 0.5, 0.25 };
    for (int k = 0; k < 5; ++k) {
        double e_max = 0;
        for (int j = 0; j < 5; ++j) {
            double T[3], R[3];
            ref_transmittance_ex(&e, 2.0, mus[j], qs[k], T);
            ref_transmittance_ex(&e, 2.0, mus[j], 0.0625, R);
            e_max = fmax(e_max, max_rel(T, R));
        }
        check(e_max < (qs[k] > 2   ? 1e-5
                       : qs[k] > 1 ? 1e-6
                                   : 1e-9),
              "transmittance step scale %.2f vs 0.0625: max rel diff %.1e", qs[k], e_max);
    }
    double T[3];
    ref_transmittance(&e, 1.0, -0.2, T);
    check(T[0] == 0 && T[1] == 0 && T[2] == 0, "ray into the ground: T = 0");
    ref_transmittance(&e, 150.0, 0.3, T);
    check(T[0] == 1 && T[1] == 1 && T[2] == 1, "upward ray above the atmosphere: T = 1");
    /* segments: multiplicative along a ray, symmetric, zero through the planet */
    double p0[3] = { 0, 0, 6361 }, d[3] = { 0.8, 0, 0.6 }, p1[3], top[3], Ta[3], Tb[3], Tc[3],
           Tr[3];
    double L = bf_exit(&e, p0, d);
    for (int i = 0; i < 3; ++i)
        p1[i] = p0[i] + 0.3 * L * d[i], top[i] = p0[i] + L * d[i];
    ref_transmittance_segment(&e, p0, p1, Ta);
    ref_transmittance_segment(&e, p1, top, Tb);
    ref_transmittance_segment(&e, p0, top, Tc);
    ref_transmittance_segment(&e, p1, p0, Tr);
    double prod[3] = { Ta[0] * Tb[0], Ta[1] * Tb[1], Ta[2] * Tb[2] };
    check(max_rel(prod, Tc) < 1e-10 && max_rel(Tr, Ta) < 1e-10,
          "segments: T(a,b) T(b,c) = T(a,c) (%.1e), T(a,b) = T(b,a) (%.1e)", max_rel(prod, Tc),
          max_rel(Tr, Ta));
    double q0[3] = { 0, -4000, 5500 }, q1[3] = { 0, 4000, 5500 };
    ref_transmittance_segment(&e, q0, q1, T);
    check(T[0] == 0 && T[2] == 0, "segment through the planet: T = 0");
    ref_transmittance(&e, 0, 1, T);
    printf("INFO Earth zenith transmittance at the ground: (%.4f, %.4f, %.4f)\n", T[0], T[1], T[2]);
}

/* ------------------------------------------------ single scattering */

/* Independent brute force: Simpson along the view ray, with Simpson sun transmittances and a
 * cumulative view optical depth. No ground, no shadow in the cases used. */
static void bf_single(const struct ref_atmosphere *a, double alt, const double v[3],
                      const double s[3], int n, int n_sun, double out[3])
{
    double p[3] = { 0, 0, a->bottom_radius + alt }, L = bf_exit(a, p, v), h = L / n;
    double cs = v[0] * s[0] + v[1] * s[1] + v[2] * s[2], tau_v[3] = { 0, 0, 0 };
    out[0] = out[1] = out[2] = 0;
    for (int i = 0; i <= n; ++i) {
        double t = i * h, x[3] = { p[0] + t * v[0], p[1] + t * v[1], p[2] + t * v[2] };
        double hx = bf_altitude(a, p, v, t), ts[3], e0[3], e1[3], e2[3];
        if (i > 0) {
            bf_extinction(a, bf_altitude(a, p, v, t - h), e0);
            bf_extinction(a, bf_altitude(a, p, v, t - 0.5 * h), e1);
            bf_extinction(a, hx, e2);
            for (int c = 0; c < 3; ++c)
                tau_v[c] += h / 6 * (e0[c] + 4 * e1[c] + e2[c]);
        }
        bf_tau(a, x, s, bf_exit(a, x, s), n_sun, ts);
        double w = (i == 0 || i == n) ? 1 : (i & 1) ? 4 : 2;
        for (int c = 0; c < 3; ++c) {
            double sr = a->rayleigh_scattering[c] * exp(-hx / a->rayleigh_scale_height);
            double sm = a->mie_scattering[c] * exp(-hx / a->mie_scale_height) +
                        a->fog_density * exp(-hx / a->fog_scale_height);
            double k = sr * ref_phase_rayleigh(cs) + sm * ref_phase_mie(cs, a->mie_g[c]);
            out[c] += w * h / 3 * exp(-tau_v[c]) * k * exp(-ts[c]);
        }
    }
}

static void test_single_scattering(void)
{
    struct ref_atmosphere e;
    ref_atmosphere_earth(&e);
    struct {
        double alt, vel, vaz, sel, saz;
    } cases[] = {
        { 0, 90, 0, 30, 0 },  { 0, 5, 0, 10, 0 },   { 0, 5, 180, 10, 0 }, { 0, 20, 90, 60, 0 },
        { 0, 1, 30, 0, 0 },   { 0, 90, 0, -2, 0 },  { 0, 10, 0, -4, 0 },  { 0, 30, 180, -6, 0 },
        { 1, -10, 0, 30, 0 }, { 5, -1, 90, 20, 0 }, { 0, 0, 0, 45, 180 }, { 300, -30, 0, 40, 0 },
    };
    int nc = (int)(sizeof cases / sizeof cases[0]);
    double worst_default = 0, worst_coarse = 0, t_total = 0;
    for (int i = 0; i < nc; ++i) {
        double v[3], s[3], fine[3], def[3], coarse[3];
        dir_from(cases[i].vel, cases[i].vaz, v);
        dir_from(cases[i].sel, cases[i].saz, s);
        double t0 = now();
        ref_single_scattering(&e, cases[i].alt, v, s, def);
        t_total += now() - t0;
        ref_single_scattering_ex(&e, cases[i].alt, v, s, 0.125, 1e-10, fine);
        ref_single_scattering_ex(&e, cases[i].alt, v, s, 1.0, 1e-5, coarse);
        worst_default = fmax(worst_default, max_rel(def, fine));
        worst_coarse = fmax(worst_coarse, max_rel(coarse, fine));
    }
    check(worst_default < 1e-6,
          "single scattering converged: %d views (twilight, ground, space) default vs refined "
          "max rel diff %.1e (coarse %.1e), %.1f ms per call",
          nc, worst_default, worst_coarse, 1e3 * t_total / nc);

    double v[3], s[3], ss[3], bf[3];
    dir_from(5, 70, v);
    dir_from(20, 0, s);
    ref_single_scattering(&e, 0, v, s, ss);
    bf_single(&e, 0, v, s, 4000, 4000, bf);
    check(max_rel(ss, bf) < 2e-6,
          "single scattering vs independent brute-force Simpson "
          "(view 5 deg, sun 20 deg): rel diff %.1e",
          max_rel(ss, bf));

    /* homogeneous slab on a huge planet: exact plane-parallel single scattering */
    struct ref_atmosphere a = slab(10);
    for (int c = 0; c < 3; ++c) {
        a.rayleigh_scattering[c] = 0.01 * (c + 1);
        a.mie_scattering[c] = 0.01, a.mie_absorption[c] = 0.002, a.mie_g[c] = 0.7 - 0.1 * c;
        a.ozone_absorption[c] = 0.003;
        a.ground_albedo[c] = 0.5;
    }
    a.fog_density = 0.004;
    double mv = 0.6, ms = 0.8, worst_up = 0, worst_down = 0;
    double vu[3] = { sqrt(1 - mv * mv), 0, mv }, vd[3] = { sqrt(1 - mv * mv), 0, -mv };
    double sd[3] = { -sqrt(1 - ms * ms) * 0.6, sqrt(1 - ms * ms) * 0.8, ms }, up[3], down[3];
    ref_single_scattering(&a, 0, vu, sd, up);
    ref_single_scattering(&a, 10, vd, sd, down);
    for (int c = 0; c < 3; ++c) {
        double st = a.rayleigh_scattering[c] + 0.012 + 0.004 + 0.003, tau = 10 * st;
        double ku = a.rayleigh_scattering[c] * ref_phase_rayleigh(vu[0] * sd[0] + mv * ms) +
                    0.014 * ref_phase_mie(vu[0] * sd[0] + mv * ms, a.mie_g[c]);
        double kd = a.rayleigh_scattering[c] * ref_phase_rayleigh(vd[0] * sd[0] - mv * ms) +
                    0.014 * ref_phase_mie(vd[0] * sd[0] - mv * ms, a.mie_g[c]);
        // L = (k/st) mu_s/(mu_s - mu_v) (e^-tau/mu_s - e^-tau/mu_v), looking up from the bottom
        double want_up = ku / st * ms / (ms - mv) * (exp(-tau / ms) - exp(-tau / mv));
        // reflected: (k/st) mu_s/(mu_s + mu_v) (1 - e^-tau(1/mu_s + 1/mu_v)) + ground term
        double want_down = kd / st * ms / (ms + mv) * (1 - exp(-tau * (1 / ms + 1 / mv))) +
                           0.5 / PI * ms * exp(-tau / ms) * exp(-tau / mv);
        worst_up = fmax(worst_up, fabs(up[c] / want_up - 1));
        worst_down = fmax(worst_down, fabs(down[c] / want_down - 1));
    }
    check(worst_up < 1e-5 && worst_down < 1e-5,
          "homogeneous slab (tau 0.2-0.5, Rayleigh+Mie+fog+ozone): exact plane-parallel single "
          "scattering, rel err up %.1e, down incl. ground %.1e",
          worst_up, worst_down);

    /* optically thin layer: L = sigma_s d p(theta) / mu_v to first order */
    struct ref_atmosphere t = slab(1);
    for (int c = 0; c < 3; ++c)
        t.rayleigh_scattering[c] = 1e-5 * (c + 1);
    double thin[3], worst = 0, cs = vu[0] * sd[0] + mv * ms;
    ref_single_scattering(&t, 0, vu, sd, thin);
    for (int c = 0; c < 3; ++c)
        worst = fmax(worst,
                     fabs(thin[c] / (t.rayleigh_scattering[c] * ref_phase_rayleigh(cs) / mv) - 1));
    check(worst < 1e-4, "thin layer (tau <= 3e-5): L = sigma_s d p / mu_v, rel err %.1e", worst);
}

/* ------------------------------------------------ Monte Carlo */

/* Plane-parallel single-scattering irradiance of a homogeneous slab, by quadrature over
 * directions: facing up at the bottom (down = 0) or facing down at the top. */
static void slab_irradiance_order1(const struct ref_atmosphere *a, const double s[3], int down,
                                   double out[3])
{
    const int nm = 1000, np = 720;
    double d = a->top_radius - a->bottom_radius, ms = s[2];
    out[0] = out[1] = out[2] = 0;
    for (int i = 0; i < nm; ++i) {
        double mu = (i + 0.5) / nm, sin_t = sqrt(1 - mu * mu);
        for (int j = 0; j < np; ++j) {
            double phi = 2 * PI * (j + 0.5) / np;
            double v[3] = { sin_t * cos(phi), sin_t * sin(phi), down ? -mu : mu };
            double cs = v[0] * s[0] + v[1] * s[1] + v[2] * s[2];
            for (int c = 0; c < 3; ++c) {
                double st = a->rayleigh_scattering[c] + a->mie_scattering[c] + a->mie_absorption[c],
                       tau = st * d, f;
                double k = a->rayleigh_scattering[c] * ref_phase_rayleigh(cs) +
                           a->mie_scattering[c] * ref_phase_mie(cs, a->mie_g[c]);
                if (down)
                    f = ms / (ms + mu) * -expm1(-tau * (1 / ms + 1 / mu));
                else if (fabs(ms - mu) < 1e-9)
                    f = tau / ms * exp(-tau / ms);
                else
                    f = ms / (ms - mu) * (exp(-tau / ms) - exp(-tau / mu));
                out[c] += k / st * f * mu * (1.0 / nm) * (2 * PI / np);
            }
        }
    }
}

static void test_monte_carlo(void)
{
    struct ref_atmosphere e;
    ref_atmosphere_earth(&e);
    struct {
        double alt, vel, vaz, sel;
    } cases[] = {
        { 0, 90, 0, 30 }, { 0, 5, 0, 10 }, { 1, -10, 30, 30 }, { 0, 10, 0, -2 }, { 0, 40, 180, 5 }
    };
    for (int i = 0; i < 5; ++i) {
        double v[3], s[3], ss[3], mc[3], se[3], z = 0;
        dir_from(cases[i].vel, cases[i].vaz, v);
        dir_from(cases[i].sel, 0, s);
        ref_single_scattering(&e, cases[i].alt, v, s, ss);
        ref_radiance_mc(&e, cases[i].alt, v, s, 1, 1, 20000, 11 + i, THREADS, mc, se);
        for (int c = 0; c < 3; ++c)
            z = fmax(z, fabs(mc[c] - ss[c]) / se[c]);
        check(z < 4,
              "MC order 1 vs deterministic (h %g, view %g/%g, sun %g): max |diff|/SE = "
              "%.2f, SE %.2f%%",
              cases[i].alt, cases[i].vel, cases[i].vaz, cases[i].sel, z, 100 * se[2] / ss[2]);
    }

    /* slab irradiance, order 1, against direction quadrature of the exact slab radiance */
    struct ref_atmosphere a = slab(8);
    for (int c = 0; c < 3; ++c) {
        a.rayleigh_scattering[c] = 0.01 * (c + 1);
        a.mie_scattering[c] = 0.01, a.mie_absorption[c] = 0.003, a.mie_g[c] = 0.6;
    }
    double s[3], want[3], mc[3], se[3], z = 0;
    dir_from(35, 20, s);
    for (int down = 0; down < 2; ++down) {
        slab_irradiance_order1(&a, s, down, want);
        ref_irradiance(&a, down ? 8.0 : 0.0, !down, s, 1, 40000, 3, THREADS, mc, se);
        z = 0;
        for (int c = 0; c < 3; ++c)
            z = fmax(z, fabs(mc[c] - want[c]) / se[c]);
        check(z < 4,
              "slab order-1 irradiance %s: MC (%.5f %.5f %.5f) vs quadrature (%.5f %.5f "
              "%.5f), max |diff|/SE %.2f",
              down ? "upward at the top" : "downward at the bottom", mc[0], mc[1], mc[2], want[0],
              want[1], want[2], z);
    }

    /* conservative slab over a white ground reflects everything: E_up(top) = mu_s */
    struct ref_atmosphere w = slab(30);
    for (int c = 0; c < 3; ++c) {
        w.rayleigh_scattering[c] = 0.004 * (c + 1);
        w.mie_scattering[c] = 0.003, w.mie_g[c] = 0.8 - 0.3 * c; /* per-channel g */
        w.ground_albedo[c] = 1.0;
    }
    w.rayleigh_scale_height = 8, w.mie_scale_height = 1.2;
    double t0 = now();
    ref_irradiance(&w, 30.0, 0, s, 60, 20000, 5, THREADS, mc, se);
    z = 0;
    for (int c = 0; c < 3; ++c)
        z = fmax(z, fabs(mc[c] - s[2]) / se[c]);
    check(z < 4,
          "energy conservation (no absorption, albedo 1, orders <= 60): E_up(top) = "
          "(%.5f %.5f %.5f) vs mu_s %.5f, SE %.2f%%, max |diff|/SE %.2f (%.1f s)",
          mc[0], mc[1], mc[2], s[2], 100 * se[2] / s[2], z, now() - t0);

    /* determinism across thread counts, monotonicity in max_order, ground albedo */
    double v[3], r1[3], e1[3], r2[3], e2[3], r3[3], e3[3];
    dir_from(90, 0, v);
    dir_from(30, 0, s);
    ref_radiance(&e, 0, v, s, 10, 3000, 99, 1, r1, e1);
    ref_radiance(&e, 0, v, s, 10, 3000, 99, 2, r2, e2);
    ref_radiance(&e, 0, v, s, 10, 3000, 99, 7, r3, e3);
    check(!memcmp(r1, r2, sizeof r1) && !memcmp(r1, r3, sizeof r1) && !memcmp(e1, e2, sizeof e1) &&
              !memcmp(e1, e3, sizeof e1),
          "MC bit-identical for 1, 2 and 7 threads");
    int mono = 1;
    double prev[3] = { 0, 0, 0 };
    for (int k = 1; k <= 10; ++k) {
        ref_radiance(&e, 0, v, s, k, 3000, 99, THREADS, r1, NULL);
        for (int c = 0; c < 3; ++c)
            mono &= r1[c] >= prev[c];
        memcpy(prev, r1, sizeof prev);
    }
    check(mono, "radiance non-decreasing in max_order 1..10 (blue at 10: %.5f)", prev[2]);
    struct ref_atmosphere white = e, black = e;
    for (int c = 0; c < 3; ++c)
        white.ground_albedo[c] = 1, black.ground_albedo[c] = 0;
    ref_radiance(&white, 0, v, s, 10, 3000, 5, THREADS, r1, NULL);
    ref_radiance(&e, 0, v, s, 10, 3000, 5, THREADS, r2, NULL);
    ref_radiance(&black, 0, v, s, 10, 3000, 5, THREADS, r3, NULL);
    check(r1[0] > r2[0] && r2[0] > r3[0] && r1[2] > r2[2] && r2[2] > r3[2],
          "zenith radiance: white ground %.5f > albedo 0.3 %.5f > black %.5f (blue)", r1[2], r2[2],
          r3[2]);
    ref_radiance(&e, 0, v, s, 10, 8000, 1, THREADS, r1, e1);
    ref_radiance(&e, 0, v, s, 10, 8000, 2, THREADS, r2, e2);
    z = 0;
    for (int c = 0; c < 3; ++c)
        z = fmax(z, fabs(r1[c] - r2[c]) / sqrt(e1[c] * e1[c] + e2[c] * e2[c]));
    check(z < 4, "two seeds agree within their standard errors: max |diff|/SE %.2f", z);
}

/* The sunlit-segment estimator (the default) against the collision-only one: the same
 * expectation in twilight, with a standard error several times smaller for the same paths
 * with the sun 6 deg down (and no larger nearer the horizon, where the gain is smaller); and
 * in daylight, where no segment meets the planet's shadow, exactly the same paths. */
static void test_twilight_estimators(void)
{
    struct ref_atmosphere e;
    ref_atmosphere_earth(&e);
    struct {
        double vel, vaz, sel;
    } cases[] = { { 90, 0, -6 }, { -90, 0, -6 }, { 3, 0, -6 }, { 10, 150, -4 }, { 1, 60, -2 } };
    const int paths = 20000, simple_paths = 8 * paths;
    for (int i = 0; i < 5; ++i) {
        double v[3], s[3], a[3], ea[3], b[3], eb[3], z = 0, gain = HUGE_VAL;
        dir_from(cases[i].vel, cases[i].vaz, v);
        dir_from(cases[i].sel, 0, s);
        double t0 = now();
        ref_radiance_mc_estimator(&e, 0, v, s, 2, 12, paths, 40 + i, THREADS,
                                  REF_MC_SUNLIT_SEGMENTS, a, ea);
        double t_sunlit = now() - t0;
        t0 = now();
        ref_radiance_mc_estimator(&e, 0, v, s, 2, 12, simple_paths, 50 + i, THREADS,
                                  REF_MC_COLLISION_ONLY, b, eb);
        double t_simple = now() - t0;
        for (int c = 0; c < 3; ++c) {
            z = fmax(z, fabs(a[c] - b[c]) / hypot(ea[c], eb[c]));
            /* the collision estimator's error at the same number of paths */
            gain = fmin(gain, eb[c] * sqrt((double)simple_paths / paths) / ea[c]);
        }
        check(z < 4 && gain > (cases[i].sel <= -6 ? 3.0 : 0.8),
              "twilight estimators (view %g/%g, sun %g), orders 2-12: sunlit segments (%.4g %.4g "
              "%.4g) +- %.2f%%, collisions (%.4g %.4g %.4g) +- %.2f%%, max |diff|/SE %.2f; "
              "standard error at equal paths %.1f times smaller (%.2f s vs %.2f s for %d and %d "
              "paths)",
              cases[i].vel, cases[i].vaz, cases[i].sel, a[0], a[1], a[2], 100 * ea[2] / a[2], b[0],
              b[1], b[2], 100 * eb[2] / b[2], z, gain, t_sunlit, t_simple, paths, simple_paths);
    }
    double v[3], s[3], a[3], ea[3], b[3], eb[3];
    dir_from(20, 200, v);
    dir_from(30, 0, s);
    ref_radiance_mc_estimator(&e, 0, v, s, 2, 12, 4000, 7, THREADS, REF_MC_SUNLIT_SEGMENTS, a, ea);
    ref_radiance_mc_estimator(&e, 0, v, s, 2, 12, 4000, 7, THREADS, REF_MC_COLLISION_ONLY, b, eb);
    check(!memcmp(a, b, sizeof a) && !memcmp(ea, eb, sizeof ea),
          "sun 30 deg up: both estimators draw the same paths (blue %.6g, %.6g)", a[2], b[2]);
}

/* ------------------------------------------------ Earth report and timings */

static void report_earth(void)
{
    struct ref_atmosphere e;
    ref_atmosphere_earth(&e);
    const double sels[] = { 30, 0, -2 };
    double v[3], s[3], L[3], se[3];
    dir_from(90, 0, v);
    for (int i = 0; i < 3; ++i) {
        int used = 0;
        dir_from(sels[i], 0, s);
        double t0 = now();
        ref_radiance(&e, 0, v, s, 10, 10000, 2024, THREADS, L, se);
        double t_fixed = now() - t0;
        t0 = now();
        ref_radiance_adaptive(&e, 0, v, s, 10, 0.003, 4096, 1 << 20, 2024, THREADS, L, se, &used);
        double dt = now() - t0, rel = 0;
        for (int c = 0; c < 3; ++c)
            rel = fmax(rel, se[c] / L[c]);
        check(rel <= 0.003 && L[0] > 0 && L[2] > 0,
              "Earth zenith radiance, sun %+g deg, orders <= 10: (%.6f %.6f %.6f), SE %.2f%% "
              "after %d paths in %.2f s (10000 paths: %.2f s) on %d threads",
              sels[i], L[0], L[1], L[2], 100 * rel, used, dt, t_fixed, THREADS);
    }
    dir_from(30, 0, s);
    ref_sky_irradiance(&e, s, 10, 8000, 7, THREADS, L, se);
    check(L[0] > 0 && L[2] > L[0],
          "Earth sky irradiance, sun 30 deg: (%.5f %.5f %.5f) +- (%.5f "
          "%.5f %.5f) per unit solar irradiance",
          L[0], L[1], L[2], se[0], se[1], se[2]);
}

int main(void)
{
    double t0 = now();
    test_phase();
    test_transmittance();
    test_single_scattering();
    test_monte_carlo();
    test_twilight_estimators();
    report_earth();
    printf("%s: %d failure(s), %.1f s\n", failures ? "FAILED" : "OK", failures, now() - t0);
    return failures ? 1 : 0;
}
