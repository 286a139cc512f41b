/* The forecast folder and the world following it (forecast_feed.h). */
#include "forecast_feed.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cjson/cJSON.h>

#include "field_errors.h"
#include "forecast.h"
#include "forecast_watch.h"
#include "log.h"
#include "utc_time.h"
#include "world_sim.h"

struct forecast_feed {
    char dir[256];
    double poll_s, next_poll_s;
    struct service_metrics *metrics;
    struct forecast_watch *watch;
    struct forecast *forecast; /* in use, or NULL */
    char file[256];            /* its file */
    unsigned generation;       /* counts the forecasts taken into use */
    /* The plan: the forecast, the revision and the simulated time it holds for. */
    unsigned planned_generation;
    unsigned long long planned_revision;
    double planned_until;
    /* The last weather map made: its forecast, its clock and when. */
    unsigned map_generation;
    double map_clock_s, map_made_s;
    struct service_metrics_forecast status;
};

struct forecast_feed *forecast_feed_create(const struct forecast_feed_params *params, char *err,
                                           size_t errlen)
{
    struct forecast_feed *feed = calloc(1, sizeof *feed);
    if (!feed) {
        snprintf(err, errlen, "out of memory for the forecast folder");
        return NULL;
    }
    snprintf(feed->dir, sizeof feed->dir, "%s", params->dir);
    feed->poll_s = params->poll_s > 0 ? params->poll_s : 5.0;
    feed->metrics = params->metrics;
    feed->status.configured = true;
    feed->status.in_range = true;
    snprintf(feed->status.dir, sizeof feed->status.dir, "%s", params->dir);
    struct forecast_watch_params watch = { .dir = params->dir,
                                           .ready = params->ready,
                                           .user = params->user };
    if (!(feed->watch = forecast_watch_create(&watch, err, errlen))) {
        free(feed);
        return NULL;
    }
    service_metrics_forecast(feed->metrics, &feed->status);
    return feed;
}

void forecast_feed_destroy(struct forecast_feed **feed_ptr)
{
    struct forecast_feed *feed = *feed_ptr;
    *feed_ptr = NULL;
    if (!feed)
        return;
    forecast_watch_destroy(&feed->watch);
    forecast_free(feed->forecast);
    free(feed);
}

static void take(struct forecast_feed *feed, const struct forecast_watch_news *news)
{
    struct service_metrics_forecast *s = &feed->status;
    snprintf(s->error, sizeof s->error, "%s", news->error);
    s->refusals = news->refusals;
    if (!news->replaced)
        return;
    forecast_free(feed->forecast);
    feed->forecast = news->forecast;
    feed->generation++;
    s->loaded = feed->forecast != NULL;
    if (!feed->forecast)
        return;
    snprintf(feed->file, sizeof feed->file, "%s", news->file);
    const struct forecast_info *info = forecast_info(feed->forecast);
    snprintf(s->file, sizeof s->file, "%s", news->file);
    s->run_unix_s = info->reference_unix_s;
    s->steps = info->step_count;
    s->first_step_unix_s = forecast_step_unix(feed->forecast, 0);
    s->last_step_unix_s = forecast_step_unix(feed->forecast, info->step_count - 1);
    s->loads++;
    char first[32], last[32];
    proto_time_format_iso8601(s->first_step_unix_s, first, sizeof first);
    proto_time_format_iso8601(s->last_step_unix_s, last, sizeof last);
    skyd_log(SKYD_LOG_INFO, "forecast %s/%s in use: %d steps from %s to %s (read in %.2f s)",
             feed->dir, news->file, s->steps, first, last, news->read_s);
}

double forecast_feed_poll(struct forecast_feed *feed, double now_s,
                          const struct proto_world_state *live)
{
    struct forecast_watch_news news;
    if (forecast_watch_take(feed->watch, &news)) {
        take(feed, &news);
        service_metrics_forecast(feed->metrics, &feed->status);
    }
    if (now_s < feed->next_poll_s)
        return feed->next_poll_s;
    feed->next_poll_s = now_s + feed->poll_s;
    struct forecast_request request = { .lat_deg = live->location.latitude_deg,
                                        .lon_deg = live->location.longitude_deg,
                                        .extent_km = live->weather.map_extent_km,
                                        .grid_size = FORECAST_DEFAULT_GRID };
    forecast_watch_look(feed->watch, &request);
    return feed->next_poll_s;
}

bool forecast_feed_loaded(const struct forecast_feed *feed, char *why, size_t capacity)
{
    if (feed && feed->forecast)
        return true;
    if (!feed)
        snprintf(why, capacity, "no forecast folder is configured (weather.forecast_dir)");
    else if (feed->status.error[0])
        snprintf(why, capacity, "no forecast is loaded from %s: %s", feed->dir, feed->status.error);
    else
        snprintf(why, capacity, "no forecast is loaded from %s: no *.grib2 or *.grb2 file yet",
                 feed->dir);
    return false;
}

