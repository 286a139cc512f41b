/* Figures that compare two renders of the same clouds (tests/render/test_cloud_vs_reference.c):
 * luminance images (row-major, width x height) and a mask of the cloud's pixels. */
#ifndef SKYD_CLOUD_COMPARE_H
#define SKYD_CLOUD_COMPARE_H

#include <stdbool.h>

/* sum |a - b| / sum b over the masked pixels (NAN when none, or b sums to 0). */
double cloud_compare_relative_error(const float *a, const float *b, const unsigned char *mask,
                                    int width, int height);

/* The same over block x block blocks: each block at least half masked compares the means of
 * its masked pixels, weighted by their count (a reference's pixel noise averages out). */
double cloud_compare_block_relative_error(const float *a, const float *b, const unsigned char *mask,
                                          int width, int height, int block);

/* Masked pixels within `band` px (Chebyshev distance) of an unmasked pixel or of the image's
 * border: the outline band (out[i] = 1); the other masked pixels are the interior (2);
 * unmasked 0. */
void cloud_compare_bands(const unsigned char *mask, int width, int height, int band,
                         unsigned char *out);

/* Mean luminance of the outline band over that of the interior (cloud_compare_bands). */
double cloud_compare_outline_ratio(const float *luma, const unsigned char *mask, int width,
                                   int height, int band);

/* Pixel-scale grain over the interior (the mask eroded by `band` px): the standard deviation
 * of the high-pass image (luma minus its 3x3 box mean) over the interior's mean luminance. */
double cloud_compare_grain(const float *luma, const unsigned char *mask, int width, int height,
                           int band);

#endif
