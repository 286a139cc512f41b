/* Statistics of whole cloud fields seen from above (cloud_field_metrics.h). */
#include "cloud_field_metrics.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

double cloud_field_fraction(const unsigned char *mask, int w, int h)
{
    if (w <= 0 || h <= 0)
        return NAN;
    size_t n = (size_t)w * (size_t)h, on = 0;
    for (size_t i = 0; i < n; i++)
        on += mask[i] != 0;
    return (double)on / (double)n;
}

/* ---- power laws ---- */

/* For u = ln(x / lo) on [0, U] with density ~ exp(-t u) (t = b - 1): the mean and variance of
 * u. Written with expm1 and sinh so that t U near 0 and large |t U| stay accurate. */
static double truncated_mean(double t, double U)
{
    double tu = t * U;
    if (fabs(tu) < 1e-6)
        return U / 2.0 - t * U * U / 12.0;
    return 1.0 / t - U / expm1(tu);
}

static double truncated_variance(double t, double U)
{
    double tu = t * U;
    if (fabs(tu) < 1e-4)
        return U * U / 12.0;
    double s = sinh(tu / 2.0);
    return 1.0 / (t * t) - U * U / (4.0 * s * s);
}

static double truncated_cdf(double u, double t, double U)
{
    if (fabs(t * U) < 1e-9)
        return u / U;
    return expm1(-t * u) / expm1(-t * U);
}

static int compare_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* The likelihood of an exponential family in ln x: its maximum is where the model's mean of
 * ln(x / lo) equals the samples' (Aban, Meerschaert & Panorska 2006, JASA 101, for the
 * truncated Pareto); the model's mean falls monotonically with t, so bisection finds it. */
double cloud_field_truncated_power_law(const double *x, int n, double lo, double hi, double *sigma,
                                       int *used)
{
    double U = log(hi / lo), sum = 0.0;
    int k = 0;
    for (int i = 0; i < n; i++)
        if (x[i] >= lo && x[i] <= hi) {
            sum += log(x[i] / lo);
            k++;
        }
    if (used)
        *used = k;
    if (sigma)
        *sigma = NAN;
    if (k < 3 || !(U > 0.0))
        return NAN;
    double mean = sum / k, t_lo = -1e3, t_hi = 1e3;
    for (int it = 0; it < 200; it++) {
        double t = 0.5 * (t_lo + t_hi);
        if (truncated_mean(t, U) > mean)
            t_lo = t;
        else
            t_hi = t;
    }
    double t = 0.5 * (t_lo + t_hi);
    if (sigma)
        *sigma = 1.0 / sqrt(k * truncated_variance(t, U));
    return 1.0 + t;
}

/* Kolmogorov-Smirnov distance of the sorted samples u (ln(x / lo)) from the truncated law. */
static double ks_distance(const double *u, int n, double t, double U)
{
    double d = 0.0;
    for (int i = 0; i < n; i++) {
        double f = truncated_cdf(u[i], t, U);
        d = fmax(d, fmax(fabs(f - (double)i / n), fabs(f - (double)(i + 1) / n)));
    }
    return d;
}

/* Log-binned density, 5 bins a decade from lo: weighted least squares of log n on log L. */
static double binned_exponent(const double *l, int n, double lo, double hi)
{
    enum { PER_DECADE = 5, MAX_BINS = 64 };
    int counts[MAX_BINS] = { 0 };
    double step = pow(10.0, 1.0 / PER_DECADE);
    int bins = (int)ceil(log(hi / lo) / log(step));
    if (bins > MAX_BINS)
        bins = MAX_BINS;
    for (int i = 0; i < n; i++) {
        int j = (int)floor(log(l[i] / lo) / log(step));
        if (j >= 0 && j < bins)
            counts[j]++;
    }
    double sw = 0, sx = 0, sy = 0, sxx = 0, sxy = 0;
    int fitted = 0;
    for (int j = 0; j < bins; j++) {
        if (counts[j] < 2)
            continue;
        double a = lo * pow(step, j), b = a * step;
        double x = log(sqrt(a * b)), y = log(counts[j] / (b - a)), wgt = counts[j];
        sw += wgt;
        sx += wgt * x;
        sy += wgt * y;
        sxx += wgt * x * x;
        sxy += wgt * x * y;
        fitted++;
    }
    if (fitted < 3)
        return NAN;
    double var = sxx - sx * sx / sw;
    return var > 0 ? -(sxy - sx * sy / sw) / var : NAN;
}

