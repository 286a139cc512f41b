/* Unit tests for the cloud field statistics (tests/common/cloud_field_metrics.c) on synthetic
 * data with known answers: cloud fraction; power-law exponents from drawn samples (also below
 * 1) and from masks of discs with power-law diameters; the Fourier transform against known
 * transforms; spectral slopes of fractional Brownian fields made by spectral synthesis, cut
 * out of a larger periodic field so that the window has edges to deal with, and of a field
 * whose slope breaks at 300 m; white noise (E ~ k^+1, and its variance). */
#include "cloud_field_metrics.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"

static const double PI = 3.14159265358979323846;

/* splitmix64: uniform in (0, 1). */
static double uniform(uint64_t *state)
{
    uint64_t z = (*state += 0x9e3779b97f4a7c15ull);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    z ^= z >> 31;
    return ((double)(z >> 11) + 0.5) / 9007199254740992.0;
}

static double gaussian(uint64_t *state)
{
    return sqrt(-2.0 * log(uniform(state))) * cos(2.0 * PI * uniform(state));
}

/* A draw from the density ~ x^-b on [lo, hi], by inverting its distribution function. */
static double draw_power_law(uint64_t *state, double b, double lo, double hi)
{
    double u = uniform(state), t = 1.0 - b;
    if (fabs(t) < 1e-12)
        return lo * pow(hi / lo, u);
    return pow(pow(lo, t) + u * (pow(hi, t) - pow(lo, t)), 1.0 / t);
}

static void *checked_calloc(size_t n, size_t size)
{
    void *p = calloc(n, size);
    if (!p)
        abort();
    return p;
}

static void test_fraction(void)
{
    unsigned char mask[40] = { 0 };
    for (int i = 0; i < 10; i++)
        mask[3 * i] = 1 + i % 3;
    CHECK_NEAR(cloud_field_fraction(mask, 8, 5), 0.25, 1e-12);
    CHECK(isnan(cloud_field_fraction(mask, 0, 5)));
}

/* 4000 draws for each b, truncated to two decades: the fit within 3 of its standard errors,
 * which are a few hundredths; too few samples give NAN. */
static void test_truncated_power_law(void)
{
    const double exponents[] = { 0.9, 1.0, 1.8, 2.6 };
    enum { N = 4000 };
    static double x[N];
    uint64_t state = 11;
    for (size_t e = 0; e < sizeof exponents / sizeof exponents[0]; e++) {
        for (int i = 0; i < N; i++)
            x[i] = draw_power_law(&state, exponents[e], 0.2, 20.0);
        double sigma;
        int used;
        double b = cloud_field_truncated_power_law(x, N, 0.2, 20.0, &sigma, &used);
        printf("truncated power law: b %.2f drawn, %.3f +- %.3f fitted\n", exponents[e], b, sigma);
        CHECK_INT(used, N);
        CHECK(sigma > 0.005 && sigma < 0.05);
        CHECK_NEAR(b, exponents[e], 3.0 * sigma);
    }
    CHECK(isnan(cloud_field_truncated_power_law(x, 2, 0.2, 20.0, NULL, NULL)));
}

/* Discs of power-law diameters (b = 1.8 and 2.6; 4 to 150 px), scattered without touching one
 * another or the border over a 2048^2 mask (1500 of them cover about 15 %); the fit above
 * 6 px (28 px of area). Pixel areas blur the diameters by about a pixel, which moves clouds
 * across the lower edge both ways. */
static void test_disc_sizes(void)
{
    enum { S = 2048, N = 1500 };
    const double exponents[] = { 1.8, 2.6 };
    unsigned char *mask = checked_calloc((size_t)S * S, 1);
    static double cx[N], cy[N], d[N];
    static struct cloud_object objects[N + 8];
    uint64_t state = 5;
    for (size_t e = 0; e < sizeof exponents / sizeof exponents[0]; e++) {
        memset(mask, 0, (size_t)S * S);
        for (int i = 0; i < N; i++)
            d[i] = draw_power_law(&state, exponents[e], 4.0, 150.0);
        int placed = 0;
        for (int i = 0; i < N; i++) {
            double r = d[i] / 2.0;
            for (int attempt = 0; attempt < 2000; attempt++) {
                double x = r + 45.0 + uniform(&state) * (S - d[i] - 90.0);
                double y = r + 45.0 + uniform(&state) * (S - d[i] - 90.0);
                bool free_spot = true;
                for (int j = 0; j < placed && free_spot; j++)
                    free_spot = hypot(x - cx[j], y - cy[j]) > r + d[j] / 2.0 + 2.0;
                if (!free_spot)
                    continue;
                cx[placed] = x;
                cy[placed] = y;
                d[placed++] = d[i];
                for (int py = (int)(y - r); py <= (int)(y + r) + 1; py++)
                    for (int px = (int)(x - r); px <= (int)(x + r) + 1; px++)
                        if (hypot(px + 0.5 - x, py + 0.5 - y) < r)
                            mask[(size_t)py * S + px] = 1;
                break;
            }
        }
        CHECK(placed >= N - 15);
        /* Two half discs on the border, in the margin the others keep clear of, which the fit
         * must leave out. */
        for (int py = 0; py < 20; py++)
            for (int px = 0; px < 40; px++)
                if (hypot(px - 20.0, py) < 20.0)
                    mask[(size_t)py * S + px + 300] = mask[(size_t)(S - 1 - py) * S + px] = 1;
        int count = cloud_metrics_objects(mask, S, S, objects, N + 8);
        struct cloud_size_fit fit = cloud_field_size_distribution(objects, count, 0.05, 28);
        printf("discs, b %.1f drawn: %d objects, %d whole, %d >= L_min %.3f km (max %.3f): "
               "b %.3f +- %.3f (Clauset %.3f, binned %.3f, KS %.3f)\n",
               exponents[e], count, fit.whole, fit.used, fit.l_min_km, fit.l_max_km, fit.b,
               fit.b_sigma, fit.b_clauset, fit.b_binned, fit.ks);
        CHECK_INT(count, placed + 2);
        CHECK_INT(fit.whole, placed);
        CHECK_NEAR(fit.l_min_km, 0.05 * sqrt(4.0 * 27.5 / PI), 1e-9);
        CHECK_NEAR(fit.b, exponents[e], 0.15);
        CHECK_NEAR(fit.b_binned, exponents[e], 0.25);
        CHECK(fit.ks < 0.05);
    }
    free(mask);
    CHECK(isnan(cloud_field_size_distribution(objects, 0, 0.05, 28).b));
}

