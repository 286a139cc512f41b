/* The forecast folder and the world following it (forecast_feed.h). */
#include "forecast_feed.h"

#include <dirent.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/stat.h>

#include <cjson/cJSON.h>

#include "field_errors.h"
#include "forecast.h"
#include "log.h"
#include "utc_time.h"
#include "world_sim.h"

/* Files of the folder looked at, and refused files remembered so as not to read them again
 * until they change. */
#define MAX_FILES 64
#define MAX_REFUSED 32

struct file_mark {
    char name[256];
    long long size;
    long long mtime_ns;
};

struct forecast_feed {
    char dir[256];
    double poll_s, next_poll_s;
    struct service_metrics *metrics;
    uint64_t signature; /* the folder's files as last looked at */
    bool scanned;
    struct sky_forecast *forecast; /* in use, or NULL */
    struct file_mark loaded;       /* its file */
    struct sky_forecast_request request;
    unsigned generation; /* counts the forecasts taken into use */
    struct file_mark refused[MAX_REFUSED];
    int refused_count;
    /* The plan: the forecast, the revision and the simulated time it holds for. */
    unsigned planned_generation;
    unsigned long long planned_revision;
    double planned_until;
    struct service_metrics_forecast status;
};

struct forecast_feed *forecast_feed_create(const struct forecast_feed_params *params)
{
    struct forecast_feed *feed = calloc(1, sizeof *feed);
    if (!feed)
        return NULL;
    snprintf(feed->dir, sizeof feed->dir, "%s", params->dir);
    feed->poll_s = params->poll_s > 0 ? params->poll_s : 5.0;
    feed->metrics = params->metrics;
    feed->status.configured = true;
    feed->status.in_range = true;
    snprintf(feed->status.dir, sizeof feed->status.dir, "%s", params->dir);
    service_metrics_forecast(feed->metrics, &feed->status);
    return feed;
}

void forecast_feed_destroy(struct forecast_feed **feed_ptr)
{
    struct forecast_feed *feed = *feed_ptr;
    *feed_ptr = NULL;
    if (!feed)
        return;
    sky_forecast_free(feed->forecast);
    free(feed);
}

static bool forecast_name(const char *name)
{
    size_t n = strlen(name);
    return name[0] != '.' && ((n > 6 && strcasecmp(name + n - 6, ".grib2") == 0) ||
                              (n > 5 && strcasecmp(name + n - 5, ".grb2") == 0));
}

static uint64_t fnv(uint64_t h, const void *bytes, size_t n)
{
    const unsigned char *p = bytes;
    for (size_t i = 0; i < n; i++)
        h = (h ^ p[i]) * 1099511628211ull;
    return h;
}

static int newest_first(const void *a, const void *b)
{
    const struct file_mark *x = a, *y = b;
    if (x->mtime_ns != y->mtime_ns)
        return x->mtime_ns > y->mtime_ns ? -1 : 1;
    return strcmp(y->name, x->name);
}

/* The folder's forecast files, newest first, and their signature; -1 when it cannot be read. */
static int list_files(const struct forecast_feed *feed, struct file_mark *files, uint64_t *sig)
{
    DIR *d = opendir(feed->dir);
    if (!d)
        return -1;
    int count = 0;
    uint64_t h = 14695981039346656037ull;
    struct dirent *entry;
    while ((entry = readdir(d)) != NULL) {
        if (!forecast_name(entry->d_name) || strlen(entry->d_name) >= sizeof files[0].name)
            continue;
        char path[560];
        struct stat st;
        snprintf(path, sizeof path, "%s/%s", feed->dir, entry->d_name);
        if (stat(path, &st) != 0 || !S_ISREG(st.st_mode))
            continue;
        struct file_mark mark = { .size = (long long)st.st_size,
                                  .mtime_ns = (long long)st.st_mtim.tv_sec * 1000000000ll +
                                              st.st_mtim.tv_nsec };
        snprintf(mark.name, sizeof mark.name, "%s", entry->d_name);
        if (count < MAX_FILES) {
            files[count++] = mark;
            continue;
        }
        int oldest = 0; /* a folder that keeps many runs: the newest MAX_FILES */
        for (int i = 1; i < count; i++)
            if (newest_first(&files[i], &files[oldest]) > 0)
                oldest = i;
        if (newest_first(&mark, &files[oldest]) < 0)
            files[oldest] = mark;
    }
    closedir(d);
    qsort(files, (size_t)count, sizeof files[0], newest_first);
    for (int i = 0; i < count; i++)
        h = fnv(h, &files[i], sizeof files[i]);
    *sig = h;
    return count;
}

