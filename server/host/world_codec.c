#include "world_codec.h"

#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "json_guard.h"
#include "state_store.h"

char *world_codec_state_text(const struct proto_world_state *state)
{
    return proto_world_state_to_text(state);
}

bool world_codec_parse_state(const char *text, struct proto_world_state *state, char *why,
                             size_t whylen)
{
    json_guard_lock();
    bool ok = state_store_parse(text, strlen(text), state, why, whylen);
    json_guard_unlock();
    return ok;
}

static void put_u32(unsigned char *at, uint32_t v)
{
    for (int i = 0; i < 4; i++)
        at[i] = (unsigned char)(v >> (8 * i));
}

static uint32_t get_u32(const unsigned char *at)
{
    return (uint32_t)at[0] | (uint32_t)at[1] << 8 | (uint32_t)at[2] << 16 | (uint32_t)at[3] << 24;
}

unsigned char *world_codec_map_bytes(const struct proto_weather_map *map, size_t *length)
{
    size_t texels = (size_t)map->width * map->height * 4;
    unsigned char *bytes = map->rgba ? malloc(8 + texels) : NULL;
    if (!bytes)
        return NULL;
    put_u32(bytes, map->width);
    put_u32(bytes + 4, map->height);
    memcpy(bytes + 8, map->rgba, texels);
    *length = 8 + texels;
    return bytes;
}

bool world_codec_parse_map(const unsigned char *bytes, size_t length, struct proto_weather_map *map)
{
    memset(map, 0, sizeof *map);
    if (length < 8)
        return false;
    uint32_t width = get_u32(bytes), height = get_u32(bytes + 4);
    if (width == 0 || height == 0 || width > 16384 || height > 16384 ||
        (size_t)width * height * 4 != length - 8)
        return false;
    struct proto_weather_map view = { .width = width,
                                      .height = height,
                                      .rgba = (uint8_t *)(bytes + 8) };
    return proto_weather_map_copy(&view, map);
}
