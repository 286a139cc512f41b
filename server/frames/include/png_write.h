/* PNG encoding with libpng, to a file or to memory: 8-bit sRGB RGBA frames, or 16-bit
 * linear-light RGB ones for lighting other tools. */
#ifndef SKYD_PNG_WRITE_H
#define SKYD_PNG_WRITE_H

#include <stddef.h>
#include <stdint.h>

/* Writes width x height RGBA8 pixels (row-major, top row first) atomically: to a temporary
 * file beside `path`, then renamed. Returns 0, or -1 with a message in err. */
int png_write_rgba8_file(const char *path, const uint8_t *rgba, uint32_t width, uint32_t height,
                         char *err, size_t errlen);

/* How hard zlib works: a live stream's frames are encoded fast (level 1, one filter), files
 * and stored state smaller (level 3, libpng's filter choice per row). Both decode alike. */
enum png_effort {
    PNG_EFFORT_STREAM,
    PNG_EFFORT_FILE,
};

/* Encodes to a malloc'd buffer (*out, *out_len); returns 0 or -1. */
int png_encode_rgba8(const uint8_t *rgba, uint32_t width, uint32_t height, enum png_effort effort,
                     uint8_t **out, size_t *out_len);

/* 16-bit linear PNGs: sample = min(1, L / full_scale) x 65535 per channel, L the luminance
 * (cd/m2) before exposure; gAMA 1.0, sRGB primaries, and full_scale in cd/m2 as the tEXt
 * chunk PNG_LINEAR16_FULL_SCALE_KEY, so L = sample / 65535 x full_scale. The full scale is
 * PNG_LINEAR16_HEADROOM over the frame's exposure (the 8-bit frame's 1.0 before its tonemap):
 * 4 stops above its white, and mid grey near sample 740. */
#define PNG_LINEAR16_FULL_SCALE_KEY "Luminance full scale cd/m2"
#define PNG_LINEAR16_HEADROOM 16.0

/* PNG_LINEAR16_HEADROOM / exposure; 0 for an exposure that is not a positive number. */
double png_linear16_full_scale(double exposure);

/* RGBA float luminance (the renderer's LINEAR output) to RGB16 samples in host order. */
void png_linear16_quantize(const float *rgba_cd_m2, size_t texels, double full_scale_cd_m2,
                           uint16_t *rgb);

int png_encode_linear16(const uint16_t *rgb, uint32_t width, uint32_t height,
                        double full_scale_cd_m2, enum png_effort effort, uint8_t **out,
                        size_t *out_len);
int png_write_linear16_file(const char *path, const uint16_t *rgb, uint32_t width, uint32_t height,
                            double full_scale_cd_m2, char *err, size_t errlen);

#endif
