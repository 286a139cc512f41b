#include "cluster_feed.h"

#include <inttypes.h>
#include <math.h>
#include <pthread.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "cluster_redis.h"
#include "cluster_url.h"
#include "error_text.h"

static const double CONNECT_TIMEOUT_S = 1.0;
static const double COMMAND_TIMEOUT_S = 3.0; /* longer than a blocked read */
static const int BLOCK_MS = 500;             /* how long destroy may wait for the thread */
static const double RETRY_MIN_S = 0.05, RETRY_MAX_S = 2.0;

struct cluster_feed {
    struct cluster_address address;
    struct cluster_keys keys;
    char world[CLUSTER_WORLD_MAX + 1];
    void (*wake)(void *user);
    void *user;
    struct cluster_log log;
    pthread_t thread;
    bool started;

    pthread_mutex_t lock;
    pthread_cond_t changed; /* stopping: cuts the back-off short */
    bool stopping;
    bool connected;
    unsigned connections;
    struct cluster_entry *head, *tail;

    /* The feed thread's own: where it reads from. */
    char last_id[CLUSTER_ID_MAX];
    uint64_t last_revision;
};

/* One line about the world, through the sink (or on stderr). */
/* clang-format off */
#if defined(__GNUC__)
__attribute__((format(printf, 3, 4)))
#endif
static void feed_log(const struct cluster_feed *f, enum cluster_log_level level,
                     const char *format, ...)
/* clang-format on */
{
    char line[1024];
    int prefix = snprintf(line, sizeof line, "cluster world \"%s\": ", f->world);
    va_list args;
    va_start(args, format);
    vsnprintf(line + prefix, sizeof line - (size_t)prefix, format, args);
    va_end(args);
    if (f->log.write)
        f->log.write(f->log.user, level, line);
    else
        fprintf(stderr, "skyd: %s\n", line);
}

static struct timespec monotonic_deadline(double after_s)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    double at = (double)t.tv_sec + (double)t.tv_nsec * 1e-9 + after_s;
    double whole = floor(at);
    return (struct timespec){ .tv_sec = (time_t)whole, .tv_nsec = (long)((at - whole) * 1e9) };
}

static void queue(struct cluster_feed *f, struct cluster_entry *e)
{
    snprintf(f->last_id, sizeof f->last_id, "%s", e->id);
    f->last_revision = e->revision;
    pthread_mutex_lock(&f->lock);
    if (f->tail)
        f->tail->next = e;
    else
        f->head = e;
    f->tail = e;
    pthread_mutex_unlock(&f->lock);
}

static bool stopping(struct cluster_feed *f)
{
    pthread_mutex_lock(&f->lock);
    bool stop = f->stopping;
    pthread_mutex_unlock(&f->lock);
    return stop;
}

static void set_connected(struct cluster_feed *f, bool connected)
{
    pthread_mutex_lock(&f->lock);
    if (connected && !f->connected)
        f->connections++;
    f->connected = connected;
    pthread_mutex_unlock(&f->lock);
}

/* The stream does not go on from where the node is: the whole world instead. */
static bool queue_snapshot(struct cluster_feed *f, redisContext *c)
{
    error_text why;
    bool absent = false;
    struct cluster_entry *e = cluster_redis_snapshot(c, &f->keys, 0, NULL, &absent, why,
                                                     sizeof why);
    if (!e) {
        feed_log(f, CLUSTER_LOG_ERROR, "cannot read the snapshot: %s", why);
        return false;
    }
    feed_log(f, CLUSTER_LOG_INFO, "catching up from the snapshot at revision %" PRIu64,
             e->revision);
    queue(f, e);
    return true;
}

/* One XREAD from last_id: queues what came, in order. false: the connection failed. */
static bool read_once(struct cluster_feed *f, redisContext *c, int block_ms)
{
    redisReply *r = redisCommand(c, "XREAD COUNT 64 BLOCK %d STREAMS %s %s", block_ms,
                                 f->keys.stream, f->last_id);
    if (!r || r->type == REDIS_REPLY_ERROR) {
        error_text why;
        cluster_redis_describe(c, r, why, sizeof why);
        feed_log(f, CLUSTER_LOG_WARNING, "reading the stream: %s", why);
        if (r)
            freeReplyObject(r);
        return false;
    }
    bool ok = true, woke = false;
    if (r->type == REDIS_REPLY_ARRAY && r->elements == 1 &&
        r->element[0]->type == REDIS_REPLY_ARRAY && r->element[0]->elements == 2) {
        const redisReply *items = r->element[0]->element[1];
        for (size_t i = 0; ok && items->type == REDIS_REPLY_ARRAY && i < items->elements; i++) {
            error_text why;
            struct cluster_entry *e = cluster_redis_parse_entry(items->element[i], why, sizeof why);
            if (!e) {
                feed_log(f, CLUSTER_LOG_ERROR, "%s", why);
                ok = false;
            } else if (e->revision <= f->last_revision) {
                snprintf(f->last_id, sizeof f->last_id, "%s", e->id); /* already applied */
                cluster_entry_free(e);
            } else if (e->revision != f->last_revision + 1) {
                feed_log(f, CLUSTER_LOG_WARNING,
                         "the stream jumps from revision %" PRIu64 " to %" PRIu64, f->last_revision,
                         e->revision);
                cluster_entry_free(e);
                ok = queue_snapshot(f, c);
                woke = true;
                break;
            } else {
                queue(f, e);
                woke = true;
            }
        }
    }
    freeReplyObject(r);
    if (woke && f->wake)
        f->wake(f->user);
    return ok;
}

