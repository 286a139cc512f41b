/* A node's view of the shared world's stream: a thread with its own Redis connection reads
 * the accepted changes in order (XREAD BLOCK) and queues them for the render thread, which
 * applies them through the world host. When Redis goes away the thread reconnects with an
 * exponential back-off and goes on from the last entry it queued; when the stream no longer
 * holds that entry (trimmed, or Redis lost it) it queues the world's snapshot instead. */
#ifndef SKYD_CLUSTER_FEED_H
#define SKYD_CLUSTER_FEED_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "cluster_entry.h"
#include "cluster_log.h"
#include "cluster_url.h"

struct cluster_feed_params {
    const struct cluster_address *address; /* copied, password included */
    const char *world;
    const char *last_id;      /* the stream id the node's state is at ("0-0": the start) */
    uint64_t last_revision;   /* and its revision */
    void (*wake)(void *user); /* called from the feed's thread when entries were queued */
    void *user;
    struct cluster_log log; /* what the feed's thread has to say */
};

struct cluster_feed;

/* Starts the thread (it connects on its own). NULL with `err`. */
struct cluster_feed *cluster_feed_create(const struct cluster_feed_params *params, char *err,
                                         size_t errlen);
/* Stops the thread (within about half a second) and frees what it queued. */
void cluster_feed_destroy(struct cluster_feed **feed);

/* Every entry queued since the last call, oldest first (free with cluster_entry_free_list). */
struct cluster_entry *cluster_feed_take(struct cluster_feed *feed);

/* Whether the thread is connected to Redis now, and how many times it connected. */
bool cluster_feed_connected(struct cluster_feed *feed, unsigned *connections);

#endif
