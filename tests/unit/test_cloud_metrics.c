/* Unit tests for the cloud image measurements (tests/common/cloud_metrics.c) on synthetic images with
 * known answers: objects, perimeters and 8-connectivity; the area-perimeter dimension of
 * squares and discs (1) and of quadratic Koch islands (1.5, exactly on the pixel grid);
 * aspect ratios of rectangles; blockiness of ramps, blocks and bilinear upsampling;
 * autocorrelation of a repeated tile, of white noise and of a checkerboard; the sun's contrast
 * in a pinhole view. */
#include "cloud_metrics.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"

static const double PI = 3.14159265358979323846;

static unsigned char *new_mask(int w, int h)
{
    unsigned char *m = calloc((size_t)w * (size_t)h, 1);
    if (!m)
        abort();
    return m;
}

static void fill_rect(unsigned char *m, int w, int x, int y, int rw, int rh)
{
    for (int j = y; j < y + rh; j++)
        memset(m + (size_t)j * (size_t)w + (size_t)x, 1, (size_t)rw);
}

static unsigned next_random(unsigned *state)
{
    *state = *state * 1103515245u + 12345u;
    return *state >> 16;
}

static void test_luma_and_mask(void)
{
    const float rgba[16] = { 1, 0, 0, 5, 0, 1, 0, 5, 0, 0, 1, 5, 2, 2, 2, 0 };
    float luma[4];
    cloud_metrics_luma(rgba, 2, 2, luma);
    CHECK_NEAR(luma[0], 0.2126, 1e-6);
    CHECK_NEAR(luma[1], 0.7152, 1e-6);
    CHECK_NEAR(luma[2], 0.0722, 1e-6);
    CHECK_NEAR(luma[3], 2.0, 1e-6);

    const float clear[6] = { 4, 4, 4, 0, 0, 4 };
    const float cloudy[6] = { 5, 3, 5.5f, 0.001f, 0, 2.5f };
    unsigned char mask[6];
    cloud_metrics_mask_from_pair(cloudy, clear, 3, 2, 0.25, mask);
    const unsigned char expected[6] = { 0, 0, 1, 1, 0, 1 }; /* strictly more than 1 = 0.25 * 4 */
    CHECK(memcmp(mask, expected, sizeof mask) == 0);
}

/* Object count by repeated 8-neighbour minimum-label propagation, independent of the flood
 * fill under test. */
static int count_objects_slowly(const unsigned char *m, int w, int h)
{
    int *label = malloc((size_t)w * (size_t)h * sizeof *label);
    if (!label)
        abort();
    for (int i = 0; i < w * h; i++)
        label[i] = m[i] ? i : -1;
    for (int changed = 1; changed;) {
        changed = 0;
        for (int y = 0; y < h; y++)
            for (int x = 0; x < w; x++)
                for (int dy = -1; dy <= 1; dy++)
                    for (int dx = -1; dx <= 1; dx++) {
                        int nx = x + dx, ny = y + dy, i = y * w + x, j = ny * w + nx;
                        if (m[i] && nx >= 0 && nx < w && ny >= 0 && ny < h && m[j] &&
                            label[j] < label[i]) {
                            label[i] = label[j];
                            changed = 1;
                        }
                    }
    }
    int n = 0;
    for (int i = 0; i < w * h; i++)
        n += m[i] && label[i] == i;
    free(label);
    return n;
}

