/* A forecast's steps as the reader fills them: each field's values over the window around the
 * place, in the units the sky uses; then the checks that every step has what is needed, the
 * accumulated precipitation turned into rates, and the samples per step and between steps.
 * Pure functions: forecast_grib.c fills the steps from the file. */
#ifndef SKYD_FORECAST_SERIES_H
#define SKYD_FORECAST_SERIES_H

#include <stdbool.h>

#include "forecast.h"
#include "forecast_grid.h"

/* The fields read, by what they are (forecast_grib.c maps shortName and level to them). */
enum forecast_field {
    FIELD_TCC,   /* total cloud cover, 0..1 */
    FIELD_LCC,   /* low cloud cover, 0..1 */
    FIELD_MCC,   /* medium cloud cover, 0..1 */
    FIELD_HCC,   /* high cloud cover, 0..1 */
    FIELD_2T,    /* 2 m temperature, C */
    FIELD_2D,    /* 2 m dew point, C */
    FIELD_10U,   /* 10 m wind towards east, m/s */
    FIELD_10V,   /* 10 m wind towards north, m/s */
    FIELD_U850,  /* 850 hPa wind towards east, m/s */
    FIELD_V850,  /* 850 hPa wind towards north, m/s */
    FIELD_PRATE, /* precipitation rate, mm/h */
    FIELD_TP,    /* total precipitation accumulated since tp_start_unix_s, mm; a rate, mm/h,
                  * once forecast_series_finish has run */
    FIELD_COUNT,
};

/* "lcc", "10u", "u at 850 hPa", ... */
const char *forecast_field_name(enum forecast_field field);

struct forecast_step {
    double valid_unix_s;
    int message[FIELD_COUNT];    /* 1-based message each field came from; 0: absent */
    double *values[FIELD_COUNT]; /* window rows x columns, row-major; NULL when absent */
    double tp_start_unix_s;      /* where the tp accumulation starts */
    bool prate_instant;          /* prate is the rate at the step, not a mean before it */
};

struct forecast {
    struct forecast_info info;
    struct forecast_window window;
    bool total_cover_known; /* tcc at every step */
    int step_count, step_capacity;
    struct forecast_step *steps; /* sorted by validity time once finished */
};

/* A forecast for the request on `grid`, with no step yet; NULL when memory is out. The window
 * and points come from forecast_window_locate. */
struct forecast *forecast_series_new(const struct forecast_request *request,
                                     const struct forecast_grid_info *grid,
                                     const struct forecast_window *window,
                                     const struct forecast_points *points);

/* The step valid at valid_unix_s, added when new; NULL (with *error) when there would be more
 * than FORECAST_MAX_STEPS, or too many values in all, or memory is out. */
struct forecast_step *forecast_series_step(struct forecast *forecast, double valid_unix_s,
                                           struct forecast_error *error);

/* The window's values of `field` at `step`, allocated, for message `message` to fill; NULL
 * with *error when that step already has the field (naming both messages) or memory is out. */
double *forecast_series_field(struct forecast *forecast, struct forecast_step *step,
                              enum forecast_field field, int message, struct forecast_error *error);

/* Sorts the steps, picks the wind (10 m, else 850 hPa) and precipitation (prate, else tp)
 * every step has, checks that every step has the cloud covers, 2t and 2d (naming the first
 * missing field and its step), and turns tp into rates. false with *error otherwise. */
bool forecast_series_finish(struct forecast *forecast, struct forecast_error *error);

/* The sample of step `index` of a finished forecast. */
void forecast_series_sample(const struct forecast *forecast, int index,
                            struct forecast_sample *sample);

/* Relative humidity, wind speed and direction of a sample from its means. */
void forecast_sample_derive(struct forecast_sample *sample);

/* Sets *error's code, message index and text (printf format). Returns false. */
bool forecast_refuse(struct forecast_error *error, enum forecast_error_code code, int message,
                     const char *format, ...) __attribute__((format(printf, 4, 5)));

#endif
