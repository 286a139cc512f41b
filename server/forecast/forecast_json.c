/* A forecast at one moment as JSON (protocol/PROTOCOL.md, "GRIB2 forecasts") and as one line
 * for people. */
#include "forecast.h"

#include <cjson/cJSON.h>

#include <stdio.h>

#include "forecast_series.h"
#include "utc_time.h"

static bool add_time(cJSON *object, const char *name, double unix_s)
{
    char iso[40];
    proto_time_format_iso8601(unix_s, iso, sizeof iso);
    return cJSON_AddStringToObject(object, name, iso) != NULL;
}

static bool add_pair(cJSON *object, const char *name, double a, double b)
{
    double pair[2] = { a, b };
    cJSON *array = cJSON_CreateDoubleArray(pair, 2);
    if (!array || !cJSON_AddItemToObject(object, name, array)) {
        cJSON_Delete(array);
        return false;
    }
    return true;
}

static bool add_step(cJSON *steps, const char *name, const struct forecast *forecast, int index,
                     double unix_s)
{
    cJSON *step = cJSON_AddObjectToObject(steps, name);
    return step && cJSON_AddNumberToObject(step, "index", index) &&
           add_time(step, "valid", unix_s) &&
           cJSON_AddNumberToObject(step, "step_h",
                                   (unix_s - forecast->info.reference_unix_s) / 3600.0);
}

/* A size x size grid as an array of rows, north first. */
static bool add_grid(cJSON *object, const char *name, const double *cells, int size)
{
    cJSON *rows = cJSON_AddArrayToObject(object, name);
    if (!rows)
        return false;
    for (int y = 0; y < size; y++) {
        cJSON *row = cJSON_CreateDoubleArray(cells + y * size, size);
        if (!row || !cJSON_AddItemToArray(rows, row)) {
            cJSON_Delete(row);
            return false;
        }
    }
    return true;
}

static bool add_points(cJSON *json, const struct forecast_info *info)
{
    const struct forecast_points *p = &info->points;
    const struct forecast_grid_info *g = &info->grid;
    cJSON *grid = cJSON_AddObjectToObject(json, "grid");
    if (!grid || !cJSON_AddStringToObject(grid, "type", "regular_ll") ||
        !cJSON_AddNumberToObject(grid, "ni", (double)g->ni) ||
        !cJSON_AddNumberToObject(grid, "nj", (double)g->nj) ||
        !add_pair(grid, "first_point_deg", g->lat_first, g->lon_first) ||
        !add_pair(grid, "last_point_deg", g->lat_last, g->lon_last) ||
        !add_pair(grid, "step_deg", g->lat_step, g->lon_step) ||
        !cJSON_AddBoolToObject(grid, "global", g->global))
        return false;
    cJSON *points = cJSON_AddObjectToObject(json, "points");
    return points && cJSON_AddStringToObject(points, "method", p->bilinear ? "bilinear" : "mean") &&
           cJSON_AddNumberToObject(points, "count", p->count) &&
           add_pair(points, "rows", (double)p->first_row, (double)p->last_row) &&
           add_pair(points, "columns", (double)p->first_column, (double)p->last_column) &&
           add_pair(points, "latitudes_deg", p->lat_min, p->lat_max) &&
           add_pair(points, "longitudes_deg", p->lon_west, p->lon_east);
}

static bool add_weather(cJSON *json, const struct forecast_info *info,
                        const struct forecast_sample *s)
{
    cJSON *clouds = cJSON_AddObjectToObject(json, "clouds");
    if (!clouds || !cJSON_AddNumberToObject(clouds, "low", s->low_cover) ||
        !cJSON_AddNumberToObject(clouds, "medium", s->medium_cover) ||
        !cJSON_AddNumberToObject(clouds, "high", s->high_cover) ||
        !(s->total_cover_known ? cJSON_AddNumberToObject(clouds, "total", s->total_cover)
                               : cJSON_AddNullToObject(clouds, "total")) ||
        !cJSON_AddStringToObject(clouds, "units_read", info->cover_in_percent ? "%" : "(0 - 1)"))
        return false;
    if (!cJSON_AddNumberToObject(json, "temperature_c", s->temperature_c) ||
        !cJSON_AddNumberToObject(json, "dew_point_c", s->dew_point_c) ||
        !cJSON_AddNumberToObject(json, "relative_humidity", s->relative_humidity))
        return false;
    cJSON *wind = cJSON_AddObjectToObject(json, "wind");
    if (!wind ||
        !cJSON_AddStringToObject(wind, "level",
                                 info->wind_level == FORECAST_WIND_10M ? "10m" : "850hPa") ||
        !cJSON_AddNumberToObject(wind, "u_m_s", s->wind_u_m_s) ||
        !cJSON_AddNumberToObject(wind, "v_m_s", s->wind_v_m_s) ||
        !cJSON_AddNumberToObject(wind, "speed_m_s", s->wind_speed_m_s) ||
        !cJSON_AddNumberToObject(wind, "direction_deg", s->wind_direction_deg))
        return false;
    cJSON *precipitation = cJSON_AddObjectToObject(json, "precipitation");
    bool rate = info->precipitation_source == FORECAST_PRECIP_RATE;
    return precipitation &&
           cJSON_AddStringToObject(precipitation, "source", rate ? "prate" : "tp") &&
           cJSON_AddNumberToObject(precipitation, "rate_mm_h", s->precipitation_mm_h);
}

