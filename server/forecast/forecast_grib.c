/* GRIB2 files through ecCodes: every message read, the fields the sky needs picked by shortName
 * and level (ECMWF's and NCEP's names), their grids and runs checked against the first such
 * message's, their values converted to the sky's units and kept over the window around the
 * place (forecast_series.h). Other fields are skipped; a GRIB edition 1 message anywhere is
 * refused. */
#include "forecast.h"

#include <eccodes.h>

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "error_text.h"
#include "forecast_grid.h"
#include "forecast_series.h"
#include "utc_time.h"

/* ecCodes reports through a logging procedure with no user data: the last line it logged on
 * this thread, quoted when a call fails, instead of its own lines on stderr. */
static _Thread_local char ecc_last_log[200];

static void keep_log(const codes_context *context, int level, const char *text)
{
    (void)context;
    (void)level;
    snprintf(ecc_last_log, sizeof ecc_last_log, "%s", text ? text : "");
}

/* A message's grid as its keys give it, to compare messages by. */
struct grid_keys {
    char type[40];
    long ni, nj, i_negative, j_positive, j_consecutive, alternative_rows;
    double lat_first, lon_first, lat_last, lon_last;
};

struct reader {
    struct forecast_request request;
    struct forecast_error *error;
    int index;                 /* 1-based, the message being read */
    const char *name;          /* its field's name, for messages */
    struct forecast *forecast; /* made at the first message of a field read */
    int first;                 /* that message */
    struct grid_keys grid;
    double *values; /* a message's values */
    size_t capacity;
};

/* Which field a message is, from its shortName and level; false for fields not read. GFS gives
 * its low, middle and high cloud cover as tcc on lowCloudLayer, middleCloudLayer and
 * highCloudLayer, ECMWF as lcc, mcc and hcc; the total is tcc on entireAtmosphere (or surface),
 * and tcc on other levels (GFS's boundary-layer and convective cloud) is not read. */
static bool classify(const char *short_name, const char *level_type, long level,
                     enum forecast_field *field)
{
    static const struct {
        const char *name;
        enum forecast_field field;
    } plain[] = {
        { "lcc", FIELD_LCC }, { "mcc", FIELD_MCC },     { "hcc", FIELD_HCC },
        { "2t", FIELD_2T },   { "2d", FIELD_2D },       { "10u", FIELD_10U },
        { "10v", FIELD_10V }, { "prate", FIELD_PRATE }, { "tp", FIELD_TP },
    };
    for (size_t i = 0; i < sizeof plain / sizeof plain[0]; i++)
        if (strcmp(short_name, plain[i].name) == 0) {
            *field = plain[i].field;
            return true;
        }
    if (strcmp(short_name, "tcc") == 0) {
        *field = strcmp(level_type, "lowCloudLayer") == 0      ? FIELD_LCC
                 : strcmp(level_type, "middleCloudLayer") == 0 ? FIELD_MCC
                 : strcmp(level_type, "highCloudLayer") == 0   ? FIELD_HCC
                                                               : FIELD_TCC;
        return *field != FIELD_TCC || strcmp(level_type, "entireAtmosphere") == 0 ||
               strcmp(level_type, "surface") == 0;
    }
    bool at_850 = strcmp(level_type, "isobaricInhPa") == 0 && level == 850;
    if (at_850 && (strcmp(short_name, "u") == 0 || strcmp(short_name, "v") == 0)) {
        *field = short_name[0] == 'u' ? FIELD_U850 : FIELD_V850;
        return true;
    }
    return false;
}

static bool refuse_key(struct reader *r, enum forecast_error_code code, const char *key, int status)
{
    return forecast_refuse(r->error, code, r->index, "message %d (%s): no %s: %s", r->index,
                           r->name, key, codes_get_error_message(status));
}

static bool get_long(struct reader *r, codes_handle *h, const char *key, long *value,
                     enum forecast_error_code code)
{
    int status = codes_get_long(h, key, value);
    return status == CODES_SUCCESS || refuse_key(r, code, key, status);
}

static bool get_double(struct reader *r, codes_handle *h, const char *key, double *value,
                       enum forecast_error_code code)
{
    int status = codes_get_double(h, key, value);
    return status == CODES_SUCCESS || refuse_key(r, code, key, status);
}

static bool get_string(struct reader *r, codes_handle *h, const char *key, char *text, size_t size,
                       enum forecast_error_code code)
{
    size_t length = size;
    int status = codes_get_string(h, key, text, &length);
    return status == CODES_SUCCESS || refuse_key(r, code, key, status);
}