static void test_objects(void)
{
    struct cloud_object o[8];
    unsigned char *m = new_mask(5, 5);
    CHECK(cloud_metrics_objects(m, 5, 5, o, 8) == 0);
    m[1 * 5 + 1] = m[2 * 5 + 2] = 1; /* diagonal neighbours: one object */
    CHECK(cloud_metrics_objects(m, 5, 5, o, 8) == 1);
    CHECK(o[0].area == 2 && o[0].perimeter == 8 && !o[0].touches_border);
    CHECK(o[0].x0 == 1 && o[0].y0 == 1 && o[0].x1 == 2 && o[0].y1 == 2);
    m[1 * 5 + 3] = 1; /* anti-diagonal too */
    CHECK(cloud_metrics_objects(m, 5, 5, o, 8) == 1);
    CHECK(o[0].area == 3 && o[0].perimeter == 12 && o[0].x1 == 3);
    m[1 * 5 + 2] = 1; /* filling the gap shares two edges */
    CHECK(cloud_metrics_objects(m, 5, 5, o, 8) == 1);
    CHECK(o[0].area == 4 && o[0].perimeter == 10);
    memset(m, 0, 25);
    m[0] = 1; /* a corner: the image's border counts as outside */
    CHECK(cloud_metrics_objects(m, 5, 5, o, 8) == 1);
    CHECK(o[0].area == 1 && o[0].perimeter == 4 && o[0].touches_border);
    m[0] = 0;
    m[4 * 5 + 2] = 1; /* bottom row */
    CHECK(cloud_metrics_objects(m, 5, 5, o, 8) == 1 && o[0].touches_border);
    free(m);

    /* A square ring: the edges around its hole count. */
    m = new_mask(7, 7);
    fill_rect(m, 7, 1, 1, 5, 5);
    m[3 * 7 + 3] = 0;
    CHECK(cloud_metrics_objects(m, 7, 7, o, 8) == 1);
    CHECK(o[0].area == 24 && o[0].perimeter == 24 && !o[0].touches_border);
    free(m);

    /* Five separate pixels, only two stored: the count is still five, in scan order. */
    m = new_mask(11, 3);
    for (int i = 0; i < 5; i++)
        m[11 + 1 + 2 * i] = 1;
    struct cloud_object sentinel = { -7, -7, 0, 0, 0, 0, false };
    for (int i = 0; i < 8; i++)
        o[i] = sentinel;
    CHECK(cloud_metrics_objects(m, 11, 3, o, 2) == 5);
    CHECK(o[0].x0 == 1 && o[1].x0 == 3 && o[2].area == -7);
    CHECK(cloud_metrics_objects(m, 11, 3, NULL, 0) == 5);
    free(m);

    /* A checkerboard is one 8-connected object whose every pixel has four free sides. */
    m = new_mask(20, 20);
    for (int i = 0; i < 400; i++)
        m[i] = (i % 20 + i / 20) % 2 == 0;
    CHECK(cloud_metrics_objects(m, 20, 20, o, 8) == 1);
    CHECK(o[0].area == 200 && o[0].perimeter == 800 && o[0].touches_border);
    free(m);

    /* A diagonal chain: one object, but every pixel has four free sides (P = 4 A). */
    m = new_mask(12, 12);
    for (int i = 1; i <= 10; i++)
        m[i * 12 + i] = 1;
    CHECK(cloud_metrics_objects(m, 12, 12, o, 8) == 1);
    CHECK(o[0].area == 10 && o[0].perimeter == 40 && !o[0].touches_border);
    free(m);

    /* An object far larger than any recursion could follow. */
    m = new_mask(600, 400);
    memset(m, 1, 600 * 400);
    CHECK(cloud_metrics_objects(m, 600, 400, o, 8) == 1);
    CHECK(o[0].area == 240000 && o[0].perimeter == 2000 && o[0].touches_border);
    CHECK(o[0].x0 == 0 && o[0].y0 == 0 && o[0].x1 == 599 && o[0].y1 == 399);
    free(m);

    /* Random masks: counts against the slow labelling, areas and perimeters against sums. */
    unsigned state = 2024;
    for (int trial = 0; trial < 20; trial++) {
        const int w = 37, h = 23;
        m = new_mask(w, h);
        int area = 0, perimeter = 0;
        for (int i = 0; i < w * h; i++)
            area += m[i] = next_random(&state) % 100 < 20u + 2u * (unsigned)trial;
        for (int y = 0; y < h; y++)
            for (int x = 0; x < w; x++)
                if (m[y * w + x])
                    perimeter += (x == 0 || !m[y * w + x - 1]) + (x == w - 1 || !m[y * w + x + 1]) +
                                 (y == 0 || !m[(y - 1) * w + x]) +
                                 (y == h - 1 || !m[(y + 1) * w + x]);
        struct cloud_object *all = malloc((size_t)(w * h) * sizeof *all);
        int n = cloud_metrics_objects(m, w, h, all, w * h);
        CHECK(n == count_objects_slowly(m, w, h));
        for (int i = 0; i < n; i++) {
            area -= all[i].area;
            perimeter -= all[i].perimeter;
        }
        CHECK(area == 0 && perimeter == 0);
        free(all);
        free(m);
    }
}