struct cloud_size_fit cloud_field_size_distribution(const struct cloud_object *objects, int count,
                                                    double pixel_km, int min_area_px)
{
    struct cloud_size_fit fit = { NAN, NAN, NAN, NAN, NAN, NAN, NAN, 0, 0 };
    size_t cap = count > 0 ? (size_t)count : 1;
    double *l = malloc(2 * cap * sizeof *l), *u = l + cap;
    if (!l)
        return fit;
    int max_area = 0;
    for (int i = 0; i < count; i++) {
        const struct cloud_object *o = &objects[i];
        if (o->touches_border)
            continue;
        fit.whole++;
        if (o->area < min_area_px)
            continue;
        l[fit.used++] = sqrt(4.0 * o->area / M_PI) * pixel_km;
        if (o->area > max_area)
            max_area = o->area;
    }
    double a_min = min_area_px > 1 ? min_area_px - 0.5 : 0.5;
    fit.l_min_km = sqrt(4.0 * a_min / M_PI) * pixel_km;
    if (fit.used > 0) {
        qsort(l, (size_t)fit.used, sizeof *l, compare_double);
        fit.l_max_km = l[fit.used - 1];
    }
    /* The largest cloud's area, like every other, stands for a bin half a pixel either side. */
    double hi = sqrt(4.0 * (max_area + 0.5) / M_PI) * pixel_km;
    if (fit.used >= 3 && l[0] < l[fit.used - 1]) {
        fit.b = cloud_field_truncated_power_law(l, fit.used, fit.l_min_km, hi, &fit.b_sigma, NULL);
        double sum = 0;
        for (int i = 0; i < fit.used; i++) {
            u[i] = log(l[i] / fit.l_min_km);
            sum += u[i];
        }
        /* Clauset, Shalizi & Newman 2009 (SIAM Rev. 51), eq. 3.1. */
        fit.b_clauset = 1.0 + fit.used / sum;
        fit.ks = ks_distance(u, fit.used, fit.b - 1.0, log(hi / fit.l_min_km));
        fit.b_binned = binned_exponent(l, fit.used, fit.l_min_km, hi);
    }
    free(l);
    return fit;
}

/* ---- Fourier transforms ---- */

static bool is_power_of_two(int n)
{
    return n > 0 && (n & (n - 1)) == 0;
}

/* One line of n complex values in place; sign -1 forward, +1 inverse (unscaled). tmp holds
 * 2 n doubles for the direct sum. */
static void dft_line(double *re, double *im, int n, double sign, double *tmp)
{
    if (is_power_of_two(n)) {
        for (int i = 1, j = 0; i < n; i++) {
            int bit = n >> 1;
            for (; j & bit; bit >>= 1)
                j ^= bit;
            j |= bit;
            if (i < j) {
                double t = re[i];
                re[i] = re[j];
                re[j] = t;
                t = im[i];
                im[i] = im[j];
                im[j] = t;
            }
        }
        for (int len = 2; len <= n; len <<= 1) {
            double angle = sign * 2.0 * M_PI / len;
            for (int i = 0; i < n; i += len)
                for (int j = 0; j < len / 2; j++) {
                    double c = cos(angle * j), s = sin(angle * j);
                    int a = i + j, b = a + len / 2;
                    double xr = re[b] * c - im[b] * s, xi = re[b] * s + im[b] * c;
                    re[b] = re[a] - xr;
                    im[b] = im[a] - xi;
                    re[a] += xr;
                    im[a] += xi;
                }
        }
        return;
    }
    for (int k = 0; k < n; k++) {
        double sr = 0, si = 0;
        for (int x = 0; x < n; x++) {
            double angle = sign * 2.0 * M_PI * (double)((long)k * x % n) / n;
            double c = cos(angle), s = sin(angle);
            sr += re[x] * c - im[x] * s;
            si += re[x] * s + im[x] * c;
        }
        tmp[k] = sr;
        tmp[n + k] = si;
    }
    memcpy(re, tmp, (size_t)n * sizeof *re);
    memcpy(im, tmp + n, (size_t)n * sizeof *im);
}

