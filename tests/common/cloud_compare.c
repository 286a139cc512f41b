#include "cloud_compare.h"

#include <math.h>
#include <stdlib.h>

double cloud_compare_relative_error(const float *a, const float *b, const unsigned char *mask,
                                    int width, int height)
{
    double diff = 0.0, sum = 0.0;
    for (long i = 0; i < (long)width * height; i++)
        if (mask[i]) {
            diff += fabs((double)a[i] - b[i]);
            sum += b[i];
        }
    return sum > 0.0 ? diff / sum : NAN;
}

double cloud_compare_block_relative_error(const float *a, const float *b, const unsigned char *mask,
                                          int width, int height, int block)
{
    double diff = 0.0, sum = 0.0;
    for (int by = 0; by + block <= height; by += block)
        for (int bx = 0; bx + block <= width; bx += block) {
            double sa = 0.0, sb = 0.0;
            int n = 0;
            for (int y = by; y < by + block; y++)
                for (int x = bx; x < bx + block; x++) {
                    long i = (long)y * width + x;
                    if (mask[i]) {
                        sa += a[i];
                        sb += b[i];
                        n++;
                    }
                }
            if (2 * n < block * block)
                continue;
            diff += fabs(sa - sb);
            sum += sb;
        }
    return sum > 0.0 ? diff / sum : NAN;
}

void cloud_compare_bands(const unsigned char *mask, int width, int height, int band,
                         unsigned char *out)
{
    for (int y = 0; y < height; y++)
        for (int x = 0; x < width; x++) {
            long i = (long)y * width + x;
            if (!mask[i]) {
                out[i] = 0;
                continue;
            }
            bool edge = false;
            for (int dy = -band; dy <= band && !edge; dy++)
                for (int dx = -band; dx <= band && !edge; dx++) {
                    int u = x + dx, v = y + dy;
                    edge = u < 0 || v < 0 || u >= width || v >= height ||
                           !mask[(long)v * width + u];
                }
            out[i] = edge ? 1 : 2;
        }
}

double cloud_compare_outline_ratio(const float *luma, const unsigned char *mask, int width,
                                   int height, int band)
{
    unsigned char *bands = malloc((size_t)width * height);
    if (!bands)
        return NAN;
    cloud_compare_bands(mask, width, height, band, bands);
    double sum[3] = { 0, 0, 0 };
    long n[3] = { 0, 0, 0 };
    for (long i = 0; i < (long)width * height; i++) {
        sum[bands[i]] += luma[i];
        n[bands[i]]++;
    }
    free(bands);
    if (n[1] == 0 || n[2] == 0 || sum[2] <= 0.0)
        return NAN;
    return (sum[1] / n[1]) / (sum[2] / n[2]);
}

double cloud_compare_grain(const float *luma, const unsigned char *mask, int width, int height,
                           int band)
{
    unsigned char *bands = malloc((size_t)width * height);
    if (!bands)
        return NAN;
    cloud_compare_bands(mask, width, height, band, bands);
    double s = 0.0, s2 = 0.0, l = 0.0;
    long n = 0;
    for (int y = 1; y < height - 1; y++)
        for (int x = 1; x < width - 1; x++) {
            long i = (long)y * width + x;
            if (bands[i] != 2)
                continue;
            double box = 0.0;
            for (int dy = -1; dy <= 1; dy++)
                for (int dx = -1; dx <= 1; dx++)
                    box += luma[i + (long)dy * width + dx];
            double h = luma[i] - box / 9.0;
            s += h;
            s2 += h * h;
            l += luma[i];
            n++;
        }
    free(bands);
    if (n < 2 || l <= 0.0)
        return NAN;
    double mean_h = s / n;
    return sqrt(fmax(s2 / n - mean_h * mean_h, 0.0)) / (l / n);
}
