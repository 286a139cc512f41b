/* The world host: the one live world state, its revision, how a change is committed (validated
 * elsewhere, then settled, written to disk, and announced), how the simulation advances it,
 * when it is written, and its render input (render_input.h): made anew whenever the state
 * changes, for the renderer host to take. It never calls the renderer. Every change to the
 * state goes through one of its verbs. Only the render thread calls these. */
#ifndef SKYD_WORLD_HOST_H
#define SKYD_WORLD_HOST_H

#include <stdbool.h>
#include <stdint.h>

#include "cluster_entry.h"
#include "cluster_store.h"
#include "error_text.h"
#include "render_input.h"
#include "weather_map.h"
#include "world_state.h"

struct world_host_params {
    const char *state_file; /* "" or NULL: no persistence */
    struct proto_world_state initial_state;
    double save_delay_s; /* a failed write is tried again after this */
    double now_s;        /* CLOCK_MONOTONIC seconds at start (save schedule) */
    double wall_s;       /* CLOCK_REALTIME seconds at start: the clock is brought there */
    /* A shared world (server/cluster/): changes are committed to Redis instead of the state
     * file (then ""), and the world's client weather map at start is `client_map`. NULL: the
     * state file. Borrowed: it outlives the host. */
    struct cluster_store *cluster;
    const struct proto_weather_map *client_map;
};

struct world_host;

/* The initial state is brought to wall_s by its epoch (a stored state resumes at the time its
 * epoch gives now, not at the time it was saved); a state without an epoch is anchored at
 * wall_s with the clock it holds, and written. NULL only when memory runs out. */
struct world_host *world_host_create(const struct world_host_params *params);
void world_host_destroy(struct world_host **host);

const struct proto_world_state *world_host_state(const struct world_host *host);
/* The live state's render input: its frame atmosphere is a client's change at once, the
 * simulation's haze once frames show the previous one (or at once, nobody watching); it
 * holds the client weather map. Valid until the next verb. */
const struct render_input *world_host_render_input(const struct world_host *host);

enum world_commit_status {
    WORLD_COMMIT_DONE,        /* committed, or nothing changed */
    WORLD_COMMIT_FAILED,      /* the disk or the renderer refused it */
    WORLD_COMMIT_CONFLICT,    /* a shared world moved on first: apply its stream, then retry */
    WORLD_COMMIT_UNAVAILABLE, /* a shared world's Redis cannot be reached */
};

/* What a commit did. */
struct world_commit {
    enum world_commit_status status;
    uint64_t current;  /* CONFLICT: the shared world's revision */
    uint64_t revision; /* the live revision afterwards */
    char *event;       /* the state_changed event for every client (malloc'd); NULL: none */
    /* The new render input when something changed (else NULL): for the renderer host. */
    const struct render_input *input;
    error_text error; /* why it failed */
};

/* Makes `next` (validated) the live state: re-anchored where its clock or wind changed and
 * brought to the wall instant of the last tick (world_sim_commit), diffed, and when anything
 * differs (or `also_changed`, a pointer outside the schema, names something else that did)
 * written to the state file (or a shared world's Redis) before anything acknowledges it,
 * given the next revision, a new render input (out->input) and announced: the event carries
 * the changed fields' new values and `by`, who changed them. false with out->error and
 * nothing changed when the disk or Redis refuses it. */
bool world_host_commit(struct world_host *host, struct proto_world_state *next,
                       const char *also_changed, const char *by, struct world_commit *out);

/* The renderer could not take the last commit's input (`why`): the state, the client weather
 * map and the state file go back to what they were before it, *out says so (status FAILED,
 * error, no event) and true is returned. A shared world's commit stays (Redis has it; a
 * renderer made again takes it): said on stderr, false. Only within the commit's tick. */
bool world_host_undo_commit(struct world_host *host, const char *why, struct world_commit *out);

/* A shared world's entry (a change another node committed, or a snapshot) made the live
 * state, without a second validation: Redis took it from a node that validated it. Entries
 * at or below the live revision (this node's own commits) are skipped. *event: the
 * state_changed event for this node's clients (malloc'd), NULL when none. false when the
 * entry cannot be read (said on stderr). */
bool world_host_apply_entry(struct world_host *host, const struct cluster_entry *entry,
                            char **event);

/* Whether `next` samples the client weather map when there is none, or the forecast's while
 * not following a forecast (errors filled). */
bool world_host_client_map_missing(const struct world_host *host,
                                   const struct proto_world_state *next,
                                   struct proto_field_errors *errors);

/* A client weather map: written to disk, then made the client map and selected by the state
 * (weather.map_source "client") in one revision whose event names "/weather/map", its render
 * input holding the map. false with out->error and the disk and the state as they were when
 * a step fails; world_host_undo_commit puts the old map back too. */
bool world_host_set_weather_map(struct world_host *host, const struct proto_weather_map *map,
                                const char *by, struct world_commit *out);

/* The followed forecast's coverage grid as the map weather.map_source "forecast" selects
 * (forecast_feed_map): copied, in the render input at once, no revision (it moves with the
 * forecast's time like the simulation's weather), written beside the state at its next save
 * and restored at start. false when memory is out (the old map stays). A commit that stops
 * following the forecast brings weather.map_source "procedural" back. */
bool world_host_set_forecast_map(struct world_host *host, const struct proto_weather_map *map);

/* A `simulation` event (malloc'd) when at least period_s passed since the last one and the
 * simulation moved fields since clients last heard of the state; NULL otherwise. */
char *world_host_simulation_event(struct world_host *host, double now_s, double period_s);

/* Brings the world to wall instant wall_s (CLOCK_REALTIME seconds) by its epoch
 * (world_sim_run_to) and makes its render input; the revision stays (it counts accepted
 * changes). Commits until the next call are anchored at wall_s. A haze change reaches the
 * frame atmosphere once the previous one has settled (frames_settled: the last frame's
 * atmosphere_settled), so a humidity that changes every tick cannot keep restarting the
 * amortized rebuild. Unwatched, it reaches it at once, and inputs ask for their atmosphere
 * to be built at once (a snapshot, or the first frames of a new subscription, show it). */
void world_host_advance(struct world_host *host, double wall_s, bool watched, bool frames_settled);

/* Frames fully show the input's frame atmosphere: a frame said so (atmosphere_settled), or a
 * renderer made again built it at once. Frames carry the live revision from now on. */
void world_host_atmosphere_shown(struct world_host *host);

/* Writes the state when a write is owed: a failed one after save_delay_s, the simulation's
 * changes every sim_period_s. Returns when it should be called again (INFINITY: not owed). */
double world_host_save_due(struct world_host *host, double now_s, double sim_period_s);
/* Writes the state now if it changed since the last write. */
void world_host_save(struct world_host *host, double now_s);

#endif
