/* The render thread: owns the renderer (every Vulkan object) and the world state. Commands
 * from clients queue up and are applied in arrival order at the start of a tick; then each
 * distinct view that is due (subscriptions at their frame rate, snapshots) is rendered once
 * and handed to the PNG encoder workers for every session that watches it. The state is
 * written to disk after changes (debounced) and when the loop stops. A lost device is
 * reported and the renderer made again for the same state (renderer_host.h). */
#ifndef SKYD_RENDER_LOOP_H
#define SKYD_RENDER_LOOP_H

#include <stdbool.h>
#include <stddef.h>

#include "config.h"
#include "live_settings.h"
#include "messages.h"
#include "service_metrics.h"
#include "session.h"
#include "shared_world.h"
#include "world_state.h"

struct render_loop_params {
    const struct skyd_config *config; /* limits, token, state file, encoder threads */
    const char *device;               /* renderer device preference; NULL = automatic */
    bool validation;
    const char *config_dir; /* presets: <config_dir>/atmosphere/<name>.json */
    const char *state_file; /* "" = no persistence */
    struct proto_world_state initial_state;
    /* A shared world initial_state was read from (shared_world.h): borrowed, used by the
     * render thread only, outliving the loop. NULL: the state file. */
    struct shared_world *shared_world;
    struct session_hub *hub;
    /* Counters for operators (frames, device losses) and the heartbeat of every tick, with
     * the revision, subscriptions and LUT progress; may be NULL. */
    struct service_metrics *metrics;
    /* The controller token and read-only mode auth checks against (a reload changes them). */
    struct live_settings *settings;
    /* Called once, from the render thread, when rendering cannot go on: the device was lost
     * and no renderer could be made again, or it was lost too often (renderer_host.h). The
     * state is saved and the loop takes no more commands; the owner should stop serving and
     * destroy the loop. May be NULL. */
    void (*on_failure)(void *user);
    void *failure_user;
};

struct render_loop;

/* Starts the thread and waits until the renderer is ready: NULL with a message when it could
 * not start (no Vulkan device, ...). */
struct render_loop *render_loop_create(const struct render_loop_params *params, char *err,
                                       size_t errlen);
/* Why the loop stopped on its own (see on_failure), or NULL while it renders. The text lives
 * as long as the loop. */
const char *render_loop_failure(struct render_loop *loop);
/* Stops the thread after the tick under way, writes the state when it changed, frees. */
void render_loop_destroy(struct render_loop **loop);

/* Queues a parsed client message; takes ownership of its contents (msg is emptied). */
void render_loop_submit_message(struct render_loop *loop, struct session *session,
                                struct proto_client_msg *msg);
/* Queues a reply built elsewhere, so it leaves in order with the replies before it. Takes
 * ownership of text (malloc'd). */
void render_loop_submit_reply(struct render_loop *loop, struct session *session, char *text);
/* The session's connection is gone: its subscriptions end. */
void render_loop_session_closed(struct render_loop *loop, struct session *session);

/* Wakes the loop (an encode finished). */
void render_loop_notify(struct render_loop *loop);

#endif
