#include "session.h"

#include <pthread.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include <libwebsockets.h>

#include "monotonic_clock.h"

struct text_item {
    struct text_item *next;
    char *buffer; /* LWS_PRE + length + 1 */
    size_t length;
};

struct frame_slot {
    bool in_use;
    int encoding; /* frames of it in the encoder */
    uint64_t subscription;
    struct encoded_frame *pending; /* latest unsent frame, or NULL */
    double pending_since;          /* CLOCK_MONOTONIC seconds since the slot has been full */
    struct slot_traffic traffic;
};

struct snapshot_item {
    struct proto_msg_id id;
    struct encoded_frame *frame;
};

struct session {
    atomic_int refs;
    void *transport;
    pthread_mutex_t lock;
    enum proto_msg_role role;
    char client_name[PROTO_MSG_CLIENT_MAX + 1];
    bool simulation_events;
    bool closed;
    /* close request */
    int close_code;
    bool close_after_output;
    char close_reason[96];
    /* text queue */
    struct text_item *text_head, *text_tail;
    size_t text_bytes;
    /* a frame whose "frame" text went out and whose binary part is next */
    struct encoded_frame *frame_in_flight;
    uint64_t frame_in_flight_number;
    uint64_t frames_sent;
    struct frame_slot slots[SESSION_MAX_SUBSCRIPTIONS];
    int next_slot; /* round-robin start */
    struct snapshot_item snapshots[SESSION_MAX_SNAPSHOTS];
    int snapshots_ready;    /* delivered, in snapshots[0 .. ready) */
    int snapshots_reserved; /* reserved, including ready ones */
};

struct session *session_create(void)
{
    struct session *s = calloc(1, sizeof *s);
    if (!s)
        return NULL;
    atomic_init(&s->refs, 1);
    s->role = PROTO_ROLE_VIEWER;
    pthread_mutex_init(&s->lock, NULL);
    return s;
}

struct session *session_ref(struct session *session)
{
    atomic_fetch_add_explicit(&session->refs, 1, memory_order_relaxed);
    return session;
}

static void drop_output(struct session *s)
{
    while (s->text_head) {
        struct text_item *t = s->text_head;
        s->text_head = t->next;
        free(t->buffer);
        free(t);
    }
    s->text_tail = NULL;
    s->text_bytes = 0;
    encoded_frame_unref(&s->frame_in_flight);
    for (int i = 0; i < SESSION_MAX_SUBSCRIPTIONS; i++)
        encoded_frame_unref(&s->slots[i].pending);
    for (int i = 0; i < s->snapshots_ready; i++)
        encoded_frame_unref(&s->snapshots[i].frame);
    s->snapshots_reserved -= s->snapshots_ready;
    s->snapshots_ready = 0;
}

void session_unref(struct session **session)
{
    struct session *s = *session;
    *session = NULL;
    if (!s || atomic_fetch_sub_explicit(&s->refs, 1, memory_order_acq_rel) != 1)
        return;
    drop_output(s);
    pthread_mutex_destroy(&s->lock);
    free(s);
}

void session_set_transport(struct session *session, void *transport)
{
    session->transport = transport;
}

void *session_transport(const struct session *session)
{
    return session->transport;
}

enum proto_msg_role session_role(struct session *s)
{
    pthread_mutex_lock(&s->lock);
    enum proto_msg_role role = s->role;
    pthread_mutex_unlock(&s->lock);
    return role;
}

void session_set_role(struct session *s, enum proto_msg_role role)
{
    pthread_mutex_lock(&s->lock);
    s->role = role;
    pthread_mutex_unlock(&s->lock);
}

void session_client_name(struct session *s, char *out, size_t capacity)
{
    pthread_mutex_lock(&s->lock);
    snprintf(out, capacity, "%s", s->client_name);
    pthread_mutex_unlock(&s->lock);
}

void session_set_client_name(struct session *s, const char *name)
{
    pthread_mutex_lock(&s->lock);
    snprintf(s->client_name, sizeof s->client_name, "%s", name);
    pthread_mutex_unlock(&s->lock);
}

bool session_wants_simulation_events(struct session *s)
{
    pthread_mutex_lock(&s->lock);
    bool wanted = s->simulation_events;
    pthread_mutex_unlock(&s->lock);
    return wanted;
}

void session_set_simulation_events(struct session *s, bool wanted)
{
    pthread_mutex_lock(&s->lock);
    s->simulation_events = wanted;
    pthread_mutex_unlock(&s->lock);
}