static void test_fft(void)
{
    /* A cosine of 3 cycles across and 2 down: w h / 2 at (3, 2) and at (-3, -2), else 0. */
    const int sizes[][2] = { { 16, 8 }, { 12, 10 } };
    for (int s = 0; s < 2; s++) {
        int w = sizes[s][0], h = sizes[s][1];
        double *re = checked_calloc((size_t)w * h, sizeof *re);
        double *im = checked_calloc((size_t)w * h, sizeof *im);
        for (int y = 0; y < h; y++)
            for (int x = 0; x < w; x++)
                re[y * w + x] = cos(2.0 * PI * (3.0 * x / w + 2.0 * y / h));
        CHECK(cloud_field_fft2(re, im, w, h, false));
        double worst = 0.0;
        for (int y = 0; y < h; y++)
            for (int x = 0; x < w; x++) {
                bool peak = (x == 3 && y == 2) || (x == w - 3 && y == h - 2);
                double expected = peak ? w * h / 2.0 : 0.0;
                worst = fmax(worst, hypot(re[y * w + x] - expected, im[y * w + x]));
            }
        CHECK(worst < 1e-9);
        /* And back. */
        CHECK(cloud_field_fft2(re, im, w, h, true));
        worst = 0.0;
        for (int y = 0; y < h; y++)
            for (int x = 0; x < w; x++)
                worst = fmax(worst,
                             hypot(re[y * w + x] - cos(2.0 * PI * (3.0 * x / w + 2.0 * y / h)),
                                   im[y * w + x]));
        CHECK(worst < 1e-12);
        free(re);
        free(im);
    }
}

/* A 1024^2 periodic Gaussian field whose 1D spectrum is E ~ k^-beta_large at wavelengths
 * above `break_px` and continues as k^-beta_small below it (2D spectral amplitude
 * |k|^-(beta + 1) / 2), scaled to a standard deviation of 100 around 1000. */
enum { BIG = 1024, CUT = 512 };
static double *synthetic_field(uint64_t seed, double beta_large, double beta_small, double break_px)
{
    double *re = checked_calloc((size_t)BIG * BIG, sizeof *re);
    double *im = checked_calloc((size_t)BIG * BIG, sizeof *im);
    uint64_t state = seed;
    double k_break = 1.0 / break_px;
    for (int y = 0; y < BIG; y++)
        for (int x = 0; x < BIG; x++) {
            double fx = (double)(x < BIG / 2 ? x : x - BIG) / BIG;
            double fy = (double)(y < BIG / 2 ? y : y - BIG) / BIG;
            double k = hypot(fx, fy);
            double a = 0.0;
            if (k > 0.0)
                a = k < k_break ? pow(k, -(beta_large + 1.0) / 2.0)
                                : pow(k_break, (beta_small - beta_large) / 2.0) *
                                      pow(k, -(beta_small + 1.0) / 2.0);
            re[(size_t)y * BIG + x] = a * gaussian(&state);
            im[(size_t)y * BIG + x] = a * gaussian(&state);
        }
    CHECK(cloud_field_fft2(re, im, BIG, BIG, true));
    free(im);
    double sum = 0.0, sum2 = 0.0;
    for (size_t i = 0; i < (size_t)BIG * BIG; i++) {
        sum += re[i];
        sum2 += re[i] * re[i];
    }
    double mean = sum / ((double)BIG * BIG);
    double scale = 100.0 / sqrt(sum2 / ((double)BIG * BIG) - mean * mean);
    for (size_t i = 0; i < (size_t)BIG * BIG; i++)
        re[i] = 1000.0 + scale * (re[i] - mean);
    return re;
}

