/* GRIB2 forecasts' pure parts (server/forecast: forecast_grid.c, forecast_series.c,
 * forecast_json.c), without ecCodes or files: grids from their first and last points (global
 * or not, 0..360 or from 180 W, across the antimeridian), the square's points and window, its
 * refusals (outside a limited area, a pole, all round the globe), means and bilinear samples of
 * linear fields, the coverage grid's orientation; steps filled by hand: a field missing named
 * with its step, a field given twice, tp turned into rates (ECMWF's accumulations from the
 * run, GFS's 3-hour buckets), interpolation in time and its range, wind direction, relative
 * humidity and the JSON. The reader is tested on real GRIB2 files by test_forecast_cli.py. */
#include "forecast.h"
#include "forecast_grid.h"
#include "forecast_series.h"
#include "metar.h"
#include "weather_map.h"
#include "weather_observation.h"

#include <cjson/cJSON.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"

#define DEG (FORECAST_PI / 180.0)

static struct forecast_grid_info make_grid(long ni, long nj, double lat_first, double lon_first,
                                           double lat_last, double lon_last)
{
    struct forecast_grid_info grid;
    char why[200] = "";
    memset(&grid, 0, sizeof grid);
    bool ok = forecast_grid_make(ni, nj, lat_first, lon_first, lat_last, lon_last, &grid, why,
                                 sizeof why);
    CHECK_MSG(ok, "%s", why);
    return grid;
}

static void test_grids(void)
{
    /* GFS 0.25: 0..359.75 E; ECMWF open data: from 180 W (GRIB2 writes 180) to 179.75 E. */
    struct forecast_grid_info gfs = make_grid(1440, 721, 90, 0, -90, 359.75);
    CHECK(gfs.global);
    CHECK_DOUBLE(gfs.lon_step, 0.25);
    CHECK_DOUBLE(gfs.lat_step, -0.25);
    struct forecast_grid_info ecmwf = make_grid(1440, 721, 90, 180, -90, 179.75);
    CHECK(ecmwf.global);
    CHECK_DOUBLE(ecmwf.lon_step, 0.25);
    /* A limited area across the antimeridian, south to north. */
    struct forecast_grid_info pacific = make_grid(21, 11, -10, 170, 10, -170);
    CHECK(!pacific.global);
    CHECK_DOUBLE(pacific.lon_step, 1.0);
    CHECK_DOUBLE(pacific.lat_step, 2.0);
    /* One point along an axis, or the same first and last latitudes: no grid. */
    struct forecast_grid_info grid;
    char why[200];
    CHECK(!forecast_grid_make(1, 10, 0, 0, 9, 0, &grid, why, sizeof why));
    CHECK_CONTAINS(why, "1 x 10 points");
    CHECK(!forecast_grid_make(10, 10, 5, 0, 5, 9, &grid, why, sizeof why));
    CHECK_CONTAINS(why, "latitudes 5 to 5");
}

static bool locate(const struct forecast_grid_info *grid, double lat, double lon, double extent,
                   struct forecast_window *window, struct forecast_points *points,
                   enum forecast_error_code *code, char *why, size_t size)
{
    struct forecast_request request = { lat, lon, extent, 4 };
    return forecast_window_locate(grid, &request, window, points, code, why, size);
}

/* A field linear in latitude and longitude over the window (longitudes from the window's
 * first column's, taken in -180..180, eastwards), which bilinear interpolation reproduces. */
static void fill_linear(const struct forecast_grid_info *grid, const struct forecast_window *w,
                        double a, double b, double c, double *values)
{
    for (int r = 0; r < w->rows; r++)
        for (int col = 0; col < w->columns; col++) {
            double lat = grid->lat_first + (double)(w->first_row + r) * grid->lat_step;
            double lon = forecast_longitude_normalized(grid->lon_first +
                                                       (double)w->first_column * grid->lon_step) +
                         (double)col * grid->lon_step;
            values[r * w->columns + col] = a + b * lat + c * lon;
        }
}