/* The clock outside the steps: said once per forecast and revision, the weather kept. */
static void out_of_range(struct forecast_feed *feed, double t0, double first, double last)
{
    bool said = !feed->status.in_range;
    feed->status.in_range = false;
    feed->planned_until = t0 < first ? first : INFINITY;
    service_metrics_forecast(feed->metrics, &feed->status);
    if (said)
        return;
    char now[32], from[32], to[32];
    proto_time_format_iso8601(t0, now, sizeof now);
    proto_time_format_iso8601(first, from, sizeof from);
    proto_time_format_iso8601(last, to, sizeof to);
    skyd_log(SKYD_LOG_WARNING,
             "the world's clock %s is outside forecast %s (%s to %s): the weather stays as it is",
             now, feed->file, from, to);
}

/* The forecast at t1 as the weather `live` moves to from t0. */
static bool transition_to(const struct forecast_feed *feed, const struct proto_world_state *live,
                          double t0, double t1, struct proto_world_state *next)
{
    struct forecast_moment moment;
    struct forecast_error error;
    if (!forecast_at(feed->forecast, t1, &moment, &error))
        return false;
    cJSON *patch = NULL, *unmapped = NULL;
    if (!forecast_patch(feed->forecast, &moment.sample, &patch, &unmapped))
        return false;
    struct proto_world_state applied = *live;
    struct proto_field_errors errors;
    bool ok = proto_world_state_apply_json(&applied, patch, &errors);
    cJSON_Delete(patch);
    cJSON_Delete(unmapped);
    if (!ok) {
        skyd_log(SKYD_LOG_WARNING, "forecast %s: %s %s", feed->file,
                 errors.count ? errors.items[0].pointer : "",
                 errors.count ? errors.items[0].reason : "");
        return false;
    }
    struct proto_weather_params now, goal;
    proto_weather_params_get(live, &now);
    proto_weather_params_get(&applied, &goal);
    *next = applied;
    proto_weather_params_put(next, &now);
    world_sim_start_transition(next, &goal, t1 - t0 >= 1.0 ? t1 - t0 : 0.0);
    return true;
}

bool forecast_feed_plan(struct forecast_feed *feed, const struct proto_world_state *live,
                        struct proto_world_state *next)
{
    bool following = live->weather.source == PROTO_WEATHER_SOURCE_FORECAST && feed->forecast;
    if (following != feed->status.following) {
        feed->status.following = following;
        feed->status.in_range = true;
        service_metrics_forecast(feed->metrics, &feed->status);
    }
    if (!following) {
        feed->planned_revision = 0;
        return false;
    }
    double t0 = live->clock.utc_unix_s;
    if (feed->planned_generation == feed->generation && feed->planned_revision == live->revision &&
        t0 < feed->planned_until)
        return false;
    feed->planned_generation = feed->generation;
    feed->planned_revision = live->revision;
    const struct forecast_info *info = forecast_info(feed->forecast);
    double first = forecast_step_unix(feed->forecast, 0);
    double last = forecast_step_unix(feed->forecast, info->step_count - 1);
    if (t0 < first || t0 > last) {
        out_of_range(feed, t0, first, last);
        return false;
    }
    if (!feed->status.in_range) {
        feed->status.in_range = true;
        service_metrics_forecast(feed->metrics, &feed->status);
    }
    double scale = live->clock.time_scale;
    double blend = scale > 0 ? fmax(FORECAST_FEED_BLEND_S, scale * FORECAST_FEED_BLEND_WALL_S) : 0;
    double t1 = fmin(t0 + blend, last);
    feed->planned_until = t1 - t0 >= 1.0 ? t1 : scale > 0 ? last + 1.0 : INFINITY;
    return transition_to(feed, live, t0, t1, next);
}

void forecast_feed_planned(struct forecast_feed *feed, unsigned long long revision)
{
    feed->planned_revision = revision;
}

bool forecast_feed_map(struct forecast_feed *feed, const struct proto_world_state *live,
                       double now_s, struct proto_weather_map *map)
{
    if (live->weather.source != PROTO_WEATHER_SOURCE_FORECAST || !feed->forecast)
        return false;
    double t = live->clock.utc_unix_s;
    bool fresh = feed->map_generation != feed->generation;
    if (!fresh && (fabs(t - feed->map_clock_s) < FORECAST_FEED_MAP_STEP_S ||
                   now_s - feed->map_made_s < FORECAST_FEED_MAP_WALL_S))
        return false;
    struct forecast_moment *moment = malloc(sizeof *moment);
    struct forecast_error error;
    bool made = moment && forecast_at(feed->forecast, t, moment, &error) &&
                forecast_weather_map(&moment->sample, live->weather.map_extent_km,
                                     live->weather.offset_east_km, live->weather.offset_north_km,
                                     map);
    free(moment);
    feed->map_generation = feed->generation; /* a clock outside the steps: tried again later */
    feed->map_clock_s = t;
    feed->map_made_s = now_s;
    if (made && map->width <= SERVICE_METRICS_FORECAST_MAP_SIDE &&
        map->height <= SERVICE_METRICS_FORECAST_MAP_SIDE) {
        feed->status.map_width = map->width;
        feed->status.map_height = map->height;
        memcpy(feed->status.map_rgba, map->rgba, (size_t)map->width * map->height * 4);
        service_metrics_forecast(feed->metrics, &feed->status);
    }
    return made;
}
