#include "png_write.h"

#include <errno.h>
#include <math.h>
#include <stdbool.h>
#include <png.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

struct memory_sink {
    uint8_t *data;
    size_t len, cap;
    int failed;
};

static void sink_write(png_structp png, png_bytep bytes, png_size_t len)
{
    struct memory_sink *s = png_get_io_ptr(png);
    if (s->failed)
        return;
    if (s->len + len > s->cap) {
        size_t cap = s->cap ? s->cap : 65536;
        while (cap < s->len + len)
            cap *= 2;
        uint8_t *grown = realloc(s->data, cap);
        if (!grown) {
            s->failed = 1;
            return;
        }
        s->data = grown;
        s->cap = cap;
    }
    memcpy(s->data + s->len, bytes, len);
    s->len += len;
}

static void sink_flush(png_structp png)
{
    (void)png;
}

/* What encode writes: RGBA8 sRGB, or RGB16 linear light with its full scale in a tEXt chunk. */
struct png_source {
    const void *pixels;
    uint32_t width, height;
    bool linear16;
    double full_scale_cd_m2;
    enum png_effort effort;
};

/* Encodes through libpng to either a FILE or a memory sink; returns 0 or -1. */
static int encode(const struct png_source *src, FILE *file, struct memory_sink *sink)
{
    png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, NULL, NULL, NULL);
    if (!png)
        return -1;
    png_infop info = png_create_info_struct(png);
    /* volatile: set after setjmp, read after a longjmp (C11 7.13.2.1) */
    png_bytep *volatile rows = NULL;
    if (!info || setjmp(png_jmpbuf(png))) {
        png_destroy_write_struct(&png, info ? &info : NULL);
        free(rows);
        return -1;
    }
    if (file)
        png_init_io(png, file);
    else
        png_set_write_fn(png, sink, sink_write, sink_flush);
    /* Frames are mostly smooth gradients. A stream takes zlib's fastest level and one filter
     * (Sub: each byte less its left neighbour's) instead of libpng's per-row trial of all five:
     * about 3x faster for a few percent more bytes (docs/PERFORMANCE.md, "PNG for streams"). */
    if (src->effort == PNG_EFFORT_STREAM) {
        png_set_compression_level(png, 1);
        png_set_filter(png, PNG_FILTER_TYPE_BASE, PNG_FILTER_SUB);
    } else {
        png_set_compression_level(png, 3);
    }
    png_set_IHDR(png, info, src->width, src->height, src->linear16 ? 16 : 8,
                 src->linear16 ? PNG_COLOR_TYPE_RGB : PNG_COLOR_TYPE_RGBA, PNG_INTERLACE_NONE,
                 PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
    char full_scale[64];
    png_text text = { .compression = PNG_TEXT_COMPRESSION_NONE,
                      .key = (png_charp)PNG_LINEAR16_FULL_SCALE_KEY,
                      .text = full_scale };
    if (src->linear16) {
        png_set_gAMA_fixed(png, info, PNG_GAMMA_LINEAR);
        /* sRGB (Rec. 709) primaries and D65 white, as the renderer's channels */
        png_set_cHRM(png, info, 0.3127, 0.3290, 0.64, 0.33, 0.30, 0.60, 0.15, 0.06);
        snprintf(full_scale, sizeof full_scale, "%.9g", src->full_scale_cd_m2);
        text.text_length = strlen(full_scale);
        png_set_text(png, info, &text, 1);
    } else {
        png_set_sRGB_gAMA_and_cHRM(png, info, PNG_sRGB_INTENT_PERCEPTUAL);
    }
    rows = malloc(sizeof *rows * src->height);
    if (!rows)
        png_error(png, "out of memory");
    size_t stride = (size_t)src->width * (src->linear16 ? 6 : 4);
    for (uint32_t y = 0; y < src->height; y++)
        rows[y] = (png_bytep)src->pixels + (size_t)y * stride;
    png_write_info(png, info);
    if (src->linear16)
        png_set_swap(png); /* samples are in host order; PNG's are big-endian */
    png_write_image(png, rows);
    png_write_end(png, NULL);
    png_destroy_write_struct(&png, &info);
    free(rows);
    return sink && sink->failed ? -1 : 0;
}