bool cloud_field_fft2(double *re, double *im, int w, int h, bool inverse)
{
    int n = w > h ? w : h;
    double *line = malloc(4 * (size_t)n * sizeof *line);
    if (!line)
        return false;
    double sign = inverse ? 1.0 : -1.0, *lr = line, *li = line + n, *tmp = line + 2 * n;
    for (int y = 0; y < h; y++)
        dft_line(re + (size_t)y * w, im + (size_t)y * w, w, sign, tmp);
    for (int x = 0; x < w; x++) {
        for (int y = 0; y < h; y++) {
            lr[y] = re[(size_t)y * w + x];
            li[y] = im[(size_t)y * w + x];
        }
        dft_line(lr, li, h, sign, tmp);
        for (int y = 0; y < h; y++) {
            re[(size_t)y * w + x] = lr[y];
            im[(size_t)y * w + x] = li[y];
        }
    }
    if (inverse) {
        double scale = 1.0 / ((double)w * h);
        for (size_t i = 0; i < (size_t)w * h; i++) {
            re[i] *= scale;
            im[i] *= scale;
        }
    }
    free(line);
    return true;
}

/* ---- spectra ---- */

/* Solves the 6 x 6 system a x = b in place (Gaussian elimination, partial pivoting); false
 * when singular. */
static bool solve6(double a[6][6], double b[6])
{
    for (int c = 0; c < 6; c++) {
        int p = c;
        for (int r = c + 1; r < 6; r++)
            if (fabs(a[r][c]) > fabs(a[p][c]))
                p = r;
        if (!(fabs(a[p][c]) > 1e-300))
            return false;
        for (int k = 0; k < 6; k++) {
            double t = a[c][k];
            a[c][k] = a[p][k];
            a[p][k] = t;
        }
        double t = b[c];
        b[c] = b[p];
        b[p] = t;
        for (int r = c + 1; r < 6; r++) {
            double f = a[r][c] / a[c][c];
            for (int k = c; k < 6; k++)
                a[r][k] -= f * a[c][k];
            b[r] -= f * b[c];
        }
    }
    for (int c = 5; c >= 0; c--) {
        for (int k = c + 1; k < 6; k++)
            b[c] -= a[c][k] * b[k];
        b[c] /= a[c][c];
    }
    return true;
}

static void quadratic_terms(int x, int y, int w, int h, double t[6])
{
    double u = (2.0 * x + 1.0) / w - 1.0, v = (2.0 * y + 1.0) / h - 1.0;
    t[0] = 1.0;
    t[1] = u;
    t[2] = v;
    t[3] = u * u;
    t[4] = u * v;
    t[5] = v * v;
}

/* f minus its least-squares quadratic surface (only its mean when the fit is singular). */
static void remove_quadratic(double *f, int w, int h)
{
    double a[6][6] = { { 0 } }, b[6] = { 0 }, t[6];
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            quadratic_terms(x, y, w, h, t);
            for (int i = 0; i < 6; i++) {
                b[i] += t[i] * f[(size_t)y * w + x];
                for (int j = 0; j < 6; j++)
                    a[i][j] += t[i] * t[j];
            }
        }
    double mean = b[0] / ((double)w * h);
    bool ok = solve6(a, b);
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            double fit = mean;
            if (ok) {
                quadratic_terms(x, y, w, h, t);
                fit = 0.0;
                for (int i = 0; i < 6; i++)
                    fit += b[i] * t[i];
            }
            f[(size_t)y * w + x] -= fit;
        }
}