static void test_windows(void)
{
    struct forecast_grid_info gfs = make_grid(1440, 721, 90, 0, -90, 359.75);
    struct forecast_window w;
    struct forecast_points p;
    enum forecast_error_code code;
    char why[300];
    /* 100 km around 45 N 6 E: +-0.4497 deg of latitude, +-0.6360 of longitude. */
    CHECK(locate(&gfs, 45, 6, 100, &w, &p, &code, why, sizeof why));
    CHECK(!p.bilinear);
    CHECK_INT(p.first_row, 179); /* 44.75 .. 45.25 */
    CHECK_INT(p.last_row, 181);
    CHECK_INT(p.first_column, 22); /* 5.5 .. 6.5 */
    CHECK_INT(p.last_column, 26);
    CHECK_INT(p.count, 15);
    CHECK_DOUBLE(p.lat_min, 44.75);
    CHECK_DOUBLE(p.lon_east, 6.5);
    CHECK_INT(w.inside_rows * w.inside_columns, 15);
    /* The same place as 366 - 360 gives the same points. */
    struct forecast_window w2;
    struct forecast_points p2;
    CHECK(locate(&gfs, 45, 366 - 360, 100, &w2, &p2, &code, why, sizeof why));
    CHECK_INT(p2.first_column, p.first_column);
    /* Across 0 E on the 0..360 grid: columns 1438 .. 2, longitudes -0.5 .. 0.5. */
    CHECK(locate(&gfs, 0, -0.1, 100, &w, &p, &code, why, sizeof why));
    CHECK_INT(p.first_column, 1438);
    CHECK_INT(p.last_column, 1);
    CHECK_DOUBLE(p.lon_west, -0.5);
    CHECK_DOUBLE(p.lon_east, 0.25);
    CHECK_INT(p.count, 3 * 4);
    /* A value index wraps: the window starts at column 1437 (359.25 E), the fourth is 0 E. */
    CHECK_INT(forecast_window_value_index(&gfs, &w, 0, 0) % 1440, 1437);
    CHECK_INT(forecast_window_value_index(&gfs, &w, 0, 3) % 1440, 0);

    /* A square smaller than a cell: the four points around, bilinear. */
    struct forecast_grid_info coarse = make_grid(72, 37, 90, 180, -90, 175);
    CHECK(locate(&coarse, 46, 7, 10, &w, &p, &code, why, sizeof why));
    CHECK(p.bilinear);
    CHECK_INT(p.count, 4);
    CHECK_DOUBLE(p.lat_min, 45);
    CHECK_DOUBLE(p.lat_max, 50);
    CHECK_DOUBLE(p.lon_west, 5);
    CHECK_DOUBLE(p.lon_east, 10);
    double values[64];
    CHECK(w.rows * w.columns <= 64);
    fill_linear(&coarse, &w, 0.25, 0.01, -0.002, values);
    /* The window's first column is at -180 + 37 x 5 = 5 E: the field at 46 N 7 E. */
    CHECK_NEAR(forecast_window_mean(&w, values), 0.25 + 0.46 - 0.014, 1e-12);
    /* 2 km north and 3 km east of the place (equirectangular offsets). */
    double lat = 46 + 2.0 / (FORECAST_EARTH_RADIUS_KM * DEG);
    double lon = 7 + 3.0 / (FORECAST_EARTH_RADIUS_KM * DEG * cos(46 * DEG));
    CHECK_NEAR(forecast_window_bilinear(&w, values, 3.0, 2.0), 0.25 + 0.01 * lat - 0.002 * lon,
               1e-12);
    /* The coverage grid: row 0 north, column 0 west, cell centres. */
    double cells[4];
    forecast_window_grid(&w, values, 10.0, 2, cells);
    double dlat = 2.5 / (FORECAST_EARTH_RADIUS_KM * DEG);
    double dlon = 2.5 / (FORECAST_EARTH_RADIUS_KM * DEG * cos(46 * DEG));
    CHECK_NEAR(cells[0], 0.25 + 0.01 * (46 + dlat) - 0.002 * (7 - dlon), 1e-12);
    CHECK_NEAR(cells[1], 0.25 + 0.01 * (46 + dlat) - 0.002 * (7 + dlon), 1e-12);
    CHECK_NEAR(cells[2], 0.25 + 0.01 * (46 - dlat) - 0.002 * (7 - dlon), 1e-12);

    /* Refusals. A limited area across the antimeridian, 10 S .. 10 N, 170 E .. 170 W. */
    struct forecast_grid_info pacific = make_grid(21, 11, -10, 170, 10, -170);
    CHECK(locate(&pacific, 0, 180, 500, &w, &p, &code, why, sizeof why));
    CHECK(locate(&pacific, 0, -175, 500, &w, &p, &code, why, sizeof why));
    CHECK(!locate(&pacific, 0, -165, 100, &w, &p, &code, why, sizeof why));
    CHECK_INT(code, FORECAST_ERR_OUTSIDE);
    CHECK_CONTAINS(why, "0.0000, -165.0000 is outside the grid (latitudes -10..10, longitudes "
                        "170..190 east)");
    CHECK(!locate(&pacific, 9, 180, 500, &w, &p, &code, why, sizeof why));
    CHECK_INT(code, FORECAST_ERR_OUTSIDE);
    CHECK_CONTAINS(why, "the 500 km square around 9.0000, 180.0000 reaches beyond the grid");
    CHECK(!locate(&gfs, 89.9, 0, 100, &w, &p, &code, why, sizeof why));
    CHECK_CONTAINS(why, "reaches a pole");
    CHECK_INT(code, FORECAST_ERR_OUTSIDE);
    /* Near a pole, a wide square still spans less than all longitudes (sin h > h / 180). */
    CHECK(locate(&gfs, 80, 0, 2000, &w, &p, &code, why, sizeof why));
    CHECK(w.columns < 1440);
}