/* Labels `m` and appends its objects to list[*n ..]. */
static void append_objects(const unsigned char *m, int w, int h, struct cloud_object *list, int *n,
                           int capacity)
{
    int found = cloud_metrics_objects(m, w, h, list + *n, capacity - *n);
    CHECK(found >= 0 && found <= capacity - *n);
    *n += found;
}

static void test_dimension_of_squares_and_discs(void)
{
    /* Squares of sides 1 .. 30 (P = 4 sqrt(A): D = 1 exactly) among objects on the border. */
    const int w = 6 * 34, h = 5 * 34 + 20;
    unsigned char *m = new_mask(w, h);
    for (int s = 1; s <= 30; s++)
        fill_rect(m, w, 2 + (s - 1) % 6 * 34, 2 + (s - 1) / 6 * 34, s, s);
    fill_rect(m, w, 0, 10, 1, 5);     /* touching the left side */
    fill_rect(m, w, w - 3, 40, 3, 9); /* the right */
    for (int x = 40; x < 90; x += 4)  /* a comb on the bottom, far from P = 4 sqrt(A) */
        fill_rect(m, w, x, h - 1 - x % 7, 1, 1 + x % 7);
    struct cloud_object list[64];
    int n = 0, used = -1;
    append_objects(m, w, h, list, &n, 64);
    CHECK(n == 30 + 2 + 13);
    CHECK_NEAR(cloud_metrics_fractal_dimension(list, n, 1, &used), 1.0, 1e-12);
    CHECK(used == 30);
    CHECK_NEAR(cloud_metrics_fractal_dimension(list, n, 100, &used), 1.0, 1e-12);
    CHECK(used == 21);
    CHECK(isnan(cloud_metrics_fractal_dimension(list, n, 29 * 29, &used)) && used == 2);
    CHECK(isnan(cloud_metrics_fractal_dimension(list, 0, 1, NULL)));
    free(m);

    /* Identical squares: no spread of log A to fit a slope to. */
    m = new_mask(40, 10);
    for (int i = 0; i < 5; i++)
        fill_rect(m, 40, 1 + 8 * i, 2, 5, 5);
    n = 0;
    append_objects(m, 40, 10, list, &n, 64);
    CHECK(n == 5 && isnan(cloud_metrics_fractal_dimension(list, n, 1, &used)) && used == 5);
    free(m);

    /* Discs of radii 3 .. 40: a digital disc's pixel perimeter is that of its bounding box. */
    const int cell = 84, cols = 8, rows = 5;
    m = new_mask(cols * cell, rows * cell);
    for (int r = 3; r <= 40; r++) {
        int cx = (r - 3) % cols * cell + cell / 2, cy = (r - 3) / cols * cell + cell / 2;
        for (int y = cy - r; y <= cy + r; y++)
            for (int x = cx - r; x <= cx + r; x++)
                if ((x - cx) * (x - cx) + (y - cy) * (y - cy) <= r * r)
                    m[y * cols * cell + x] = 1;
    }
    n = 0;
    append_objects(m, cols * cell, rows * cell, list, &n, 64);
    CHECK(n == 38);
    for (int i = 0; i < n; i++)
        CHECK(list[i].perimeter == 2 * (list[i].x1 - list[i].x0 + 1 + list[i].y1 - list[i].y0 + 1));
    /* P = 8r + 4 against A ~ pi r^2: the + 4 steepens the small end, D a little under 1. */
    double d = cloud_metrics_fractal_dimension(list, n, 1, &used);
    CHECK(used == 38 && d > 0.95 && d < 1.0);
    CHECK_NEAR(cloud_metrics_fractal_dimension(list, n, 300, &used), 1.0, 0.03);
    free(m);
}