static void grid_text(const struct grid_keys *g, char *text, size_t size)
{
    snprintf(text, size, "%s %ld x %ld points from %g, %g to %g, %g", g->type, g->ni, g->nj,
             g->lat_first, g->lon_first, g->lat_last, g->lon_last);
}

static bool read_grid(struct reader *r, codes_handle *h, struct grid_keys *g)
{
    if (!get_string(r, h, "gridType", g->type, sizeof g->type, FORECAST_ERR_GRID))
        return false;
    if (strcmp(g->type, "regular_ll") != 0)
        return forecast_refuse(r->error, FORECAST_ERR_GRID, r->index,
                               "message %d (%s): a %s grid; only regular_ll (a regular "
                               "latitude/longitude grid) is read",
                               r->index, r->name, g->type);
    enum forecast_error_code c = FORECAST_ERR_GRID;
    if (!get_long(r, h, "Ni", &g->ni, c) || !get_long(r, h, "Nj", &g->nj, c) ||
        !get_long(r, h, "iScansNegatively", &g->i_negative, c) ||
        !get_long(r, h, "jScansPositively", &g->j_positive, c) ||
        !get_long(r, h, "jPointsAreConsecutive", &g->j_consecutive, c) ||
        !get_long(r, h, "alternativeRowScanning", &g->alternative_rows, c) ||
        !get_double(r, h, "latitudeOfFirstGridPointInDegrees", &g->lat_first, c) ||
        !get_double(r, h, "longitudeOfFirstGridPointInDegrees", &g->lon_first, c) ||
        !get_double(r, h, "latitudeOfLastGridPointInDegrees", &g->lat_last, c) ||
        !get_double(r, h, "longitudeOfLastGridPointInDegrees", &g->lon_last, c))
        return false;
    if (g->i_negative || g->j_consecutive || g->alternative_rows)
        return forecast_refuse(r->error, FORECAST_ERR_GRID, r->index,
                               "message %d (%s): its points are scanned %s; only rows scanned "
                               "eastwards one after the other are read",
                               r->index, r->name,
                               g->i_negative      ? "westwards"
                               : g->j_consecutive ? "along meridians first"
                                                  : "in alternating directions");
    return true;
}

/* The first field read sets the grid, the window around the place and the run; every later
 * one must share them. */
static bool check_grid(struct reader *r, codes_handle *h, double reference_unix_s)
{
    struct grid_keys g;
    memset(&g, 0, sizeof g);
    if (!read_grid(r, h, &g))
        return false;
    if (r->forecast) {
        if (memcmp(&g, &r->grid, sizeof g) == 0) {
            if (reference_unix_s == r->forecast->info.reference_unix_s)
                return true;
            char mine[40], theirs[40];
            proto_time_format_iso8601(reference_unix_s, mine, sizeof mine);
            proto_time_format_iso8601(r->forecast->info.reference_unix_s, theirs, sizeof theirs);
            return forecast_refuse(r->error, FORECAST_ERR_INCONSISTENT, r->index,
                                   "message %d (%s) is from the run of %s, message %d from the "
                                   "run of %s",
                                   r->index, r->name, mine, r->first, theirs);
        }
        char mine[160], theirs[160];
        grid_text(&g, mine, sizeof mine);
        grid_text(&r->grid, theirs, sizeof theirs);
        return forecast_refuse(r->error, FORECAST_ERR_INCONSISTENT, r->index,
                               "message %d (%s) is on a grid of %s, message %d on %s", r->index,
                               r->name, mine, r->first, theirs);
    }
    struct forecast_grid_info grid;
    error_text why;
    if (!forecast_grid_make(g.ni, g.nj, g.lat_first, g.lon_first, g.lat_last, g.lon_last, &grid,
                            why, sizeof why))
        return forecast_refuse(r->error, FORECAST_ERR_GRID, r->index, "message %d (%s): %s",
                               r->index, r->name, why);
    struct forecast_window window;
    struct forecast_points points;
    enum forecast_error_code code;
    if (!forecast_window_locate(&grid, &r->request, &window, &points, &code, why, sizeof why))
        return forecast_refuse(r->error, code, r->index, "%s", why);
    r->forecast = forecast_series_new(&r->request, &grid, &window, &points);
    if (!r->forecast)
        return forecast_refuse(r->error, FORECAST_ERR_MEMORY, r->index, "out of memory");
    r->forecast->info.reference_unix_s = reference_unix_s;
    r->grid = g;
    r->first = r->index;
    return true;
}

