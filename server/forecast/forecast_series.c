/* A forecast's steps: filled by the reader, checked and finished, sampled per step and between
 * steps (forecast_series.h, forecast.h). */
#include "forecast_series.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "metar.h"
#include "utc_time.h"

static const char *const field_names[FIELD_COUNT] = {
    "tcc", "lcc", "mcc",          "hcc",          "2t",    "2d",
    "10u", "10v", "u at 850 hPa", "v at 850 hPa", "prate", "tp",
};

static const char *const field_meanings[FIELD_COUNT] = {
    "total cloud cover",          "low cloud cover",         "medium cloud cover",
    "high cloud cover",           "2 m temperature",         "2 m dew point",
    "10 m wind towards east",     "10 m wind towards north", "850 hPa wind towards east",
    "850 hPa wind towards north", "precipitation rate",      "total precipitation",
};

const char *forecast_field_name(enum forecast_field field)
{
    return (unsigned)field < FIELD_COUNT ? field_names[field] : "?";
}

bool forecast_refuse(struct forecast_error *error, enum forecast_error_code code, int message,
                     const char *format, ...)
{
    if (!error)
        return false;
    error->code = code;
    error->message = message;
    va_list args;
    va_start(args, format);
    vsnprintf(error->text, sizeof error->text, format, args);
    va_end(args);
    return false;
}

struct forecast *forecast_series_new(const struct forecast_request *request,
                                     const struct forecast_grid_info *grid,
                                     const struct forecast_window *window,
                                     const struct forecast_points *points)
{
    struct forecast *forecast = calloc(1, sizeof *forecast);
    if (!forecast)
        return NULL;
    forecast->info.request = *request;
    forecast->info.grid = *grid;
    forecast->info.points = *points;
    forecast->window = *window;
    return forecast;
}

void forecast_free(struct forecast *forecast)
{
    if (!forecast)
        return;
    for (int k = 0; k < forecast->step_count; k++)
        for (int f = 0; f < FIELD_COUNT; f++)
            free(forecast->steps[k].values[f]);
    free(forecast->steps);
    free(forecast);
}

static size_t window_points(const struct forecast *forecast)
{
    return (size_t)forecast->window.rows * (size_t)forecast->window.columns;
}

struct forecast_step *forecast_series_step(struct forecast *forecast, double valid_unix_s,
                                           struct forecast_error *error)
{
    for (int k = 0; k < forecast->step_count; k++)
        if (forecast->steps[k].valid_unix_s == valid_unix_s)
            return &forecast->steps[k];
    if (forecast->step_count >= FORECAST_MAX_STEPS) {
        forecast_refuse(error, FORECAST_ERR_TOO_LARGE, 0,
                        "more than %d forecast steps (validity times)", FORECAST_MAX_STEPS);
        return NULL;
    }
    if ((double)window_points(forecast) * (forecast->step_count + 1) * FIELD_COUNT >
        (double)FORECAST_MAX_WINDOW_VALUES * FIELD_COUNT / 4.0) {
        forecast_refuse(error, FORECAST_ERR_TOO_LARGE, 0,
                        "%d steps of %d x %d grid points in the square are more than this reader "
                        "keeps; ask for a smaller extent",
                        forecast->step_count + 1, forecast->window.rows, forecast->window.columns);
        return NULL;
    }
    if (forecast->step_count == forecast->step_capacity) {
        int capacity = forecast->step_capacity ? 2 * forecast->step_capacity : 8;
        struct forecast_step *steps = realloc(forecast->steps, (size_t)capacity * sizeof *steps);
        if (!steps) {
            forecast_refuse(error, FORECAST_ERR_MEMORY, 0, "out of memory");
            return NULL;
        }
        forecast->steps = steps;
        forecast->step_capacity = capacity;
    }
    struct forecast_step *step = &forecast->steps[forecast->step_count++];
    memset(step, 0, sizeof *step);
    step->valid_unix_s = valid_unix_s;
    return step;
}

/* "2026-06-21T06:00:00Z (+6 h)" */
static void step_text(const struct forecast *forecast, double valid_unix_s, char *text, size_t size)
{
    char iso[40];
    proto_time_format_iso8601(valid_unix_s, iso, sizeof iso);
    snprintf(text, size, "%s (%+g h)", iso,
             (valid_unix_s - forecast->info.reference_unix_s) / 3600.0);
}

