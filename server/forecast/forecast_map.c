/* A forecast sample's coverage grid as a weather map (forecast.h, sky_forecast_weather_map). */
#include "forecast.h"
#include "weather_map.h"
#include "weather_observation.h"

#include <math.h>
#include <stdint.h>
#include <stdlib.h>

/* The low layer's base, as the patch puts it (forecast_patch.c). */
#define LOW_BASE_M 1000.0

static uint8_t texel(double value)
{
    return (uint8_t)lround(fmin(fmax(value, 0.0), 1.0) * 255.0);
}

bool sky_forecast_weather_map(const struct sky_forecast_sample *s, struct sky_weather_map *map)
{
    int n = s->grid_size;
    map->width = map->height = 0;
    map->rgba = NULL;
    if (n < 1 || n > SKY_FORECAST_MAX_GRID)
        return false;
    uint8_t *rgba = malloc((size_t)n * (size_t)n * 4);
    if (!rgba)
        return false;
    for (int i = 0; i < n * n; i++) {
        double low = fmin(fmax(s->low_grid[i], 0.0), 1.0);
        rgba[4 * i + 0] = texel(low);
        rgba[4 * i + 1] = texel(s->high_grid[i]);
        rgba[4 * i + 2] = texel(sky_obs_low_type(low, LOW_BASE_M));
        rgba[4 * i + 3] = texel(sky_forecast_precipitation_level(s->precipitation_grid[i]));
    }
    map->width = map->height = (uint32_t)n;
    map->rgba = rgba;
    return true;
}
