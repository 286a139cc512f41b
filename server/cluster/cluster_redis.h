/* What the store (the render thread's commands) and the feed (the subscriber thread) share:
 * the world's keys, connecting with a timeout, the scripts, the snapshot and the parsing of
 * stream entries. Internal to server/cluster/. */
#ifndef SKYD_CLUSTER_REDIS_H
#define SKYD_CLUSTER_REDIS_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include <hiredis.h>

#include "cluster_entry.h"
#include "cluster_url.h"

/* Keys of world W: skyd:{W}:rev (the revision), :state (its JSON), :map (the client weather
 * map), :stream (the accepted changes, in revision order). */
struct cluster_keys {
    char rev[96], state[96], map[96], stream[96];
};

void cluster_keys_make(const char *world, struct cluster_keys *keys);

/* Connects (and SELECTs the URL's database) within timeout_s; commands then time out after
 * command_timeout_s. NULL with `why`. */
redisContext *cluster_redis_connect(const struct cluster_address *address, double timeout_s,
                                    double command_timeout_s, char *why, size_t whylen);

/* The world's state, revision, map and newest stream id in one atomic read. When the world
 * does not exist yet and initial_state is not NULL, it is made first from that state at
 * initial_revision. Returns a snapshot entry, or NULL with `why` (*absent: no such world). */
struct cluster_entry *cluster_redis_snapshot(redisContext *c, const struct cluster_keys *keys,
                                             uint64_t initial_revision, const char *initial_state,
                                             bool *absent, char *why, size_t whylen);

/* A stream entry ([id, [field, value, ...]]) as an entry; NULL with `why`. */
struct cluster_entry *cluster_redis_parse_entry(const redisReply *item, char *why, size_t whylen);

/* Why a command failed: the context's error, or the reply's. */
void cluster_redis_describe(const redisContext *c, const redisReply *reply, char *why,
                            size_t whylen);

#endif