/* Adds the spectra of the field's four 512^2 quarters (none of them periodic, each on a ramp
 * that the detrending must take away) with pixels of pixel_km to sum[], as the render test
 * adds its views. */
static int add_quarters(const double *field, double pixel_km, double *k, double *sum)
{
    static float cut[CUT * CUT];
    static double e[CUT];
    int rings = 0;
    for (int q = 0; q < 4; q++) {
        int x0 = (q % 2) * CUT, y0 = (q / 2) * CUT;
        for (int y = 0; y < CUT; y++)
            for (int x = 0; x < CUT; x++)
                cut[y * CUT + x] =
                    (float)(field[(size_t)(y + y0) * BIG + x + x0] + 200.0 * x / CUT);
        rings = cloud_field_spectrum(cut, CUT, CUT, pixel_km, k, e, CUT);
        CHECK_INT(rings, CUT / 2 - 1);
        for (int r = 0; r < rings; r++)
            sum[r] += e[r];
    }
    return rings;
}

/* The render test's two bands: 1-8 km at 48 m pixels, 52-200 m at 13 m pixels (4 px up),
 * over the eight quarters of two fields: one 512^2 view alone scatters by about 0.16 over
 * 1-8 km (cloud_field_metrics.h). */
static void test_spectral_slopes(void)
{
    const double betas[] = { 1.3, 5.0 / 3.0, 2.0, 3.0 };
    static double k_large[CUT], k_small[CUT], large[CUT], small[CUT];
    for (size_t i = 0; i < sizeof betas / sizeof betas[0]; i++) {
        memset(large, 0, sizeof large);
        memset(small, 0, sizeof small);
        int rings = 0;
        for (uint64_t seed = 1; seed <= 2; seed++) {
            double *field = synthetic_field(seed, betas[i], betas[i], 1.0);
            rings = add_quarters(field, 0.048, k_large, large);
            add_quarters(field, 0.013, k_small, small);
            free(field);
        }
        int used_large, used_small;
        double beta_large = cloud_field_spectral_slope(k_large, large, rings, 1.0, 8.0,
                                                       &used_large);
        double beta_small = cloud_field_spectral_slope(k_small, small, rings, 0.052, 0.2,
                                                       &used_small);
        printf("fBm beta %.3f: %.3f over 1-8 km (%d rings), %.3f over 52-200 m (%d rings)\n",
               betas[i], beta_large, used_large, beta_small, used_small);
        CHECK_NEAR(beta_large, betas[i], 0.1);
        CHECK_NEAR(beta_small, betas[i], 0.1);
        CHECK(used_large >= 20);
        CHECK(used_small >= 20);
    }
    /* A break at 300 m (23 px of 13 m): 1.5 above it, 3 below; the 52-200 m band sees 3,
     * the band 0.5-1.5 km sees 1.5. */
    memset(large, 0, sizeof large);
    double *field = synthetic_field(3, 1.5, 3.0, 0.3 / 0.013);
    int rings = add_quarters(field, 0.013, k_small, large);
    free(field);
    double above = cloud_field_spectral_slope(k_small, large, rings, 0.5, 1.5, NULL);
    double below = cloud_field_spectral_slope(k_small, large, rings, 0.052, 0.2, NULL);
    printf("broken spectrum 1.5 / 3 at 300 m: %.3f over 0.5-1.5 km, %.3f over 52-200 m\n", above,
           below);
    CHECK_NEAR(above, 1.5, 0.1);
    CHECK_NEAR(below, 3.0, 0.1);
}

/* White noise of variance 4: E(k) ~ k (ring lengths grow as k), and sum E dk is the part of
 * the variance inside the largest ring, pi / 4 of it for a square image. */
static void test_white_noise(void)
{
    enum { S = 256 };
    static float noise[S * S];
    static double k[S], e[S];
    uint64_t state = 9;
    for (int i = 0; i < S * S; i++)
        noise[i] = (float)(10.0 + 2.0 * gaussian(&state));
    int rings = cloud_field_spectrum(noise, S, S, 0.1, k, e, S);
    double total = 0.0;
    for (int r = 0; r < rings; r++)
        total += e[r] * (k[1] - k[0]);
    double slope = cloud_field_spectral_slope(k, e, rings, 0.2, 2.0, NULL);
    printf("white noise: beta %.3f, variance in the rings %.3f (pi = %.3f)\n", slope, total, PI);
    CHECK_NEAR(slope, -1.0, 0.1);
    CHECK_NEAR(total, 4.0 * PI / 4.0, 0.1 * PI);
    CHECK_INT(cloud_field_spectrum(noise, 4, 4, 0.1, k, e, S), -1);
    CHECK(isnan(cloud_field_spectral_slope(k, e, rings, 100.0, 200.0, NULL)));
}

int main(void)
{
    test_fraction();
    test_truncated_power_law();
    test_disc_sizes();
    test_fft();
    test_spectral_slopes();
    test_white_noise();
    return check_summary();
}
