/* A client session's outgoing side, shared by three kinds of threads: the render thread
 * (replies, events, subscriptions), the PNG encoder workers (frames) and the transport thread
 * (which drains it). Everything here is guarded by the session's own mutex; the transport is
 * woken through the hub's wake callback whenever a session gains output.
 *
 * Memory per session is bounded:
 *   - queued text replies and events: at most SESSION_MAX_QUEUED_TEXT_BYTES; a client that lets
 *     more pile up is not reading and is closed (1008, "client is not reading");
 *   - frames: one latest-frame slot per subscription (at most SESSION_MAX_SUBSCRIPTIONS) and at
 *     most SESSION_MAX_SNAPSHOTS snapshots; each holds a reference to a frame shared with the
 *     other sessions that watch the same view, and a newer frame replaces an unsent one;
 *   - plus the transport's own buffers: the message being received (<= max_message_bytes)
 *     and the unsent rest of one message.
 */
#ifndef SKYD_SESSION_H
#define SKYD_SESSION_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "encoded_frame.h"
#include "messages.h"

#define SESSION_MAX_SUBSCRIPTIONS 4
#define SESSION_MAX_SNAPSHOTS 4
#define SESSION_MAX_QUEUED_TEXT_BYTES (1u << 20)
/* Frames of one subscription in the encoder at once: the next frame renders while the last
 * one encodes. */
#define SESSION_MAX_FRAMES_ENCODING 2

/* Close codes (RFC 6455). */
#define SESSION_CLOSE_GOING_AWAY 1001
#define SESSION_CLOSE_POLICY 1008
#define SESSION_CLOSE_INTERNAL_ERROR 1011

struct session;

struct session *session_create(void);
struct session *session_ref(struct session *session);
void session_unref(struct session **session);

/* The transport's handle for this session (its connection); only the transport uses it. */
void session_set_transport(struct session *session, void *transport);
void *session_transport(const struct session *session);

/* Role; changed by the render thread (auth), read anywhere. */
enum proto_msg_role session_role(struct session *session);
void session_set_role(struct session *session, enum proto_msg_role role);

/* The name the client gave in its hello ("" until it gives one), copied into out (at least
 * PROTO_MSG_CLIENT_MAX + 1 bytes); set by the render thread, read anywhere. */
void session_client_name(struct session *session, char *out, size_t capacity);
void session_set_client_name(struct session *session, const char *name);
/* Whether its hello asked for simulation events. */
bool session_wants_simulation_events(struct session *session);
void session_set_simulation_events(struct session *session, bool wanted);

/* Queues a text message (copied). Returns false when the queue is over its bound: the session
 * is then marked to close as not reading. A closed session drops it and returns true. */
bool session_push_text(struct session *session, const char *text);

/* Closes after the queued text is sent (after_output) or at once. The first request wins. */
void session_request_close(struct session *session, int code, const char *reason,
                           bool after_output);

/* Marks the transport gone: producers drop their output from now on. */
void session_mark_closed(struct session *session);

/* Subscriptions' latest-frame slots. add returns false when all slots are in use. */
bool session_add_slot(struct session *session, uint64_t subscription);
void session_remove_slot(struct session *session, uint64_t subscription);
enum slot_state {
    SLOT_READY = 0, /* a frame may be rendered for it */
    SLOT_ENCODING,  /* SESSION_MAX_FRAMES_ENCODING frames of it are being encoded */
    SLOT_STALLED,   /* its last frame has waited unsent longer than stale_after_s */
    SLOT_GONE,      /* no such subscription, or the session closed */
};
/* Whether to render for a subscription at time now_s (CLOCK_MONOTONIC seconds). A client
 * that does not take its frames costs no rendering until it reads again. */
enum slot_state session_slot_state(struct session *session, uint64_t subscription, double now_s,
                                   double stale_after_s);
/* Counts one more frame of it in the encoder; false when it is gone or the encoder holds
 * SESSION_MAX_FRAMES_ENCODING of its frames. */
bool session_slot_begin_encode(struct session *session, uint64_t subscription);
/* Ends an encode: a frame (NULL when encoding failed) enters the slot unless the slot holds a
 * newer one, replacing an unsent older one. The reference is taken, not stolen. */
void session_slot_deliver(struct session *session, uint64_t subscription,
                          struct encoded_frame *frame);

/* What a subscription's frames cost: the bytes of its frames handed to the transport, and the
 * size and JPEG quality of the newest frame its slot received (frames_delivered counts them). */
struct slot_traffic {
    uint64_t bytes_sent;
    uint64_t frames_delivered;
    size_t last_frame_bytes;
    int last_quality;
};
/* false when there is no such subscription. */
bool session_slot_traffic(struct session *session, uint64_t subscription, struct slot_traffic *out);

/* Snapshots: reserve a place before rendering (false when SESSION_MAX_SNAPSHOTS are pending);
 * deliver the frame (or NULL after a failure, which frees the place). */
bool session_snapshot_reserve(struct session *session);
void session_snapshot_deliver(struct session *session, const struct proto_msg_id *id,
                              struct encoded_frame *frame);
/* A snapshot that could not be rendered or encoded: frees its place and queues an `error`
 * `internal` reply with `message` (the sender must not wait in silence). false when the reply
 * could not be built; the caller counts the ones that were. */
bool session_snapshot_fail(struct session *session, const struct proto_msg_id *id,
                           const char *message);

enum session_output_kind {
    SESSION_OUTPUT_NONE = 0,
    SESSION_OUTPUT_TEXT,  /* text .. text + length; preceded by LWS_PRE writable bytes */
    SESSION_OUTPUT_FRAME, /* the binary message of frame, numbered frame_number */
    SESSION_OUTPUT_CLOSE, /* close with code and reason */
};

struct session_output {
    enum session_output_kind kind;
    char *text_buffer; /* TEXT: owned; free() it */
    char *text;
    size_t length;
    struct encoded_frame *frame; /* FRAME: a reference; unref it */
    uint64_t frame_number;
    int close_code;
    char close_reason[96];
};

/* Takes the next message to send, in this order: a close requested at once; the binary part of
 * a frame whose text part went out; queued text; a close requested after output; snapshots;
 * subscription frames in turn. A frame yields a TEXT output (its "frame" message) and then, on
 * the next call, the FRAME itself. */
void session_next_output(struct session *session, struct session_output *out);
void session_output_release(struct session_output *out);
bool session_has_output(struct session *session);

/* ---- the set of live sessions ---- */

struct session_hub;

/* wake(user) is called from any thread after a session gained output. */
struct session_hub *session_hub_create(void (*wake)(void *user), void *user);
void session_hub_destroy(struct session_hub **hub);
void session_hub_set_wake(struct session_hub *hub, void (*wake)(void *user), void *user);

void session_hub_add(struct session_hub *hub, struct session *session);
void session_hub_remove(struct session_hub *hub, struct session *session);
int session_hub_count(struct session_hub *hub);
void session_hub_wake(struct session_hub *hub);

/* Queues text to every open session and wakes the transport. */
void session_hub_broadcast(struct session_hub *hub, const char *text);
/* Calls fn for every session (under the hub's lock: fn must not call back into the hub). */
void session_hub_for_each(struct session_hub *hub, void (*fn)(struct session *, void *),
                          void *user);

#endif