struct turtle {
    int x, y, dx, dy;
    int *vx, *vy, n;
};

/* Minkowski's quadratic Koch curve: F -> F+F-F-FF+F+F-F, each step a quarter as long. */
static void koch_side(struct turtle *t, int level, int length)
{
    static const char rule[] = "F+F-F-FF+F+F-F";
    if (level == 0) {
        t->x += t->dx * length;
        t->y += t->dy * length;
        t->vx[t->n] = t->x;
        t->vy[t->n++] = t->y;
        return;
    }
    for (const char *c = rule; *c; c++) {
        int dx = t->dx;
        if (*c == 'F') {
            koch_side(t, level - 1, length / 4);
        } else if (*c == '+') {
            t->dx = -t->dy;
            t->dy = dx;
        } else {
            t->dx = t->dy;
            t->dy = -dx;
        }
    }
}

/* The quadratic Koch island of `level` on a unit segment: side 4^level, area 16^level and
 * perimeter 4 * 8^level pixels, so P = 4 A^(3/4) and D = 1.5 (log 8 / log 4). */
static struct cloud_object koch_island(int level)
{
    int side = 1 << (2 * level), corners = 4 << (3 * level);
    struct turtle t = {
        0, 0, 1, 0, malloc(sizeof(int) * (size_t)corners), malloc(sizeof(int) * (size_t)corners), 0
    };
    int *cross = malloc(sizeof(int) * (size_t)corners);
    if (!t.vx || !t.vy || !cross)
        abort();
    for (int i = 0; i < 4; i++) {
        koch_side(&t, level, side);
        int dx = t.dx; /* turn left: the island lies on the turtle's left */
        t.dx = -t.dy;
        t.dy = dx;
    }
    int x0 = 0, y0 = 0, x1 = 0, y1 = 0;
    for (int i = 0; i < t.n; i++) {
        x0 = t.vx[i] < x0 ? t.vx[i] : x0;
        x1 = t.vx[i] > x1 ? t.vx[i] : x1;
        y0 = t.vy[i] < y0 ? t.vy[i] : y0;
        y1 = t.vy[i] > y1 ? t.vy[i] : y1;
    }
    int w = x1 - x0 + 2, h = y1 - y0 + 2; /* one pixel of margin on every side */
    unsigned char *m = new_mask(w, h);
    /* Scanline fill: a pixel is inside when its centre is, by crossings of vertical edges. */
    for (int y = y0; y < y1; y++) {
        int k = 0;
        for (int i = 0; i < t.n; i++) {
            int j = (i + 1) % t.n;
            if (t.vx[i] == t.vx[j] && (t.vy[i] <= y) != (t.vy[j] <= y))
                cross[k++] = t.vx[i];
        }
        for (int a = 1; a < k; a++) /* few crossings per row: insertion sort */
            for (int b = a; b > 0 && cross[b - 1] > cross[b]; b--) {
                int c = cross[b];
                cross[b] = cross[b - 1];
                cross[b - 1] = c;
            }
        for (int a = 0; a + 1 < k; a += 2)
            memset(m + (size_t)(y - y0 + 1) * (size_t)w + (cross[a] - x0 + 1), 1,
                   (size_t)(cross[a + 1] - cross[a]));
    }
    struct cloud_object o = { 0 };
    CHECK(cloud_metrics_objects(m, w, h, &o, 1) == 1);
    CHECK(o.area == side * side);
    CHECK(o.perimeter == 4 << (3 * level));
    free(m);
    free(cross);
    free(t.vx);
    free(t.vy);
    return o;
}

