/* The forecast folder's worker (forecast_watch.h). */
#include "forecast_watch.h"

#include <dirent.h>
#include <math.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/stat.h>
#include <time.h>

#include "error_text.h"
#include "log.h"
#include "monotonic_clock.h"
#include "test_faults.h"

/* Files of the folder looked at, and refused files remembered so as not to read them again
 * until they change. */
#define MAX_FILES 64
#define MAX_REFUSED 32

struct file_mark {
    char name[256];
    long long size;
    long long mtime_ns;
};

struct forecast_watch {
    char dir[256];
    void (*ready)(void *user);
    void *user;
    pthread_t thread;
    bool started;
    atomic_bool cancel; /* destroy's: a read under way gives up */

    /* Under lock: the look asked for, the news not yet taken, stopping. */
    pthread_mutex_t lock;
    pthread_cond_t wake;
    bool stopping, asked;
    struct forecast_request asked_request;
    bool pending;
    struct forecast_watch_news news;

    /* The worker's own. */
    uint64_t signature; /* the folder's files as last looked at */
    bool scanned, unreadable_said;
    bool has_forecast; /* one was handed over and not dropped since */
    struct file_mark loaded;
    struct forecast_request request;
    struct file_mark refused[MAX_REFUSED];
    int refused_count;
    error_text error;
    uint64_t refusals;
};

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
static int list_files(const struct forecast_watch *w, struct file_mark *files, uint64_t *sig)
{
    DIR *d = opendir(w->dir);
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
        snprintf(path, sizeof path, "%.255s/%.255s", w->dir, entry->d_name);
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

static bool same_request(const struct forecast_request *a, const struct forecast_request *b)
{
    return a->lat_deg == b->lat_deg && a->lon_deg == b->lon_deg && a->extent_km == b->extent_km &&
           a->grid_size == b->grid_size;
}

static bool was_refused(const struct forecast_watch *w, const struct file_mark *f)
{
    for (int i = 0; i < w->refused_count; i++)
        if (same_mark(&w->refused[i], f))
            return true;
    return false;
}

static void refuse(struct forecast_watch *w, const struct file_mark *f,
                   const struct forecast_error *error)
{
    if (w->refused_count == MAX_REFUSED)
        w->refused_count = 0;
    w->refused[w->refused_count++] = *f;
    w->refusals++;
    error_text_mark_cut(w->error, sizeof w->error,
                        snprintf(w->error, sizeof w->error, "%s: %s", f->name, error->text));
    skyd_log(SKYD_LOG_WARNING, "forecast %s/%s refused: %s%s", w->dir, f->name, error->text,
             w->has_forecast ? "; the forecast in use stays" : "");
}

/* The news of a look, merged into what is not yet taken (a forecast replaced twice before a
 * take: the first one is freed). */
static void publish(struct forecast_watch *w, bool replaced, struct forecast *forecast,
                    const char *file, double read_s)
{
    pthread_mutex_lock(&w->lock);
    struct forecast_watch_news *n = &w->news;
    if (replaced) {
        if (w->pending && n->replaced)
            forecast_free(n->forecast);
        n->replaced = true;
        n->forecast = forecast;
        snprintf(n->file, sizeof n->file, "%.255s", file); /* a name in the folder: 255 at most */
        n->read_s = read_s;
    }
    snprintf(n->error, sizeof n->error, "%s", w->error);
    n->refusals = w->refusals;
    w->pending = true;
    pthread_mutex_unlock(&w->lock);
    if (w->ready)
        w->ready(w->user);
}

/* The forecast_read_delay fault (tests only): a wait that destroy cuts short. */
static void test_delay(struct forecast_watch *w)
{
    double delay = test_fault_forecast_read_delay();
    if (!(delay > 0.0))
        return;
    double until = monotonic_seconds() + delay;
    pthread_mutex_lock(&w->lock);
    while (!w->stopping && monotonic_seconds() < until) {
        double whole = floor(until);
        struct timespec deadline = { .tv_sec = (time_t)whole,
                                     .tv_nsec = (long)((until - whole) * 1e9) };
        pthread_cond_timedwait(&w->wake, &w->lock, &deadline);
    }
    pthread_mutex_unlock(&w->lock);
}

/* The newest file that reads for `request`, unless the one in use is newer than every other
 * that does. A place that changed drops a forecast none of them reads for. */
static void load_newest(struct forecast_watch *w, const struct file_mark *files, int count,
                        const struct forecast_request *request, bool place_changed)
{
    uint64_t refusals = w->refusals;
    for (int i = 0; i < count; i++) {
        const struct file_mark *f = &files[i];
        if (w->has_forecast && !place_changed && same_mark(f, &w->loaded)) {
            if (w->refusals != refusals)
                publish(w, false, NULL, "", 0.0);
            return;
        }
        if (was_refused(w, f))
            continue;
        char path[560];
        snprintf(path, sizeof path, "%.255s/%.255s", w->dir, f->name);
        struct forecast_error error;
        double start = monotonic_seconds();
        test_delay(w);
        struct forecast *forecast = forecast_read_until(path, request, &w->cancel, &error);
        if (atomic_load(&w->cancel)) {
            forecast_free(forecast);
            return;
        }
        if (forecast) {
            w->has_forecast = true;
            w->loaded = *f;
            w->request = *request;
            w->error[0] = '\0';
            publish(w, true, forecast, f->name, monotonic_seconds() - start);
            return;
        }
        refuse(w, f, &error);
    }
    if (place_changed && w->has_forecast) {
        skyd_log(SKYD_LOG_WARNING, "no forecast in %s covers the world's place: none in use",
                 w->dir);
        w->has_forecast = false;
        publish(w, true, NULL, "", 0.0);
    } else if (w->refusals != refusals) {
        publish(w, false, NULL, "", 0.0);
    }
}

static void look(struct forecast_watch *w, const struct forecast_request *request)
{
    bool place_changed = w->has_forecast && !same_request(request, &w->request);
    struct file_mark files[MAX_FILES];
    uint64_t sig = 0;
    int count = list_files(w, files, &sig);
    if (count < 0) {
        if (!w->unreadable_said)
            skyd_log(SKYD_LOG_WARNING, "forecast folder %s cannot be read", w->dir);
        w->unreadable_said = true;
        snprintf(w->error, sizeof w->error, "the folder cannot be read");
        w->signature = 0;
        publish(w, false, NULL, "", 0.0);
    } else if (!w->scanned || sig != w->signature || place_changed) {
        w->unreadable_said = false;
        if (place_changed)
            w->refused_count = 0;
        w->signature = sig;
        load_newest(w, files, count, request, place_changed);
    }
    w->scanned = true;
}

static void *worker_main(void *arg)
{
    struct forecast_watch *w = arg;
    pthread_mutex_lock(&w->lock);
    for (;;) {
        while (!w->asked && !w->stopping)
            pthread_cond_wait(&w->wake, &w->lock);
        if (w->stopping)
            break;
        struct forecast_request request = w->asked_request;
        w->asked = false;
        pthread_mutex_unlock(&w->lock);
        look(w, &request);
        pthread_mutex_lock(&w->lock);
    }
    pthread_mutex_unlock(&w->lock);
    return NULL;
}

struct forecast_watch *forecast_watch_create(const struct forecast_watch_params *params, char *err,
                                             size_t errlen)
{
    struct forecast_watch *w = calloc(1, sizeof *w);
    if (!w) {
        snprintf(err, errlen, "out of memory for the forecast folder");
        return NULL;
    }
    snprintf(w->dir, sizeof w->dir, "%s", params->dir);
    w->ready = params->ready;
    w->user = params->user;
    atomic_init(&w->cancel, false);
    pthread_mutex_init(&w->lock, NULL);
    pthread_condattr_t attr;
    pthread_condattr_init(&attr);
    pthread_condattr_setclock(&attr, CLOCK_MONOTONIC);
    pthread_cond_init(&w->wake, &attr);
    pthread_condattr_destroy(&attr);
    w->started = pthread_create(&w->thread, NULL, worker_main, w) == 0;
    if (!w->started) {
        snprintf(err, errlen, "cannot start the forecast folder's thread");
        forecast_watch_destroy(&w);
    }
    return w;
}

void forecast_watch_destroy(struct forecast_watch **watch_ptr)
{
    struct forecast_watch *w = *watch_ptr;
    *watch_ptr = NULL;
    if (!w)
        return;
    atomic_store(&w->cancel, true);
    pthread_mutex_lock(&w->lock);
    w->stopping = true;
    pthread_cond_broadcast(&w->wake);
    pthread_mutex_unlock(&w->lock);
    if (w->started)
        pthread_join(w->thread, NULL);
    if (w->pending && w->news.replaced)
        forecast_free(w->news.forecast);
    pthread_cond_destroy(&w->wake);
    pthread_mutex_destroy(&w->lock);
    free(w);
}

void forecast_watch_look(struct forecast_watch *w, const struct forecast_request *request)
{
    pthread_mutex_lock(&w->lock);
    w->asked = true;
    w->asked_request = *request;
    pthread_cond_signal(&w->wake);
    pthread_mutex_unlock(&w->lock);
}

bool forecast_watch_take(struct forecast_watch *w, struct forecast_watch_news *news)
{
    pthread_mutex_lock(&w->lock);
    bool pending = w->pending;
    if (pending) {
        *news = w->news;
        memset(&w->news, 0, sizeof w->news);
        w->pending = false;
    }
    pthread_mutex_unlock(&w->lock);
    return pending;
}