/* A forecast around 45 N 6 E on a 1-degree grid, a 250 km square (+-1.12 degrees of latitude,
 * +-1.59 of longitude: nine points), with hand-made steps. */
static struct forecast *small_forecast(void)
{
    struct forecast_grid_info grid = make_grid(360, 181, 90, 0, -90, 359);
    struct forecast_request request = { 45, 6, 250, 2 };
    struct forecast_window w;
    struct forecast_points p;
    enum forecast_error_code code;
    char why[300];
    bool ok = forecast_window_locate(&grid, &request, &w, &p, &code, why, sizeof why);
    CHECK_MSG(ok, "%s", why);
    CHECK_INT(p.count, 9);
    struct forecast *forecast = forecast_series_new(&request, &grid, &w, &p);
    forecast->info.reference_unix_s = 1782000000.0; /* 2026-06-21T00:00:00Z */
    return forecast;
}

/* Sets `field` at the step valid `hours` after the run to value + slope x (window index). */
static void set_field(struct forecast *forecast, double hours, enum forecast_field field,
                      double value, double slope)
{
    struct forecast_error error;
    struct forecast_step *step =
        forecast_series_step(forecast, forecast->info.reference_unix_s + hours * 3600.0, &error);
    double *values = step ? forecast_series_field(forecast, step, field, 1, &error) : NULL;
    CHECK_MSG(values != NULL, "%s", error.text);
    if (!values)
        return;
    int n = forecast->window.rows * forecast->window.columns;
    for (int i = 0; i < n; i++)
        values[i] = value + slope * i;
}

static void fill_step(struct forecast *forecast, double hours, double k)
{
    set_field(forecast, hours, FIELD_LCC, 0.2 + 0.1 * k, 0.01);
    set_field(forecast, hours, FIELD_MCC, 0.5, 0.0);
    set_field(forecast, hours, FIELD_HCC, 0.9 - 0.2 * k, 0.0);
    set_field(forecast, hours, FIELD_2T, 20.0 + 2.0 * k, 0.0);
    set_field(forecast, hours, FIELD_2D, 10.0, 0.0);
    set_field(forecast, hours, FIELD_10U, 4.0 * k, 0.0);
    set_field(forecast, hours, FIELD_10V, -4.0 + 4.0 * k, 0.0);
}