static void test_dimension_of_fractal_outlines(void)
{
    struct cloud_object list[5];
    int used;
    for (int level = 0; level < 5; level++)
        list[level] = koch_island(level);
    CHECK_NEAR(cloud_metrics_fractal_dimension(list, 5, 1, &used), 1.5, 1e-9);
    CHECK(used == 5);

    /* Objects given P = 3.1 A^0.7 (rounded to whole edges): D = 1.4. */
    struct cloud_object synthetic[40];
    for (int i = 0; i < 40; i++) {
        int area = (int)lround(20.0 * pow(10.0, i / 10.0));
        synthetic[i] =
            (struct cloud_object){ area, (int)lround(3.1 * pow(area, 0.7)), 10, 10, 20, 20, false };
    }
    CHECK_NEAR(cloud_metrics_fractal_dimension(synthetic, 40, 1, &used), 1.4, 0.005);
    CHECK(used == 40);
}

static void test_aspect(void)
{
    const int w = 80, h = 40;
    unsigned char *m = new_mask(w, h);
    fill_rect(m, w, 2, 2, 4, 2);                          /* h/w 0.5 */
    fill_rect(m, w, 10, 2, 5, 5);                         /* 1 */
    fill_rect(m, w, 20, 2, 3, 6);                         /* 2 */
    fill_rect(m, w, 30, 2, 4, 12);                        /* 3 */
    fill_rect(m, w, 40, 2, 1, 7);                         /* 7, one pixel wide */
    fill_rect(m, w, 50, 0, 3, 30);                        /* 10, on the border */
    m[20 * w + 10] = m[21 * w + 11] = m[22 * w + 12] = 1; /* a diagonal: its bounding box, 1 */
    struct cloud_object list[16];
    int n = cloud_metrics_objects(m, w, h, list, 16), used = -1;
    double max_ratio = 0;
    CHECK(n == 7);
    CHECK_NEAR(cloud_metrics_median_aspect(list, n, 2, &used, &max_ratio), 1.0, 1e-12);
    CHECK(used == 5);
    CHECK_NEAR(max_ratio, 3.0, 1e-12);
    CHECK_NEAR(cloud_metrics_median_aspect(list, n, 4, &used, &max_ratio), 1.0, 1e-12);
    CHECK(used == 3);
    CHECK_NEAR(cloud_metrics_median_aspect(list, n, 1, &used, NULL), 1.5, 1e-12);
    CHECK(used == 6);
    CHECK_NEAR(cloud_metrics_median_aspect(list, n, 1, NULL, &max_ratio), 1.5, 1e-12);
    CHECK_NEAR(max_ratio, 7.0, 1e-12);
    CHECK(isnan(cloud_metrics_median_aspect(list, n, 100, &used, &max_ratio)));
    CHECK(used == 0 && isnan(max_ratio));
    free(m);
}

