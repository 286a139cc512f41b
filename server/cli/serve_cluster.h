/* `skyd serve` with "cluster" in its configuration: Redis is reached and the shared world
 * read (made from the configuration's initial_state when it does not exist yet) before the
 * renderer starts, so that an unreachable Redis is a clear error at start. */
#ifndef SKYD_SERVE_CLUSTER_H
#define SKYD_SERVE_CLUSTER_H

#include <stdbool.h>
#include <stddef.h>

#include "cluster_entry.h"
#include "cluster_store.h"
#include "config.h"
#include "weather_map.h"
#include "world_state.h"

struct serve_cluster {
    struct cluster_store *store;
    struct cluster_entry *start;   /* the snapshot the node starts from */
    struct sky_weather_map map;    /* its client weather map (no texels: none) */
};

/* Fills *state from the shared world; false with `err` naming the field and the cluster. */
bool serve_cluster_open(struct serve_cluster *cluster, const struct skyd_config *config,
                        struct sky_world_state *state, char *err, size_t errlen);
void serve_cluster_close(struct serve_cluster *cluster);

#endif
