/* tests/common/cloud_compare.c on synthetic images with known answers. */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "check.h"
#include "cloud_compare.h"

#define W 32
#define H 24

static float a[W * H], b[W * H];
static unsigned char mask[W * H], bands[W * H];

/* A disk of radius 8 px at the centre. */
static void disk_mask(void)
{
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++)
            mask[y * W + x] = hypot(x - 15.5, y - 11.5) < 8.0;
}

int main(void)
{
    disk_mask();
    /* Relative error: a = 1.1 b on the mask, anything off it. */
    for (int i = 0; i < W * H; i++) {
        b[i] = 2.0f;
        a[i] = mask[i] ? 2.2f : 100.0f;
    }
    double e = cloud_compare_relative_error(a, b, mask, W, H);
    CHECK_MSG(fabs(e - 0.1) < 1e-6, "relative error %g, expected 0.1", e);
    /* Per block: +-20 % alternating pixel by pixel averages out in 2x2 blocks. */
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++)
            a[y * W + x] = 2.0f * ((x + y) % 2 ? 1.2f : 0.8f);
    double pixel = cloud_compare_relative_error(a, b, mask, W, H);
    double block = cloud_compare_block_relative_error(a, b, mask, W, H, 2);
    CHECK_MSG(fabs(pixel - 0.2) < 1e-6 && block < 0.02,
              "checkerboard error %g per pixel, "
              "%g per block",
              pixel, block);

    /* Bands: a 1 px band of a 3x3 square is its 8 outer pixels, its centre the interior. */
    memset(mask, 0, sizeof mask);
    for (int y = 5; y < 8; y++)
        for (int x = 5; x < 8; x++)
            mask[y * W + x] = 1;
    cloud_compare_bands(mask, W, H, 1, bands);
    int outline = 0, interior = 0;
    for (int i = 0; i < W * H; i++) {
        outline += bands[i] == 1;
        interior += bands[i] == 2;
    }
    CHECK_MSG(outline == 8 && interior == 1 && bands[6 * W + 6] == 2, "bands %d, %d", outline,
              interior);

    /* Outline ratio: 3 on the 2 px band, 1.5 inside: 2. */
    disk_mask();
    cloud_compare_bands(mask, W, H, 2, bands);
    for (int i = 0; i < W * H; i++)
        a[i] = bands[i] == 1 ? 3.0f : bands[i] == 2 ? 1.5f : 50.0f;
    double r = cloud_compare_outline_ratio(a, mask, W, H, 2);
    CHECK_MSG(fabs(r - 2.0) < 1e-9, "outline ratio %g, expected 2", r);

    /* Grain: a uniform image has none; a checkerboard m +- d has a high-pass of +-8d/9 (the
     * 3x3 mean of a checkerboard is +-d/9 around m), so grain 8d / (9m). A smooth ramp, whose
     * 3x3 mean equals it, has none either. */
    for (int i = 0; i < W * H; i++)
        a[i] = 4.0f;
    double g = cloud_compare_grain(a, mask, W, H, 2);
    CHECK_MSG(fabs(g) < 1e-9, "grain of a uniform image %g", g);
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++)
            a[y * W + x] = 4.0f + ((x + y) % 2 ? 1.0f : -1.0f);
    g = cloud_compare_grain(a, mask, W, H, 2);
    double expected = 8.0 / (9.0 * 4.0);
    /* The interior holds a few more pixels of one colour than the other: its mean is 4 +- 1/n. */
    CHECK_MSG(fabs(g - expected) < 0.01 * expected, "checkerboard grain %g, expected %g", g,
              expected);
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++)
            a[y * W + x] = 1.0f + 0.1f * x + 0.05f * y;
    g = cloud_compare_grain(a, mask, W, H, 2);
    CHECK_MSG(fabs(g) < 1e-5, "grain of a ramp %g", g);
    printf("relative error %.3f, outline ratio %.3f, checkerboard grain %.4f\n", e, r, expected);
    return check_summary();
}