static int encode_to_memory(const struct png_source *src, uint8_t **out, size_t *out_len)
{
    struct memory_sink sink = { 0 };
    if (encode(src, NULL, &sink) != 0) {
        free(sink.data);
        return -1;
    }
    *out = sink.data;
    *out_len = sink.len;
    return 0;
}

int png_encode_rgba8(const uint8_t *rgba, uint32_t width, uint32_t height, enum png_effort effort,
                     uint8_t **out, size_t *out_len)
{
    struct png_source src = { .pixels = rgba, .width = width, .height = height, .effort = effort };
    return encode_to_memory(&src, out, out_len);
}

int png_encode_linear16(const uint16_t *rgb, uint32_t width, uint32_t height,
                        double full_scale_cd_m2, enum png_effort effort, uint8_t **out,
                        size_t *out_len)
{
    struct png_source src = { .pixels = rgb,
                              .width = width,
                              .height = height,
                              .linear16 = true,
                              .full_scale_cd_m2 = full_scale_cd_m2,
                              .effort = effort };
    return encode_to_memory(&src, out, out_len);
}

void png_linear16_quantize(const float *rgba_cd_m2, size_t texels, double full_scale_cd_m2,
                           uint16_t *rgb)
{
    double scale = full_scale_cd_m2 > 0.0 ? 65535.0 / full_scale_cd_m2 : 0.0;
    for (size_t i = 0; i < texels; i++)
        for (int c = 0; c < 3; c++) {
            double v = rgba_cd_m2[i * 4 + (size_t)c] * scale;
            /* NaN and negatives to 0, above full scale clipped */
            rgb[i * 3 + (size_t)c] = (uint16_t)(v > 0.0 ? (v < 65535.0 ? v + 0.5 : 65535.0) : 0.0);
        }
}

double png_linear16_full_scale(double exposure)
{
    return exposure > 0.0 && isfinite(exposure) ? PNG_LINEAR16_HEADROOM / exposure : 0.0;
}

/* Writes atomically: to a temporary file beside `path`, then renamed. */
static int write_file(const char *path, const struct png_source *src, char *err, size_t errlen)
{
    size_t n = strlen(path) + 16;
    char *tmp = malloc(n);
    if (!tmp) {
        snprintf(err, errlen, "out of memory");
        return -1;
    }
    snprintf(tmp, n, "%s.tmp%ld", path, (long)getpid());
    FILE *f = fopen(tmp, "wb");
    if (!f) {
        snprintf(err, errlen, "cannot create %s: %s", tmp, strerror(errno));
        free(tmp);
        return -1;
    }
    int rc = encode(src, f, NULL);
    if (fflush(f) != 0 || ferror(f))
        rc = -1;
    if (fclose(f) != 0)
        rc = -1;
    if (rc == 0 && rename(tmp, path) != 0) {
        snprintf(err, errlen, "cannot rename %s to %s: %s", tmp, path, strerror(errno));
        unlink(tmp);
        free(tmp);
        return -1;
    }
    if (rc != 0) {
        snprintf(err, errlen, "cannot write PNG %s", path);
        unlink(tmp);
    }
    free(tmp);
    return rc;
}

int png_write_rgba8_file(const char *path, const uint8_t *rgba, uint32_t width, uint32_t height,
                         char *err, size_t errlen)
{
    struct png_source src = {
        .pixels = rgba, .width = width, .height = height, .effort = PNG_EFFORT_FILE
    };
    return write_file(path, &src, err, errlen);
}

int png_write_linear16_file(const char *path, const uint16_t *rgb, uint32_t width, uint32_t height,
                            double full_scale_cd_m2, char *err, size_t errlen)
{
    struct png_source src = { .pixels = rgb,
                              .width = width,
                              .height = height,
                              .linear16 = true,
                              .full_scale_cd_m2 = full_scale_cd_m2,
                              .effort = PNG_EFFORT_FILE };
    return write_file(path, &src, err, errlen);
}
