/* What the render thread does with each client message, at a tick boundary: replies, state
 * changes (all or nothing, with a new revision and an event to every client), presets,
 * probes, statistics, and the subscriptions and snapshots that the tick then renders. Only
 * the render thread calls these. */
#ifndef SKYD_RENDER_COMMANDS_H
#define SKYD_RENDER_COMMANDS_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "cluster_sync.h"
#include "config.h"
#include "forecast_feed.h"
#include "messages.h"
#include "frame_scheduler.h"
#include "live_settings.h"
#include "presets.h"
#include "renderer_host.h"
#include "service_metrics.h"
#include "session.h"
#include "world_host.h"
#include "world_state.h"

/* The owners a command reaches; the render loop holds them. Every change goes through one of
 * their verbs: the world state through the world host, subscriptions and snapshots through
 * the frame scheduler, the renderer through the renderer host. */
struct render_context {
    const struct skyd_config *config;
    const char *config_dir;
    struct live_settings *settings; /* token and read-only mode, as the last reload left them */
    struct session_hub *hub;
    struct world_host *world;
    struct frame_scheduler *frames;
    struct renderer_host *renderer;
    struct service_metrics *metrics; /* counts the errors the commands answer; may be NULL */
    struct forecast_feed *forecast;  /* weather.forecast_dir's; NULL without one */
    /* A shared world (NULL: the state file). A commit that finds the world moved on sets
     * conflict_revision; the change is then made again over the caught-up state. */
    struct cluster_sync *cluster;
    uint64_t conflict_revision;
    /* The message render_commands_handle is handling (NULL between messages), for the log of
     * refusals. */
    const struct proto_client_msg *handling;
    /* A preset folder's listing (16 KiB): the render thread's scratch, kept off its stack. */
    char preset_names[PROTO_MSG_MAX_PRESETS][WORLD_PRESET_NAME_MAX + 1];
};

/* false: a change to a shared world found it moved on; the caller tries the message again
 * at the next tick, after the world's stream is applied, and says how long it has been
 * trying (waited_s). Past a limit the sender gets `unavailable` instead. */
bool render_commands_handle(struct render_context *ctx, struct session *session,
                            const struct proto_client_msg *msg, double waited_s);
/* What following the forecast changes now (forecast_feed_plan), committed as the forecast's
 * own change and announced to every client. */
void render_commands_follow_forecast(struct render_context *ctx);
void render_commands_session_closed(struct render_context *ctx, struct session *session);

#endif
