/* The daemon's counters and gauges for operators: frames, messages, errors, device losses, the
 * render thread's heartbeat. Written by the render thread, the encoder workers and the service
 * thread, read by the service thread for GET /metrics (Prometheus text exposition 0.0.4) and
 * GET /healthz. Every call is thread-safe. */
#ifndef SKYD_SERVICE_METRICS_H
#define SKYD_SERVICE_METRICS_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "error_text.h"
#include "messages.h"

struct service_metrics;

struct service_metrics *service_metrics_create(void);
void service_metrics_destroy(struct service_metrics **metrics);

/* A view rendered (render_seconds: the render call's wall time, encoding not included). */
void service_metrics_frame_rendered(struct service_metrics *m, double render_seconds);
/* A frame of `bytes` (its binary message or HTTP body) written to a client (WebSocket or HTTP). */
void service_metrics_frame_sent(struct service_metrics *m, size_t bytes);
/* A subscription's frame that was due but not rendered: its client had not taken the last one. */
void service_metrics_frame_skipped(struct service_metrics *m);
/* A client message by its type; PROTO_MSG_NONE for one that could not be parsed. */
void service_metrics_message(struct service_metrics *m, enum proto_msg_type type);
/* An error answered to a client. */
void service_metrics_error(struct service_metrics *m, enum proto_msg_error_code code);
void service_metrics_device_lost(struct service_metrics *m);

/* The render thread's view of the world, once per tick: also its heartbeat. */
struct service_metrics_tick {
    double at_s; /* CLOCK_MONOTONIC seconds */
    uint64_t state_revision;
    size_t subscriptions;
    double lut_rebuild_progress; /* 0..1, 1 when no rebuild is under way */
    /* A shared world's feed: -1 without one, else whether it is connected to Redis now, and
     * how many times it connected since start. */
    int cluster_connected;
    unsigned cluster_connections;
};
void service_metrics_tick(struct service_metrics *m, const struct service_metrics_tick *tick);
/* Every subscription's traffic as of this tick (frame_scheduler_session_stats), for the
 * per-subscription families; at most SERVICE_METRICS_MAX_SUBSCRIPTIONS are kept. */
#define SERVICE_METRICS_MAX_SUBSCRIPTIONS 256
void service_metrics_subscriptions(struct service_metrics *m,
                                   const struct proto_msg_subscription_stats *stats, size_t count);

/* The forecast's weather map is at most this many texels a side (FORECAST_MAX_GRID). */
#define SERVICE_METRICS_FORECAST_MAP_SIDE 32
/* The forecast folder's state (weather.forecast_dir), as the render thread last published it:
 * for GET /api/weather/forecast and the skyd_forecast_* families. Times are unix seconds. */
struct service_metrics_forecast {
    bool configured;   /* a folder is configured */
    char dir[256];     /* the folder */
    bool loaded;       /* a forecast is in use */
    char file[256];    /* its file's name in the folder */
    double run_unix_s; /* the run's reference time */
    int steps;
    double first_step_unix_s, last_step_unix_s;
    bool following;   /* weather.source is "forecast" */
    bool in_range;    /* the world's clock is within the steps (while following) */
    error_text error; /* the last refusal: the file and the reader's error; "" none */
    uint64_t loads, refusals;
    /* The last weather map made of the forecast's cover grid (while following; 0 x 0 none):
     * RGBA8 texels as set_weather_map's, row-major from the north-west corner. */
    unsigned map_width, map_height;
    unsigned char
        map_rgba[SERVICE_METRICS_FORECAST_MAP_SIDE * SERVICE_METRICS_FORECAST_MAP_SIDE * 4];
};
void service_metrics_forecast(struct service_metrics *m, const struct service_metrics_forecast *f);
struct service_metrics_forecast service_metrics_last_forecast(struct service_metrics *m);

/* The last tick (at_s 0 before the first). */
struct service_metrics_tick service_metrics_last_tick(struct service_metrics *m);

/* The exposition text (malloc'd, NUL-terminated) with `clients` as the skyd_clients gauge;
 * NULL when memory is out. */
char *service_metrics_exposition(struct service_metrics *m, int clients);

#endif
