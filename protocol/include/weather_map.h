/* A client's weather map as the protocol carries it (set_weather_map) and as the daemon keeps
 * it on disk: width x height RGBA8 texels, row-major from the north-west corner (x east,
 * y south), channels as in sky_renderer_set_weather_map:
 *   r low-layer coverage, g high-layer coverage, b low-layer cloud type (0 stratus ..
 *   255 cumulonimbus), a precipitation.
 * Decoding is pure (no I/O): base64 text, then raw texels or a PNG in memory. */
#ifndef SKYD_WEATHER_MAP_H
#define SKYD_WEATHER_MAP_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

/* The renderer resamples any map to its 256 x 256 weather texture; twice that per side keeps
 * every detail it can show and bounds what a client may upload (1 MiB of texels). */
#define PROTO_WEATHER_MAP_MAX_SIDE 512

enum proto_weather_map_format {
    PROTO_WEATHER_MAP_RGBA8 = 0, /* "rgba8": width * height * 4 bytes */
    PROTO_WEATHER_MAP_PNG = 1,   /* "png": any PNG libpng reads; no alpha channel = no rain */
};

struct proto_weather_map {
    uint32_t width, height;
    uint8_t *rgba; /* malloc'd, width * height * 4 bytes */
};

/* Decodes standard base64 (RFC 4648 section 4, padding required, no whitespace) into a
 * malloc'd buffer. Returns false with a reason naming the first bad character's offset. */
bool proto_base64_decode(const char *text, size_t length, uint8_t **out, size_t *out_length,
                         char *reason, size_t reason_size);

/* Encodes into a malloc'd, NUL-terminated string; NULL when memory runs out. */
char *proto_base64_encode(const uint8_t *bytes, size_t length);

/* Turns `bytes` of `format` into a map. width and height are required for RGBA8 (1 ..
 * PROTO_WEATHER_MAP_MAX_SIDE); for PNG they are the file's own, and 0 accepts any size in that
 * range. Returns false with a reason and *map zeroed. */
bool proto_weather_map_decode(enum proto_weather_map_format format, const uint8_t *bytes,
                              size_t length, uint32_t width, uint32_t height,
                              struct proto_weather_map *map, char *reason, size_t reason_size);

void proto_weather_map_free(struct proto_weather_map *map);
/* A deep copy into *to (a map without texels copies as one); false when memory is out. */
bool proto_weather_map_copy(const struct proto_weather_map *from, struct proto_weather_map *to);

#endif
