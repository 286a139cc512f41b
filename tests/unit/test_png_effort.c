/* PNG encoding efforts (server/frames/png_write.c): a live stream's fast encode and a file's
 * smaller one both decode to the very pixels encoded, 8-bit and 16-bit, and the stream's costs
 * few bytes more on a sky-like frame (a smooth gradient with a little grain). */
#include "png_write.h"

#include <png.h>

#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"

#define WIDTH 320
#define HEIGHT 180

/* A zenith-to-horizon gradient with the renderer's dither-sized grain (deterministic). */
static void sky_frame(uint8_t *rgba)
{
    uint32_t seed = 12345;
    for (int y = 0; y < HEIGHT; y++)
        for (int x = 0; x < WIDTH; x++) {
            seed = seed * 1664525u + 1013904223u;
            int grain = (int)(seed >> 30) - 1; /* -1, 0, 1, 2 */
            double t = (double)y / (HEIGHT - 1);
            uint8_t *p = rgba + ((size_t)y * WIDTH + (size_t)x) * 4;
            p[0] = (uint8_t)(60 + 120 * t + grain);
            p[1] = (uint8_t)(110 + 90 * t + grain);
            p[2] = (uint8_t)(200 + 40 * t + grain);
            p[3] = 255;
        }
}

/* Decodes to RGBA8 (format 8) or 16-bit linear RGB; NULL when it does not decode. */
static void *decode(const uint8_t *png, size_t length, bool linear16)
{
    png_image image;
    memset(&image, 0, sizeof image);
    image.version = PNG_IMAGE_VERSION;
    if (!png_image_begin_read_from_memory(&image, png, length))
        return NULL;
    image.format = linear16 ? PNG_FORMAT_LINEAR_RGB : PNG_FORMAT_RGBA;
    void *pixels = malloc(PNG_IMAGE_SIZE(image));
    bool ok = pixels && image.width == WIDTH && image.height == HEIGHT &&
              png_image_finish_read(&image, NULL, pixels, 0, NULL);
    if (!ok) {
        png_image_free(&image);
        free(pixels);
        return NULL;
    }
    return pixels;
}

static void test_rgba8(void)
{
    uint8_t *rgba = malloc((size_t)WIDTH * HEIGHT * 4);
    sky_frame(rgba);
    uint8_t *stream = NULL, *file = NULL;
    size_t stream_bytes = 0, file_bytes = 0;
    CHECK(png_encode_rgba8(rgba, WIDTH, HEIGHT, PNG_EFFORT_STREAM, &stream, &stream_bytes) == 0);
    CHECK(png_encode_rgba8(rgba, WIDTH, HEIGHT, PNG_EFFORT_FILE, &file, &file_bytes) == 0);
    uint8_t *a = stream ? decode(stream, stream_bytes, false) : NULL;
    uint8_t *b = file ? decode(file, file_bytes, false) : NULL;
    CHECK(a && memcmp(a, rgba, (size_t)WIDTH * HEIGHT * 4) == 0);
    CHECK(b && memcmp(b, rgba, (size_t)WIDTH * HEIGHT * 4) == 0);
    printf("info: 8-bit sky frame %dx%d: stream %zu bytes, file %zu bytes (%.2fx)\n", WIDTH, HEIGHT,
           stream_bytes, file_bytes, (double)stream_bytes / (double)file_bytes);
    CHECK_LE((double)stream_bytes, 1.25 * (double)file_bytes);
    free(a);
    free(b);
    free(stream);
    free(file);
    free(rgba);
}

static void test_linear16(void)
{
    uint16_t *rgb = malloc((size_t)WIDTH * HEIGHT * 3 * sizeof *rgb);
    uint8_t *rgba = malloc((size_t)WIDTH * HEIGHT * 4);
    sky_frame(rgba);
    for (size_t i = 0; i < (size_t)WIDTH * HEIGHT; i++)
        for (int c = 0; c < 3; c++)
            rgb[i * 3 + (size_t)c] = (uint16_t)(rgba[i * 4 + (size_t)c] * 97u + (i & 15u));
    uint8_t *stream = NULL, *file = NULL;
    size_t stream_bytes = 0, file_bytes = 0;
    CHECK(png_encode_linear16(rgb, WIDTH, HEIGHT, 1000.0, PNG_EFFORT_STREAM, &stream,
                              &stream_bytes) == 0);
    CHECK(png_encode_linear16(rgb, WIDTH, HEIGHT, 1000.0, PNG_EFFORT_FILE, &file, &file_bytes) ==
          0);
    uint16_t *a = stream ? decode(stream, stream_bytes, true) : NULL;
    uint16_t *b = file ? decode(file, file_bytes, true) : NULL;
    /* gAMA 1.0: the simplified reader hands the samples back as they are */
    CHECK(a && memcmp(a, rgb, (size_t)WIDTH * HEIGHT * 3 * sizeof *rgb) == 0);
    CHECK(b && memcmp(b, rgb, (size_t)WIDTH * HEIGHT * 3 * sizeof *rgb) == 0);
    printf("info: 16-bit frame: stream %zu bytes, file %zu bytes (%.2fx)\n", stream_bytes,
           file_bytes, (double)stream_bytes / (double)file_bytes);
    free(a);
    free(b);
    free(stream);
    free(file);
    free(rgba);
    free(rgb);
}

int main(void)
{
    test_rgba8();
    test_linear16();
    return check_summary();
}
