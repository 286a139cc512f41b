/* skyd_encode_bench: bytes per frame and encode time of PNG (a stream's effort and a file's)
 * and JPEG for rendered frames. Each argument is an 8-bit PNG (e.g. from `skyd render`); it is
 * decoded once, then encoded N times each way on one thread, as an encoder worker does, and
 * the median time printed with the frames per second one core sustains. Not a test: it
 * asserts nothing. */
#include <png.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "jpeg_write.h"
#include "png_write.h"

#define RUNS 15

static double now_ms(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return t.tv_sec * 1e3 + t.tv_nsec / 1e6;
}

static int compare_doubles(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

static uint8_t *read_rgba(const char *path, uint32_t *width, uint32_t *height)
{
    png_image image;
    memset(&image, 0, sizeof image);
    image.version = PNG_IMAGE_VERSION;
    if (!png_image_begin_read_from_file(&image, path))
        return NULL;
    image.format = PNG_FORMAT_RGBA;
    uint8_t *rgba = malloc(PNG_IMAGE_SIZE(image));
    if (!rgba || !png_image_finish_read(&image, NULL, rgba, 0, NULL)) {
        png_image_free(&image);
        free(rgba);
        return NULL;
    }
    *width = image.width;
    *height = image.height;
    return rgba;
}

/* Median milliseconds of RUNS encodes; *bytes the encoded size. quality 0: PNG at `effort`. */
static double time_encode(const uint8_t *rgba, uint32_t w, uint32_t h, int quality,
                          enum png_effort effort, size_t *bytes)
{
    double ms[RUNS];
    for (int i = 0; i < RUNS; i++) {
        uint8_t *out = NULL;
        double t0 = now_ms();
        int rc = quality ? jpeg_encode_rgba8(rgba, w, h, quality, &out, bytes)
                         : png_encode_rgba8(rgba, w, h, effort, &out, bytes);
        ms[i] = now_ms() - t0;
        free(out);
        if (rc != 0)
            return -1;
    }
    qsort(ms, RUNS, sizeof ms[0], compare_doubles);
    return ms[RUNS / 2];
}

int main(int argc, char **argv)
{
    if (argc < 2) {
        fprintf(stderr, "usage: skyd_encode_bench [--quality Q] FRAME.png...\n");
        return 2;
    }
    int quality = JPEG_QUALITY_DEFAULT, first = 1;
    if (strcmp(argv[1], "--quality") == 0 && argc > 3) {
        quality = atoi(argv[2]);
        first = 3;
    }
    printf("| frame | size | PNG stream bytes | ms | fps per core | PNG file bytes | ms | "
           "JPEG q%d bytes | ms | fps per core |\n"
           "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |\n",
           quality);
    for (int i = first; i < argc; i++) {
        uint32_t w, h;
        uint8_t *rgba = read_rgba(argv[i], &w, &h);
        if (!rgba) {
            fprintf(stderr, "skyd_encode_bench: cannot read %s\n", argv[i]);
            return 1;
        }
        size_t stream_bytes = 0, file_bytes = 0, jpeg_bytes = 0;
        double stream_ms = time_encode(rgba, w, h, 0, PNG_EFFORT_STREAM, &stream_bytes);
        double file_ms = time_encode(rgba, w, h, 0, PNG_EFFORT_FILE, &file_bytes);
        double jpeg_ms = time_encode(rgba, w, h, quality, PNG_EFFORT_STREAM, &jpeg_bytes);
        const char *name = strrchr(argv[i], '/') ? strrchr(argv[i], '/') + 1 : argv[i];
        printf("| %s | %ux%u | %zu | %.2f | %.1f | %zu | %.2f | %zu | %.2f | %.1f |\n", name, w, h,
               stream_bytes, stream_ms, 1e3 / stream_ms, file_bytes, file_ms, jpeg_bytes, jpeg_ms,
               1e3 / jpeg_ms);
        free(rgba);
    }
    return 0;
}
