/* Image measurements of rendered clouds (cloud_metrics.h). */
#include "cloud_metrics.h"

#include <math.h>
#include <limits.h>
#include <stdlib.h>

void cloud_metrics_luma(const float *rgba, int w, int h, float *luma)
{
    size_t n = (w > 0 && h > 0) ? (size_t)w * (size_t)h : 0;
    for (size_t i = 0; i < n; i++) {
        const float *p = rgba + 4 * i;
        luma[i] = 0.2126f * p[0] + 0.7152f * p[1] + 0.0722f * p[2];
    }
}

void cloud_metrics_mask_from_pair(const float *cloudy_luma, const float *clear_luma, int w, int h,
                                  double relative, unsigned char *mask)
{
    size_t n = (w > 0 && h > 0) ? (size_t)w * (size_t)h : 0;
    for (size_t i = 0; i < n; i++) {
        double clear = clear_luma[i];
        mask[i] = fabs((double)cloudy_luma[i] - clear) > relative * clear;
    }
}

int cloud_metrics_objects(const unsigned char *mask, int w, int h, struct cloud_object *out,
                          int max_objects)
{
    if (w <= 0 || h <= 0)
        return 0;
    size_t n = (size_t)w * (size_t)h;
    /* A pixel is marked when pushed, so the stack never holds more than n entries. */
    unsigned char *seen = calloc(n, 1);
    size_t *stack = malloc(n * sizeof *stack);
    if (!seen || !stack) {
        free(seen);
        free(stack);
        return -1;
    }
    int count = 0;
    for (size_t start = 0; start < n; start++) {
        if (!mask[start] || seen[start])
            continue;
        struct cloud_object o = { 0, 0, w, h, -1, -1, false };
        size_t top = 0;
        stack[top++] = start;
        seen[start] = 1;
        while (top > 0) {
            size_t i = stack[--top];
            int x = (int)(i % (size_t)w), y = (int)(i / (size_t)w);
            o.area++;
            if (x < o.x0)
                o.x0 = x;
            if (x > o.x1)
                o.x1 = x;
            if (y < o.y0)
                o.y0 = y;
            if (y > o.y1)
                o.y1 = y;
            /* Edges to the four sides: outside the image or a pixel not in the mask. */
            o.perimeter += (x == 0 || !mask[i - 1]) + (x == w - 1 || !mask[i + 1]) +
                           (y == 0 || !mask[i - (size_t)w]) + (y == h - 1 || !mask[i + (size_t)w]);
            for (int dy = -1; dy <= 1; dy++) {
                int ny = y + dy;
                if (ny < 0 || ny >= h)
                    continue;
                for (int dx = -1; dx <= 1; dx++) {
                    int nx = x + dx;
                    if (nx < 0 || nx >= w)
                        continue;
                    size_t j = (size_t)ny * (size_t)w + (size_t)nx;
                    if (mask[j] && !seen[j]) {
                        seen[j] = 1;
                        stack[top++] = j;
                    }
                }
            }
        }
        o.touches_border = o.x0 == 0 || o.y0 == 0 || o.x1 == w - 1 || o.y1 == h - 1;
        if (count < max_objects)
            out[count] = o;
        if (count < INT_MAX)
            count++;
    }
    free(seen);
    free(stack);
    return count;
}

/* Lovejoy 1982 (Science 216, 185-187): the area-perimeter relation P ~ A^(D/2). */
double cloud_metrics_fractal_dimension(const struct cloud_object *objects, int count, int min_area,
                                       int *used)
{
    double sx = 0, sy = 0, sxx = 0, sxy = 0;
    int k = 0;
    for (int i = 0; i < count; i++) {
        const struct cloud_object *o = &objects[i];
        if (o->touches_border || o->area < min_area || o->area <= 0)
            continue;
        double x = log((double)o->area), y = log((double)o->perimeter);
        sx += x;
        sy += y;
        sxx += x * x;
        sxy += x * y;
        k++;
    }
    if (used)
        *used = k;
    if (k < 3)
        return NAN;
    double var = sxx - sx * sx / k, cov = sxy - sx * sy / k;
    /* Relative test: identical areas leave only rounding in var. */
    if (!(var > 1e-12 * (sxx > 1 ? sxx : 1)))
        return NAN;
    return 2.0 * cov / var;
}

static int compare_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

double cloud_metrics_median_aspect(const struct cloud_object *objects, int count, int min_width,
                                   int *used, double *max_ratio)
{
    double *ratio = malloc((count > 0 ? (size_t)count : 1) * sizeof *ratio);
    int k = 0;
    double largest = NAN, median = NAN;
    if (ratio) {
        for (int i = 0; i < count; i++) {
            const struct cloud_object *o = &objects[i];
            int width = o->x1 - o->x0 + 1;
            if (o->touches_border || width < min_width || width <= 0)
                continue;
            ratio[k++] = (double)(o->y1 - o->y0 + 1) / width;
        }
        if (k > 0) {
            qsort(ratio, (size_t)k, sizeof *ratio, compare_double);
            median = k % 2 ? ratio[k / 2] : 0.5 * (ratio[k / 2 - 1] + ratio[k / 2]);
            largest = ratio[k - 1];
        }
        free(ratio);
    }
    if (used)
        *used = k;
    if (max_ratio)
        *max_ratio = largest;
    return median;
}

double cloud_metrics_blockiness(const float *luma, int w, int h, int period)
{
    if (w < 2 || h < 1 || period < 2)
        return NAN;
    double on = 0, off = 0;
    long n_on = 0, n_off = 0;
    for (int y = 0; y < h; y++) {
        const float *row = luma + (size_t)y * (size_t)w;
        for (int x = 1; x < w; x++) {
            double d = fabs((double)row[x] - row[x - 1]);
            if (x % period == 0) {
                on += d;
                n_on++;
            } else {
                off += d;
                n_off++;
            }
        }
    }
    if (n_on == 0 || n_off == 0 || off == 0)
        return NAN;
    return (on / n_on) / (off / n_off);
}

