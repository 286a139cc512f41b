#include "weather_map.h"

#include <png.h>

#include <setjmp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* ---- base64 (RFC 4648 section 4) ---------------------------------------------------------- */

static const char alphabet[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";

static int sextet(unsigned char c)
{
    if (c >= 'A' && c <= 'Z')
        return c - 'A';
    if (c >= 'a' && c <= 'z')
        return c - 'a' + 26;
    if (c >= '0' && c <= '9')
        return c - '0' + 52;
    if (c == '+')
        return 62;
    if (c == '/')
        return 63;
    return -1;
}

bool proto_base64_decode(const char *text, size_t length, uint8_t **out, size_t *out_length,
                         char *reason, size_t reason_size)
{
    *out = NULL;
    *out_length = 0;
    if (length % 4 != 0) {
        snprintf(reason, reason_size, "base64 length %zu is not a multiple of 4", length);
        return false;
    }
    size_t padding = 0;
    if (length >= 4 && text[length - 1] == '=')
        padding = text[length - 2] == '=' ? 2 : 1;
    size_t decoded = length / 4 * 3 - padding;
    uint8_t *bytes = malloc(decoded ? decoded : 1);
    if (!bytes) {
        snprintf(reason, reason_size, "out of memory for %zu bytes", decoded);
        return false;
    }
    size_t written = 0;
    for (size_t i = 0; i < length; i += 4) {
        uint32_t group = 0;
        for (size_t k = 0; k < 4; k++) {
            size_t at = i + k;
            int value = sextet((unsigned char)text[at]);
            /* '=' only as the last one or two characters of the text. */
            if (value < 0 && !(text[at] == '=' && at >= length - padding)) {
                snprintf(reason, reason_size, "invalid base64 character at offset %zu", at);
                free(bytes);
                return false;
            }
            group = group << 6 | (uint32_t)(value < 0 ? 0 : value);
        }
        uint8_t three[3] = { (uint8_t)(group >> 16), (uint8_t)(group >> 8), (uint8_t)group };
        size_t take = decoded - written < 3 ? decoded - written : 3;
        memcpy(bytes + written, three, take);
        written += take;
    }
    *out = bytes;
    *out_length = decoded;
    return true;
}

char *proto_base64_encode(const uint8_t *bytes, size_t length)
{
    size_t size = (length + 2) / 3 * 4;
    char *text = malloc(size + 1);
    if (!text)
        return NULL;
    char *w = text;
    for (size_t i = 0; i < length; i += 3) {
        size_t left = length - i;
        uint32_t group = (uint32_t)bytes[i] << 16 | (left > 1 ? (uint32_t)bytes[i + 1] << 8 : 0) |
                         (left > 2 ? bytes[i + 2] : 0);
        *w++ = alphabet[group >> 18 & 63];
        *w++ = alphabet[group >> 12 & 63];
        *w++ = left > 1 ? alphabet[group >> 6 & 63] : '=';
        *w++ = left > 2 ? alphabet[group & 63] : '=';
    }
    *w = '\0';
    return text;
}

/* ---- PNG in memory ----------------------------------------------------------------------- */

struct png_source {
    const uint8_t *bytes;
    size_t length, offset;
};

static void read_from_memory(png_structp png, png_bytep data, size_t length)
{
    struct png_source *src = png_get_io_ptr(png);
    if (length > src->length - src->offset)
        png_error(png, "the PNG ends early");
    memcpy(data, src->bytes + src->offset, length);
    src->offset += length;
}

struct png_failure {
    char *reason;
    size_t reason_size;
};

static void on_png_error(png_structp png, png_const_charp message)
{
    struct png_failure *failure = png_get_error_ptr(png);
    snprintf(failure->reason, failure->reason_size, "PNG: %s", message);
    png_longjmp(png, 1);
}

static void on_png_warning(png_structp png, png_const_charp message)
{
    (void)png;
    (void)message;
}

static bool side_is_valid(uint32_t side)
{
    return side >= 1 && side <= PROTO_WEATHER_MAP_MAX_SIDE;
}

/* The texels as stored: the map is data, not colour, so no gamma or colour-space conversion
 * (libpng's simplified reader would convert 16-bit files as linear light). Any bit depth and
 * colour type become RGBA8; without an alpha channel (or tRNS) alpha is 0: no precipitation. */
static bool decode_png(const uint8_t *bytes, size_t length, uint32_t want_width,
                       uint32_t want_height, struct proto_weather_map *map, char *reason,
                       size_t reason_size)
{
    if (length < 8 || png_sig_cmp(bytes, 0, 8) != 0) {
        snprintf(reason, reason_size, "not a PNG file (bad signature)");
        return false;
    }
    /* The size from the IHDR chunk that must come first, for a clear refusal; libpng's own
     * user limits below then stop anything that slips past. */
    if (length >= 24 && memcmp(bytes + 12, "IHDR", 4) == 0) {
        uint32_t w = (uint32_t)bytes[16] << 24 | (uint32_t)bytes[17] << 16 |
                     (uint32_t)bytes[18] << 8 | bytes[19];
        uint32_t h = (uint32_t)bytes[20] << 24 | (uint32_t)bytes[21] << 16 |
                     (uint32_t)bytes[22] << 8 | bytes[23];
        if (!side_is_valid(w) || !side_is_valid(h)) {
            snprintf(reason, reason_size, "PNG is %ux%u; each side must be 1..%d", w, h,
                     PROTO_WEATHER_MAP_MAX_SIDE);
            return false;
        }
    }
    struct png_failure failure = { reason, reason_size };
    struct png_source source = { bytes, length, 0 };
    png_structp png = png_create_read_struct(PNG_LIBPNG_VER_STRING, &failure, on_png_error,
                                             on_png_warning);
    png_infop info = png ? png_create_info_struct(png) : NULL;
    if (!info) {
        png_destroy_read_struct(&png, NULL, NULL);
        snprintf(reason, reason_size, "out of memory for the PNG reader");
        return false;
    }
    uint8_t *volatile pixels = NULL;
    png_bytep *volatile rows = NULL;
    if (setjmp(png_jmpbuf(png))) {
        free(pixels);
        free(rows);
        png_destroy_read_struct(&png, &info, NULL);
        return false;
    }
    png_set_read_fn(png, &source, read_from_memory);
    /* Bounds before any texel is inflated: a small file may declare a huge image. */
    png_set_user_limits(png, PROTO_WEATHER_MAP_MAX_SIDE, PROTO_WEATHER_MAP_MAX_SIDE);
    png_read_info(png, info);
    uint32_t width = png_get_image_width(png, info), height = png_get_image_height(png, info);
    if ((want_width && want_width != width) || (want_height && want_height != height)) {
        snprintf(reason, reason_size, "PNG is %ux%u, the message says %ux%u", width, height,
                 want_width, want_height);
        png_longjmp(png, 1);
    }
    int color = png_get_color_type(png, info);
    bool has_alpha = (color & PNG_COLOR_MASK_ALPHA) || png_get_valid(png, info, PNG_INFO_tRNS);
    png_set_expand(png); /* palette -> RGB, gray < 8 bits -> 8, tRNS -> alpha */
    png_set_strip_16(png);
    png_set_gray_to_rgb(png);
    if (!has_alpha)
        png_set_add_alpha(png, 0, PNG_FILLER_AFTER);
    png_set_interlace_handling(png);
    png_read_update_info(png, info);
    if (png_get_rowbytes(png, info) != (size_t)width * 4) {
        snprintf(reason, reason_size, "PNG rows did not convert to RGBA8");
        png_longjmp(png, 1);
    }
    pixels = malloc((size_t)width * height * 4);
    rows = malloc(sizeof(png_bytep) * height);
    if (!pixels || !rows) {
        snprintf(reason, reason_size, "out of memory for a %ux%u map", width, height);
        png_longjmp(png, 1);
    }
    for (uint32_t y = 0; y < height; y++)
        rows[y] = pixels + (size_t)y * width * 4;
    png_read_image(png, rows);
    png_read_end(png, NULL);
    free(rows);
    png_destroy_read_struct(&png, &info, NULL);
    map->width = width;
    map->height = height;
    map->rgba = pixels;
    return true;
}

bool proto_weather_map_decode(enum proto_weather_map_format format, const uint8_t *bytes,
                              size_t length, uint32_t width, uint32_t height,
                              struct proto_weather_map *map, char *reason, size_t reason_size)
{
    memset(map, 0, sizeof *map);
    if (format == PROTO_WEATHER_MAP_PNG)
        return decode_png(bytes, length, width, height, map, reason, reason_size);
    if (format != PROTO_WEATHER_MAP_RGBA8) {
        snprintf(reason, reason_size, "unknown map format %d", (int)format);
        return false;
    }
    if (!side_is_valid(width) || !side_is_valid(height)) {
        snprintf(reason, reason_size, "map is %ux%u; each side must be 1..%d", width, height,
                 PROTO_WEATHER_MAP_MAX_SIDE);
        return false;
    }
    size_t expected = (size_t)width * height * 4;
    if (length != expected) {
        snprintf(reason, reason_size, "%ux%u RGBA8 texels are %zu bytes, got %zu", width, height,
                 expected, length);
        return false;
    }
    if (!(map->rgba = malloc(expected))) {
        snprintf(reason, reason_size, "out of memory for a %ux%u map", width, height);
        return false;
    }
    memcpy(map->rgba, bytes, expected);
    map->width = width;
    map->height = height;
    return true;
}

bool proto_weather_map_copy(const struct proto_weather_map *from, struct proto_weather_map *to)
{
    memset(to, 0, sizeof *to);
    if (!from || !from->rgba)
        return true;
    size_t bytes = (size_t)from->width * from->height * 4;
    if (!(to->rgba = malloc(bytes)))
        return false;
    memcpy(to->rgba, from->rgba, bytes);
    to->width = from->width;
    to->height = from->height;
    return true;
}

void proto_weather_map_free(struct proto_weather_map *map)
{
    if (!map)
        return;
    free(map->rgba);
    memset(map, 0, sizeof *map);
}
