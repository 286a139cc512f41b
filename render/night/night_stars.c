#include "night_stars.h"

#include <math.h>
#include <stdbool.h>
#include <stdlib.h>
#include <string.h>

#include "night_shared.h"
#include "star_catalogue.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif
#define DEG (M_PI / 180.0)

struct star {
    double dir[3]; /* J2000 equatorial unit vector */
    double ra_deg, dec_deg, magnitude, temperature_k;
};

struct night_stars {
    uint32_t (*words)[4];
    size_t word_count, star_count;
    double total_lux, brightest_lux;
};

double night_star_illuminance_lux(double v_magnitude)
{
    return pow(10.0, -0.4 * (v_magnitude + 14.18));
}

void night_blackbody_rgb(double temperature_k, double rgb[3])
{
    double t = fmin(fmax(temperature_k, 1667.0), 25000.0);
    double t1 = 1e3 / t, t2 = t1 * t1, t3 = t2 * t1;
    /* Kim et al. 2002, "Design of advanced color temperature control system for HDTV", eqs. for
     * the Planckian locus in CIE 1931 xy. */
    double x = t < 4000.0 ? -0.2661239 * t3 - 0.2343589 * t2 + 0.8776956 * t1 + 0.179910
                          : -3.0258469 * t3 + 2.1070379 * t2 + 0.2226347 * t1 + 0.240390;
    double x2 = x * x, x3 = x2 * x, y;
    if (t < 2222.0)
        y = -1.1063814 * x3 - 1.34811020 * x2 + 2.18555832 * x - 0.20219683;
    else if (t < 4000.0)
        y = -0.9549476 * x3 - 1.37418593 * x2 + 2.09137015 * x - 0.16748867;
    else
        y = 3.0817580 * x3 - 5.87338670 * x2 + 3.75112997 * x - 0.37001483;
    double X = x / y, Y = 1.0, Z = (1.0 - x - y) / y;
    /* CIE XYZ -> linear sRGB (IEC 61966-2-1), then unit luminance. */
    rgb[0] = fmax(0.0, 3.2406 * X - 1.5372 * Y - 0.4986 * Z);
    rgb[1] = fmax(0.0, -0.9689 * X + 1.8758 * Y + 0.0415 * Z);
    rgb[2] = fmax(0.0, 0.0557 * X - 0.2040 * Y + 1.0570 * Z);
    double lum = 0.2126 * rgb[0] + 0.7152 * rgb[1] + 0.0722 * rgb[2];
    for (int c = 0; c < 3; c++)
        rgb[c] /= lum;
}

static void set_direction(struct star *s)
{
    double ra = s->ra_deg * DEG, dec = s->dec_deg * DEG;
    s->dir[0] = cos(dec) * cos(ra);
    s->dir[1] = cos(dec) * sin(ra);
    s->dir[2] = sin(dec);
}

/* Stars brighter than m over the whole sky: log10 N = 0.74 + 0.49 m, a fit to the counts of
 * Allen's Astrophysical Quantities (4th ed., table 19.1) for 1 < m < 7. */
static double count_brighter(double m)
{
    return pow(10.0, 0.74 + 0.49 * m);
}

static uint64_t next_random(uint64_t *state)
{
    /* xorshift64* (Vigna 2016): a fixed seed gives the same field on every start. */
    *state ^= *state >> 12;
    *state ^= *state << 25;
    *state ^= *state >> 27;
    return *state * 2685821657736338717ull;
}

static double uniform01(uint64_t *state)
{
    return (double)(next_random(state) >> 11) * (1.0 / 9007199254740992.0);
}

/* Temperature of a random naked-eye star: spectral classes in the proportions of the stars
 * brighter than 6.5 (B 19 %, A 23 %, F 14 %, G 13 %, K 27 %, M 4 %; Yale Bright Star
 * Catalogue), uniform within a class. */
