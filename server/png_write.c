#include "png_write.h"

#include <errno.h>
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

/* Encodes through libpng to either a FILE or a memory sink; returns 0 or -1. */
static int encode(const uint8_t *rgba, uint32_t width, uint32_t height, FILE *file,
                  struct memory_sink *sink)
{
    png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, NULL, NULL, NULL);
    if (!png)
        return -1;
    png_infop info = png_create_info_struct(png);
    png_bytep *rows = NULL;
    if (!info || setjmp(png_jmpbuf(png))) {
        png_destroy_write_struct(&png, info ? &info : NULL);
        free(rows);
        return -1;
    }
    if (file)
        png_init_io(png, file);
    else
        png_set_write_fn(png, sink, sink_write, sink_flush);
    /* Frames are mostly smooth gradients: a fast level compresses them well enough. */
    png_set_compression_level(png, 3);
    png_set_IHDR(png, info, width, height, 8, PNG_COLOR_TYPE_RGBA, PNG_INTERLACE_NONE,
                 PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
    png_set_sRGB_gAMA_and_cHRM(png, info, PNG_sRGB_INTENT_PERCEPTUAL);
    rows = malloc(sizeof *rows * height);
    if (!rows)
        png_error(png, "out of memory");
    for (uint32_t y = 0; y < height; y++)
        rows[y] = (png_bytep)(rgba + (size_t)y * width * 4);
    png_write_info(png, info);
    png_write_image(png, rows);
    png_write_end(png, NULL);
    png_destroy_write_struct(&png, &info);
    free(rows);
    return sink && sink->failed ? -1 : 0;
}

int png_encode_rgba8(const uint8_t *rgba, uint32_t width, uint32_t height, uint8_t **out,
                     size_t *out_len)
{
    struct memory_sink sink = { 0 };
    if (encode(rgba, width, height, NULL, &sink) != 0) {
        free(sink.data);
        return -1;
    }
    *out = sink.data;
    *out_len = sink.len;
    return 0;
}

int png_write_rgba8_file(const char *path, const uint8_t *rgba, uint32_t width, uint32_t height,
                         char *err, size_t errlen)
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
    int rc = encode(rgba, width, height, f, NULL);
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
