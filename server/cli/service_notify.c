#include "service_notify.h"

#include <errno.h>
#include <pthread.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

#include <systemd/sd-daemon.h>

#include "error_text.h"
#include "log.h"

struct service_notify {
    bool active;
    bool (*healthy)(void *user, char *why, size_t len);
    void *user;
    uint64_t watchdog_usec;
    pthread_t thread;
    bool thread_started;
    pthread_mutex_t lock;
    pthread_cond_t wake;
    bool stopping;
};

/* Pings at half the interval; an unhealthy daemon is not pinged, so that the manager restarts
 * it, and says why once per spell. */
static void *watchdog_main(void *arg)
{
    struct service_notify *n = arg;
    bool was_healthy = true;
    pthread_mutex_lock(&n->lock);
    while (!n->stopping) {
        pthread_mutex_unlock(&n->lock);
        error_text why = "";
        bool healthy = !n->healthy || n->healthy(n->user, why, sizeof why);
        if (healthy)
            sd_notify(0, "WATCHDOG=1");
        else if (was_healthy)
            skyd_log(SKYD_LOG_ERROR, "not pinging the watchdog: %s", why);
        was_healthy = healthy;
        struct timespec deadline;
        clock_gettime(CLOCK_MONOTONIC, &deadline);
        uint64_t half = n->watchdog_usec / 2;
        deadline.tv_sec += (time_t)(half / 1000000u);
        deadline.tv_nsec += (long)(half % 1000000u) * 1000;
        if (deadline.tv_nsec >= 1000000000L) {
            deadline.tv_sec++;
            deadline.tv_nsec -= 1000000000L;
        }
        pthread_mutex_lock(&n->lock);
        while (!n->stopping && pthread_cond_timedwait(&n->wake, &n->lock, &deadline) != ETIMEDOUT)
            ;
    }
    pthread_mutex_unlock(&n->lock);
    return NULL;
}

struct service_notify *service_notify_create(bool (*healthy)(void *user, char *why, size_t len),
                                             void *user)
{
    struct service_notify *n = calloc(1, sizeof *n);
    if (!n)
        return NULL;
    n->active = getenv("NOTIFY_SOCKET") != NULL;
    n->healthy = healthy;
    n->user = user;
    pthread_mutex_init(&n->lock, NULL);
    pthread_condattr_t attr;
    pthread_condattr_init(&attr);
    pthread_condattr_setclock(&attr, CLOCK_MONOTONIC);
    pthread_cond_init(&n->wake, &attr);
    pthread_condattr_destroy(&attr);
    if (n->active && sd_watchdog_enabled(0, &n->watchdog_usec) > 0 && n->watchdog_usec > 0) {
        n->thread_started = pthread_create(&n->thread, NULL, watchdog_main, n) == 0;
        if (!n->thread_started) {
            service_notify_destroy(&n);
            return NULL;
        }
    }
    return n;
}

void service_notify_destroy(struct service_notify **notify)
{
    struct service_notify *n = *notify;
    *notify = NULL;
    if (!n)
        return;
    if (n->thread_started) {
        pthread_mutex_lock(&n->lock);
        n->stopping = true;
        pthread_cond_broadcast(&n->wake);
        pthread_mutex_unlock(&n->lock);
        pthread_join(n->thread, NULL);
    }
    pthread_cond_destroy(&n->wake);
    pthread_mutex_destroy(&n->lock);
    free(n);
}

void service_notify_ready(struct service_notify *n, const char *status)
{
    if (n && n->active)
        sd_notifyf(0, "READY=1\nSTATUS=%s", status ? status : "serving");
}

void service_notify_reloading(struct service_notify *n)
{
    if (!n || !n->active)
        return;
    struct timespec now;
    clock_gettime(CLOCK_MONOTONIC, &now);
    /* systemd 253 and later expect the reload's monotonic time beside RELOADING=1. */
    sd_notifyf(0, "RELOADING=1\nMONOTONIC_USEC=%llu\nSTATUS=reloading the configuration",
               (unsigned long long)now.tv_sec * 1000000ull +
                   (unsigned long long)now.tv_nsec / 1000);
}

void service_notify_stopping(struct service_notify *n)
{
    if (n && n->active)
        sd_notify(0, "STOPPING=1\nSTATUS=shutting down");
}

bool service_notify_active(const struct service_notify *n)
{
    return n && n->active;
}