static void test_series_refusals(void)
{
    struct forecast_error error;
    struct forecast *f = small_forecast();
    fill_step(f, 0, 0);
    fill_step(f, 6, 1);
    /* No precipitation at all. */
    CHECK(!forecast_series_finish(f, &error));
    CHECK_INT(error.code, FORECAST_ERR_MISSING);
    CHECK_CONTAINS(error.text, "no prate (precipitation rate) in the file, nor tp at every step");
    forecast_free(f);

    /* hcc missing at +6 h only; the steps come in any order. */
    f = small_forecast();
    fill_step(f, 6, 1);
    set_field(f, 3, FIELD_LCC, 0.1, 0);
    CHECK(!forecast_series_finish(f, &error));
    CHECK_CONTAINS(error.text, "mcc (medium cloud cover) is missing at the step valid "
                               "2026-06-21T03:00:00Z (+3 h)");
    forecast_free(f);

    /* A field twice at one step. */
    f = small_forecast();
    set_field(f, 0, FIELD_LCC, 0.1, 0);
    struct forecast_step *step = forecast_series_step(f, f->info.reference_unix_s, &error);
    CHECK(forecast_series_field(f, step, FIELD_LCC, 7, &error) == NULL);
    CHECK_INT(error.code, FORECAST_ERR_INCONSISTENT);
    CHECK_CONTAINS(error.text, "message 7 gives lcc valid at 2026-06-21T00:00:00Z (+0 h) again, "
                               "after message 1");
    forecast_free(f);

    /* 10 m wind without 10v, and no 850 hPa wind: 10v is named. */
    f = small_forecast();
    fill_step(f, 0, 0);
    free(f->steps[0].values[FIELD_10V]);
    f->steps[0].values[FIELD_10V] = NULL;
    set_field(f, 0, FIELD_PRATE, 0, 0);
    CHECK(!forecast_series_finish(f, &error));
    CHECK_CONTAINS(error.text, "no 10v (10 m wind towards north) in the file, nor u and v at "
                               "850 hPa at every step");
    forecast_free(f);
}

static void test_interpolation(void)
{
    struct forecast_error error;
    struct forecast *f = small_forecast();
    double run = f->info.reference_unix_s;
    fill_step(f, 6, 1);
    fill_step(f, 0, 0);
    set_field(f, 0, FIELD_PRATE, 0.0, 0.0);
    set_field(f, 6, FIELD_PRATE, 3.0, 0.0);
    set_field(f, 0, FIELD_TCC, 0.4, 0.0);
    set_field(f, 6, FIELD_TCC, 0.8, 0.0);
    /* 850 hPa wind as well: the 10 m wind is taken when every step has it. */
    set_field(f, 0, FIELD_U850, 50, 0);
    set_field(f, 0, FIELD_V850, 50, 0);
    set_field(f, 6, FIELD_U850, 50, 0);
    set_field(f, 6, FIELD_V850, 50, 0);
    bool ok = forecast_series_finish(f, &error);
    CHECK_MSG(ok, "%s", error.text);
    if (!ok) {
        forecast_free(f);
        return;
    }
    CHECK_INT(f->info.wind_level, FORECAST_WIND_10M);
    CHECK_INT(f->info.precipitation_source, FORECAST_PRECIP_RATE);
    CHECK_DOUBLE(forecast_step_unix(f, 0), run);
    struct forecast_moment *m = malloc(sizeof *m);
    /* 1.5 h: a quarter of the way. The window holds 5 x 5 points (a ring around the square
     * for the bilinear samples), the nine inside are its middle, whose mean index is 12: lcc's
     * mean is 0.2 + 0.01 x 12 at the run. */
    CHECK_INT(f->window.rows * f->window.columns, 25);
    CHECK(forecast_at(f, run + 5400, m, &error));
    CHECK_INT(m->step_before, 0);
    CHECK_INT(m->step_after, 1);
    CHECK_DOUBLE(m->weight, 0.25);
    CHECK_NEAR(m->sample.low_cover, 0.75 * 0.32 + 0.25 * 0.42, 1e-15);
    CHECK_NEAR(m->sample.high_cover, 0.75 * 0.9 + 0.25 * 0.7, 1e-15);
    CHECK(m->sample.total_cover_known);
    CHECK_NEAR(m->sample.total_cover, 0.5, 1e-15);
    CHECK_NEAR(m->sample.temperature_c, 20.5, 1e-15);
    CHECK_NEAR(m->sample.precipitation_mm_h, 0.75, 1e-15);
    /* The wind interpolated as a vector, (1, -3): from 341.57 deg (north-north-west). */
    CHECK_NEAR(m->sample.wind_u_m_s, 1.0, 1e-15);
    CHECK_NEAR(m->sample.wind_v_m_s, -3.0, 1e-15);
    CHECK_NEAR(m->sample.wind_speed_m_s, sqrt(10.0), 1e-12);
    CHECK_NEAR(m->sample.wind_direction_deg, 360.0 - atan(1.0 / 3.0) / DEG, 1e-12);
    CHECK_DOUBLE(m->sample.relative_humidity, proto_metar_relative_humidity(20.5, 10.0));
    /* The coverage grid interpolates the same way. */
    CHECK_INT(m->sample.grid_size, 2);
    struct forecast_sample *first = malloc(sizeof *first), *second = malloc(sizeof *second);
    forecast_series_sample(f, 0, first);
    forecast_series_sample(f, 1, second);
    for (int i = 0; i < 4; i++)
        CHECK_NEAR(m->sample.low_grid[i], 0.75 * first->low_grid[i] + 0.25 * second->low_grid[i],
                   1e-15);
    CHECK(first->low_grid[0] < first->low_grid[1]); /* grows east along the window's rows */
    /* At a step exactly: that step, weight 0, one step on either side. */
    CHECK(forecast_at(f, run + 6 * 3600, m, &error));
    CHECK_INT(m->step_before, 1);
    CHECK_INT(m->step_after, 1);
    CHECK_DOUBLE(m->sample.high_cover, second->high_cover);
    /* Calm: direction 0. At the run, u = 0 and v = -4: from the north. */
    CHECK(forecast_at(f, run, m, &error));
    CHECK_DOUBLE(m->sample.wind_direction_deg, 0.0);
    CHECK_DOUBLE(m->sample.wind_speed_m_s, 4.0);
    /* Outside the range: refused with the range. */
    CHECK(!forecast_at(f, run + 6 * 3600 + 1, m, &error));
    CHECK_INT(error.code, FORECAST_ERR_TIME);
    CHECK_STR(error.text, "2026-06-21T06:00:01Z is outside the forecast: its 2 steps cover "
                          "2026-06-21T00:00:00Z to 2026-06-21T06:00:00Z");
    CHECK(!forecast_at(f, run - 1, m, &error));
    CHECK(!forecast_at(f, NAN, m, &error));
    /* The JSON names what the CLI test reads. */
    CHECK(forecast_at(f, run + 5400, m, &error));
    cJSON *json = forecast_to_json(f, m);
    CHECK(json != NULL);
    cJSON *steps = cJSON_GetObjectItem(json, "steps");
    CHECK(cJSON_GetNumberValue(cJSON_GetObjectItem(steps, "weight")) == 0.25);
    cJSON *clouds = cJSON_GetObjectItem(json, "clouds");
    CHECK_NEAR(cJSON_GetNumberValue(cJSON_GetObjectItem(clouds, "low")), m->sample.low_cover, 0);
    cJSON *map = cJSON_GetObjectItem(json, "coverage_grid");
    CHECK_INT(cJSON_GetArraySize(cJSON_GetObjectItem(map, "high")), 2);
    CHECK_STR(cJSON_GetStringValue(cJSON_GetObjectItem(cJSON_GetObjectItem(json, "wind"), "level")),
              "10m");
    cJSON_Delete(json);
    char summary[512];
    forecast_summary(f, m, summary, sizeof summary);
    CHECK_CONTAINS(summary, "2026-06-21T01:30:00Z at 45.000 N 6.000 E (250 km, 9 grid points, "
                            "steps +0 h..+6 h): cloud low 0.35 medium 0.50 high 0.85");
    free(first);
    free(second);
    free(m);
    forecast_free(f);
}

