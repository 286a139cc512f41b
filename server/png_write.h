/* PNG encoding with libpng: 8-bit sRGB RGBA frames to a file or to memory. */
#ifndef SKYD_PNG_WRITE_H
#define SKYD_PNG_WRITE_H

#include <stddef.h>
#include <stdint.h>

/* Writes width x height RGBA8 pixels (row-major, top row first) atomically: to a temporary
 * file beside `path`, then renamed. Returns 0, or -1 with a message in err. */
int png_write_rgba8_file(const char *path, const uint8_t *rgba, uint32_t width, uint32_t height,
                         char *err, size_t errlen);

/* Encodes to a malloc'd buffer (*out, *out_len); returns 0 or -1. */
int png_encode_rgba8(const uint8_t *rgba, uint32_t width, uint32_t height, uint8_t **out,
                     size_t *out_len);

#endif