/* dataDate and dataTime as seconds since 1970. */
static bool reference_time(struct reader *r, codes_handle *h, double *unix_s)
{
    long date, time;
    if (!get_long(r, h, "dataDate", &date, FORECAST_ERR_NOT_GRIB) ||
        !get_long(r, h, "dataTime", &time, FORECAST_ERR_NOT_GRIB))
        return false;
    char iso[160];
    error_text why;
    snprintf(iso, sizeof iso, "%04ld-%02ld-%02ldT%02ld:%02ld:00Z", date / 10000, date / 100 % 100,
             date % 100, time / 100, time % 100);
    if (!proto_time_parse_iso8601(iso, unix_s, why, sizeof why))
        return forecast_refuse(r->error, FORECAST_ERR_NOT_GRIB, r->index,
                               "message %d (%s): dataDate %ld dataTime %ld: %s", r->index, r->name,
                               date, time, why);
    return true;
}

/* The factor and offset into the sky's units, from the units ecCodes names, and the range a
 * value may take there; false for units not known. */
static bool conversion(enum forecast_field field, const char *units, double *scale, double *offset,
                       double *min, double *max)
{
    *offset = 0.0;
    switch (field) {
    case FIELD_TCC:
    case FIELD_LCC:
    case FIELD_MCC:
    case FIELD_HCC:
        *min = 0.0;
        *max = 1.0;
        *scale = strcmp(units, "%") == 0 ? 0.01 : 1.0;
        return strcmp(units, "%") == 0 || strcmp(units, "(0 - 1)") == 0;
    case FIELD_2T:
    case FIELD_2D:
        *scale = 1.0;
        *offset = -273.15; /* K to degrees Celsius */
        *min = 150.0 - 273.15;
        *max = 350.0 - 273.15;
        return strcmp(units, "K") == 0;
    case FIELD_10U:
    case FIELD_10V:
    case FIELD_U850:
    case FIELD_V850:
        *scale = 1.0;
        *min = -200.0;
        *max = 200.0;
        return strcmp(units, "m s**-1") == 0;
    case FIELD_PRATE:
        *scale = 3600.0; /* kg m-2 s-1 (mm/s of water) to mm/h */
        *min = 0.0;
        *max = 3600.0;
        return strcmp(units, "kg m**-2 s**-1") == 0;
    case FIELD_TP:
        *scale = strcmp(units, "m") == 0 ? 1000.0 : 1.0; /* m of water, or kg m-2 = mm */
        *min = 0.0;
        *max = 1e5;
        return strcmp(units, "m") == 0 || strcmp(units, "kg m**-2") == 0;
    case FIELD_COUNT:
        break;
    }
    return false;
}

/* Packing rounds a field's zero to a little below it and a cover's 1 a little above: within
 * this share of the range a value is taken as the bound. */
#define RANGE_SLACK 0.005