double *forecast_series_field(struct forecast *forecast, struct forecast_step *step,
                              enum forecast_field field, int message, struct forecast_error *error)
{
    if (step->values[field]) {
        char when[64];
        step_text(forecast, step->valid_unix_s, when, sizeof when);
        forecast_refuse(error, FORECAST_ERR_INCONSISTENT, message,
                        "message %d gives %s valid at %s again, after message %d (an ensemble, "
                        "or several runs in one file?)",
                        message, field_names[field], when, step->message[field]);
        return NULL;
    }
    step->values[field] = calloc(window_points(forecast), sizeof(double));
    if (!step->values[field]) {
        forecast_refuse(error, FORECAST_ERR_MEMORY, message, "out of memory");
        return NULL;
    }
    step->message[field] = message;
    return step->values[field];
}

static int by_validity(const void *a, const void *b)
{
    double ta = ((const struct forecast_step *)a)->valid_unix_s;
    double tb = ((const struct forecast_step *)b)->valid_unix_s;
    return (ta > tb) - (ta < tb);
}

/* The first step without `field`, or -1 when every step has it. */
static int first_without(const struct forecast *forecast, enum forecast_field field)
{
    for (int k = 0; k < forecast->step_count; k++)
        if (!forecast->steps[k].values[field])
            return k;
    return -1;
}

static bool refuse_missing(const struct forecast *forecast, enum forecast_field field, int step,
                           const char *also, struct forecast_error *error)
{
    bool anywhere = false;
    for (int k = 0; k < forecast->step_count; k++)
        anywhere = anywhere || forecast->steps[k].values[field] != NULL;
    if (!anywhere)
        return forecast_refuse(error, FORECAST_ERR_MISSING, 0, "no %s (%s) in the file%s",
                               field_names[field], field_meanings[field], also);
    char when[64];
    step_text(forecast, forecast->steps[step].valid_unix_s, when, sizeof when);
    return forecast_refuse(error, FORECAST_ERR_MISSING, 0,
                           "%s (%s) is missing at the step valid %s%s", field_names[field],
                           field_meanings[field], when, also);
}

/* tp accumulated over [tp_start, valid] into the mean rate, mm/h, over the interval before each
 * step: the difference with the step before when both accumulations start together (ECMWF's
 * 0-3, 0-6, ...; GFS's 0-3 then 0-6), else the accumulation over its own window (GFS's 6-9);
 * a step that accumulates over no time (step 0) takes the rate of the interval after it. Runs
 * backwards so that each difference reads the accumulation before it still unchanged. */
static bool precipitation_rates(struct forecast *forecast, struct forecast_error *error)
{
    size_t n = window_points(forecast);
    for (int k = forecast->step_count - 1; k >= 0; k--) {
        struct forecast_step *step = &forecast->steps[k];
        const struct forecast_step *before = k > 0 ? &forecast->steps[k - 1] : NULL;
        double *rate = step->values[FIELD_TP];
        if (before && before->tp_start_unix_s == step->tp_start_unix_s) {
            double hours = (step->valid_unix_s - before->valid_unix_s) / 3600.0;
            for (size_t i = 0; i < n; i++)
                rate[i] = fmax(0.0, (rate[i] - before->values[FIELD_TP][i]) / hours);
        } else if (step->valid_unix_s > step->tp_start_unix_s) {
            double hours = (step->valid_unix_s - step->tp_start_unix_s) / 3600.0;
            for (size_t i = 0; i < n; i++)
                rate[i] = fmax(0.0, rate[i] / hours);
        } else if (k + 1 < forecast->step_count) {
            memcpy(rate, forecast->steps[k + 1].values[FIELD_TP], n * sizeof *rate);
        } else {
            char when[64];
            step_text(forecast, step->valid_unix_s, when, sizeof when);
            return forecast_refuse(error, FORECAST_ERR_MISSING, step->message[FIELD_TP],
                                   "tp valid at %s accumulates over no time and no later step "
                                   "gives a rate",
                                   when);
        }
    }
    return true;
}