static void request_close_locked(struct session *s, int code, const char *reason, bool after_output)
{
    if (s->close_code)
        return;
    s->close_code = code;
    s->close_after_output = after_output;
    snprintf(s->close_reason, sizeof s->close_reason, "%s", reason);
}

bool session_push_text(struct session *s, const char *text)
{
    size_t length = strlen(text);
    pthread_mutex_lock(&s->lock);
    if (s->closed || (s->close_code && !s->close_after_output)) {
        pthread_mutex_unlock(&s->lock);
        return true;
    }
    if (s->text_bytes + length > SESSION_MAX_QUEUED_TEXT_BYTES) {
        drop_output(s);
        request_close_locked(s, SESSION_CLOSE_POLICY, "client is not reading", false);
        pthread_mutex_unlock(&s->lock);
        return false;
    }
    struct text_item *t = calloc(1, sizeof *t);
    char *buffer = t ? malloc(LWS_PRE + length + 1) : NULL;
    if (!buffer) {
        free(t);
        pthread_mutex_unlock(&s->lock);
        return true; /* out of memory: the message is lost, the session goes on */
    }
    memcpy(buffer + LWS_PRE, text, length + 1);
    t->buffer = buffer;
    t->length = length;
    if (s->text_tail)
        s->text_tail->next = t;
    else
        s->text_head = t;
    s->text_tail = t;
    s->text_bytes += length;
    pthread_mutex_unlock(&s->lock);
    return true;
}

void session_request_close(struct session *s, int code, const char *reason, bool after_output)
{
    pthread_mutex_lock(&s->lock);
    request_close_locked(s, code, reason, after_output);
    pthread_mutex_unlock(&s->lock);
}

void session_mark_closed(struct session *s)
{
    pthread_mutex_lock(&s->lock);
    s->closed = true;
    drop_output(s);
    pthread_mutex_unlock(&s->lock);
}

static struct frame_slot *find_slot(struct session *s, uint64_t subscription)
{
    for (int i = 0; i < SESSION_MAX_SUBSCRIPTIONS; i++)
        if (s->slots[i].in_use && s->slots[i].subscription == subscription)
            return &s->slots[i];
    return NULL;
}

bool session_add_slot(struct session *s, uint64_t subscription)
{
    pthread_mutex_lock(&s->lock);
    bool added = false;
    for (int i = 0; i < SESSION_MAX_SUBSCRIPTIONS && !added; i++) {
        if (!s->slots[i].in_use) {
            s->slots[i] = (struct frame_slot){ .in_use = true, .subscription = subscription };
            added = true;
        }
    }
    pthread_mutex_unlock(&s->lock);
    return added;
}

void session_remove_slot(struct session *s, uint64_t subscription)
{
    pthread_mutex_lock(&s->lock);
    struct frame_slot *slot = find_slot(s, subscription);
    if (slot) {
        encoded_frame_unref(&slot->pending);
        *slot = (struct frame_slot){ 0 };
    }
    pthread_mutex_unlock(&s->lock);
}

enum slot_state session_slot_state(struct session *s, uint64_t subscription, double now_s,
                                   double stale_after_s)
{
    pthread_mutex_lock(&s->lock);
    struct frame_slot *slot = s->closed ? NULL : find_slot(s, subscription);
    enum slot_state state = SLOT_READY;
    if (!slot)
        state = SLOT_GONE;
    else if (slot->encoding >= SESSION_MAX_FRAMES_ENCODING)
        state = SLOT_ENCODING;
    else if (slot->pending && now_s - slot->pending_since > stale_after_s)
        state = SLOT_STALLED;
    pthread_mutex_unlock(&s->lock);
    return state;
}

bool session_slot_begin_encode(struct session *s, uint64_t subscription)
{
    pthread_mutex_lock(&s->lock);
    struct frame_slot *slot = s->closed ? NULL : find_slot(s, subscription);
    bool begin = slot && slot->encoding < SESSION_MAX_FRAMES_ENCODING;
    if (begin)
        slot->encoding++;
    pthread_mutex_unlock(&s->lock);
    return begin;
}

void session_slot_deliver(struct session *s, uint64_t subscription, struct encoded_frame *frame)
{
    pthread_mutex_lock(&s->lock);
    struct frame_slot *slot = s->closed ? NULL : find_slot(s, subscription);
    if (slot) {
        if (slot->encoding > 0)
            slot->encoding--;
        bool newer = !slot->pending ||
                     (frame && encoded_frame_meta(frame)->render_sequence >
                                   encoded_frame_meta(slot->pending)->render_sequence);
        if (frame) {
            slot->traffic.frames_delivered++;
            slot->traffic.last_frame_bytes = encoded_frame_message_length(frame);
            slot->traffic.last_quality = encoded_frame_meta(frame)->quality;
        }
        if (frame && newer) {
            if (!slot->pending)
                slot->pending_since =
                    monotonic_seconds(); /* kept by replacements: stall detection */
            encoded_frame_unref(&slot->pending);
            slot->pending = encoded_frame_ref(frame);
        }
    }
    pthread_mutex_unlock(&s->lock);
}

