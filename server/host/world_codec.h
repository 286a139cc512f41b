/* The world as a shared world's entries carry it (server/cluster/): the state as the JSON text
 * the state file holds, the client weather map as bytes (width and height, little-endian
 * 32-bit, then the RGBA texels). */
#ifndef SKYD_WORLD_CODEC_H
#define SKYD_WORLD_CODEC_H

#include <stdbool.h>
#include <stddef.h>

#include "weather_map.h"
#include "world_state.h"

/* malloc'd JSON text with "revision"; NULL when memory is out. */
char *world_codec_state_text(const struct proto_world_state *state);
/* false with `why`; *state untouched. */
bool world_codec_parse_state(const char *text, struct proto_world_state *state, char *why,
                             size_t whylen);

/* malloc'd bytes of a map with texels; NULL when memory is out. */
unsigned char *world_codec_map_bytes(const struct proto_weather_map *map, size_t *length);
/* false when the bytes are not a map; *map then empty. */
bool world_codec_parse_map(const unsigned char *bytes, size_t length,
                           struct proto_weather_map *map);

#endif
