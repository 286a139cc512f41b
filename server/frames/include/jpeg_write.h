/* JPEG encoding with libjpeg-turbo's TurboJPEG API, to a file or to memory: 8-bit sRGB RGBA
 * frames (alpha dropped), 4:2:0 chroma subsampling. */
#ifndef SKYD_JPEG_WRITE_H
#define SKYD_JPEG_WRITE_H

#include <stddef.h>
#include <stdint.h>

#define JPEG_QUALITY_MIN 1
#define JPEG_QUALITY_MAX 100
#define JPEG_QUALITY_DEFAULT 85

/* Encodes width x height RGBA8 pixels (row-major, top row first) at quality 1..100 to a
 * malloc'd buffer (*out, *out_len). Returns 0, or -1. */
int jpeg_encode_rgba8(const uint8_t *rgba, uint32_t width, uint32_t height, int quality,
                      uint8_t **out, size_t *out_len);

/* The same, written atomically to `path` (a temporary file beside it, then renamed). Returns 0,
 * or -1 with a message in err. */
int jpeg_write_rgba8_file(const char *path, const uint8_t *rgba, uint32_t width, uint32_t height,
                          int quality, char *err, size_t errlen);

#endif
