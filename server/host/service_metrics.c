#include "service_metrics.h"

#include <pthread.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#ifdef __GLIBC__
#include <malloc.h>
#endif

/* Room for every message type and error code the protocol names (both enums are far smaller). */
#define MAX_KINDS 48

/* Upper bounds of the render-time buckets, seconds: lavapipe frames take 5-200 ms, a GPU's
 * well under 5 ms, a LUT rebuild or a first compile up to seconds. */
static const double frame_buckets_s[] = { 0.001, 0.0025, 0.005, 0.01, 0.025, 0.05,
                                          0.1,   0.25,   0.5,   1.0,  2.5,   5.0 };
#define BUCKET_COUNT (sizeof frame_buckets_s / sizeof frame_buckets_s[0])

struct counts {
    uint64_t frames_rendered, frames_sent, frames_skipped, device_losses, bytes_sent;
    uint64_t messages[MAX_KINDS];
    uint64_t errors[MAX_KINDS];
    uint64_t frame_bucket[BUCKET_COUNT]; /* per bucket, not cumulative */
    uint64_t frame_count;
    double frame_seconds_sum;
    struct service_metrics_tick tick;
    struct service_metrics_forecast forecast;
};

struct service_metrics {
    pthread_mutex_t lock;
    struct counts c;
    size_t subscription_count;
    struct proto_msg_subscription_stats subscriptions[SERVICE_METRICS_MAX_SUBSCRIPTIONS];
};

struct service_metrics *service_metrics_create(void)
{
    struct service_metrics *m = calloc(1, sizeof *m);
    if (m && pthread_mutex_init(&m->lock, NULL) != 0) {
        free(m);
        return NULL;
    }
    if (m)
        m->c.tick.lut_rebuild_progress = 1.0;
    return m;
}

void service_metrics_destroy(struct service_metrics **metrics)
{
    struct service_metrics *m = *metrics;
    *metrics = NULL;
    if (!m)
        return;
    pthread_mutex_destroy(&m->lock);
    free(m);
}

#define LOCKED(m, statement)                                                                       \
    do {                                                                                           \
        if (!(m))                                                                                  \
            break;                                                                                 \
        pthread_mutex_lock(&(m)->lock);                                                            \
        statement;                                                                                 \
        pthread_mutex_unlock(&(m)->lock);                                                          \
    } while (0)

void service_metrics_frame_rendered(struct service_metrics *m, double render_seconds)
{
    size_t bucket = 0;
    while (bucket < BUCKET_COUNT && render_seconds > frame_buckets_s[bucket])
        bucket++;
    LOCKED(m, {
        m->c.frames_rendered++;
        m->c.frame_count++;
        m->c.frame_seconds_sum += render_seconds;
        if (bucket < BUCKET_COUNT)
            m->c.frame_bucket[bucket]++;
    });
}

void service_metrics_frame_sent(struct service_metrics *m, size_t bytes)
{
    LOCKED(m, {
        m->c.frames_sent++;
        m->c.bytes_sent += bytes;
    });
}

void service_metrics_frame_skipped(struct service_metrics *m)
{
    LOCKED(m, m->c.frames_skipped++);
}

void service_metrics_message(struct service_metrics *m, enum proto_msg_type type)
{
    size_t index = (size_t)type < MAX_KINDS ? (size_t)type : 0;
    LOCKED(m, m->c.messages[index]++);
}

void service_metrics_error(struct service_metrics *m, enum proto_msg_error_code code)
{
    if ((size_t)code >= MAX_KINDS || code == PROTO_MSG_OK)
        code = PROTO_MSG_ERR_INTERNAL;
    LOCKED(m, m->c.errors[code]++);
}

void service_metrics_device_lost(struct service_metrics *m)
{
    LOCKED(m, m->c.device_losses++);
}

void service_metrics_tick(struct service_metrics *m, const struct service_metrics_tick *tick)
{
    LOCKED(m, m->c.tick = *tick);
}

void service_metrics_subscriptions(struct service_metrics *m,
                                   const struct proto_msg_subscription_stats *stats, size_t count)
{
    if (count > SERVICE_METRICS_MAX_SUBSCRIPTIONS)
        count = SERVICE_METRICS_MAX_SUBSCRIPTIONS;
    LOCKED(m, {
        memcpy(m->subscriptions, stats, sizeof *stats * count);
        m->subscription_count = count;
    });
}

struct service_metrics_tick service_metrics_last_tick(struct service_metrics *m)
{
    struct service_metrics_tick tick = { 0 };
    LOCKED(m, tick = m->c.tick);
    return tick;
}

/* ---- the exposition ---- */

struct text {
    char *bytes;
    size_t length, capacity;
    bool failed;
};