static bool choose_precipitation(struct forecast *forecast, struct forecast_error *error)
{
    if (first_without(forecast, FIELD_PRATE) < 0) {
        forecast->info.precipitation_source = FORECAST_PRECIP_RATE;
        return true;
    }
    /* tp at the run's own time accumulates nothing: it may be left out. */
    for (int k = 0; k < forecast->step_count; k++) {
        struct forecast_step *step = &forecast->steps[k];
        if (!step->values[FIELD_TP] && step->valid_unix_s == forecast->info.reference_unix_s) {
            if (!forecast_series_field(forecast, step, FIELD_TP, 0, error))
                return false;
            step->tp_start_unix_s = step->valid_unix_s;
        }
    }
    int missing = first_without(forecast, FIELD_TP);
    if (missing >= 0) {
        int missing_rate = first_without(forecast, FIELD_PRATE);
        return refuse_missing(forecast, FIELD_PRATE, missing_rate, ", nor tp at every step", error);
    }
    forecast->info.precipitation_source = FORECAST_PRECIP_ACCUMULATED;
    return precipitation_rates(forecast, error);
}

bool forecast_series_finish(struct forecast *forecast, struct forecast_error *error)
{
    if (forecast->step_count == 0)
        return refuse_missing(forecast, FIELD_LCC, 0, "", error);
    qsort(forecast->steps, (size_t)forecast->step_count, sizeof *forecast->steps, by_validity);
    forecast->info.step_count = forecast->step_count;
    static const enum forecast_field needed[] = { FIELD_LCC, FIELD_MCC, FIELD_HCC, FIELD_2T,
                                                  FIELD_2D };
    for (size_t i = 0; i < sizeof needed / sizeof needed[0]; i++) {
        int missing = first_without(forecast, needed[i]);
        if (missing >= 0)
            return refuse_missing(forecast, needed[i], missing, "", error);
    }
    int no_u = first_without(forecast, FIELD_10U), no_v = first_without(forecast, FIELD_10V);
    if (no_u < 0 && no_v < 0) {
        forecast->info.wind_level = FORECAST_WIND_10M;
    } else if (first_without(forecast, FIELD_U850) < 0 && first_without(forecast, FIELD_V850) < 0) {
        forecast->info.wind_level = FORECAST_WIND_850HPA;
    } else {
        enum forecast_field field = no_u >= 0 ? FIELD_10U : FIELD_10V;
        return refuse_missing(forecast, field, no_u >= 0 ? no_u : no_v,
                              ", nor u and v at 850 hPa at every step", error);
    }
    forecast->total_cover_known = first_without(forecast, FIELD_TCC) < 0;
    return choose_precipitation(forecast, error);
}

void forecast_sample_derive(struct forecast_sample *sample)
{
    sample->relative_humidity = proto_metar_relative_humidity(sample->temperature_c,
                                                              sample->dew_point_c);
    double u = sample->wind_u_m_s, v = sample->wind_v_m_s;
    sample->wind_speed_m_s = hypot(u, v);
    /* The direction it blows from: the bearing of (-u, -v), north through east. */
    double from = sample->wind_speed_m_s > 0.0 ? atan2(-u, -v) * 180.0 / FORECAST_PI : 0.0;
    sample->wind_direction_deg = from < 0.0 ? from + 360.0 : from;
}

void forecast_series_sample(const struct forecast *forecast, int index,
                            struct forecast_sample *sample)
{
    const struct forecast_step *step = &forecast->steps[index];
    const struct forecast_window *w = &forecast->window;
    bool ten_metres = forecast->info.wind_level == FORECAST_WIND_10M;
    enum forecast_field precipitation = forecast->info.precipitation_source == FORECAST_PRECIP_RATE
                                            ? FIELD_PRATE
                                            : FIELD_TP;
    memset(sample, 0, sizeof *sample);
    sample->valid_unix_s = step->valid_unix_s;
    sample->low_cover = forecast_window_mean(w, step->values[FIELD_LCC]);
    sample->medium_cover = forecast_window_mean(w, step->values[FIELD_MCC]);
    sample->high_cover = forecast_window_mean(w, step->values[FIELD_HCC]);
    sample->total_cover_known = forecast->total_cover_known;
    if (forecast->total_cover_known)
        sample->total_cover = forecast_window_mean(w, step->values[FIELD_TCC]);
    sample->temperature_c = forecast_window_mean(w, step->values[FIELD_2T]);
    sample->dew_point_c = forecast_window_mean(w, step->values[FIELD_2D]);
    sample->wind_u_m_s = forecast_window_mean(w, step->values[ten_metres ? FIELD_10U : FIELD_U850]);
    sample->wind_v_m_s = forecast_window_mean(w, step->values[ten_metres ? FIELD_10V : FIELD_V850]);
    sample->precipitation_mm_h = forecast_window_mean(w, step->values[precipitation]);
    int size = forecast->info.request.grid_size;
    double extent = forecast->info.request.extent_km;
    sample->grid_size = size;
    forecast_window_grid(w, step->values[FIELD_LCC], extent, size, sample->low_grid);
    forecast_window_grid(w, step->values[FIELD_MCC], extent, size, sample->medium_grid);
    forecast_window_grid(w, step->values[FIELD_HCC], extent, size, sample->high_grid);
    forecast_window_grid(w, step->values[precipitation], extent, size, sample->precipitation_grid);
    forecast_sample_derive(sample);
}