/* tp into rates: ECMWF accumulates from the run (0, 0-6, 0-12); GFS in buckets that restart
 * every 6 hours (0-3, 0-6, 6-9, 6-12). */
static void test_accumulations(void)
{
    struct forecast_error error;
    struct forecast *f = small_forecast();
    double run = f->info.reference_unix_s;
    const double hours[] = { 0, 3, 6, 9, 12 }, starts[] = { 0, 0, 0, 6, 6 };
    const double totals[] = { 0, 1.5, 6, 3, 3 }; /* mm */
    for (int k = 0; k < 5; k++) {
        fill_step(f, hours[k], 0);
        if (k > 0) { /* tp at the run is absent, as GFS leaves it out: zero */
            set_field(f, hours[k], FIELD_TP, totals[k], 0.0);
            f->steps[k].tp_start_unix_s = run + starts[k] * 3600.0;
        }
    }
    bool ok = forecast_series_finish(f, &error);
    CHECK_MSG(ok, "%s", error.text);
    if (ok) {
        CHECK_INT(f->info.precipitation_source, FORECAST_PRECIP_ACCUMULATED);
        /* (0, 3]: 1.5 mm in 3 h; (3, 6]: 4.5 mm; (6, 9]: the 6-9 bucket; (9, 12]: 0. */
        const double rates[] = { 0.5, 0.5, 1.5, 1.0, 0.0 };
        struct forecast_moment *m = malloc(sizeof *m);
        for (int k = 0; k < 5; k++) {
            CHECK(forecast_at(f, run + hours[k] * 3600.0, m, &error));
            CHECK_NEAR(m->sample.precipitation_mm_h, rates[k], 1e-15);
        }
        /* Between steps: the rate of the interval, not a blend. */
        CHECK(forecast_at(f, run + 4 * 3600.0, m, &error));
        CHECK_NEAR(m->sample.precipitation_mm_h, 1.5, 1e-15);
        CHECK(forecast_at(f, run + 3600.0, m, &error));
        CHECK_NEAR(m->sample.precipitation_mm_h, 0.5, 1e-15);
        CHECK_NEAR(m->sample.precipitation_grid[3], 0.5, 1e-15);
        free(m);
    }
    forecast_free(f);

    /* One step of tp accumulating over no time, and nothing after it: no rate. */
    f = small_forecast();
    fill_step(f, 0, 0);
    set_field(f, 0, FIELD_TP, 0.0, 0.0);
    f->steps[0].tp_start_unix_s = run;
    CHECK(!forecast_series_finish(f, &error));
    CHECK_CONTAINS(error.text, "accumulates over no time");
    forecast_free(f);
}