static double field_temperature(uint64_t *state)
{
    static const double share[6] = { 0.19, 0.23, 0.14, 0.13, 0.27, 0.04 };
    static const double hot[6] = { 31000, 9700, 7200, 5900, 5200, 3850 };
    static const double cool[6] = { 10700, 7400, 6000, 5300, 3900, 2400 };
    double u = uniform01(state), sub = uniform01(state);
    for (int i = 0; i < 6; i++) {
        if (u < share[i] || i == 5)
            return hot[i] + (cool[i] - hot[i]) * sub;
        u -= share[i];
    }
    return 5800.0;
}

static int by_magnitude(const void *a, const void *b)
{
    double ma = ((const struct star *)a)->magnitude, mb = ((const struct star *)b)->magnitude;
    return (ma > mb) - (ma < mb);
}

static struct star *make_stars(size_t *count)
{
    double n_field = count_brighter(NIGHT_STARS_FAINTEST_MAG) -
                     count_brighter(NIGHT_STARS_FIELD_BRIGHTEST_MAG);
    size_t field = (size_t)n_field;
    /* The catalogue repeats a few names; each star once. */
    size_t total = STAR_CATALOGUE_COUNT + field, n = 0;
    struct star *stars = calloc(total, sizeof *stars);
    if (!stars)
        return NULL;
    for (size_t i = 0; i < STAR_CATALOGUE_COUNT; i++) {
        const struct star_catalogue_entry *e = &star_catalogue[i];
        bool duplicate = false;
        for (size_t j = 0; j < n; j++)
            duplicate |= stars[j].ra_deg == e->ra_deg && stars[j].dec_deg == e->dec_deg;
        if (duplicate)
            continue;
        stars[n] = (struct star){ .ra_deg = e->ra_deg,
                                  .dec_deg = e->dec_deg,
                                  .magnitude = e->v_magnitude,
                                  .temperature_k = e->temperature_k };
        set_direction(&stars[n++]);
    }
    uint64_t rng = 0x5eed5a11d5ca1e5ull;
    double n_bright = count_brighter(NIGHT_STARS_FIELD_BRIGHTEST_MAG);
    for (size_t i = 0; i < field; i++) {
        struct star *s = &stars[n++];
        /* Uniform on the sphere; magnitude by inverting the cumulative count. */
        s->dec_deg = asin(2.0 * uniform01(&rng) - 1.0) / DEG;
        s->ra_deg = 360.0 * uniform01(&rng);
        double cumulative = n_bright + n_field * uniform01(&rng);
        s->magnitude = (log10(cumulative) - 0.74) / 0.49;
        s->temperature_k = field_temperature(&rng);
        set_direction(s);
    }
    qsort(stars, n, sizeof *stars, by_magnitude);
    *count = n;
    return stars;
}

static double angle_between(const double a[3], const double b[3])
{
    double c = a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    return acos(fmin(1.0, fmax(-1.0, c)));
}

static void cell_point(double ra_deg, double dec_deg, double out[3])
{
    struct star s = { .ra_deg = ra_deg, .dec_deg = dec_deg };
    set_direction(&s);
    memcpy(out, s.dir, sizeof s.dir);
}

static void cell_insert(uint32_t (*cells)[4], uint32_t cell, uint32_t index)
{
    uint32_t *pair = &cells[cell / 2][(cell & 1u) * 2];
    for (int k = 0; k < NIGHT_STAR_CELL_CAPACITY; k++) {
        uint32_t *word = &pair[k / 2];
        uint32_t shift = 16u * (uint32_t)(k & 1);
        if (((*word >> shift) & 0xFFFFu) == NIGHT_STAR_EMPTY) {
            *word = (*word & ~(0xFFFFu << shift)) | (index << shift);
            return;
        }
    }
    /* Full: the cell keeps its brighter stars (insertion runs brightest first). */
}