bool session_slot_traffic(struct session *s, uint64_t subscription, struct slot_traffic *out)
{
    pthread_mutex_lock(&s->lock);
    struct frame_slot *slot = find_slot(s, subscription);
    if (slot)
        *out = slot->traffic;
    pthread_mutex_unlock(&s->lock);
    return slot != NULL;
}

bool session_snapshot_reserve(struct session *s)
{
    pthread_mutex_lock(&s->lock);
    bool ok = !s->closed && s->snapshots_reserved < SESSION_MAX_SNAPSHOTS;
    if (ok)
        s->snapshots_reserved++;
    pthread_mutex_unlock(&s->lock);
    return ok;
}

void session_snapshot_deliver(struct session *s, const struct proto_msg_id *id,
                              struct encoded_frame *frame)
{
    pthread_mutex_lock(&s->lock);
    if (s->closed || !frame) {
        if (!s->closed && s->snapshots_reserved > s->snapshots_ready)
            s->snapshots_reserved--;
    } else {
        struct snapshot_item *item = &s->snapshots[s->snapshots_ready++];
        item->id = *id;
        item->frame = encoded_frame_ref(frame);
    }
    pthread_mutex_unlock(&s->lock);
}

bool session_snapshot_fail(struct session *s, const struct proto_msg_id *id, const char *message)
{
    char *text = proto_msg_build_error(id, PROTO_MSG_ERR_INTERNAL, message, NULL);
    if (text)
        session_push_text(s, text);
    free(text);
    session_snapshot_deliver(s, id, NULL);
    return text != NULL;
}

static void take_text(struct session *s, struct session_output *out)
{
    struct text_item *t = s->text_head;
    s->text_head = t->next;
    if (!s->text_head)
        s->text_tail = NULL;
    s->text_bytes -= t->length;
    out->kind = SESSION_OUTPUT_TEXT;
    out->text_buffer = t->buffer;
    out->text = t->buffer + LWS_PRE;
    out->length = t->length;
    free(t);
}

/* Announces `frame` with its "frame" text; the binary part follows on the next call. */
static void start_frame(struct session *s, const struct proto_msg_id *id, uint64_t subscription,
                        struct encoded_frame *frame, struct session_output *out)
{
    uint64_t number = ++s->frames_sent;
    char *json = proto_msg_build_frame(id, subscription, number);
    char *buffer = json ? malloc(LWS_PRE + strlen(json) + 1) : NULL;
    if (!buffer) {
        free(json);
        encoded_frame_unref(&frame);
        return; /* out of memory: this frame is dropped */
    }
    size_t length = strlen(json);
    memcpy(buffer + LWS_PRE, json, length + 1);
    free(json);
    s->frame_in_flight = frame;
    s->frame_in_flight_number = number;
    out->kind = SESSION_OUTPUT_TEXT;
    out->text_buffer = buffer;
    out->text = buffer + LWS_PRE;
    out->length = length;
}

static void take_close(struct session *s, struct session_output *out)
{
    out->kind = SESSION_OUTPUT_CLOSE;
    out->close_code = s->close_code;
    snprintf(out->close_reason, sizeof out->close_reason, "%s", s->close_reason);
}

void session_next_output(struct session *s, struct session_output *out)
{
    memset(out, 0, sizeof *out);
    pthread_mutex_lock(&s->lock);
    if (s->closed) {
        pthread_mutex_unlock(&s->lock);
        return;
    }
    if (s->close_code && !s->close_after_output) {
        take_close(s, out);
    } else if (s->frame_in_flight) {
        out->kind = SESSION_OUTPUT_FRAME;
        out->frame = s->frame_in_flight;
        out->frame_number = s->frame_in_flight_number;
        s->frame_in_flight = NULL;
    } else if (s->text_head) {
        take_text(s, out);
    } else if (s->close_code) {
        take_close(s, out);
    } else if (s->snapshots_ready > 0) {
        struct snapshot_item item = s->snapshots[0];
        memmove(&s->snapshots[0], &s->snapshots[1],
                sizeof s->snapshots[0] * (size_t)(s->snapshots_ready - 1));
        s->snapshots_ready--;
        s->snapshots_reserved--;
        start_frame(s, &item.id, 0, item.frame, out);
    } else {
        for (int k = 0; k < SESSION_MAX_SUBSCRIPTIONS; k++) {
            struct frame_slot *slot = &s->slots[(s->next_slot + k) % SESSION_MAX_SUBSCRIPTIONS];
            if (!slot->in_use || !slot->pending)
                continue;
            s->next_slot = (s->next_slot + k + 1) % SESSION_MAX_SUBSCRIPTIONS;
            struct encoded_frame *frame = slot->pending;
            slot->pending = NULL;
            slot->traffic.bytes_sent += encoded_frame_message_length(frame);
            start_frame(s, NULL, slot->subscription, frame, out);
            break;
        }
    }
    pthread_mutex_unlock(&s->lock);
}

