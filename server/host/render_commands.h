/* What the render thread does with each client message, at a tick boundary: replies, state
 * changes (all or nothing, with a new revision and an event to every client), presets,
 * probes, statistics, and the subscriptions and snapshots that the tick then renders. Only
 * the render thread calls these. */
#ifndef SKYD_RENDER_COMMANDS_H
#define SKYD_RENDER_COMMANDS_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "config.h"
#include "messages.h"
#include "renderer_host.h"
#include "session.h"
#include "weather_map.h"
#include "sky_renderer.h"
#include "world_state.h"

struct subscription {
    uint64_t id; /* unique in the daemon, >= 1 */
    struct session *session;
    struct sky_msg_view view;
    double period_s, next_due; /* CLOCK_MONOTONIC seconds */
    bool waiting_for_encoder;
};

struct pending_snapshot {
    struct session *session;
    struct sky_msg_id id;
    struct sky_msg_view view;
};

struct render_context {
    const struct skyd_config *config;
    const char *config_dir;
    char state_file[SKYD_CONFIG_STRING];
    struct sky_world_state state;
    struct renderer_host *renderer;
    struct session_hub *hub;
    bool dirty;              /* a write the daemon owes itself (retried after state_save_delay_s) */
    double last_change_s;    /* when that write was last due */
    double start_time_s;
    uint64_t render_sequence;
    uint64_t last_subscription_id;
    struct subscription *subscriptions;
    size_t subscription_count, subscription_capacity;
    struct pending_snapshot *snapshots;
    size_t snapshot_count, snapshot_capacity;
    struct sky_render_stats last_stats;
    bool has_stats;
    double fps; /* frames rendered per second over the last second */
    uint64_t settled_revision; /* the newest revision frames fully show */
    bool atmosphere_pending;   /* the atmosphere changed and frames do not show it fully yet */
    /* World simulation: the atmosphere frames are asked to show (a client's change at once,
     * the simulation's haze when the last change has settled), the last tick, and whether the
     * simulation changed the state since it was last written. */
    struct sky_render_atmosphere atmosphere;
    double last_tick_s;
    bool sim_dirty;
    double last_save_s;
    /* The client weather map the state may select (no texels: none), as it is on disk. */
    struct sky_weather_map client_map;
};

void render_commands_handle(struct render_context *ctx, struct session *session,
                            const struct sky_client_msg *msg);
void render_commands_session_closed(struct render_context *ctx, struct session *session);
/* Drops every subscription and pending snapshot. */
void render_commands_release(struct render_context *ctx);

#endif