void service_metrics_forecast(struct service_metrics *m, const struct service_metrics_forecast *f)
{
    LOCKED(m, m->c.forecast = *f);
}

struct service_metrics_forecast service_metrics_last_forecast(struct service_metrics *m)
{
    struct service_metrics_forecast f = { 0 };
    LOCKED(m, f = m->c.forecast);
    return f;
}

static void append(struct text *t, const char *format, ...)
{
    if (t->failed)
        return;
    for (;;) {
        va_list args;
        va_start(args, format);
        int n = vsnprintf(t->bytes + t->length, t->capacity - t->length, format, args);
        va_end(args);
        if (n < 0) {
            t->failed = true;
            return;
        }
        if ((size_t)n < t->capacity - t->length) {
            t->length += (size_t)n;
            return;
        }
        size_t capacity = t->capacity * 2 + (size_t)n;
        char *grown = realloc(t->bytes, capacity);
        if (!grown) {
            t->failed = true;
            return;
        }
        t->bytes = grown;
        t->capacity = capacity;
    }
}

static void family(struct text *t, const char *name, const char *type, const char *help)
{
    append(t, "# HELP %s %s\n# TYPE %s %s\n", name, help, name, type);
}

static void counter(struct text *t, const char *name, const char *help, uint64_t value)
{
    family(t, name, "counter", help);
    append(t, "%s %llu\n", name, (unsigned long long)value);
}

static void gauge(struct text *t, const char *name, const char *help, double value)
{
    family(t, name, "gauge", help);
    append(t, "%s %.17g\n", name, value);
}

#if defined(__has_feature)
#if __has_feature(address_sanitizer)
#define SKYD_ASAN_ALLOCATOR 1
#endif
#endif
#if defined(__SANITIZE_ADDRESS__)
#define SKYD_ASAN_ALLOCATOR 1
#endif

#ifdef SKYD_ASAN_ALLOCATOR
/* AddressSanitizer replaces malloc, and its mallinfo2 answers zeros; its own allocator
 * interface (sanitizer/allocator_interface.h, which GCC does not install) has the figures. */
size_t __sanitizer_get_current_allocated_bytes(void);
size_t __sanitizer_get_free_bytes(void);
#endif

/* The C heap as the allocator sees it: what the daemon holds, and the free space the
 * allocator keeps (resident until trimmed). Resident memory that grows while the first stays
 * flat is the allocator's, not a leak. mallinfo2 (glibc 2.33) walks every arena's free lists
 * under its lock, once per scrape. */
static void append_heap(struct text *t)
{
#if defined(SKYD_ASAN_ALLOCATOR)
    gauge(t, "skyd_heap_in_use_bytes",
          "Bytes of the C heap in use (AddressSanitizer's allocator: this is a sanitized build).",
          (double)__sanitizer_get_current_allocated_bytes());
    gauge(t, "skyd_heap_free_bytes",
          "Free bytes AddressSanitizer's allocator keeps (a sanitized build).",
          (double)__sanitizer_get_free_bytes());
#elif defined(__GLIBC__) && (__GLIBC__ > 2 || (__GLIBC__ == 2 && __GLIBC_MINOR__ >= 33))
    struct mallinfo2 mi = mallinfo2();
    gauge(t, "skyd_heap_in_use_bytes",
          "Bytes of the C heap in use (glibc's mallinfo2: arenas' allocated chunks and mmap'd "
          "blocks).",
          (double)(mi.uordblks + mi.hblkhd));
    gauge(t, "skyd_heap_free_bytes",
          "Free bytes the C heap keeps in its arenas (glibc's mallinfo2 fordblks).",
          (double)mi.fordblks);
#else
    (void)t;
#endif
}