/* Lists the star in every cell whose area comes within the support radius of it. */
static void insert_star(uint32_t (*cells)[4], const struct star *s, uint32_t index)
{
    const double support = NIGHT_STAR_SUPPORT_DEG;
    int row0 = (int)floor(s->dec_deg + 90.0 - support - 1.0);
    int row1 = (int)floor(s->dec_deg + 90.0 + support + 1.0);
    for (int row = row0 < 0 ? 0 : row0; row <= row1 && row < NIGHT_STAR_GRID_H; row++) {
        double dec_lo = row - 90.0, dec_hi = dec_lo + 1.0;
        double worst = fmin(90.0, fmax(fabs(dec_lo), fabs(dec_hi)) + support);
        double c = cos(worst * DEG);
        int col0 = 0, col1 = NIGHT_STAR_GRID_W - 1;
        if (c > 1e-3) {
            double half = (support + 1.0) / c;
            if (half < 180.0) {
                col0 = (int)floor(s->ra_deg - half);
                col1 = (int)floor(s->ra_deg + half);
            }
        }
        for (int col = col0; col <= col1; col++) {
            int wrapped = ((col % NIGHT_STAR_GRID_W) + NIGHT_STAR_GRID_W) % NIGHT_STAR_GRID_W;
            double centre[3], corner[3], reach = 0.0;
            cell_point(wrapped + 0.5, dec_lo + 0.5, centre);
            for (int k = 0; k < 4; k++) {
                cell_point(wrapped + (k & 1), dec_lo + (k >> 1), corner);
                reach = fmax(reach, angle_between(centre, corner));
            }
            if (angle_between(centre, s->dir) <= support * DEG + reach)
                cell_insert(cells, (uint32_t)(row * NIGHT_STAR_GRID_W + wrapped), index);
        }
    }
}

static float as_float_bits(double v, uint32_t *out)
{
    float f = (float)v;
    memcpy(out, &f, sizeof f);
    return f;
}

struct night_stars *night_stars_create(void)
{
    struct night_stars *ns = calloc(1, sizeof *ns);
    size_t count = 0;
    struct star *stars = ns ? make_stars(&count) : NULL;
    if (!stars || count >= NIGHT_STAR_EMPTY)
        goto destroy_partial;
    size_t cells = (size_t)NIGHT_STAR_GRID_W * NIGHT_STAR_GRID_H;
    size_t cell_words = (cells + 1) / 2;
    ns->word_count = 1 + cell_words + 2 * count;
    ns->words = malloc(ns->word_count * sizeof *ns->words);
    if (!ns->words)
        goto destroy_partial;
    ns->star_count = count;
    uint32_t *header = ns->words[0];
    header[0] = NIGHT_STAR_GRID_W;
    header[1] = NIGHT_STAR_GRID_H;
    header[2] = (uint32_t)count;
    header[3] = NIGHT_STAR_CELL_CAPACITY;
    memset(ns->words + 1, 0xFF, cell_words * sizeof *ns->words);
    uint32_t(*star_words)[4] = ns->words + 1 + cell_words;
    for (size_t i = 0; i < count; i++) {
        const struct star *s = &stars[i];
        insert_star(ns->words + 1, s, (uint32_t)i);
        double e = night_star_illuminance_lux(s->magnitude), rgb[3];
        night_blackbody_rgb(s->temperature_k, rgb);
        for (int c = 0; c < 3; c++) {
            as_float_bits(s->dir[c], &star_words[2 * i][c]);
            as_float_bits(e * rgb[c], &star_words[2 * i + 1][c]);
        }
        star_words[2 * i][3] = star_words[2 * i + 1][3] = 0;
        ns->total_lux += e;
        ns->brightest_lux = fmax(ns->brightest_lux, e);
    }
    free(stars);
    return ns;
destroy_partial:
    free(stars);
    night_stars_destroy(&ns);
    return NULL;
}

void night_stars_destroy(struct night_stars **pns)
{
    struct night_stars *ns = pns ? *pns : NULL;
    if (!ns)
        return;
    free(ns->words);
    free(ns);
    *pns = NULL;
}

const uint32_t (*night_stars_words(const struct night_stars *ns, size_t *words))[4]
{
    *words = ns->word_count;
    return (const uint32_t(*)[4])ns->words;
}

size_t night_stars_count(const struct night_stars *ns)
{
    return ns->star_count;
}

double night_stars_total_lux(const struct night_stars *ns)
{
    return ns->total_lux;
}

double night_stars_brightest_lux(const struct night_stars *ns)
{
    return ns->brightest_lux;
}
