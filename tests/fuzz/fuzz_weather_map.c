/* libFuzzer target: a client weather map's bytes as base64 text and as a PNG or raw texels
 * (protocol/weather_map.c): the first byte picks the format and, for raw texels, the next two
 * the size. */
#include "weather_map.h"

#include <stdint.h>
#include <stdlib.h>
#include <string.h>

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (size < 3)
        return 0;
    char reason[256];
    uint8_t *decoded = NULL;
    size_t decoded_length = 0;
    if (proto_base64_decode((const char *)data + 3, size - 3, &decoded, &decoded_length, reason,
                            sizeof reason)) {
        char *again = proto_base64_encode(decoded, decoded_length);
        if (!again || strlen(again) != size - 3) /* padded base64 round-trips in length */
            abort();
        free(again);
    }
    free(decoded);
    struct proto_weather_map map;
    enum proto_weather_map_format format = data[0] & 1 ? PROTO_WEATHER_MAP_PNG
                                                       : PROTO_WEATHER_MAP_RGBA8;
    uint32_t width = format == PROTO_WEATHER_MAP_PNG ? 0 : data[1] + 1u;
    uint32_t height = format == PROTO_WEATHER_MAP_PNG ? 0 : data[2] + 1u;
    if (proto_weather_map_decode(format, data + 3, size - 3, width, height, &map, reason,
                                 sizeof reason)) {
        if (!map.rgba || map.width < 1 || map.width > PROTO_WEATHER_MAP_MAX_SIDE ||
            map.height < 1 || map.height > PROTO_WEATHER_MAP_MAX_SIDE)
            abort();
        volatile uint8_t last = map.rgba[(size_t)map.width * map.height * 4 - 1];
        (void)last;
    }
    proto_weather_map_free(&map);
    return 0;
}
