/* Maps the world state (protocol/) onto the renderer's inputs (render/). */
#ifndef SKYD_WORLD_RENDER_H
#define SKYD_WORLD_RENDER_H

#include <stdint.h>

#include "sky_renderer.h"
#include "world_state.h"

void world_to_render_atmosphere(const struct sky_world_state *state,
                                struct sky_render_atmosphere *out);
/* The state's camera, sun and exposure as a view of width x height. */
void world_to_render_view(const struct sky_world_state *state, uint32_t width, uint32_t height,
                          enum sky_render_output_kind output, struct sky_render_view *out);
/* The state's clouds.* and weather.* as the renderer's clouds (sky_renderer_set_clouds). */
void world_to_render_clouds(const struct sky_world_state *state, struct sky_render_clouds *out);
void world_to_lut_sizes(const struct sky_world_state *state, struct sky_render_lut_sizes *out);

#endif
