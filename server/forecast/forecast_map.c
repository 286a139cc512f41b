/* A forecast sample's coverage grid as a weather map (forecast.h, forecast_weather_map). */
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

/* The cell grid at (x, y) in cells (0 at the first cell's centre), bilinear and wrapped: the
 * renderer tiles the map. */
static double wrapped(const double *cells, int n, double x, double y)
{
    x = fmod(x, n) + (x < 0 ? n : 0);
    y = fmod(y, n) + (y < 0 ? n : 0);
    int x0 = (int)floor(x) % n, y0 = (int)floor(y) % n;
    int x1 = (x0 + 1) % n, y1 = (y0 + 1) % n;
    double fx = x - floor(x), fy = y - floor(y);
    return (cells[y0 * n + x0] * (1 - fx) + cells[y0 * n + x1] * fx) * (1 - fy) +
           (cells[y1 * n + x0] * (1 - fx) + cells[y1 * n + x1] * fx) * fy;
}

bool forecast_weather_map(const struct forecast_sample *s, double extent_km, double offset_east_km,
                          double offset_north_km, struct proto_weather_map *map)
{
    int n = s->grid_size;
    map->width = map->height = 0;
    map->rgba = NULL;
    if (n < 1 || n > FORECAST_MAX_GRID || !(extent_km > 0.0))
        return false;
    uint8_t *rgba = malloc((size_t)n * (size_t)n * 4);
    if (!rgba)
        return false;
    /* Texel (i, j) is drawn offset_* from where cell (i, j) lies: it holds the cell there. */
    double dx = offset_east_km / extent_km * n, dy = -offset_north_km / extent_km * n;
    bool shifted = fmod(fabs(dx), n) > 1e-9 || fmod(fabs(dy), n) > 1e-9;
    for (int j = 0; j < n; j++)
        for (int i = 0; i < n; i++) {
            int k = j * n + i;
            double x = i + dx, y = j + dy;
            double low = shifted ? wrapped(s->low_grid, n, x, y) : s->low_grid[k];
            double high = shifted ? wrapped(s->high_grid, n, x, y) : s->high_grid[k];
            double rate = shifted ? wrapped(s->precipitation_grid, n, x, y)
                                  : s->precipitation_grid[k];
            low = fmin(fmax(low, 0.0), 1.0);
            rgba[4 * k + 0] = texel(low);
            rgba[4 * k + 1] = texel(high);
            rgba[4 * k + 2] = texel(proto_obs_low_type(low, LOW_BASE_M));
            rgba[4 * k + 3] = texel(forecast_precipitation_level(rate));
        }
    map->width = map->height = (uint32_t)n;
    map->rgba = rgba;
    return true;
}
