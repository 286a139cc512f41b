/* A world shared by many nodes in Redis (server/cluster/, docs/SCALING.md), as `skyd serve`
 * opens it before the renderer starts, so that an unreachable Redis is a clear error at start:
 * Redis is reached and the shared world read, made from the configuration's initial_state when
 * it does not exist yet. The render loop then commits to it and reads its stream
 * (render_loop_params.shared_world). */
#ifndef SKYD_SHARED_WORLD_H
#define SKYD_SHARED_WORLD_H

#include <stddef.h>

#include "config.h"
#include "world_state.h"

struct shared_world;

/* The world named by the configuration's "cluster"; fills *state (with its revision) from it.
 * NULL with `err` naming the field and the cluster. */
struct shared_world *shared_world_open(const struct skyd_config *config,
                                       struct proto_world_state *state, char *err, size_t errlen);
void shared_world_close(struct shared_world **world);

#endif
