/* GRIB2 forecasts (ECMWF open data, NCEP GFS, any model on a regular latitude/longitude grid)
 * read through ecCodes and reduced to what the sky needs around one place: the low, medium and
 * high cloud cover (0..1) as the mean over the grid points within a square around the place and
 * as a coarse grid over that square (a weather map), temperature, dew point and relative
 * humidity at 2 m, the wind at 10 m (or 850 hPa), the precipitation rate; per forecast step,
 * and at any instant between two steps by linear interpolation.
 *
 * A file is read completely or refused with an error that says why (not GRIB, GRIB edition 1,
 * a field missing and which, the place outside the grid, grids that disagree); on refusal
 * nothing is returned. Fields read, units and the JSON: protocol/PROTOCOL.md, "GRIB2
 * forecasts". */
#ifndef SKYD_FORECAST_H
#define SKYD_FORECAST_H

#include <stdatomic.h>
#include <stdbool.h>
#include <stddef.h>

#include "error_text.h"

struct cJSON;
struct proto_weather_map;

/* The coverage grid is at most this many cells a side; the square at most this wide. */
#define FORECAST_MAX_GRID 32
#define FORECAST_DEFAULT_GRID 16
#define FORECAST_MAX_EXTENT_KM 2000.0
#define FORECAST_DEFAULT_EXTENT_KM 60.0 /* weather.map_extent_km's default */
/* Forecast steps (distinct validity times) a file may hold. */
#define FORECAST_MAX_STEPS 512

/* Stable error ids; tests assert these rather than the message text. */
enum forecast_error_code {
    FORECAST_OK = 0,
    FORECAST_ERR_ARGUMENT = 1,     /* latitude, longitude, extent or grid size out of range */
    FORECAST_ERR_FILE = 2,         /* the file cannot be opened or read */
    FORECAST_ERR_NOT_GRIB = 3,     /* no GRIB message in it, or a damaged one */
    FORECAST_ERR_EDITION = 4,      /* a GRIB edition 1 message: only GRIB2 is read */
    FORECAST_ERR_GRID = 5,         /* a grid this reader does not take (not regular_ll, ...) */
    FORECAST_ERR_INCONSISTENT = 6, /* grids or runs that differ, a field given twice */
    FORECAST_ERR_UNITS = 7,        /* a field in units it does not know, or out of range */
    FORECAST_ERR_MISSING = 8,      /* a needed field is absent (at some step) */
    FORECAST_ERR_OUTSIDE = 9,      /* the place or its square reaches beyond the grid */
    FORECAST_ERR_TIME = 10,        /* the time is outside the steps' range */
    FORECAST_ERR_TOO_LARGE = 11,   /* too many steps, or grid points in the square */
    FORECAST_ERR_MEMORY = 12,
    FORECAST_ERR_CANCELLED = 13, /* the reader's caller gave up (forecast_read_until) */
};

struct forecast_error {
    enum forecast_error_code code;
    int message; /* 1-based index of the offending GRIB message; 0: the file as a whole */
    /* `message 3 (hcc): grid 16 x 31 from 60 N 0 E differs from message 1's 16 x 31 ...` */
    error_text text;
};

/* Where the forecast is wanted: a square of side extent_km centred on lat/lon, on the local
 * east/north plane (the weather map's square, weather.map_extent_km). */
struct forecast_request {
    double lat_deg;   /* -90..90 */
    double lon_deg;   /* -180..360; 0..360 and -180..180 both work on every grid */
    double extent_km; /* (0, FORECAST_MAX_EXTENT_KM] */
    int grid_size;    /* coverage grid cells a side, 1..FORECAST_MAX_GRID */
};

enum forecast_wind_level {
    FORECAST_WIND_10M = 0,    /* 10u, 10v */
    FORECAST_WIND_850HPA = 1, /* u, v at isobaricInhPa 850 */
};

enum forecast_precipitation_source {
    FORECAST_PRECIP_RATE = 0,        /* prate: as the message gives it, interpolated */
    FORECAST_PRECIP_ACCUMULATED = 1, /* tp: the mean rate between steps, held over each */
};

/* The regular latitude/longitude grid the file's fields share (GRIB2 template 3.0). */
struct forecast_grid_info {
    long ni, nj;                 /* points along a parallel, along a meridian */
    double lat_first, lon_first; /* the first point as the message gives it, degrees */
    double lat_last, lon_last;
    double lat_step, lon_step; /* degrees between points in scan order (lat_step < 0: N to S) */
    bool global;               /* the parallels go all the way round */
};

/* The grid points the means take: rows first_row..last_row (in scan order) and columns
 * first_column, first_column + 1, ... last_column, counted modulo ni on a global grid. When no
 * point falls inside the square (a grid coarser than it), the four points around the place,
 * interpolated bilinearly. */
struct forecast_points {
    bool bilinear; /* no point inside the square: the four around the place */
    int count;
    long first_row, last_row, first_column, last_column;
    double lat_min, lat_max;   /* degrees */
    double lon_west, lon_east; /* degrees, -180..180 */
};