/* The cover grid as a weather map: the channels, and the grid shifted against the wind's
 * offsets (wrapped), so that the renderer's drift puts each cell back over its ground. */
static void test_weather_map(void)
{
    struct forecast_sample *s = calloc(1, sizeof *s);
    if (!s)
        return;
    s->grid_size = 4;
    for (int j = 0; j < 4; j++)
        for (int i = 0; i < 4; i++) {
            s->low_grid[j * 4 + i] = i / 3.0;  /* clear in the west, overcast in the east */
            s->high_grid[j * 4 + i] = j / 3.0; /* high cover in the south */
            s->precipitation_grid[j * 4 + i] = i == 3 ? 10.0 : 0.0;
        }
    struct proto_weather_map map;
    CHECK(forecast_weather_map(s, 40.0, 0.0, 0.0, &map));
    CHECK_INT(map.width, 4);
    CHECK_INT(map.height, 4);
    if (map.rgba) {
        const uint8_t *t = map.rgba;
        CHECK_INT(t[0], 0);
        CHECK_INT(t[4 * 1], 85);
        CHECK_INT(t[4 * 3], 255);
        CHECK_INT(t[4 * 12 + 1], 255); /* the south-west texel's high cover */
        CHECK_INT(t[4 * 3 + 3], 230);  /* 10 mm/h: 0.9 */
        CHECK_INT(t[4 * 0 + 3], 0);
        CHECK_INT(t[4 * 1 + 2], (int)lround(proto_obs_low_type(1.0 / 3.0, 1000.0) * 255));
    }
    proto_weather_map_free(&map);
    /* The wind carried the map 10 km (a cell) east and 10 km north: texel (i, j) shows the
     * ground of cell (i + 1, j - 1). */
    CHECK(forecast_weather_map(s, 40.0, 10.0, 10.0, &map));
    if (map.rgba) {
        const uint8_t *t = map.rgba;
        CHECK_INT(t[4 * (1 * 4 + 0)], 85);      /* (0, 1) holds (1, 0): low 1/3 */
        CHECK_INT(t[4 * (1 * 4 + 3)], 0);       /* (3, 1) holds (0, 0), wrapped */
        CHECK_INT(t[4 * (0 * 4 + 0) + 1], 255); /* (0, 0) holds (1, 3), wrapped: south */
        CHECK_INT(t[4 * (2 * 4 + 0) + 1], 85);  /* (0, 2) holds (1, 1) */
    }
    proto_weather_map_free(&map);
    /* Half a cell: bilinear between neighbours. */
    CHECK(forecast_weather_map(s, 40.0, 5.0, 0.0, &map));
    if (map.rgba)
        CHECK_INT(map.rgba[0], (int)lround(255.0 / 6.0));
    proto_weather_map_free(&map);
    free(s);
}

int main(void)
{
    test_grids();
    test_windows();
    test_series_refusals();
    test_interpolation();
    test_accumulations();
    test_weather_map();
    return check_summary();
}