/* The window's values of the message into `out`, converted and checked. */
static bool keep_values(struct reader *r, codes_handle *h, enum forecast_field field, double *out)
{
    char units[64];
    if (!get_string(r, h, "units", units, sizeof units, FORECAST_ERR_UNITS))
        return false;
    double scale, offset, min, max;
    if (!conversion(field, units, &scale, &offset, &min, &max))
        return forecast_refuse(r->error, FORECAST_ERR_UNITS, r->index,
                               "message %d (%s): units \"%s\" are not ones this reader knows",
                               r->index, r->name, units);
    if (field <= FIELD_HCC && strcmp(units, "%") == 0)
        r->forecast->info.cover_in_percent = true;
    const struct forecast_grid_info *grid = &r->forecast->info.grid;
    size_t count = 0;
    int status = codes_get_size(h, "values", &count);
    if (status != CODES_SUCCESS)
        return refuse_key(r, FORECAST_ERR_NOT_GRIB, "values", status);
    if (count != (size_t)grid->ni * (size_t)grid->nj)
        return forecast_refuse(r->error, FORECAST_ERR_GRID, r->index,
                               "message %d (%s): %zu values for a grid of %ld x %ld points",
                               r->index, r->name, count, grid->ni, grid->nj);
    if (count > r->capacity) {
        double *values = realloc(r->values, count * sizeof *values);
        if (!values)
            return forecast_refuse(r->error, FORECAST_ERR_MEMORY, r->index, "out of memory");
        r->values = values;
        r->capacity = count;
    }
    status = codes_get_double_array(h, "values", r->values, &count);
    if (status != CODES_SUCCESS)
        return forecast_refuse(r->error, FORECAST_ERR_NOT_GRIB, r->index,
                               "message %d (%s): its values cannot be decoded: %s (%s)", r->index,
                               r->name, codes_get_error_message(status), ecc_last_log);
    long bitmap = 0;
    double missing = 0.0;
    if (codes_get_long(h, "bitmapPresent", &bitmap) != CODES_SUCCESS)
        bitmap = 0;
    if (bitmap && !get_double(r, h, "missingValue", &missing, FORECAST_ERR_NOT_GRIB))
        return false;
    const struct forecast_window *w = &r->forecast->window;
    double slack = RANGE_SLACK * (max - min);
    for (int row = 0; row < w->rows; row++)
        for (int column = 0; column < w->columns; column++) {
            long index = forecast_window_value_index(grid, w, row, column);
            double raw = r->values[index];
            double lat = grid->lat_first + (double)(w->first_row + row) * grid->lat_step;
            double lon = forecast_longitude_normalized(
                grid->lon_first + (double)(w->first_column + column) * grid->lon_step);
            if (bitmap && raw == missing)
                return forecast_refuse(r->error, FORECAST_ERR_MISSING, r->index,
                                       "message %d (%s) has no value at %g, %g, beside the place",
                                       r->index, r->name, lat, lon);
            double value = raw * scale + offset;
            if (!(value >= min - slack && value <= max + slack))
                return forecast_refuse(r->error, FORECAST_ERR_UNITS, r->index,
                                       "message %d (%s): %g %s at %g, %g is out of range: are "
                                       "the units right?",
                                       r->index, r->name, raw, units, lat, lon);
            out[row * w->columns + column] = fmin(max, fmax(min, value));
        }
    return true;
}

/* Where a message's values go in its step, or NULL (*values) to skip it. A field comes once per
 * step, but for two that GFS gives twice: prate as it is at the step and as a mean over the
 * hours before it (the instantaneous one is kept), and tp over windows that end together (the
 * one that starts first is kept). */
static bool pick(struct reader *r, struct forecast_step *step, enum forecast_field field,
                 bool instant, double start_unix_s, double **values)
{
    double *kept = step->values[field];
    bool replace = kept && ((field == FIELD_PRATE && instant && !step->prate_instant) ||
                            (field == FIELD_TP && start_unix_s < step->tp_start_unix_s));
    bool skip = kept && ((field == FIELD_PRATE && !instant && step->prate_instant) ||
                         (field == FIELD_TP && start_unix_s > step->tp_start_unix_s));
    if (skip)
        return true;
    if (replace) {
        step->message[field] = r->index;
        *values = kept;
    } else {
        *values = forecast_series_field(r->forecast, step, field, r->index, r->error);
        if (!*values)
            return false;
    }
    if (field == FIELD_PRATE)
        step->prate_instant = instant;
    if (field == FIELD_TP)
        step->tp_start_unix_s = start_unix_s;
    return true;
}

/* One message: skipped when not a field read, else kept in its step. */
static bool read_message(struct reader *r, codes_handle *h)
{
    long edition = 0;
    r->name = "?";
    if (!get_long(r, h, "edition", &edition, FORECAST_ERR_NOT_GRIB))
        return false;
    if (edition != 2)
        return forecast_refuse(r->error, FORECAST_ERR_EDITION, r->index,
                               "message %d is GRIB edition %ld; only GRIB2 is read", r->index,
                               edition);
    char short_name[64], level_type[64];
    long level = 0;
    if (!get_string(r, h, "shortName", short_name, sizeof short_name, FORECAST_ERR_NOT_GRIB) ||
        !get_string(r, h, "typeOfLevel", level_type, sizeof level_type, FORECAST_ERR_NOT_GRIB) ||
        !get_long(r, h, "level", &level, FORECAST_ERR_NOT_GRIB))
        return false;
    enum forecast_field field;
    if (!classify(short_name, level_type, level, &field))
        return true;
    r->name = forecast_field_name(field);
    double reference;
    if (!reference_time(r, h, &reference) || !check_grid(r, h, reference))
        return false;
    /* Steps in seconds, whatever unit the message counts them in. */
    size_t length = 2;
    long start = 0, end = 0;
    int status = codes_set_string(h, "stepUnits", "s", &length);
    if (status != CODES_SUCCESS)
        return refuse_key(r, FORECAST_ERR_NOT_GRIB, "stepUnits", status);
    if (!get_long(r, h, "startStep", &start, FORECAST_ERR_NOT_GRIB) ||
        !get_long(r, h, "endStep", &end, FORECAST_ERR_NOT_GRIB))
        return false;
    /* Validity time = dataDate and dataTime + step (the end of an accumulation's window). */
    struct forecast_step *step = forecast_series_step(r->forecast, reference + (double)end,
                                                      r->error);
    if (!step)
        return false;
    char step_type[32] = "";
    if (field == FIELD_PRATE &&
        !get_string(r, h, "stepType", step_type, sizeof step_type, FORECAST_ERR_NOT_GRIB))
        return false;
    double *values = NULL;
    if (!pick(r, step, field, strcmp(step_type, "instant") == 0, reference + (double)start,
              &values))
        return false;
    return !values || keep_values(r, h, field, values);
}