static void test_blockiness(void)
{
    const int w = 129, h = 32; /* 16 spans of 8 */
    float *l = malloc(sizeof(float) * w * h);
    float *coarse = malloc(sizeof(float) * (w / 8 + 1) * (h / 8 + 1));
    if (!l || !coarse)
        abort();
    for (int i = 0; i < w * h; i++)
        l[i] = 0.01f * (float)(i % w) + 0.1f * (float)(i / w);
    CHECK_NEAR(cloud_metrics_blockiness(l, w, h, 8), 1.0, 1e-3);

    /* Constant 8 x 8 blocks: all the change is on the grid (plus a faint ramp to divide by). */
    unsigned state = 7;
    for (int i = 0; i < (w / 8 + 1) * (h / 8 + 1); i++)
        coarse[i] = (float)(next_random(&state) % 1000) / 1000.0f;
    for (int i = 0; i < w * h; i++)
        l[i] = coarse[i / w / 8 * (w / 8 + 1) + i % w / 8] + 1e-4f * (float)(i % w);
    CHECK(cloud_metrics_blockiness(l, w, h, 8) > 1000.0);

    /* Bilinear upsampling of the coarse grid. With nodes on the grid's columns every span of 8
     * differences holds one grid column: 1 up to rounding. With nodes between them (texel
     * centres) the flat clamped margin and a partial span move it a little. */
    for (int offset = 0; offset <= 4; offset += 4) {
        for (int y = 0; y < h; y++)
            for (int x = 0; x < w; x++) {
                double u = fmax(0, (x - offset) / 8.0), v = fmax(0, (y - offset) / 8.0);
                int i = (int)u < w / 8 - 1 ? (int)u : w / 8 - 1;
                int j = (int)v < h / 8 - 1 ? (int)v : h / 8 - 1;
                double fu = u - i, fv = v - j;
                const float *c = coarse + j * (w / 8 + 1) + i;
                l[y * w + x] = (float)((1 - fv) * ((1 - fu) * c[0] + fu * c[1]) +
                                       fv * ((1 - fu) * c[w / 8 + 1] + fu * c[w / 8 + 2]));
            }
        CHECK_NEAR(cloud_metrics_blockiness(l, w, h, 8), 1.0, offset ? 0.1 : 1e-3);
    }

    for (int i = 0; i < w * h; i++)
        l[i] = 0.5f;
    CHECK(isnan(cloud_metrics_blockiness(l, w, h, 8)));
    for (int i = 0; i < w * h; i++)
        l[i] = (float)(i % w);
    CHECK(isnan(cloud_metrics_blockiness(l, w, h, 1))); /* no column off the grid */
    CHECK(isnan(cloud_metrics_blockiness(l, 8, h, 8))); /* no column on it */
    for (int i = 0; i < 9 * h; i++)
        l[i] = (float)(i % 9);
    CHECK_NEAR(cloud_metrics_blockiness(l, 9, h, 8), 1.0, 1e-6);
    free(l);
    free(coarse);
}

static double angle_deg(const double a[3], const double b[3])
{
    double d = a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    double la = sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]);
    double lb = sqrt(b[0] * b[0] + b[1] * b[1] + b[2] * b[2]);
    d /= la * lb;
    return acos(d > 1 ? 1 : d < -1 ? -1 : d) * 180.0 / PI;
}

/* A random 12 x 9 tile repeated over the image correlates fully with itself one tile over,
 * in either direction and diagonally, and hardly at other shifts; white noise hardly at any;
 * a checkerboard is anticorrelated one pixel over. A flat image has none to measure. */
static void test_autocorrelation(void)
{
    const int w = 96, h = 54, tw = 12, th = 9;
    float *l = malloc(sizeof(float) * w * h), tile[12 * 9];
    if (!l)
        abort();
    unsigned state = 11;
    for (int i = 0; i < tw * th; i++)
        tile[i] = (float)(next_random(&state) % 1000) / 1000.0f;
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++)
            l[y * w + x] = tile[(y % th) * tw + x % tw];
    CHECK_NEAR(cloud_metrics_autocorrelation(l, w, h, 0, 0), 1.0, 1e-9);
    CHECK_NEAR(cloud_metrics_autocorrelation(l, w, h, tw, 0), 1.0, 1e-9);
    CHECK_NEAR(cloud_metrics_autocorrelation(l, w, h, 0, -th), 1.0, 1e-9);
    CHECK_NEAR(cloud_metrics_autocorrelation(l, w, h, -2 * tw, th), 1.0, 1e-9);
    CHECK(fabs(cloud_metrics_autocorrelation(l, w, h, tw / 2, 0)) < 0.3);
    CHECK(fabs(cloud_metrics_autocorrelation(l, w, h, 5, 4)) < 0.3);

    for (int i = 0; i < w * h; i++)
        l[i] = (float)(next_random(&state) % 1000) / 1000.0f;
    for (int d = 1; d < 40; d += 7) {
        CHECK(fabs(cloud_metrics_autocorrelation(l, w, h, d, 0)) < 0.1);
        CHECK(fabs(cloud_metrics_autocorrelation(l, w, h, 0, 1 + d / 2)) < 0.1);
    }

    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++)
            l[y * w + x] = (float)((x + y) % 2);
    CHECK_NEAR(cloud_metrics_autocorrelation(l, w, h, 1, 0), -1.0, 1e-9);
    CHECK_NEAR(cloud_metrics_autocorrelation(l, w, h, 1, 1), 1.0, 1e-9);

    for (int i = 0; i < w * h; i++)
        l[i] = 0.5f;
    CHECK(isnan(cloud_metrics_autocorrelation(l, w, h, 3, 0)));
    CHECK(isnan(cloud_metrics_autocorrelation(l, w, h, w, 0)));
    free(l);
}

