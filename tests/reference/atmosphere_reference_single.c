/* Single scattering of the atmosphere reference (atmosphere_reference.h,
 * atmosphere_reference_internal.h). */
#include "atmosphere_reference_internal.h"

#include <math.h>
#include <stdlib.h>

/* ---------------------------------------------------------------- single scattering */

/* Kronrod 15 abscissae (positive half, descending) and weights; Gauss 7 weights for the
 * odd-indexed abscissae. */
static const double gk_x[8] = { 0.99145537112081264, 0.94910791234275853,
                                0.86486442335976907, 0.74153118559939444,
                                0.58608723546769113, 0.40584515137739717,
                                0.20778495500789847, 0.0 };
static const double gk_w[8] = { 0.02293532201052922, 0.06309209262997855, 0.10479001032225018,
                                0.14065325971552592, 0.16900472663926790, 0.19035057806478541,
                                0.20443294007529889, 0.20948214108472783 };
static const double g7_w[4] = { 0.12948496616886969, 0.27970539148927667, 0.38183005050511894,
                                0.41795918367346939 };

struct ss_state {
    struct ctx view, sun;
    double s[3], p_r, p_m[3]; /* phase values: the scattering angle is fixed along the ray */
    struct march m, shadow;
    double K[MARCH_CAP][3], G[MARCH_CAP][3]; /* first pass per piece */
};

static void ss_integrand(struct ss_state *S, int k, double t, double f[3])
{
    double acc[4], col[4], x[3], st[3], sr[3], sm[3], Ts[3];
    ref_medium_gl5(&S->view, &S->m.r, S->m.t[k], t, acc);
    for (int q = 0; q < 4; ++q)
        col[q] = S->m.col[k][q] + acc[q];
    along(S->m.r.o, S->m.r.d, t, x);
    local_coefs(&S->view, ray_radius(&S->m.r, t), st, sr, sm);
    ref_medium_transmittance_to_top(&S->sun, x, S->s, &S->shadow, Ts);
    // dL = T_view sigma_s p T_sun dt
    for (int ch = 0; ch < 3; ++ch)
        f[ch] = exp(-tau_ch(&S->view, ch, col)) * (sr[ch] * S->p_r + sm[ch] * S->p_m[ch]) * Ts[ch];
}

/* Gauss-Kronrod 7-15 on [a, b] inside piece k: K (15 points) and G (7 points). */
static void gk15(struct ss_state *S, int k, double a, double b, double K[3], double G[3])
{
    double mid = 0.5 * (a + b), half = 0.5 * (b - a), f1[3], f2[3];
    ss_integrand(S, k, mid, f1);
    for (int ch = 0; ch < 3; ++ch)
        K[ch] = half * gk_w[7] * f1[ch], G[ch] = half * g7_w[3] * f1[ch];
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
        for (int ch = 0; ch < 3; ++ch)
            sum[ch] += K[ch];
        return;
    }
    for (int ch = 0; ch < 3; ++ch)
        half_tol[ch] = 0.5 * tol[ch];
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
        if (t > 0 && os + t * ds < 0)
            out[n++] = t;
    }
    return n;
}

void ref_single_scattering_ex(const struct ref_atmosphere *a, double altitude,
                              const double view_dir[3], const double sun_dir[3], double step_scale,
                              double rel_tol, double out[3])
{
    struct ss_state *S = malloc(sizeof *S);
    double o[3] = { 0, 0, a->bottom_radius + altitude }, d[3], extra[2];
    out[0] = out[1] = out[2] = S ? 0.0 : NAN;
    if (!S)
        return;
    ref_medium_ctx_init(&S->view, a, step_scale);
    ref_medium_ctx_init(&S->sun, a, step_scale);
    normalize3(view_dir, d);
    normalize3(sun_dir, S->s);
    S->p_r = ref_phase_rayleigh(dot3(d, S->s));
    for (int ch = 0; ch < 3; ++ch)
        S->p_m[ch] = ref_phase_mie(dot3(d, S->s), a->mie_g[ch]);
    struct ray r;
    ray_set(&r, o, d);
    int ne = shadow_breaks(&r, S->s, a->bottom_radius, extra);
    ref_medium_march_ray(&S->view, &r, HUGE_VAL, extra, ne, 0, &S->m);
    double total[3] = { 0, 0, 0 }, tol[3], x[3], n[3], Ts[3];
    for (int k = 0; k < S->m.n; ++k) {
        gk15(S, k, S->m.t[k], S->m.t[k + 1], S->K[k], S->G[k]);
        for (int ch = 0; ch < 3; ++ch)
            total[ch] += S->K[k][ch];
    }
    for (int ch = 0; ch < 3; ++ch)
        tol[ch] = rel_tol * fabs(total[ch]) / sqrt(fmax(1.0, S->m.n));
    for (int k = 0; k < S->m.n; ++k)
        gk_adapt(S, k, S->m.t[k], S->m.t[k + 1], S->K[k], S->G[k], tol, 0, out);
    if (S->m.in_medium && S->m.ground) {
        along(o, d, S->m.t[S->m.n], x);
        normalize3(x, n);
        ref_medium_transmittance_to_top(&S->sun, x, S->s, &S->shadow, Ts);
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
