/* What the render loop takes from a shared world opened by shared_world_open: the store it
 * commits to, the snapshot the node starts from and that snapshot's client weather map. Each
 * lives as long as the shared world. */
#ifndef SKYD_SHARED_WORLD_INTERNAL_H
#define SKYD_SHARED_WORLD_INTERNAL_H

#include "cluster_entry.h"
#include "cluster_store.h"
#include "shared_world.h"
#include "weather_map.h"

struct cluster_store *shared_world_store(struct shared_world *world);
const struct cluster_entry *shared_world_start(const struct shared_world *world);
/* No texels: the snapshot has no client weather map, or it cannot be read. */
const struct proto_weather_map *shared_world_client_map(const struct shared_world *world);

#endif