static void test_sun_contrast(void)
{
    const int w = 160, h = 120;
    const double forward[3] = { 0, 1, 0 }, right[3] = { 1, 0, 0 }, up[3] = { 0, 0, 1 };
    const double tan_half = tan(30.0 * PI / 180.0), aspect = (double)w / h;
    float *l = malloc(sizeof(float) * w * h);
    if (!l)
        abort();
    /* Brightness by angle from the sun: 1000 within 1.5 degrees, 1 from 2.5 to 12, and values
     * that would spoil the answer between and beyond. */
    const double sun[3] = { 0.1, 1, 0.05 };
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            double sx = (2.0 * (x + 0.5) / w - 1) * tan_half * aspect;
            double sy = (1 - 2.0 * (y + 0.5) / h) * tan_half;
            double d[3] = { sx, 1, sy }, a = angle_deg(d, sun);
            l[y * w + x] = a <= 1.5 ? 1000.0f : a < 2.5 ? 5.0f : a <= 12 ? 1.0f : 1e6f;
        }
    const double ring[2] = { 3, 10 };
    CHECK_NEAR(cloud_metrics_sun_contrast(l, w, h, forward, right, up, tan_half, sun, 1, ring),
               1000.0, 1e-9);
    const double sun3[3] = { 0.3, 3, 0.15 }; /* any length */
    CHECK_NEAR(cloud_metrics_sun_contrast(l, w, h, forward, right, up, tan_half, sun3, 2, ring),
               1000.0, 1e-9);
    const double ring_with_halo[2] = { 2, 10 }, ring_too_wide[2] = { 3, 20 };
    CHECK(cloud_metrics_sun_contrast(l, w, h, forward, right, up, tan_half, sun, 1,
                                     ring_with_halo) < 999.0);
    CHECK(cloud_metrics_sun_contrast(l, w, h, forward, right, up, tan_half, sun, 1, ring_too_wide) <
          1.0);

    /* Orientation: one bright pixel in the upper right (v = 0 at the top), the sun on its
     * centre, then in the lower left. */
    const int px[2] = { 130, 17 }, py[2] = { 11, 100 };
    for (int k = 0; k < 2; k++) {
        for (int i = 0; i < w * h; i++)
            l[i] = 2.0f;
        l[py[k] * w + px[k]] = 2000.0f;
        double ndc_x = 2.0 * (px[k] + 0.5) / w - 1, ndc_y = 1 - 2.0 * (py[k] + 0.5) / h;
        double at[3] = { ndc_x * tan_half * aspect, 1, ndc_y * tan_half };
        CHECK_NEAR(cloud_metrics_sun_contrast(l, w, h, forward, right, up, tan_half, at, 0.2, ring),
                   1000.0, 1e-3);
    }

    const double behind[3] = { 0, -1, 0 }, ahead[3] = { 0, 1, 0 }, outside[2] = { 100, 120 };
    CHECK(
        isnan(cloud_metrics_sun_contrast(l, w, h, forward, right, up, tan_half, behind, 1, ring)));
    CHECK(isnan(
        cloud_metrics_sun_contrast(l, w, h, forward, right, up, tan_half, ahead, 1, outside)));
    for (int i = 0; i < w * h; i++)
        l[i] = 0.0f;
    CHECK(isnan(cloud_metrics_sun_contrast(l, w, h, forward, right, up, tan_half, ahead, 1, ring)));
    free(l);
}

int main(void)
{
    test_luma_and_mask();
    test_objects();
    test_dimension_of_squares_and_discs();
    test_dimension_of_fractal_outlines();
    test_aspect();
    test_blockiness();
    test_autocorrelation();
    test_sun_contrast();
    return check_summary();
}