static bool same_mark(const struct file_mark *a, const struct file_mark *b)
{
    return a->size == b->size && a->mtime_ns == b->mtime_ns && strcmp(a->name, b->name) == 0;
}

static bool same_request(const struct sky_forecast_request *a, const struct sky_forecast_request *b)
{
    return a->lat_deg == b->lat_deg && a->lon_deg == b->lon_deg && a->extent_km == b->extent_km &&
           a->grid_size == b->grid_size;
}

static bool was_refused(const struct forecast_feed *feed, const struct file_mark *f)
{
    for (int i = 0; i < feed->refused_count; i++)
        if (same_mark(&feed->refused[i], f))
            return true;
    return false;
}

static void refuse(struct forecast_feed *feed, const struct file_mark *f,
                   const struct sky_forecast_error *error)
{
    if (feed->refused_count == MAX_REFUSED)
        feed->refused_count = 0;
    feed->refused[feed->refused_count++] = *f;
    feed->status.refusals++;
    snprintf(feed->status.error, sizeof feed->status.error, "%.255s: %.383s", f->name, error->text);
    skyd_log(SKYD_LOG_WARNING, "forecast %s/%s refused: %s%s", feed->dir, f->name, error->text,
             feed->forecast ? "; the forecast in use stays" : "");
}

static void take(struct forecast_feed *feed, struct sky_forecast *forecast,
                 const struct file_mark *f, const struct sky_forecast_request *request)
{
    sky_forecast_free(feed->forecast);
    feed->forecast = forecast;
    feed->loaded = *f;
    feed->request = *request;
    feed->generation++;
    const struct sky_forecast_info *info = sky_forecast_info(forecast);
    struct service_metrics_forecast *s = &feed->status;
    s->loaded = true;
    snprintf(s->file, sizeof s->file, "%.255s", f->name);
    s->run_unix_s = info->reference_unix_s;
    s->steps = info->step_count;
    s->first_step_unix_s = sky_forecast_step_unix(forecast, 0);
    s->last_step_unix_s = sky_forecast_step_unix(forecast, info->step_count - 1);
    s->error[0] = '\0';
    s->loads++;
    char first[32], last[32];
    sky_time_format_iso8601(s->first_step_unix_s, first, sizeof first);
    sky_time_format_iso8601(s->last_step_unix_s, last, sizeof last);
    skyd_log(SKYD_LOG_INFO, "forecast %s/%s in use: %d steps from %s to %s", feed->dir, f->name,
             s->steps, first, last);
}

/* The newest file that reads for `request`, unless the one in use is newer than every other
 * that does. A place that changed drops a forecast none of them reads for. */
static void load_newest(struct forecast_feed *feed, const struct file_mark *files, int count,
                        const struct sky_forecast_request *request, bool place_changed)
{
    for (int i = 0; i < count; i++) {
        const struct file_mark *f = &files[i];
        if (feed->forecast && !place_changed && same_mark(f, &feed->loaded))
            return;
        if (was_refused(feed, f))
            continue;
        char path[560];
        snprintf(path, sizeof path, "%.255s/%.255s", feed->dir, f->name);
        struct sky_forecast_error error;
        struct sky_forecast *forecast = sky_forecast_read(path, request, &error);
        if (forecast) {
            take(feed, forecast, f, request);
            return;
        }
        refuse(feed, f, &error);
    }
    if (place_changed && feed->forecast) {
        skyd_log(SKYD_LOG_WARNING, "no forecast in %s covers the world's place: none in use",
                 feed->dir);
        sky_forecast_free(feed->forecast);
        feed->forecast = NULL;
        feed->status.loaded = false;
        feed->generation++;
    }
}

