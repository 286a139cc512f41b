#include "shared_world.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "error_text.h"
#include "log.h"
#include "secret_file.h"
#include "shared_world_internal.h"
#include "wall_clock.h"
#include "world_codec.h"
#include "world_sim.h"

struct shared_world {
    struct cluster_store *store;
    struct cluster_entry *start;  /* the snapshot the node starts from */
    struct proto_weather_map map; /* its client weather map (no texels: none) */
};

/* Reads the world, made from `initial` when it does not exist yet, into *state. */
static bool read_world(struct shared_world *w, const struct skyd_config *config,
                       const struct proto_world_state *initial, struct proto_world_state *state,
                       char *err, size_t errlen)
{
    error_text why;
    char *initial_text = world_codec_state_text(initial);
    if (!initial_text) {
        snprintf(err, errlen, "out of memory");
        return false;
    }
    w->start = cluster_store_open(w->store, config->initial_state.revision, initial_text, why,
                                  sizeof why);
    free(initial_text);
    if (!w->start) {
        snprintf(err, errlen, "/cluster: %s", why);
        return false;
    }
    if (!world_codec_parse_state(w->start->state, state, why, sizeof why)) {
        snprintf(err, errlen, "/cluster: the world %s holds a state this node cannot use: %s",
                 cluster_store_name(w->store), why);
        return false;
    }
    state->revision = w->start->revision;
    if (w->start->map && !world_codec_parse_map(w->start->map, w->start->map_length, &w->map))
        skyd_log(SKYD_LOG_WARNING, "the shared world's client weather map cannot be read");
    return true;
}

/* The password file's first line, checked as the controller token's file is (secret_file.h). */
static bool read_password(const char *path, char *password, size_t size, char *why, size_t whylen)
{
    size_t length = 0;
    if (secret_file_read(path, password, size, &length, why, whylen) != SECRET_FILE_READ)
        return false;
    error_text reason;
    if (!secret_file_first_line(password, length, size, reason, sizeof reason)) {
        memset(password, 0, size);
        error_text_mark_cut(why, whylen,
                            snprintf(why, whylen, "%s holds no password: %s", path, reason));
        return false;
    }
    return true;
}

struct shared_world *shared_world_open(const struct skyd_config *config,
                                       struct proto_world_state *state, char *err, size_t errlen)
{
    struct shared_world *w = calloc(1, sizeof *w);
    if (!w) {
        snprintf(err, errlen, "out of memory");
        return NULL;
    }
    struct cluster_store_params params = { .url = config->cluster_redis,
                                           .world = config->cluster_world };
    error_text why;
    char password[CLUSTER_PASSWORD_MAX + 2];
    if (config->cluster_redis_password_file[0]) {
        if (!read_password(config->cluster_redis_password_file, password, sizeof password, why,
                           sizeof why)) {
            snprintf(err, errlen, "/cluster/redis_password_file: %s", why);
            shared_world_close(&w);
            return NULL;
        }
        params.password = password;
    }
    w->store = cluster_store_create(&params, why, sizeof why);
    memset(password, 0, sizeof password);
    if (!w->store) {
        snprintf(err, errlen, "/cluster/redis: %s", why);
        shared_world_close(&w);
        return NULL;
    }
    /* A world made by this node gets its epoch now, so that every node that reads it later
     * computes the same simulated instant (a node anchoring it at its own start would not). */
    struct proto_world_state anchored = config->initial_state;
    world_sim_anchor(&anchored, wall_clock_seconds());
    if (!read_world(w, config, &anchored, state, err, errlen)) {
        shared_world_close(&w);
        return NULL;
    }
    skyd_log(SKYD_LOG_INFO, "shared world %s at revision %llu", cluster_store_name(w->store),
             (unsigned long long)state->revision);
    return w;
}

void shared_world_close(struct shared_world **world)
{
    struct shared_world *w = *world;
    *world = NULL;
    if (!w)
        return;
    cluster_entry_free(w->start);
    proto_weather_map_free(&w->map);
    cluster_store_destroy(&w->store);
    free(w);
}

struct cluster_store *shared_world_store(struct shared_world *world)
{
    return world->store;
}

const struct cluster_entry *shared_world_start(const struct shared_world *world)
{
    return world->start;
}

const struct proto_weather_map *shared_world_client_map(const struct shared_world *world)
{
    return &world->map;
}