const struct forecast_info *forecast_info(const struct forecast *forecast)
{
    return &forecast->info;
}

double forecast_step_unix(const struct forecast *forecast, int index)
{
    return forecast->steps[index].valid_unix_s;
}

/* Linear interpolation written so that w = 0 gives a and w = 1 gives b exactly. */
static double lerp(double a, double b, double w)
{
    return (1.0 - w) * a + w * b;
}

static void lerp_cells(double *a, const double *b, double w, int count)
{
    for (int i = 0; i < count; i++)
        a[i] = lerp(a[i], b[i], w);
}

bool forecast_at(const struct forecast *forecast, double unix_s, struct forecast_moment *moment,
                 struct forecast_error *error)
{
    int n = forecast->step_count;
    double first = forecast->steps[0].valid_unix_s, last = forecast->steps[n - 1].valid_unix_s;
    if (!(unix_s >= first && unix_s <= last)) {
        char when[40], from[40], to[40];
        proto_time_format_iso8601(unix_s, when, sizeof when);
        proto_time_format_iso8601(first, from, sizeof from);
        proto_time_format_iso8601(last, to, sizeof to);
        if (n == 1)
            return forecast_refuse(error, FORECAST_ERR_TIME, 0,
                                   "%s is not the forecast's one step, valid %s", when, from);
        return forecast_refuse(error, FORECAST_ERR_TIME, 0,
                               "%s is outside the forecast: its %d steps cover %s to %s", when, n,
                               from, to);
    }
    int after = 0;
    while (forecast->steps[after].valid_unix_s < unix_s)
        after++;
    int before = forecast->steps[after].valid_unix_s == unix_s ? after : after - 1;
    memset(moment, 0, sizeof *moment);
    moment->step_before = before;
    moment->step_after = after;
    moment->before_unix_s = forecast->steps[before].valid_unix_s;
    moment->after_unix_s = forecast->steps[after].valid_unix_s;
    forecast_series_sample(forecast, before, &moment->sample);
    if (before == after)
        return true;
    struct forecast_sample *next = malloc(sizeof *next);
    if (!next)
        return forecast_refuse(error, FORECAST_ERR_MEMORY, 0, "out of memory");
    forecast_series_sample(forecast, after, next);
    double w = (unix_s - moment->before_unix_s) / (moment->after_unix_s - moment->before_unix_s);
    moment->weight = w;
    struct forecast_sample *s = &moment->sample;
    s->valid_unix_s = unix_s;
    s->low_cover = lerp(s->low_cover, next->low_cover, w);
    s->medium_cover = lerp(s->medium_cover, next->medium_cover, w);
    s->high_cover = lerp(s->high_cover, next->high_cover, w);
    s->total_cover = lerp(s->total_cover, next->total_cover, w);
    s->temperature_c = lerp(s->temperature_c, next->temperature_c, w);
    s->dew_point_c = lerp(s->dew_point_c, next->dew_point_c, w);
    s->wind_u_m_s = lerp(s->wind_u_m_s, next->wind_u_m_s, w);
    s->wind_v_m_s = lerp(s->wind_v_m_s, next->wind_v_m_s, w);
    int cells = s->grid_size * s->grid_size;
    lerp_cells(s->low_grid, next->low_grid, w, cells);
    lerp_cells(s->medium_grid, next->medium_grid, w, cells);
    lerp_cells(s->high_grid, next->high_grid, w, cells);
    if (forecast->info.precipitation_source == FORECAST_PRECIP_RATE) {
        s->precipitation_mm_h = lerp(s->precipitation_mm_h, next->precipitation_mm_h, w);
        lerp_cells(s->precipitation_grid, next->precipitation_grid, w, cells);
    } else {
        /* From tp, the mean rate over the interval that ends at the step after. */
        s->precipitation_mm_h = next->precipitation_mm_h;
        memcpy(s->precipitation_grid, next->precipitation_grid,
               (size_t)cells * sizeof *s->precipitation_grid);
    }
    free(next);
    forecast_sample_derive(s);
    return true;
}