static double hann(int i, int n)
{
    return 0.5 - 0.5 * cos(2.0 * M_PI * (i + 0.5) / n);
}

/* Prewhitening (Blackman & Tukey 1958): the window's leakage carries power from the lowest
 * rings, where a steep spectrum holds most of it, into the next ones and steepens the fit
 * there (by 0.1 over rings 4-24 of a k^-2 field). The differences along x and y have a
 * spectrum flatter by k^2, which leaks little; each mode of the image is then their power over
 * the differences' response |e^(2 pi i f) - 1|^2 = 4 sin^2(pi f). */
int cloud_field_spectrum(const float *luma, int w, int h, double pixel_km, double *k, double *e,
                         int max_rings)
{
    if (w < 8 || h < 8)
        return -1;
    size_t n = (size_t)w * (size_t)h;
    double *f = malloc(n * sizeof *f), *buf = calloc(4 * n, sizeof *buf);
    if (!f || !buf) {
        free(f);
        free(buf);
        return -1;
    }
    double *xr = buf, *xi = buf + n, *yr = buf + 2 * n, *yi = buf + 3 * n;
    for (size_t i = 0; i < n; i++)
        f[i] = luma[i];
    remove_quadratic(f, w, h);
    double window_power = 0.0;
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            size_t i = (size_t)y * w + x;
            double win = hann(x, w) * hann(y, h);
            xr[i] = x + 1 < w ? (f[i + 1] - f[i]) * win : 0.0;
            yr[i] = y + 1 < h ? (f[i + w] - f[i]) * win : 0.0;
            window_power += win * win;
        }
    free(f);
    if (!cloud_field_fft2(xr, xi, w, h, false) || !cloud_field_fft2(yr, yi, w, h, false)) {
        free(buf);
        return -1;
    }
    int side = w < h ? w : h, rings = side / 2 - 1;
    if (rings > max_rings)
        rings = max_rings;
    double dk = 1.0 / (side * pixel_km);
    for (int r = 0; r < rings; r++) {
        k[r] = (r + 1) * dk;
        e[r] = 0.0;
    }
    /* Parseval: sum |F|^2 = w h sum f^2, and the window keeps window_power / (w h) of the
     * variance. */
    double scale = 1.0 / ((double)n * window_power * dk);
    for (int y = 0; y < h; y++) {
        double fy = (double)(y < h / 2 ? y : y - h) / h, sy = sin(M_PI * fy);
        for (int x = 0; x < w; x++) {
            double fx = (double)(x < w / 2 ? x : x - w) / w, sx = sin(M_PI * fx);
            int r = (int)floor(hypot(fx, fy) * side + 0.5);
            if (r < 1 || r > rings)
                continue;
            size_t i = (size_t)y * w + x;
            double power = xr[i] * xr[i] + xi[i] * xi[i] + yr[i] * yr[i] + yi[i] * yi[i];
            e[r - 1] += power / (4.0 * (sx * sx + sy * sy)) * scale;
        }
    }
    free(buf);
    return rings;
}

double cloud_field_spectral_slope(const double *k, const double *e, int rings, double lambda_min_km,
                                  double lambda_max_km, int *used)
{
    double sx = 0, sy = 0, sxx = 0, sxy = 0;
    int n = 0;
    for (int r = 0; r < rings; r++) {
        if (!(k[r] > 0) || !(e[r] > 0))
            continue;
        double lambda = 1.0 / k[r];
        if (lambda < lambda_min_km || lambda > lambda_max_km)
            continue;
        double x = log(k[r]), y = log(e[r]);
        sx += x;
        sy += y;
        sxx += x * x;
        sxy += x * y;
        n++;
    }
    if (used)
        *used = n;
    if (n < 3)
        return NAN;
    double var = sxx - sx * sx / n;
    return var > 0 ? -(sxy - sx * sy / n) / var : NAN;
}