void session_output_release(struct session_output *out)
{
    free(out->text_buffer);
    encoded_frame_unref(&out->frame);
    memset(out, 0, sizeof *out);
}

bool session_has_output(struct session *s)
{
    pthread_mutex_lock(&s->lock);
    bool has = !s->closed &&
               (s->close_code || s->frame_in_flight || s->text_head || s->snapshots_ready > 0);
    for (int i = 0; i < SESSION_MAX_SUBSCRIPTIONS && !has; i++)
        has = s->slots[i].in_use && s->slots[i].pending;
    pthread_mutex_unlock(&s->lock);
    return has;
}

/* ---- hub ---- */

struct session_hub {
    pthread_mutex_t lock;
    struct session **sessions;
    int count, capacity;
    void (*wake)(void *user);
    void *wake_user;
};

struct session_hub *session_hub_create(void (*wake)(void *user), void *user)
{
    struct session_hub *hub = calloc(1, sizeof *hub);
    if (!hub)
        return NULL;
    pthread_mutex_init(&hub->lock, NULL);
    hub->wake = wake;
    hub->wake_user = user;
    return hub;
}

void session_hub_destroy(struct session_hub **hub)
{
    struct session_hub *h = *hub;
    *hub = NULL;
    if (!h)
        return;
    for (int i = 0; i < h->count; i++)
        session_unref(&h->sessions[i]);
    free(h->sessions);
    pthread_mutex_destroy(&h->lock);
    free(h);
}

void session_hub_set_wake(struct session_hub *hub, void (*wake)(void *user), void *user)
{
    pthread_mutex_lock(&hub->lock);
    hub->wake = wake;
    hub->wake_user = user;
    pthread_mutex_unlock(&hub->lock);
}

void session_hub_add(struct session_hub *hub, struct session *session)
{
    pthread_mutex_lock(&hub->lock);
    if (hub->count == hub->capacity) {
        int capacity = hub->capacity ? hub->capacity * 2 : 16;
        struct session **grown = realloc(hub->sessions, sizeof *grown * (size_t)capacity);
        if (!grown) {
            pthread_mutex_unlock(&hub->lock);
            return;
        }
        hub->sessions = grown;
        hub->capacity = capacity;
    }
    hub->sessions[hub->count++] = session_ref(session);
    pthread_mutex_unlock(&hub->lock);
}

void session_hub_remove(struct session_hub *hub, struct session *session)
{
    pthread_mutex_lock(&hub->lock);
    for (int i = 0; i < hub->count; i++) {
        if (hub->sessions[i] == session) {
            session_unref(&hub->sessions[i]);
            hub->sessions[i] = hub->sessions[--hub->count];
            break;
        }
    }
    pthread_mutex_unlock(&hub->lock);
}

int session_hub_count(struct session_hub *hub)
{
    pthread_mutex_lock(&hub->lock);
    int n = hub->count;
    pthread_mutex_unlock(&hub->lock);
    return n;
}

void session_hub_wake(struct session_hub *hub)
{
    pthread_mutex_lock(&hub->lock);
    void (*wake)(void *) = hub->wake;
    void *user = hub->wake_user;
    pthread_mutex_unlock(&hub->lock);
    if (wake)
        wake(user);
}

void session_hub_broadcast(struct session_hub *hub, const char *text)
{
    pthread_mutex_lock(&hub->lock);
    for (int i = 0; i < hub->count; i++)
        session_push_text(hub->sessions[i], text);
    pthread_mutex_unlock(&hub->lock);
    session_hub_wake(hub);
}

void session_hub_for_each(struct session_hub *hub, void (*fn)(struct session *, void *), void *user)
{
    pthread_mutex_lock(&hub->lock);
    for (int i = 0; i < hub->count; i++)
        fn(hub->sessions[i], user);
    pthread_mutex_unlock(&hub->lock);
}
