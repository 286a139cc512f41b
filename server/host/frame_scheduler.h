/* The frame scheduler: the subscriptions (a view at a frame rate) and pending snapshots of
 * every session, which of them are due, one render per distinct view shared by everyone who
 * watches it, and the encoder workers that turn those renders into frames in the sessions'
 * slots. Only the render thread calls these. */
#ifndef SKYD_FRAME_SCHEDULER_H
#define SKYD_FRAME_SCHEDULER_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "error_text.h"
#include "messages.h"
#include "render_input.h"
#include "renderer_host.h"
#include "service_metrics.h"
#include "session.h"
#include "sky_renderer.h"

struct frame_scheduler_params {
    int encoder_threads;
    struct session_hub *hub;
    /* Called from an encoder worker after each frame (the render thread may render the next
     * frame of that view). */
    void (*encoded)(void *user);
    void *user;
    /* frames rendered and skipped, render times, snapshots answered with an error; may be
     * NULL */
    struct service_metrics *metrics;
};

struct frame_scheduler;

/* NULL when the encoder workers cannot start. */
struct frame_scheduler *frame_scheduler_create(const struct frame_scheduler_params *params);
/* Ends every subscription, drops the pending snapshots, stops the workers. */
void frame_scheduler_destroy(struct frame_scheduler **scheduler);

/* A refusal: PROTO_MSG_OK, or the error and a message for the client. */
struct frame_refusal {
    enum proto_msg_error_code code;
    error_text message;
};

/* A new subscription of the session to `view` (its fps sets the period); *id is its number. */
struct frame_refusal frame_scheduler_subscribe(struct frame_scheduler *scheduler,
                                               struct session *session,
                                               const struct proto_msg_view *view, uint64_t *id);
/* false when the session has no such subscription. */
bool frame_scheduler_unsubscribe(struct frame_scheduler *scheduler, struct session *session,
                                 uint64_t id);
/* One frame of `view` at the next tick, answered as a reply to `id`. */
struct frame_refusal frame_scheduler_snapshot(struct frame_scheduler *scheduler,
                                              struct session *session,
                                              const struct proto_msg_id *id,
                                              const struct proto_msg_view *view);
/* The session's connection is gone: its subscriptions and snapshots end. */
void frame_scheduler_session_closed(struct frame_scheduler *scheduler, struct session *session);
/* Rendering cannot go on: every pending snapshot is answered with `message`. */
void frame_scheduler_fail_snapshots(struct frame_scheduler *scheduler, const char *message);

size_t frame_scheduler_subscription_count(const struct frame_scheduler *scheduler);
/* The session's subscriptions (at most `capacity`, SESSION_MAX_SUBSCRIPTIONS is enough), or
 * every session's when `session` is NULL: bytes sent, effective frame rate and JPEG quality.
 * Returns how many were written. */
size_t frame_scheduler_session_stats(const struct frame_scheduler *scheduler,
                                     struct session *session,
                                     struct proto_msg_subscription_stats *out, size_t capacity);

/* Renders every view that is due (pending snapshots, subscriptions whose frame is due and not
 * still encoding), each once, through the renderer host, of the render input, and hands them
 * to the encoders. *atmosphere_shown: a frame showed the input's frame atmosphere fully (from
 * then on frames carry the input's revision; world_host_atmosphere_shown). Returns when it
 * should next be called (CLOCK_MONOTONIC seconds). */
double frame_scheduler_render_due(struct frame_scheduler *scheduler, struct renderer_host *renderer,
                                  const struct render_input *input, double now_s,
                                  bool *atmosphere_shown);

/* Frames rendered per second over the last whole second (updated by frame_scheduler_tick). */
void frame_scheduler_tick(struct frame_scheduler *scheduler, double now_s);
double frame_scheduler_fps(const struct frame_scheduler *scheduler);
/* The last frame's statistics, or NULL before the first. */
const struct sky_render_stats *frame_scheduler_last_stats(const struct frame_scheduler *scheduler);

#endif
