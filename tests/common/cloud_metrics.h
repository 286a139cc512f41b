/* Image measurements of rendered clouds, for the cloud-shape, light and stream tests: masks,
 * connected cloud objects, the area-perimeter fractal dimension of their outlines (Lovejoy
 * 1982), their aspect ratios, blockiness on a pixel grid, autocorrelation at a shift, and the
 * sun's brightness against the sky around it. Pure C on float images; no Vulkan. */
#ifndef SKYD_TEST_CLOUD_METRICS_H
#define SKYD_TEST_CLOUD_METRICS_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

/* Luminance (Rec. 709 weights) of w x h RGBA float pixels into luma[w * h]. */
void cloud_metrics_luma(const float *rgba, int w, int h, float *luma);

/* mask[i] = 1 where the cloudy render differs from the clear render of the same view by more
 * than `relative` of the clear luminance (|cloudy - clear| > relative * clear), else 0. */
void cloud_metrics_mask_from_pair(const float *cloudy_luma, const float *clear_luma, int w, int h,
                                  double relative, unsigned char *mask);

/* One connected cloud object (8-connected pixels of the mask). */
struct cloud_object {
    int area;           /* pixels */
    int perimeter;      /* pixel edges between the object and anything outside it */
    int x0, y0, x1, y1; /* bounding box, inclusive */
    bool touches_border;
};

/* Labels the mask's 8-connected objects into out[0 .. max_objects - 1], in the order of their
 * first pixel in row-major scan; returns how many there are (may exceed max_objects: only the
 * first max_objects are stored; out may be NULL when max_objects is 0), or -1 when out of
 * memory. The perimeter counts the image's border as outside and includes the edges of holes.
 * touches_border: a pixel on the first or last row or column. */
int cloud_metrics_objects(const unsigned char *mask, int w, int h, struct cloud_object *out,
                          int max_objects);

/* Area-perimeter dimension of the whole objects (not touching the border) with area of at
 * least min_area: D = 2 * slope of the least-squares fit of log P on log A (P ~ A^(D/2)).
 * *used (when not NULL) receives how many objects entered the fit; returns NAN when fewer
 * than 3 or when their areas are all the same. Pixel perimeters bias small objects: specks of
 * a few pixels give D near 1.6 to 2 (a diagonal chain of n pixels has P = 4n), so use a
 * min_area of 30 to 100 pixels, and trust the fit only over a decade or more of areas. */
double cloud_metrics_fractal_dimension(const struct cloud_object *objects, int count, int min_area,
                                       int *used);

/* Median bounding-box height / width of the whole objects (not touching the border) at least
 * min_width pixels wide (the mean of the middle two for an even count); *used (when not NULL)
 * receives how many; NAN when none. *max_ratio (when not NULL) the largest ratio, or NAN. */
double cloud_metrics_median_aspect(const struct cloud_object *objects, int count, int min_width,
                                   int *used, double *max_ratio);

/* Blockiness of a w x h luminance image on a grid of `period` pixels: the mean |L(x) - L(x-1)|
 * over columns x with x % period == 0, over the same mean for every other column (x >= 1),
 * over all rows. Horizontal differences only. 1 for an image without block structure; NAN
 * for a flat image (nothing to divide by), a period under 2 or an image not wider than it. */
double cloud_metrics_blockiness(const float *luma, int w, int h, int period);

/* Normalized autocorrelation of a w x h luminance image at shift (dx, dy) pixels: Pearson's
 * correlation between L(x, y) and L(x + dx, y + dy) over the pixels where both lie in the image,
 * each side about its own mean. 1 for an image that repeats with that shift, near 0 for one
 * whose structure is smaller than the shift and not periodic. NAN when the images overlap in
 * fewer than 2 pixels or either side is flat. */
double cloud_metrics_autocorrelation(const float *luma, int w, int h, int dx, int dy);

/* The sun against the sky around it in a pinhole view (camera.glsl's conventions: uv (0,0)
 * at the top left, aspect w / h; forward, right and up unit vectors in any common frame;
 * tan_half the tangent of half the vertical field of view; sun_dir of any length): the
 * brightest pixel (by its centre's direction) within `disk_deg` of `sun_dir`, over the mean
 * luminance of the pixels between `ring_deg[0]` and `ring_deg[1]` (inclusive) from it. NAN
 * when no pixel lies in one of the regions or the ring's mean is 0. */
double cloud_metrics_sun_contrast(const float *luma, int w, int h, const double forward[3],
                                  const double right[3], const double up[3], double tan_half,
                                  const double sun_dir[3], double disk_deg,
                                  const double ring_deg[2]);

/* Pictures of what the tests measure, for the PNGs they write (8-bit sRGB RGBA, w x h x 4):
 * a linear render exposed so that its mean luminance is 0.25 and tone mapped (Reinhard); a
 * mask, grey where set, with boxes around its objects, green those `measured` accepts and red
 * those cut by the border (the others unboxed). */
void cloud_metrics_picture(const float *rgba, int w, int h, uint8_t *out);
void cloud_metrics_mask_picture(const unsigned char *mask, int w, int h,
                                const struct cloud_object *objects, int count,
                                bool (*measured)(const struct cloud_object *o, const void *ctx),
                                const void *ctx, uint8_t *out);

#endif