char *service_metrics_exposition(struct service_metrics *m, int clients)
{
    struct counts copy;
    struct proto_msg_subscription_stats *subscriptions =
        malloc(sizeof *subscriptions * SERVICE_METRICS_MAX_SUBSCRIPTIONS);
    if (!subscriptions)
        return NULL;
    pthread_mutex_lock(&m->lock);
    copy = m->c;
    size_t subscription_count = m->subscription_count;
    memcpy(subscriptions, m->subscriptions, sizeof subscriptions[0] * subscription_count);
    pthread_mutex_unlock(&m->lock);

    struct text t = { .capacity = 4096 };
    t.bytes = malloc(t.capacity);
    if (!t.bytes) {
        free(subscriptions);
        return NULL;
    }
    t.bytes[0] = '\0';
    counter(&t, "skyd_frames_rendered_total",
            "Views rendered (one render serves every "
            "subscriber of the view).",
            copy.frames_rendered);
    counter(&t, "skyd_frames_sent_total", "Frames written to clients.", copy.frames_sent);
    counter(&t, "skyd_bytes_sent_total",
            "Bytes of frames written to clients (WebSocket "
            "messages with their 48-byte header, HTTP bodies).",
            copy.bytes_sent);
    counter(&t, "skyd_frames_skipped_total",
            "Subscription frames that were due but not "
            "rendered because the client had not taken the previous one.",
            copy.frames_skipped);
    family(&t, "skyd_messages_total", "counter",
           "Client messages received, by type "
           "(\"invalid\": not parsed far enough to know it).");
    for (size_t i = 0; i < MAX_KINDS; i++) {
        const char *name = i == 0 ? "invalid" : proto_msg_type_name((enum proto_msg_type)i);
        if (name)
            append(&t, "skyd_messages_total{type=\"%s\"} %llu\n", name,
                   (unsigned long long)copy.messages[i]);
    }
    family(&t, "skyd_errors_total", "counter", "Error replies sent to clients, by code.");
    for (size_t i = 1; i < MAX_KINDS; i++) {
        const char *name = proto_msg_error_name((int)i);
        if (name)
            append(&t, "skyd_errors_total{code=\"%s\"} %llu\n", name,
                   (unsigned long long)copy.errors[i]);
    }
    counter(&t, "skyd_device_losses_total", "Rendering devices lost (and made again).",
            copy.device_losses);
    gauge(&t, "skyd_clients", "Connected WebSocket clients.", clients);
    gauge(&t, "skyd_subscriptions", "Frame subscriptions.", (double)copy.tick.subscriptions);
    gauge(&t, "skyd_state_revision", "Revision of the world state.",
          (double)copy.tick.state_revision);
    append_heap(&t);
    gauge(&t, "skyd_lut_rebuild_progress",
          "Progress of the look-up-table rebuild under way, "
          "0 to 1 (1: none).",
          copy.tick.lut_rebuild_progress);
    if (copy.tick.cluster_connected >= 0) { /* only in cluster mode (docs/SCALING.md) */
        gauge(&t, "skyd_cluster_connected",
              "Whether the shared world's stream is read from "
              "Redis now (1) or not (0).",
              copy.tick.cluster_connected);
        counter(&t, "skyd_cluster_connections_total",
                "Connections of the stream reader to "
                "Redis since start (more than 1: it reconnected).",
                copy.tick.cluster_connections);
    }
    if (copy.forecast.configured) { /* only with weather.forecast_dir */
        gauge(&t, "skyd_forecast_loaded", "Whether a forecast from the folder is in use.",
              copy.forecast.loaded);
        gauge(&t, "skyd_forecast_in_range",
              "Whether the world's clock is within the forecast's steps (1 when not following).",
              !copy.forecast.following || copy.forecast.in_range);
        counter(&t, "skyd_forecast_loads_total", "Forecast files read and taken into use.",
                copy.forecast.loads);
        counter(&t, "skyd_forecast_refusals_total",
                "Forecast files refused (not GRIB2, a field missing, the place outside).",
                copy.forecast.refusals);
    }
    family(&t, "skyd_subscription_bytes_sent_total", "counter",
           "Bytes of frames sent to each "
           "current subscription (its number), headers included.");
    for (size_t i = 0; i < subscription_count; i++)
        append(&t, "skyd_subscription_bytes_sent_total{subscription=\"%llu\"} %llu\n",
               (unsigned long long)subscriptions[i].subscription,
               (unsigned long long)subscriptions[i].bytes_sent);
    family(&t, "skyd_subscription_fps", "gauge",
           "Each current subscription's effective frame "
           "rate (lowered to keep within its max_kbps).");
    for (size_t i = 0; i < subscription_count; i++)
        append(&t, "skyd_subscription_fps{subscription=\"%llu\"} %.17g\n",
               (unsigned long long)subscriptions[i].subscription, subscriptions[i].fps);
    family(&t, "skyd_frame_seconds", "histogram", "Wall time of each view's render, seconds.");
    uint64_t cumulative = 0;
    for (size_t i = 0; i < BUCKET_COUNT; i++) {
        cumulative += copy.frame_bucket[i];
        append(&t, "skyd_frame_seconds_bucket{le=\"%g\"} %llu\n", frame_buckets_s[i],
               (unsigned long long)cumulative);
    }
    append(&t, "skyd_frame_seconds_bucket{le=\"+Inf\"} %llu\n",
           (unsigned long long)copy.frame_count);
    append(&t, "skyd_frame_seconds_sum %.17g\n", copy.frame_seconds_sum);
    append(&t, "skyd_frame_seconds_count %llu\n", (unsigned long long)copy.frame_count);
    free(subscriptions);
    if (t.failed) {
        free(t.bytes);
        return NULL;
    }
    return t.bytes;
}
