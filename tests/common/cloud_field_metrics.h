/* Statistics of whole cloud fields seen from above, for test_cloud_field: the cloud fraction of
 * a mask, the power-law exponent of the cloud size distribution (objects from cloud_metrics.h),
 * and the radial power spectrum of a luminance image with its slope over a wavelength band.
 * Pure C on masks and float images; no Vulkan. */
#ifndef SKYD_TEST_CLOUD_FIELD_METRICS_H
#define SKYD_TEST_CLOUD_FIELD_METRICS_H

#include <stdbool.h>

#include "cloud_metrics.h"

/* Fraction of the w x h mask that is set; NAN for an empty image. */
double cloud_field_fraction(const unsigned char *mask, int w, int h);

/* Exponent b of the number density n(L) ~ L^-b, L the equivalent diameter sqrt(4 A / pi).
 * This is the convention of the cited cumulus studies (Neggers et al. 2003; Zhao & Di Girolamo
 * 2007; De Vera et al. 2024): clouds per unit size interval, b ~ 1.7-2.9; the cumulative
 * count N(>L) then falls as L^-(b-1). */
struct cloud_size_fit {
    double b;         /* maximum likelihood, power law truncated to [l_min_km, l_max_km] */
    double b_sigma;   /* its standard error (Fisher information) */
    double b_clauset; /* maximum likelihood without the upper truncation, Clauset et al.
                          2009 eq. 3.1: 1 + n / sum ln(L / l_min); above 1 by construction */
    double b_binned;  /* least squares of log n(L) on log L, 5 bins a decade, bins of >= 2
                          clouds weighted by their count; NAN with fewer than 3 such bins */
    double ks;        /* Kolmogorov-Smirnov distance of the data from the truncated fit */
    double l_min_km;  /* lower edge: the diameter of min_area_px - 0.5 pixels */
    double l_max_km;  /* the largest cloud's L */
    int whole;        /* objects that do not touch the border */
    int used;         /* of those, the ones of at least min_area_px pixels */
};

/* The size distribution of the objects that do not touch the image's border and have at
 * least min_area_px pixels, pixel_km the side of a pixel in km. Areas are whole pixels, so a
 * cloud of A pixels stands for [A - 0.5, A + 0.5) and the fit starts at A_min - 0.5 (a
 * continuity correction). b, b_sigma, b_clauset and ks are NAN with fewer than 3 clouds or
 * when they all have the same area. */
struct cloud_size_fit cloud_field_size_distribution(const struct cloud_object *objects, int count,
                                                    double pixel_km, int min_area_px);

/* Maximum-likelihood exponent b of the density p(x) ~ x^-b on [lo, hi] (hi > lo > 0) from the
 * n samples x that lie in it; *sigma (when not NULL) its standard error, *used (when not
 * NULL) how many samples. Any real b, also b <= 1 (which the truncation keeps normalisable).
 * NAN with fewer than 3 samples. */
double cloud_field_truncated_power_law(const double *x, int n, double lo, double hi, double *sigma,
                                       int *used);

/* The 2D discrete Fourier transform of the w x h complex image (re, im), in place, rows and
 * then columns: forward exp(-2 pi i k x / n) without scaling; inverse exp(+...) divided by
 * w h. Radix 2 for power-of-two sides, a direct sum for others. Returns false when out of
 * memory (the image is then undefined). */
bool cloud_field_fft2(double *re, double *im, int w, int h, bool inverse);

/* The azimuthally summed power spectrum of the w x h luminance image with pixels of pixel_km:
 * the least-squares quadratic surface is removed (the view-angle trends of a render), a
 * separable Hann window applied, then the 2D transform; ring i (i = 1 .. min(w, h) / 2 - 1)
 * sums |F|^2 over |k| in [(i - 1/2) dk, (i + 1/2) dk), dk = 1 / (min(w, h) pixel_km), and
 * k[i - 1] = i dk in cycles per km. That is the 1D spectrum E(k) = sum of |F|^2 over the ring
 * / dk; for an isotropic field E(k) ~ 2 pi k P2(k), P2 the 2D spectral density, so a field
 * whose 1D transects have a k^-5/3 spectrum gives E ~ k^-5/3 here too (slopes of transects
 * and of this E agree; P2 itself is one steeper). Normalised so that sum(E dk) is the
 * variance of the detrended image. Returns the number of rings written (at most max_rings),
 * or -1 when out of memory or the image is smaller than 8 x 8. */
int cloud_field_spectrum(const float *luma, int w, int h, double pixel_km, double *k, double *e,
                         int max_rings);

/* Spectral exponent beta of E(k) ~ k^-beta over the rings with wavelengths 1/k in
 * [lambda_min_km, lambda_max_km]: least squares of log E on log k, one point a ring. The
 * rings are evenly spaced in k, so the short end of the band weighs more, and there each ring
 * averages more Fourier modes: the lowest rings of an image hold a few dozen modes each, and
 * the window smears them over +-2 rings. Keep lambda_max_km at a quarter of the image or less
 * and average E over several views: one 512^2 view of a k^-5/3 field gives beta over rings
 * 4-24 with a scatter of about 0.16, four views about 0.1. *used (when not NULL): the rings
 * in the fit. NAN with fewer than 3. */
double cloud_field_spectral_slope(const double *k, const double *e, int rings, double lambda_min_km,
                                  double lambda_max_km, int *used);

#endif
