/* The render input: everything the renderer needs from one state of the world, translated
 * once (world_render_input, world_render.c) and read-only afterwards. The world host makes a
 * new one whenever its state changes (a commit, an entry of a shared world, the simulation's
 * advance); the renderer host takes it (renderer_host_take, renderer_host_render). It flows
 * one way: nothing the renderer does writes to it. */
#ifndef SKYD_RENDER_INPUT_H
#define SKYD_RENDER_INPUT_H

#include <stdbool.h>
#include <stdint.h>

#include "sky_renderer.h"
#include "weather_map.h"
#include "world_state.h"

struct render_input {
    /* The state it was made from: views (world_render_view) and probes resolve against it,
     * and frames carry its simulation time. */
    struct proto_world_state state;
    /* The state's own atmosphere (probes), and the one frames are asked to show: the same,
     * except while the simulation's haze waits for the previous change to settle. */
    struct sky_render_atmosphere atmosphere;
    struct sky_render_atmosphere frame_atmosphere;
    /* Nobody watches: frame_atmosphere's LUTs are built at once, not amortized, so that a
     * snapshot or a new subscription's first frames show it. */
    bool atmosphere_at_once;
    /* frame_atmosphere differs from the last one frames fully showed; until a frame shows it,
     * frames carry settled_revision instead of state.revision. */
    bool atmosphere_pending;
    uint64_t settled_revision;
    struct sky_render_clouds clouds;
    struct sky_render_night night;
    struct sky_render_lut_sizes lut_sizes;
    /* The client weather map (NULL or no texels: none), and a number that changes whenever it
     * does. The map is the world host's: valid as long as this input is. */
    const struct proto_weather_map *client_map;
    uint64_t map_generation;
};

#endif
