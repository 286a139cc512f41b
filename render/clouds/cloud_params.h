/* The cloud uniform block from the renderer's cloud description: layer radii, extinction,
 * phase and octave parameters, weather pattern and noise tiling, and the cloud-type height
 * profiles (as data, below in cloud_params.c). */
#ifndef SKYD_CLOUD_PARAMS_H
#define SKYD_CLOUD_PARAMS_H

#include <stdbool.h>

#include "cloud_shared.h"
#include "sky_renderer.h"

/* True when a layer can show a cloud (coverage above zero, or a client map in use). */
bool cloud_params_any_layer(const struct sky_render_clouds *c);

/* Fills everything but shadow_sun and march.w. */
void cloud_params_fill(const struct sky_render_clouds *c, double bottom_radius_km,
                       struct sky_cloud_uniforms *u);

/* Cells across the weather map for each cloud type's pattern (cloud_weather.comp): cumulus,
 * cumulonimbus, stratocumulus, stratus; whole numbers so that the map tiles. */
void cloud_params_weather_periods(const struct sky_render_clouds *c, float periods[4]);

/* Trace block size of a resolution: 1, 2 or 4 pixels of the cloud image per side. */
int cloud_params_block(enum sky_render_cloud_resolution resolution);

/* How much smaller than the output the cloud image is per side: 1 or 2. */
int cloud_params_downscale(enum sky_render_cloud_resolution resolution);

#endif
