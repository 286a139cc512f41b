#include "cluster_sync.h"

#include <stdio.h>
#include <stdlib.h>

#include "cluster_feed.h"
#include "log.h"

struct cluster_sync {
    struct cluster_feed *feed;
};

_Static_assert(CLUSTER_LOG_ERROR == (int)SKYD_LOG_ERROR &&
                   CLUSTER_LOG_WARNING == (int)SKYD_LOG_WARNING &&
                   CLUSTER_LOG_INFO == (int)SKYD_LOG_INFO &&
                   CLUSTER_LOG_DEBUG == (int)SKYD_LOG_DEBUG,
               "the cluster's log levels are the daemon's");

/* The feed's lines join the daemon's log (skyd_log is thread-safe). */
static void log_cluster_line(void *user, enum cluster_log_level level, const char *line)
{
    (void)user;
    skyd_log((enum skyd_log_level)level, "%s", line);
}

struct cluster_sync *cluster_sync_create(const struct cluster_store *store,
                                         const struct cluster_entry *start,
                                         void (*wake)(void *user), void *user, char *err,
                                         size_t errlen)
{
    struct cluster_sync *s = calloc(1, sizeof *s);
    if (!s) {
        snprintf(err, errlen, "out of memory");
        return NULL;
    }
    struct cluster_feed_params params = { .address = cluster_store_address(store),
                                          .world = cluster_store_world(store),
                                          .last_id = start->id,
                                          .last_revision = start->revision,
                                          .wake = wake,
                                          .user = user,
                                          .log = { .write = log_cluster_line } };
    s->feed = cluster_feed_create(&params, err, errlen);
    if (!s->feed) {
        free(s);
        return NULL;
    }
    return s;
}

void cluster_sync_destroy(struct cluster_sync **sync)
{
    struct cluster_sync *s = sync ? *sync : NULL;
    if (!s)
        return;
    cluster_feed_destroy(&s->feed);
    free(s);
    *sync = NULL;
}

void cluster_sync_apply(struct cluster_sync *s, struct world_host *world, struct session_hub *hub)
{
    struct cluster_entry *list = cluster_feed_take(s->feed);
    bool told = false;
    for (struct cluster_entry *e = list; e; e = e->next) {
        char *event = NULL;
        world_host_apply_entry(world, e, &event);
        if (event) {
            session_hub_broadcast(hub, event);
            told = true;
        }
        free(event);
    }
    cluster_entry_free_list(list);
    if (told)
        session_hub_wake(hub);
}

bool cluster_sync_connected(struct cluster_sync *s, unsigned *connections)
{
    return cluster_feed_connected(s->feed, connections);
}