double cloud_metrics_autocorrelation(const float *luma, int w, int h, int dx, int dy)
{
    int x0 = dx < 0 ? -dx : 0, x1 = dx > 0 ? w - dx : w;
    int y0 = dy < 0 ? -dy : 0, y1 = dy > 0 ? h - dy : h;
    if (x1 <= x0 || y1 <= y0 || (long)(x1 - x0) * (y1 - y0) < 2)
        return NAN;
    double sa = 0, sb = 0;
    long n = (long)(x1 - x0) * (y1 - y0);
    for (int y = y0; y < y1; y++)
        for (int x = x0; x < x1; x++) {
            sa += luma[(size_t)y * (size_t)w + (size_t)x];
            sb += luma[(size_t)(y + dy) * (size_t)w + (size_t)(x + dx)];
        }
    double ma = sa / n, mb = sb / n, ab = 0, aa = 0, bb = 0;
    for (int y = y0; y < y1; y++)
        for (int x = x0; x < x1; x++) {
            double a = luma[(size_t)y * (size_t)w + (size_t)x] - ma;
            double b = luma[(size_t)(y + dy) * (size_t)w + (size_t)(x + dx)] - mb;
            ab += a * b;
            aa += a * a;
            bb += b * b;
        }
    if (aa <= 0 || bb <= 0)
        return NAN;
    return ab / sqrt(aa * bb);
}

double cloud_metrics_sun_contrast(const float *luma, int w, int h, const double forward[3],
                                  const double right[3], const double up[3], double tan_half,
                                  const double sun_dir[3], double disk_deg,
                                  const double ring_deg[2])
{
    const double deg = 3.14159265358979323846 / 180.0;
    double sun_len =
        sqrt(sun_dir[0] * sun_dir[0] + sun_dir[1] * sun_dir[1] + sun_dir[2] * sun_dir[2]);
    if (w <= 0 || h <= 0 || !(sun_len > 0))
        return NAN;
    double aspect = (double)w / h;
    double peak = -INFINITY, sum = 0;
    long n_disk = 0, n_ring = 0;
    for (int y = 0; y < h; y++) {
        double ndc_y = 1.0 - 2.0 * ((y + 0.5) / h);
        for (int x = 0; x < w; x++) {
            double ndc_x = 2.0 * ((x + 0.5) / w) - 1.0;
            double d[3], len2 = 0, dot = 0;
            for (int c = 0; c < 3; c++) {
                d[c] = forward[c] + right[c] * ndc_x * tan_half * aspect + up[c] * ndc_y * tan_half;
                len2 += d[c] * d[c];
                dot += d[c] * sun_dir[c];
            }
            dot /= sqrt(len2) * sun_len;
            double angle = acos(dot < -1 ? -1 : dot > 1 ? 1 : dot) / deg;
            double l = luma[(size_t)y * (size_t)w + (size_t)x];
            if (angle <= disk_deg) {
                if (l > peak)
                    peak = l;
                n_disk++;
            }
            if (angle >= ring_deg[0] && angle <= ring_deg[1]) {
                sum += l;
                n_ring++;
            }
        }
    }
    if (n_disk == 0 || n_ring == 0 || sum == 0)
        return NAN;
    return peak / (sum / n_ring);
}

static uint8_t srgb8(double linear)
{
    double v = linear <= 0.0031308 ? 12.92 * linear : 1.055 * pow(linear, 1.0 / 2.4) - 0.055;
    return (uint8_t)lround(fmin(fmax(v, 0.0), 1.0) * 255.0);
}

void cloud_metrics_picture(const float *rgba, int w, int h, uint8_t *out)
{
    size_t n = (w > 0 && h > 0) ? (size_t)w * (size_t)h : 0;
    double mean = 0.0;
    for (size_t i = 0; i < n; i++) {
        const float *p = rgba + 4 * i;
        mean += 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2];
    }
    double k = n > 0 ? 0.25 / fmax(mean / (double)n, 1e-9) : 0.0;
    for (size_t i = 0; i < n; i++) {
        for (int c = 0; c < 3; c++) {
            double v = rgba[4 * i + c] * k;
            out[4 * i + c] = srgb8(v / (1.0 + v));
        }
        out[4 * i + 3] = 255;
    }
}

void cloud_metrics_mask_picture(const unsigned char *mask, int w, int h,
                                const struct cloud_object *objects, int count,
                                bool (*measured)(const struct cloud_object *o, const void *ctx),
                                const void *ctx, uint8_t *out)
{
    size_t n = (w > 0 && h > 0) ? (size_t)w * (size_t)h : 0;
    for (size_t i = 0; i < n; i++) {
        uint8_t v = mask[i] ? 200 : 0;
        out[4 * i] = out[4 * i + 1] = out[4 * i + 2] = v;
        out[4 * i + 3] = 255;
    }
    for (int k = 0; k < count; k++) {
        const struct cloud_object *o = &objects[k];
        bool used = measured(o, ctx);
        if (!used && !o->touches_border)
            continue;
        for (int y = o->y0; y <= o->y1; y++)
            for (int x = o->x0; x <= o->x1; x++) {
                if (y != o->y0 && y != o->y1 && x != o->x0 && x != o->x1)
                    continue;
                uint8_t *p = out + 4 * ((size_t)y * (size_t)w + (size_t)x);
                p[0] = used ? 0 : 255;
                p[1] = used ? 255 : 0;
                p[2] = 0;
            }
    }
}