static bool check_request(const struct forecast_request *q, struct forecast_error *error)
{
    if (!(q->lat_deg >= -90.0 && q->lat_deg <= 90.0))
        return forecast_refuse(error, FORECAST_ERR_ARGUMENT, 0, "latitude %g is not within -90..90",
                               q->lat_deg);
    if (!(q->lon_deg >= -180.0 && q->lon_deg <= 360.0))
        return forecast_refuse(error, FORECAST_ERR_ARGUMENT, 0,
                               "longitude %g is not within -180..360", q->lon_deg);
    if (!(q->extent_km > 0.0 && q->extent_km <= FORECAST_MAX_EXTENT_KM))
        return forecast_refuse(error, FORECAST_ERR_ARGUMENT, 0,
                               "extent %g km is not within (0, %g]", q->extent_km,
                               FORECAST_MAX_EXTENT_KM);
    if (q->grid_size < 1 || q->grid_size > FORECAST_MAX_GRID)
        return forecast_refuse(error, FORECAST_ERR_ARGUMENT, 0, "grid size %d is not within 1..%d",
                               q->grid_size, FORECAST_MAX_GRID);
    return true;
}

struct forecast *forecast_read(const char *path, const struct forecast_request *request,
                               struct forecast_error *error)
{
    return forecast_read_until(path, request, NULL, error);
}

struct forecast *forecast_read_until(const char *path, const struct forecast_request *request,
                                     const atomic_bool *cancel, struct forecast_error *error)
{
    struct forecast_error spare;
    if (!error)
        error = &spare;
    memset(error, 0, sizeof *error);
    if (!check_request(request, error))
        return NULL;
    FILE *file = fopen(path, "rb");
    if (!file) {
        forecast_refuse(error, FORECAST_ERR_FILE, 0, "%s: %s", path, strerror(errno));
        return NULL;
    }
    codes_context *context = codes_context_get_default();
    codes_context_set_logging_proc(context, keep_log);
    struct reader r;
    memset(&r, 0, sizeof r);
    r.request = *request;
    r.error = error;
    bool ok = true;
    for (;;) {
        if (cancel && atomic_load(cancel)) {
            ok = forecast_refuse(error, FORECAST_ERR_CANCELLED, 0, "%s: the read was given up",
                                 path);
            break;
        }
        int status = CODES_SUCCESS;
        ecc_last_log[0] = '\0';
        codes_handle *h = codes_handle_new_from_file(context, file, PRODUCT_GRIB, &status);
        if (!h) {
            if (status != CODES_SUCCESS)
                ok = forecast_refuse(error, FORECAST_ERR_NOT_GRIB, r.index + 1,
                                     "%s: message %d is damaged or cut short: %s", path,
                                     r.index + 1, codes_get_error_message(status));
            break;
        }
        r.index++;
        ok = read_message(&r, h);
        codes_handle_delete(h);
        if (!ok)
            break;
    }
    bool read_error = ferror(file);
    fclose(file);
    free(r.values);
    if (ok && read_error)
        ok = forecast_refuse(error, FORECAST_ERR_FILE, 0, "%s: read error", path);
    if (ok && r.index == 0)
        ok = forecast_refuse(error, FORECAST_ERR_NOT_GRIB, 0,
                             "%s holds no GRIB message: not a GRIB file", path);
    if (ok && !r.forecast)
        ok = forecast_refuse(error, FORECAST_ERR_MISSING, 0,
                             "none of the %d messages of %s is a field this reader uses (lcc, "
                             "mcc, hcc, 2t, 2d, 10u/10v or u/v at 850 hPa, prate or tp)",
                             r.index, path);
    if (ok)
        ok = forecast_series_finish(r.forecast, error);
    if (!ok) {
        forecast_free(r.forecast);
        return NULL;
    }
    return r.forecast;
}