cJSON *forecast_to_json(const struct forecast *forecast, const struct forecast_moment *moment)
{
    const struct forecast_info *info = &forecast->info;
    const struct forecast_sample *s = &moment->sample;
    cJSON *json = cJSON_CreateObject();
    cJSON *location = json ? cJSON_AddObjectToObject(json, "location") : NULL;
    cJSON *steps = NULL, *map = NULL;
    bool ok = location && cJSON_AddNumberToObject(location, "lat_deg", info->request.lat_deg) &&
              cJSON_AddNumberToObject(location, "lon_deg", info->request.lon_deg) &&
              cJSON_AddNumberToObject(location, "extent_km", info->request.extent_km) &&
              add_time(json, "time", s->valid_unix_s) &&
              cJSON_AddNumberToObject(json, "time_unix_s", s->valid_unix_s) &&
              add_time(json, "reference_time", info->reference_unix_s) &&
              (steps = cJSON_AddObjectToObject(json, "steps")) != NULL &&
              add_step(steps, "before", forecast, moment->step_before, moment->before_unix_s) &&
              add_step(steps, "after", forecast, moment->step_after, moment->after_unix_s) &&
              cJSON_AddNumberToObject(steps, "weight", moment->weight) &&
              cJSON_AddNumberToObject(steps, "count", info->step_count) &&
              add_time(steps, "first", forecast->steps[0].valid_unix_s) &&
              add_time(steps, "last", forecast->steps[info->step_count - 1].valid_unix_s) &&
              add_weather(json, info, s) && add_points(json, info) &&
              (map = cJSON_AddObjectToObject(json, "coverage_grid")) != NULL &&
              cJSON_AddNumberToObject(map, "size", s->grid_size) &&
              cJSON_AddNumberToObject(map, "cell_km", info->request.extent_km / s->grid_size) &&
              add_grid(map, "low", s->low_grid, s->grid_size) &&
              add_grid(map, "medium", s->medium_grid, s->grid_size) &&
              add_grid(map, "high", s->high_grid, s->grid_size) &&
              add_grid(map, "precipitation_mm_h", s->precipitation_grid, s->grid_size);
    if (!ok) {
        cJSON_Delete(json);
        return NULL;
    }
    return json;
}

void forecast_summary(const struct forecast *forecast, const struct forecast_moment *moment,
                      char *text, size_t capacity)
{
    const struct forecast_info *info = &forecast->info;
    const struct forecast_sample *s = &moment->sample;
    char when[40];
    proto_time_format_iso8601(s->valid_unix_s, when, sizeof when);
    double lat = info->request.lat_deg, lon = info->request.lon_deg;
    snprintf(text, capacity,
             "%s at %.3f %c %.3f %c (%g km, %d grid points, steps %+g h..%+g h): cloud low %.2f "
             "medium %.2f high %.2f, %.1f C dew point %.1f C RH %.0f %%, wind %.0f deg %.1f m/s "
             "(%s), precipitation %.2f mm/h",
             when, lat < 0 ? -lat : lat, lat < 0 ? 'S' : 'N',
             lon > 180 ? 360 - lon
             : lon < 0 ? -lon
                       : lon,
             lon > 180 || lon < 0 ? 'W' : 'E', info->request.extent_km, info->points.count,
             (moment->before_unix_s - info->reference_unix_s) / 3600.0,
             (moment->after_unix_s - info->reference_unix_s) / 3600.0, s->low_cover,
             s->medium_cover, s->high_cover, s->temperature_c, s->dew_point_c,
             100.0 * s->relative_humidity, s->wind_direction_deg, s->wind_speed_m_s,
             info->wind_level == FORECAST_WIND_10M ? "10 m" : "850 hPa", s->precipitation_mm_h);
}