double forecast_feed_poll(struct forecast_feed *feed, double now_s,
                          const struct sky_world_state *live)
{
    if (now_s < feed->next_poll_s)
        return feed->next_poll_s;
    feed->next_poll_s = now_s + feed->poll_s;
    struct sky_forecast_request request = { .lat_deg = live->location.latitude_deg,
                                            .lon_deg = live->location.longitude_deg,
                                            .extent_km = live->weather.map_extent_km,
                                            .grid_size = SKY_FORECAST_DEFAULT_GRID };
    bool place_changed = feed->forecast && !same_request(&request, &feed->request);
    struct file_mark files[MAX_FILES];
    uint64_t sig = 0;
    int count = list_files(feed, files, &sig);
    if (count < 0) {
        if (!feed->scanned || feed->signature != 0)
            skyd_log(SKYD_LOG_WARNING, "forecast folder %s cannot be read", feed->dir);
        snprintf(feed->status.error, sizeof feed->status.error, "the folder cannot be read");
        feed->signature = 0;
    } else if (!feed->scanned || sig != feed->signature || place_changed) {
        if (place_changed)
            feed->refused_count = 0;
        feed->signature = sig;
        load_newest(feed, files, count, &request, place_changed);
    }
    feed->scanned = true;
    service_metrics_forecast(feed->metrics, &feed->status);
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
    sky_time_format_iso8601(t0, now, sizeof now);
    sky_time_format_iso8601(first, from, sizeof from);
    sky_time_format_iso8601(last, to, sizeof to);
    skyd_log(SKYD_LOG_WARNING,
             "the world's clock %s is outside forecast %s (%s to %s): the weather stays as it is",
             now, feed->loaded.name, from, to);
}

/* The forecast at t1 as the weather `live` moves to from t0. */
static bool transition_to(const struct forecast_feed *feed, const struct sky_world_state *live,
                          double t0, double t1, struct sky_world_state *next)
{
    struct sky_forecast_moment moment;
    struct sky_forecast_error error;
    if (!sky_forecast_at(feed->forecast, t1, &moment, &error))
        return false;
    cJSON *patch = NULL, *unmapped = NULL;
    if (!sky_forecast_patch(feed->forecast, &moment.sample, &patch, &unmapped))
        return false;
    struct sky_world_state applied = *live;
    struct sky_field_errors errors;
    bool ok = sky_world_state_apply_json(&applied, patch, &errors);
    cJSON_Delete(patch);
    cJSON_Delete(unmapped);
    if (!ok) {
        skyd_log(SKYD_LOG_WARNING, "forecast %s: %s %s", feed->loaded.name,
                 errors.count ? errors.items[0].pointer : "",
                 errors.count ? errors.items[0].reason : "");
        return false;
    }
    struct sky_weather_params now, goal;
    sky_weather_params_get(live, &now);
    sky_weather_params_get(&applied, &goal);
    *next = applied;
    sky_weather_params_put(next, &now);
    world_sim_start_transition(next, &goal, t1 - t0 >= 1.0 ? t1 - t0 : 0.0);
    return true;
}

bool forecast_feed_plan(struct forecast_feed *feed, const struct sky_world_state *live,
                        struct sky_world_state *next)
{
    bool following = live->weather.source == SKY_WEATHER_SOURCE_FORECAST && feed->forecast;
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
    const struct sky_forecast_info *info = sky_forecast_info(feed->forecast);
    double first = sky_forecast_step_unix(feed->forecast, 0);
    double last = sky_forecast_step_unix(feed->forecast, info->step_count - 1);
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
