/* The forecast folder (weather.forecast_dir) and what the world follows from it while
 * weather.source is "forecast". The folder is looked at every poll_s on a thread of its own
 * (forecast_watch.h): when its files (*.grib2, *.grb2: names, sizes, times) or the world's
 * place change, the newest file that reads (forecast.h) for the world's place and map square
 * becomes the forecast, taken up at the render thread's next poll once read; a refused file is
 * logged with the reader's error and the forecast in use stays. Following, each plan is a
 * weather transition from the weather as it stands to the forecast a blend ahead on the
 * world's clock, planned again when it ends, when the forecast changes or when anything else
 * changed the state. Only the render thread calls these. */
#ifndef SKYD_FORECAST_FEED_H
#define SKYD_FORECAST_FEED_H

#include <stdbool.h>
#include <stddef.h>

#include "service_metrics.h"
#include "weather_map.h"
#include "world_state.h"

/* Simulated seconds of a plan's transition at least, and wall seconds of the clock's pace at
 * least (a fast clock plans less often). */
#define FORECAST_FEED_BLEND_S 300.0
#define FORECAST_FEED_BLEND_WALL_S 10.0
/* The forecast's weather map is made again when the clock moved this many simulated seconds,
 * and this many wall seconds passed, since the last one. */
#define FORECAST_FEED_MAP_STEP_S 60.0
#define FORECAST_FEED_MAP_WALL_S 1.0

struct forecast_feed_params {
    const char *dir;
    double poll_s;
    struct service_metrics *metrics; /* the status is published there; may be NULL */
    /* Called from the folder's thread when a look found something (wakes the render thread). */
    void (*ready)(void *user);
    void *user;
};

struct forecast_feed;

/* NULL with the reason when memory is out or the folder's thread cannot start. Nothing is read
 * before the first poll. */
struct forecast_feed *forecast_feed_create(const struct forecast_feed_params *params, char *err,
                                           size_t errlen);
void forecast_feed_destroy(struct forecast_feed **feed);

/* Takes up what the folder's thread read since the last call, and asks it to look at the
 * folder for the place of `live` when a poll is due (now_s: CLOCK_MONOTONIC seconds); never
 * waits for a read. Returns when it should be called again. */
double forecast_feed_poll(struct forecast_feed *feed, double now_s,
                          const struct proto_world_state *live);

/* Whether a forecast is in use; when not, why (for a refused weather.source "forecast"). */
bool forecast_feed_loaded(const struct forecast_feed *feed, char *why, size_t capacity);

/* What following the forecast makes of `live`: true with *next the change to commit (a new
 * transition), false when nothing is to change now (not following, the plan under way, or the
 * clock outside the forecast's steps: reported, the weather left as it is). */
bool forecast_feed_plan(struct forecast_feed *feed, const struct proto_world_state *live,
                        struct proto_world_state *next);
/* While following, with the clock within the steps: the forecast's coverage grid at the clock
 * of `live` as a weather map (forecast_weather_map), when one is due: the first, one of a
 * new forecast, or FORECAST_FEED_MAP_STEP_S on the clock and FORECAST_FEED_MAP_WALL_S on
 * now_s (CLOCK_MONOTONIC) after the last. false when none is due; the caller frees *map. */
bool forecast_feed_map(struct forecast_feed *feed, const struct proto_world_state *live,
                       double now_s, struct proto_weather_map *map);

/* The revision that the plan's commit made the live one: a later revision means something
 * else changed the state, and the plan is made again over it. */
void forecast_feed_planned(struct forecast_feed *feed, unsigned long long revision);

#endif
