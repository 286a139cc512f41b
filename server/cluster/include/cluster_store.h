/* A shared world in Redis, as the render thread writes it: one connection, a commit that is
 * checked against the current revision and appended to the world's stream atomically (one
 * Lua script), and the snapshot a node starts from. Acknowledged means Redis answered the
 * script; with `appendfsync always` (config/redis.conf) that answer comes after the append-only
 * file reached the disk. When Redis cannot be reached the store says so at once and tries
 * again only after a back-off, so that a change refused for it never holds up a frame. */
#ifndef SKYD_CLUSTER_STORE_H
#define SKYD_CLUSTER_STORE_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "cluster_entry.h"
#include "cluster_url.h"

/* Stream entries kept (XADD MAXLEN ~): a node that falls further behind starts again from
 * the snapshot. */
#define CLUSTER_STREAM_KEEP 1000

struct cluster_store_params {
    const char *url;   /* redis://[USER[:PASSWORD]@]HOST:PORT[/DB], see cluster_url_parse */
    const char *world; /* checked by cluster_world_name_check */
    /* The password when it comes from elsewhere than the URL (a file); NULL: the URL's, if
     * any. A URL with a password of its own and this one too is refused. */
    const char *password;
};

struct cluster_store;

/* Connects; NULL with `err` naming the cluster and why (unreachable, refused, bad DB). */
struct cluster_store *cluster_store_create(const struct cluster_store_params *params, char *err,
                                           size_t errlen);
void cluster_store_destroy(struct cluster_store **store);

/* "redis://127.0.0.1:6379 world \"demo\"", for messages; the URL without its password
 * (cluster_url_redacted). */
const char *cluster_store_name(const struct cluster_store *store);
const char *cluster_store_url(const struct cluster_store *store);
const char *cluster_store_world(const struct cluster_store *store);
/* Where Redis is and who the node is there, password included, for the feed's connection. */
const struct cluster_address *cluster_store_address(const struct cluster_store *store);

/* The world's snapshot; a world that does not exist yet is made from initial_state (JSON) at
 * initial_revision first, atomically, so that the first of several nodes starting at once
 * decides it. NULL with `err`. */
struct cluster_entry *cluster_store_open(struct cluster_store *store, uint64_t initial_revision,
                                         const char *initial_state, char *err, size_t errlen);

enum cluster_commit_result {
    CLUSTER_COMMITTED,   /* in Redis; *current is the new revision, id the stream id */
    CLUSTER_CONFLICT,    /* another node committed first: *current is the world's revision */
    CLUSTER_UNAVAILABLE, /* Redis cannot be reached (or lost the world): err says why */
};

/* Appends the change (state JSON at revision expected + 1, who made it, the changed
 * pointers, and a client weather map when map is not NULL) if the world's revision is still
 * `expected`. */
enum cluster_commit_result cluster_store_commit(struct cluster_store *store, uint64_t expected,
                                                const char *state, const char *by,
                                                const char *changed, const unsigned char *map,
                                                size_t map_length, uint64_t *current,
                                                char id[CLUSTER_ID_MAX], char *err, size_t errlen);

#endif
