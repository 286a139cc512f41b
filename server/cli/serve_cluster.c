#include "serve_cluster.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "log.h"
#include "wall_clock.h"
#include "world_sim.h"
#include "world_codec.h"

bool serve_cluster_open(struct serve_cluster *c, const struct skyd_config *config,
                        struct sky_world_state *state, char *err, size_t errlen)
{
    memset(c, 0, sizeof *c);
    struct cluster_store_params params = { .url = config->cluster_redis,
                                           .world = config->cluster_world };
    char why[512];
    c->store = cluster_store_create(&params, why, sizeof why);
    if (!c->store) {
        snprintf(err, errlen, "/cluster/redis: %s", why);
        return false;
    }
    /* A world made by this node gets its epoch now, so that every node that reads it later
     * computes the same simulated instant (a node anchoring it at its own start would not). */
    struct sky_world_state anchored = config->initial_state;
    world_sim_anchor(&anchored, wall_clock_seconds());
    char *initial = world_codec_state_text(&anchored);
    if (!initial) {
        snprintf(err, errlen, "out of memory");
        serve_cluster_close(c);
        return false;
    }
    c->start = cluster_store_open(c->store, config->initial_state.revision, initial, why,
                                  sizeof why);
    free(initial);
    if (!c->start) {
        snprintf(err, errlen, "/cluster: %s", why);
        serve_cluster_close(c);
        return false;
    }
    if (!world_codec_parse_state(c->start->state, state, why, sizeof why)) {
        snprintf(err, errlen, "/cluster: the world %s holds a state this node cannot use: %s",
                 cluster_store_name(c->store), why);
        serve_cluster_close(c);
        return false;
    }
    state->revision = c->start->revision;
    if (c->start->map && !world_codec_parse_map(c->start->map, c->start->map_length, &c->map))
        skyd_log(SKYD_LOG_WARNING, "the shared world's client weather map cannot be read");
    skyd_log(SKYD_LOG_INFO, "shared world %s at revision %llu", cluster_store_name(c->store),
             (unsigned long long)state->revision);
    return true;
}

void serve_cluster_close(struct serve_cluster *c)
{
    cluster_entry_free(c->start);
    c->start = NULL;
    sky_weather_map_free(&c->map);
    cluster_store_destroy(&c->store);
}
