/* A shared world on the render thread's side: the feed (server/cluster/) reads the world's
 * stream on its own thread; at each tick the render thread applies what it queued, in
 * revision order, through the world host, and tells this node's clients. Only the render thread calls these (create and destroy excepted). */
#ifndef SKYD_CLUSTER_SYNC_H
#define SKYD_CLUSTER_SYNC_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "cluster_entry.h"
#include "cluster_store.h"
#include "session.h"
#include "world_host.h"

struct cluster_sync;

/* Starts the feed from `start` (the snapshot the world host was made from); wake(user) is
 * called from the feed's thread when entries wait. NULL with `err`. */
struct cluster_sync *cluster_sync_create(const struct cluster_store *store,
                                         const struct cluster_entry *start,
                                         void (*wake)(void *user), void *user, char *err,
                                         size_t errlen);
void cluster_sync_destroy(struct cluster_sync **sync);

/* Applies every queued entry to the world host; their events go to every client of the hub. */
void cluster_sync_apply(struct cluster_sync *sync, struct world_host *world,
                        struct session_hub *hub);

/* Whether the feed is connected now, and how often it connected since start. */
bool cluster_sync_connected(struct cluster_sync *sync, unsigned *connections);

#endif