/* The forecast around the place at one instant, a step's or one between two steps. */
struct forecast_sample {
    double valid_unix_s;
    /* Cloud cover 0..1, mean over the points of the square. total: tcc, when every step has it. */
    double low_cover, medium_cover, high_cover;
    bool total_cover_known;
    double total_cover;
    double temperature_c, dew_point_c; /* the means of 2t and 2d */
    double relative_humidity;          /* 0..1 from the means, Magnus (metar.h) */
    double wind_u_m_s, wind_v_m_s;     /* towards east, towards north: the means */
    double wind_speed_m_s;
    double wind_direction_deg; /* where it blows from, north through east (0 when calm) */
    double precipitation_mm_h; /* kg m-2 h-1 */
    /* The square as grid_size x grid_size cells, row-major from the north-west corner (x east,
     * y south, as weather_map.h): each cell the bilinear interpolation of the field at its
     * centre. Coverage 0..1, precipitation in mm/h. */
    int grid_size;
    double low_grid[FORECAST_MAX_GRID * FORECAST_MAX_GRID];
    double medium_grid[FORECAST_MAX_GRID * FORECAST_MAX_GRID];
    double high_grid[FORECAST_MAX_GRID * FORECAST_MAX_GRID];
    double precipitation_grid[FORECAST_MAX_GRID * FORECAST_MAX_GRID];
};

/* The forecast at a requested instant and the steps it came from. */
struct forecast_moment {
    struct forecast_sample sample;
    int step_before, step_after; /* equal when the instant is a step's */
    double before_unix_s, after_unix_s;
    double weight; /* of step_after: 0 at step_before, 1 at step_after */
};

/* What a file holds once read for a place: opaque, made by forecast_read. */
struct forecast;

/* Reads every message of the GRIB2 file at `path` for `request`. Returns the forecast, or NULL
 * with *error saying why (error may be NULL). Messages of other fields are skipped. */
struct forecast *forecast_read(const char *path, const struct forecast_request *request,
                               struct forecast_error *error);
/* As forecast_read, but gives up between two messages once *cancel is true (set by another
 * thread), with FORECAST_ERR_CANCELLED. cancel may be NULL. */
struct forecast *forecast_read_until(const char *path, const struct forecast_request *request,
                                     const atomic_bool *cancel, struct forecast_error *error);
void forecast_free(struct forecast *forecast);

/* What was read: the run's reference time (dataDate, dataTime), the steps' validity times
 * (sorted), the sources of wind and precipitation, the grid and the points the means take. */
struct forecast_info {
    struct forecast_request request;
    double reference_unix_s;
    int step_count;
    enum forecast_wind_level wind_level;
    enum forecast_precipitation_source precipitation_source;
    bool cover_in_percent; /* the cloud covers came in % (GFS) rather than 0-1 (ECMWF) */
    struct forecast_grid_info grid;
    struct forecast_points points;
};
const struct forecast_info *forecast_info(const struct forecast *forecast);
/* Validity time of step `index` (0 .. step_count - 1), seconds since 1970 (UTC). */
double forecast_step_unix(const struct forecast *forecast, int index);

/* The forecast at unix_s: the bracketing steps interpolated linearly (validity time = dataDate
 * and dataTime + step). An instant before the first step or after the last is refused with the
 * range the file covers in the message. */
bool forecast_at(const struct forecast *forecast, double unix_s, struct forecast_moment *moment,
                 struct forecast_error *error);

/* The forecast at that moment as JSON (protocol/PROTOCOL.md, "GRIB2 forecasts"); NULL when
 * memory is out. The caller deletes it. */
struct cJSON *forecast_to_json(const struct forecast *forecast,
                               const struct forecast_moment *moment);

/* One line for people: "2026-06-21T15:00:00Z at 45.000 N 6.000 E: cloud low 0.30 ...". */
void forecast_summary(const struct forecast *forecast, const struct forecast_moment *moment,
                      char *text, size_t capacity);

/* A sample as a world-state patch (protocol/PROTOCOL.md, "Forecasts in the world"): low cover
 * into clouds.low (its type from the cover, weather_observation.h), high cover into
 * clouds.high, medium cover into clouds.mid, 2 m relative humidity into weather.humidity, the
 * wind at the clouds (the 10 m wind by the power law at 1 km; 850 hPa as it is), the rate into
 * clouds.precipitation, weather.source "forecast" and the autopilot off. New objects the
 * caller deletes; false when memory is out. */
bool forecast_patch(const struct forecast *forecast, const struct forecast_sample *sample,
                    struct cJSON **patch, struct cJSON **unmapped);

/* A sample's coverage grid over a square extent_km wide as a weather map
 * (protocol/weather_map.h, the channels of set_weather_map): grid_size x grid_size texels from
 * the north-west corner, r the low cover, g the high cover, b the low layer's type from its
 * cover as the patch gives the mean's, a the precipitation level of the cell's rate. The
 * middle cover has no channel (clouds.mid from the patch applies over the map). The renderer
 * draws a map carried by the wind (weather.offset_east_km, _north_km) and tiled: each texel
 * holds the grid where those offsets draw it (bilinear, wrapped), so that the forecast stays
 * over the ground it is for. False when memory is out; the caller frees *map
 * (proto_weather_map_free). */
bool forecast_weather_map(const struct forecast_sample *sample, double extent_km,
                          double offset_east_km, double offset_north_km,
                          struct proto_weather_map *map);

/* clouds.precipitation 0..1 for a rate in mm/h: 0.3 at 0.5 mm/h (light rain), 0.6 at 4 mm/h
 * (moderate), 0.9 at 10 mm/h (heavy, AMS Glossary), 1 from 20 mm/h; linear between. */
double forecast_precipitation_level(double rate_mm_h);

#endif