/* After a (re)connection: whether the stream still holds the entry after last_id. The
 * oldest entry kept tells: a node behind it takes the snapshot. */
static bool catch_up(struct cluster_feed *f, redisContext *c)
{
    redisReply *r = redisCommand(c, "XRANGE %s - + COUNT 1", f->keys.stream);
    if (!r || r->type != REDIS_REPLY_ARRAY) {
        if (r)
            freeReplyObject(r);
        return false;
    }
    bool ok = true;
    if (r->elements == 1) {
        error_text why;
        struct cluster_entry *oldest = cluster_redis_parse_entry(r->element[0], why, sizeof why);
        if (oldest && oldest->revision > f->last_revision + 1) {
            ok = queue_snapshot(f, c);
            if (ok && f->wake)
                f->wake(f->user);
        }
        cluster_entry_free(oldest);
    }
    freeReplyObject(r);
    return ok;
}

static void *feed_main(void *arg)
{
    struct cluster_feed *f = arg;
    double retry = RETRY_MIN_S;
    unsigned failures = 0; /* connection attempts failed in a row: the first is logged */
    while (!stopping(f)) {
        error_text why;
        redisContext *c = cluster_redis_connect(&f->address, CONNECT_TIMEOUT_S, COMMAND_TIMEOUT_S,
                                                why, sizeof why);
        if (c && catch_up(f, c)) {
            if (failures > 0)
                feed_log(f, CLUSTER_LOG_INFO,
                         "reconnected to Redis after %u failed attempt%s; reading from %s",
                         failures, failures == 1 ? "" : "s", f->last_id);
            failures = 0;
            set_connected(f, true);
            retry = RETRY_MIN_S;
            while (!stopping(f) && read_once(f, c, BLOCK_MS)) {
            }
            set_connected(f, false);
        } else if (!c && failures++ == 0) {
            feed_log(f, CLUSTER_LOG_ERROR,
                     "cannot reach Redis: %s (trying again with back-off up to %.0f s)", why,
                     RETRY_MAX_S);
        }
        if (c)
            redisFree(c);
        /* The back-off, cut short by destroy. */
        struct timespec until = monotonic_deadline(retry);
        pthread_mutex_lock(&f->lock);
        while (!f->stopping && pthread_cond_timedwait(&f->changed, &f->lock, &until) == 0) {
        }
        pthread_mutex_unlock(&f->lock);
        retry = fmin(retry * 2, RETRY_MAX_S);
    }
    return NULL;
}

struct cluster_feed *cluster_feed_create(const struct cluster_feed_params *p, char *err,
                                         size_t errlen)
{
    struct cluster_feed *f = calloc(1, sizeof *f);
    if (!f) {
        snprintf(err, errlen, "out of memory");
        return NULL;
    }
    error_text why;
    f->address = *p->address;
    if (!cluster_world_name_check(p->world, why, sizeof why)) {
        snprintf(err, errlen, "cluster: %s", why);
        free(f);
        return NULL;
    }
    snprintf(f->world, sizeof f->world, "%s", p->world);
    cluster_keys_make(p->world, &f->keys);
    snprintf(f->last_id, sizeof f->last_id, "%s", p->last_id && p->last_id[0] ? p->last_id : "0-0");
    f->last_revision = p->last_revision;
    f->wake = p->wake;
    f->user = p->user;
    f->log = p->log;
    pthread_mutex_init(&f->lock, NULL);
    pthread_condattr_t attr;
    pthread_condattr_init(&attr);
    pthread_condattr_setclock(&attr, CLOCK_MONOTONIC);
    pthread_cond_init(&f->changed, &attr);
    pthread_condattr_destroy(&attr);
    f->started = pthread_create(&f->thread, NULL, feed_main, f) == 0;
    if (!f->started) {
        snprintf(err, errlen, "cannot start the cluster feed thread");
        cluster_feed_destroy(&f);
        return NULL;
    }
    return f;
}

void cluster_feed_destroy(struct cluster_feed **feed)
{
    struct cluster_feed *f = feed ? *feed : NULL;
    if (!f)
        return;
    pthread_mutex_lock(&f->lock);
    f->stopping = true;
    pthread_cond_broadcast(&f->changed);
    pthread_mutex_unlock(&f->lock);
    if (f->started)
        pthread_join(f->thread, NULL);
    cluster_entry_free_list(f->head);
    memset(&f->address, 0, sizeof f->address); /* the password */
    pthread_cond_destroy(&f->changed);
    pthread_mutex_destroy(&f->lock);
    free(f);
    *feed = NULL;
}

struct cluster_entry *cluster_feed_take(struct cluster_feed *f)
{
    pthread_mutex_lock(&f->lock);
    struct cluster_entry *list = f->head;
    f->head = f->tail = NULL;
    pthread_mutex_unlock(&f->lock);
    return list;
}

bool cluster_feed_connected(struct cluster_feed *f, unsigned *connections)
{
    pthread_mutex_lock(&f->lock);
    bool connected = f->connected;
    if (connections)
        *connections = f->connections;
    pthread_mutex_unlock(&f->lock);
    return connected;
}
