#include "frame_scheduler.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "encoder_pool.h"
#include "log.h"
#include "monotonic_clock.h"
#include "png_write.h"
#include "world_render.h"

struct subscription {
    uint64_t id; /* unique in the daemon, >= 1 */
    struct session *session;
    struct proto_msg_view view;
    double period_s, next_due; /* CLOCK_MONOTONIC seconds */
    bool waiting_for_encoder;
    /* Under view.max_kbps: the JPEG quality frames are encoded at now, and how many frames the
     * slot had received when the rate and quality were last adjusted. */
    int quality;
    uint64_t frames_seen;
};

struct pending_snapshot {
    struct session *session;
    struct proto_msg_id id;
    struct proto_msg_view view;
};

/* How a rendered view becomes a frame. */
struct encoding {
    enum proto_frame_format format;
    int quality;
};

/* The sessions that get a rendered view in one encoding. */
struct group_output {
    struct encoding encoding;
    struct encode_target *targets;
    size_t count, capacity;
};

/* Views that are due this tick, one entry per distinct render view: it is rendered once and
 * encoded once per encoding its watchers asked for (a PNG and a JPEG subscription to the same
 * view share the render). */
struct render_group {
    struct sky_render_view view;
    struct group_output *outputs;
    size_t output_count;
};

struct frame_scheduler {
    struct session_hub *hub;
    struct service_metrics *metrics;
    int encoder_threads;
    struct encoder_pool *encoder;
    uint64_t last_subscription_id;
    struct subscription *subscriptions;
    size_t subscription_count, subscription_capacity;
    struct pending_snapshot *snapshots;
    size_t snapshot_count, snapshot_capacity;
    uint64_t render_sequence;
    /* This render_due call's frames: one showed its input's frame atmosphere fully. */
    bool atmosphere_shown;
    struct sky_render_stats last_stats;
    bool has_stats;
    double fps; /* frames rendered per second over the last second */
    double fps_window_start;
    int fps_window_frames;
};

/* world_render_view zero-fills the struct first, so equal views compare equal bytewise. */
static struct render_group *group_for(struct render_group **groups, size_t *count,
                                      const struct sky_render_view *view)
{
    for (size_t i = 0; i < *count; i++)
        if (memcmp(&(*groups)[i].view, view, sizeof *view) == 0)
            return &(*groups)[i];
    struct render_group *grown = realloc(*groups, sizeof *grown * (*count + 1));
    if (!grown)
        return NULL;
    *groups = grown;
    struct render_group *g = &grown[(*count)++];
    memset(g, 0, sizeof *g);
    g->view = *view;
    return g;
}

static struct group_output *output_for(struct render_group *g, struct encoding encoding)
{
    for (size_t i = 0; i < g->output_count; i++)
        if (g->outputs[i].encoding.format == encoding.format &&
            g->outputs[i].encoding.quality == encoding.quality)
            return &g->outputs[i];
    struct group_output *grown = realloc(g->outputs, sizeof *grown * (g->output_count + 1));
    if (!grown)
        return NULL;
    g->outputs = grown;
    struct group_output *o = &grown[g->output_count++];
    memset(o, 0, sizeof *o);
    o->encoding = encoding;
    return o;
}

/* Adds a target to the group's output in `encoding`; false when memory is out. */
static bool group_add(struct render_group *g, struct encoding encoding, struct session *session,
                      uint64_t subscription, const struct proto_msg_id *snapshot_id)
{
    struct group_output *o = output_for(g, encoding);
    if (!o)
        return false;
    if (o->count == o->capacity) {
        size_t capacity = o->capacity ? o->capacity * 2 : 4;
        struct encode_target *grown = realloc(o->targets, sizeof *grown * capacity);
        if (!grown)
            return false;
        o->targets = grown;
        o->capacity = capacity;
    }
    struct encode_target *t = &o->targets[o->count++];
    memset(t, 0, sizeof *t);
    t->session = session_ref(session);
    t->subscription = subscription;
    if (snapshot_id)
        t->snapshot_id = *snapshot_id;
    return true;
}

static size_t group_target_count(const struct render_group *g)
{
    size_t count = 0;
    for (size_t i = 0; i < g->output_count; i++)
        count += g->outputs[i].count;
    return count;
}

/* A snapshot answered with an error instead of its frame. The encoder workers call it too:
 * service_metrics takes its own lock. */
static void count_failed_snapshot(void *user)
{
    struct frame_scheduler *fs = user;
    service_metrics_error(fs->metrics, PROTO_MSG_ERR_INTERNAL);
}

static void fail_snapshot(struct frame_scheduler *fs, struct session *session,
                          const struct proto_msg_id *id, const char *message)
{
    if (session_snapshot_fail(session, id, message))
        count_failed_snapshot(fs);
}

/* A view that could not be rendered: its subscriptions skip a frame, its snapshots are
 * answered with `message`. */
static void fail_targets(struct frame_scheduler *fs, struct encode_target *targets, size_t count,
                         const char *message)
{
    for (size_t i = 0; i < count; i++) {
        if (targets[i].subscription)
            session_slot_deliver(targets[i].session, targets[i].subscription, NULL);
        else
            fail_snapshot(fs, targets[i].session, &targets[i].snapshot_id, message);
        session_unref(&targets[i].session);
    }
    free(targets);
}

/* While an atmosphere change is still being rebuilt, a frame carries the last revision whose
 * atmosphere was on screen: a client waiting for its revision then knows its change is
 * visible when a frame carries it. */
static uint64_t carried_revision(struct frame_scheduler *fs, const struct render_input *input,
                                 bool atmosphere_settled)
{
    fs->atmosphere_shown |= atmosphere_settled;
    return fs->atmosphere_shown || !input->atmosphere_pending ? input->state.revision
                                                              : input->settled_revision;
}

/* Frees what the group holds that no encoder job took. */
static void free_group(struct render_group *g)
{
    for (size_t i = 0; i < g->output_count; i++)
        free(g->outputs[i].targets);
    free(g->outputs);
    g->outputs = NULL;
    g->output_count = 0;
}

static void render_group(struct frame_scheduler *fs, struct renderer_host *renderer,
                         const struct render_input *input, struct render_group *g)
{
    bool linear = g->view.output == SKY_RENDER_OUTPUT_LINEAR;
    size_t bytes = (size_t)g->view.width * g->view.height * (linear ? 16 : 4);
    void *pixels = malloc(bytes);
    /* Amortizing map builds only helps a stream: with nobody subscribed a snapshot shows the
     * clouds asked for at once. */
    bool unwatched = fs->subscription_count == 0;
    struct sky_render_stats stats;
    double started = monotonic_seconds();
    int rendered = pixels ? renderer_host_render(renderer, input, &g->view, unwatched, pixels,
                                                 bytes, &stats)
                          : -1;
    if (rendered != 0) {
        char what[64], message[512];
        snprintf(what, sizeof what, "rendering the %ux%u view", g->view.width, g->view.height);
        if (pixels)
            renderer_host_describe_failure(renderer, what, message, sizeof message);
        else
            snprintf(message, sizeof message, "%s failed: out of memory for its pixels", what);
        skyd_log(SKYD_LOG_ERROR, "%s", message);
        free(pixels);
        for (size_t i = 0; i < g->output_count; i++)
            fail_targets(fs, g->outputs[i].targets, g->outputs[i].count, message);
        free(g->outputs);
        g->outputs = NULL;
        g->output_count = 0;
        session_hub_wake(fs->hub);
        return;
    }
    service_metrics_frame_rendered(fs->metrics, monotonic_seconds() - started);
    fs->last_stats = stats;
    fs->has_stats = true;
    uint64_t revision = carried_revision(fs, input, stats.atmosphere_settled);
    fs->fps_window_frames++;
    uint64_t sequence = ++fs->render_sequence; /* every encoding of this render carries it */
    /* One job per encoding; each owns its pixels, so all but the last get a copy. */
    size_t last_used = g->output_count;
    for (size_t i = 0; i < g->output_count; i++)
        if (g->outputs[i].count > 0)
            last_used = i;
    for (size_t i = 0; i < g->output_count; i++) {
        struct group_output *o = &g->outputs[i];
        if (o->count == 0) {
            free(o->targets);
            continue;
        }
        bool last = i == last_used;
        void *own = last ? pixels : malloc(bytes);
        if (!own) {
            fail_targets(fs, o->targets, o->count, "out of memory for an encoding's pixels");
            continue;
        }
        if (!last)
            memcpy(own, pixels, bytes);
        struct encode_job job = {
            .pixels = own,
            .full_scale_cd_m2 = linear ? png_linear16_full_scale(stats.exposure) : 0.0,
            .quality = o->encoding.quality,
            .meta = { .render_sequence = sequence,
                      .state_revision = revision,
                      .simulation_time_s = input->state.clock.utc_unix_s,
                      .width = g->view.width,
                      .height = g->view.height,
                      .format = o->encoding.format,
                      .quality = o->encoding.quality },
            .targets = o->targets,
            .target_count = o->count,
        };
        encoder_pool_submit(fs->encoder, &job);
    }
    if (last_used == g->output_count)
        free(pixels);
    free(g->outputs);
    g->outputs = NULL;
    g->output_count = 0;
}

static struct encoding encoding_of(const struct proto_msg_view *view, int quality)
{
    return (struct encoding){ .format = view->format,
                              .quality = view->format == PROTO_FRAME_FORMAT_JPEG ? quality : 0 };
}

static struct encoding subscription_encoding(const struct subscription *s)
{
    return encoding_of(&s->view, s->quality);
}

/* Keeps a subscription with max_kbps within its bound, from the size of its newest frame:
 * a JPEG's quality drops in steps of 5 (not below 50) while the requested rate would exceed
 * the bound, and climbs back while it would use under half of it; the period then stretches
 * so that frames of that size fit. Sizes are looked at once per new frame. */
#define BANDWIDTH_QUALITY_FLOOR 50
#define BANDWIDTH_QUALITY_STEP 5
static void fit_bandwidth(struct subscription *s)
{
    struct slot_traffic traffic;
    if (s->view.max_kbps <= 0 || !session_slot_traffic(s->session, s->id, &traffic) ||
        traffic.frames_delivered == s->frames_seen || traffic.last_frame_bytes == 0)
        return;
    s->frames_seen = traffic.frames_delivered;
    double budget_bytes_s = s->view.max_kbps * 1000.0 / 8.0;
    double wanted_bytes_s = (double)traffic.last_frame_bytes * s->view.fps;
    bool jpeg = s->view.format == PROTO_FRAME_FORMAT_JPEG;
    /* Only a frame of the current quality says what that quality costs. */
    if (jpeg && traffic.last_quality == s->quality) {
        int floor = s->view.quality < BANDWIDTH_QUALITY_FLOOR ? s->view.quality
                                                              : BANDWIDTH_QUALITY_FLOOR;
        if (wanted_bytes_s > budget_bytes_s && s->quality > floor)
            s->quality = s->quality - BANDWIDTH_QUALITY_STEP > floor
                             ? s->quality - BANDWIDTH_QUALITY_STEP
                             : floor;
        else if (wanted_bytes_s < 0.5 * budget_bytes_s && s->quality < s->view.quality)
            s->quality = s->quality + BANDWIDTH_QUALITY_STEP < s->view.quality
                             ? s->quality + BANDWIDTH_QUALITY_STEP
                             : s->view.quality;
    }
    double period = fmax(1.0 / s->view.fps, (double)traffic.last_frame_bytes / budget_bytes_s);
    s->next_due += period - s->period_s;
    s->period_s = period;
}

/* Next due time after a frame: keeps the rate, without a burst after falling behind. */
static double advance_due(double due, double period, double now)
{
    return now - due < period ? due + period : now + period;
}

/* Subscriptions to the same view are scheduled together, so they stay in step and share
 * every rendering: a view is rendered when one of its subscriptions is due and none of them
 * has a frame in the encoder; it then serves every subscription within half a period of due.
 */
static void schedule_view(struct frame_scheduler *fs, const size_t *members, size_t count,
                          const struct sky_render_view *view, struct render_group **groups,
                          size_t *group_count, double now)
{
    enum slot_state states[count];
    bool in_encoder = false, due = false;
    for (size_t k = 0; k < count; k++) {
        struct subscription *s = &fs->subscriptions[members[k]];
        states[k] = session_slot_state(s->session, s->id, now, fmax(2.0 * s->period_s, 0.25));
        in_encoder |= states[k] == SLOT_ENCODING;
        due |= states[k] == SLOT_READY && now >= s->next_due;
        if (states[k] == SLOT_STALLED && now >= s->next_due) {
            s->next_due = now + s->period_s; /* look again later; nothing is rendered */
            service_metrics_frame_skipped(fs->metrics);
        }
    }
    for (size_t k = 0; k < count; k++)
        fs->subscriptions[members[k]].waiting_for_encoder = in_encoder;
    if (in_encoder || !due)
        return;
    struct render_group *g = group_for(groups, group_count, view);
    for (size_t k = 0; k < count && g; k++) {
        struct subscription *s = &fs->subscriptions[members[k]];
        if (states[k] != SLOT_READY || now < s->next_due - 0.5 * s->period_s ||
            !session_slot_begin_encode(s->session, s->id))
            continue;
        if (!group_add(g, subscription_encoding(s), s->session, s->id, NULL)) {
            session_slot_deliver(s->session, s->id, NULL);
            continue;
        }
        s->next_due = advance_due(s->next_due, s->period_s, now);
    }
}

/* Groups the pending snapshots and the due subscriptions by view, renders each view once, and
 * returns when the loop should next look at the schedule. */
double frame_scheduler_render_due(struct frame_scheduler *fs, struct renderer_host *renderer,
                                  const struct render_input *input, double now,
                                  bool *atmosphere_shown)
{
    fs->atmosphere_shown = false;
    struct render_group *groups = NULL;
    size_t group_count = 0;
    double next_wake = now + 1.0;
    bool encoder_full = encoder_pool_backlog(fs->encoder) >= 2 * fs->encoder_threads;

    for (size_t i = 0; i < fs->snapshot_count; i++) {
        struct pending_snapshot *p = &fs->snapshots[i];
        struct sky_render_view view;
        world_render_view(input, &p->view, &view);
        struct render_group *g = group_for(&groups, &group_count, &view);
        if (!g || !group_add(g, encoding_of(&p->view, p->view.quality), p->session, 0, &p->id))
            session_snapshot_deliver(p->session, &p->id, NULL);
        session_unref(&p->session);
    }
    fs->snapshot_count = 0;

    size_t n = fs->subscription_count;
    struct sky_render_view *views = n ? malloc(sizeof *views * n) : NULL;
    size_t *members = n ? malloc(sizeof *members * n) : NULL;
    bool *grouped = n ? calloc(n, sizeof *grouped) : NULL;
    if (n && (!views || !members || !grouped))
        encoder_full = true; /* out of memory: try again at the next tick */
    for (size_t i = 0; i < n; i++)
        fs->subscriptions[i].waiting_for_encoder = encoder_full;
    for (size_t i = 0; i < n && !encoder_full; i++) {
        world_render_view(input, &fs->subscriptions[i].view, &views[i]);
        fit_bandwidth(&fs->subscriptions[i]);
    }
    for (size_t i = 0; i < n && !encoder_full; i++) {
        if (grouped[i])
            continue;
        size_t count = 0;
        for (size_t j = i; j < n; j++) {
            if (!grouped[j] && memcmp(&views[i], &views[j], sizeof views[i]) == 0) {
                grouped[j] = true;
                members[count++] = j;
            }
        }
        /* The group's cloud history follows its oldest subscription, which keeps it while the
         * camera moves (reprojection handles that); snapshots share key 0. */
        views[i].history_key = fs->subscriptions[members[0]].id;
        views[i].live = true; /* a new subscriber's clouds converge live, nobody waits */
        schedule_view(fs, members, count, &views[i], &groups, &group_count, now);
    }
    free(views);
    free(members);
    free(grouped);
    for (size_t i = 0; i < group_count; i++) {
        if (group_target_count(&groups[i]) > 0)
            render_group(fs, renderer, input, &groups[i]);
        else
            free_group(&groups[i]);
    }
    free(groups);

    double after = monotonic_seconds();
    for (size_t i = 0; i < fs->subscription_count; i++) {
        struct subscription *s = &fs->subscriptions[i];
        if (!s->waiting_for_encoder)
            next_wake = fmin(next_wake, fmax(s->next_due, after));
    }
    *atmosphere_shown = fs->atmosphere_shown;
    return next_wake;
}
void frame_scheduler_tick(struct frame_scheduler *fs, double now)
{
    double elapsed = now - fs->fps_window_start;
    if (elapsed < 1.0)
        return;
    fs->fps = fs->fps_window_frames / elapsed;
    fs->fps_window_frames = 0;
    fs->fps_window_start = now;
}

double frame_scheduler_fps(const struct frame_scheduler *fs)
{
    return fs->fps;
}

const struct sky_render_stats *frame_scheduler_last_stats(const struct frame_scheduler *fs)
{
    return fs->has_stats ? &fs->last_stats : NULL;
}

size_t frame_scheduler_subscription_count(const struct frame_scheduler *fs)
{
    return fs->subscription_count;
}

size_t frame_scheduler_session_stats(const struct frame_scheduler *fs, struct session *session,
                                     struct proto_msg_subscription_stats *out, size_t capacity)
{
    size_t count = 0;
    for (size_t i = 0; i < fs->subscription_count && count < capacity; i++) {
        const struct subscription *s = &fs->subscriptions[i];
        struct slot_traffic traffic = { 0 };
        if ((session && s->session != session) ||
            !session_slot_traffic(s->session, s->id, &traffic))
            continue;
        out[count++] = (struct proto_msg_subscription_stats){
            .subscription = s->id,
            .bytes_sent = traffic.bytes_sent,
            .fps = 1.0 / s->period_s,
            .quality = subscription_encoding(s).quality,
            .max_kbps = s->view.max_kbps,
        };
    }
    return count;
}

/* ---- subscriptions and snapshots ---- */

struct frame_scheduler *frame_scheduler_create(const struct frame_scheduler_params *params)
{
    struct frame_scheduler *fs = calloc(1, sizeof *fs);
    if (!fs)
        return NULL;
    fs->hub = params->hub;
    fs->metrics = params->metrics;
    fs->encoder_threads = params->encoder_threads;
    fs->fps_window_start = monotonic_seconds();
    struct encoder_pool_callbacks callbacks = { .done = params->encoded,
                                                .done_user = params->user,
                                                .failed = count_failed_snapshot,
                                                .failed_user = fs };
    fs->encoder = encoder_pool_create(params->encoder_threads, params->hub, &callbacks);
    if (!fs->encoder) {
        free(fs);
        return NULL;
    }
    return fs;
}

static void remove_subscription(struct frame_scheduler *fs, size_t index)
{
    struct subscription *s = &fs->subscriptions[index];
    session_remove_slot(s->session, s->id);
    session_unref(&s->session);
    fs->subscriptions[index] = fs->subscriptions[--fs->subscription_count];
}

void frame_scheduler_destroy(struct frame_scheduler **scheduler)
{
    struct frame_scheduler *fs = scheduler ? *scheduler : NULL;
    if (!fs)
        return;
    encoder_pool_destroy(&fs->encoder);
    while (fs->subscription_count > 0)
        remove_subscription(fs, fs->subscription_count - 1);
    for (size_t i = 0; i < fs->snapshot_count; i++)
        session_unref(&fs->snapshots[i].session);
    free(fs->subscriptions);
    free(fs->snapshots);
    free(fs);
    *scheduler = NULL;
}

/* Makes room for one more item in a growing array; false when memory is out. */
static bool reserve_one(void **items, size_t *capacity, size_t count, size_t item_size)
{
    if (count < *capacity)
        return true;
    size_t grown_capacity = *capacity ? *capacity * 2 : 8;
    void *grown = realloc(*items, item_size * grown_capacity);
    if (!grown)
        return false;
    *items = grown;
    *capacity = grown_capacity;
    return true;
}

/* clang-format off */
#if defined(__GNUC__)
__attribute__((format(printf, 2, 3)))
#endif
static struct frame_refusal refusal(enum proto_msg_error_code code, const char *format, ...)
/* clang-format on */
{
    struct frame_refusal r = { .code = code };
    va_list args;
    va_start(args, format);
    vsnprintf(r.message, sizeof r.message, format, args);
    va_end(args);
    return r;
}

struct frame_refusal frame_scheduler_subscribe(struct frame_scheduler *fs, struct session *session,
                                               const struct proto_msg_view *view, uint64_t *id)
{
    if (!reserve_one((void **)&fs->subscriptions, &fs->subscription_capacity,
                     fs->subscription_count, sizeof *fs->subscriptions))
        return refusal(PROTO_MSG_ERR_INTERNAL, "out of memory");
    uint64_t next = fs->last_subscription_id + 1;
    if (!session_add_slot(session, next)) {
        return refusal(PROTO_MSG_ERR_LIMIT_REACHED, "at most %d subscriptions per connection",
                       SESSION_MAX_SUBSCRIPTIONS);
    }
    fs->last_subscription_id = next;
    fs->subscriptions[fs->subscription_count++] = (struct subscription){
        .id = next,
        .session = session_ref(session),
        .view = *view,
        .period_s = 1.0 / view->fps,
        .next_due = monotonic_seconds(),
        .quality = view->quality,
    };
    *id = next;
    return (struct frame_refusal){ .code = PROTO_MSG_OK };
}

bool frame_scheduler_unsubscribe(struct frame_scheduler *fs, struct session *session, uint64_t id)
{
    for (size_t i = 0; i < fs->subscription_count; i++) {
        if (fs->subscriptions[i].session == session && fs->subscriptions[i].id == id) {
            remove_subscription(fs, i);
            return true;
        }
    }
    return false;
}

struct frame_refusal frame_scheduler_snapshot(struct frame_scheduler *fs, struct session *session,
                                              const struct proto_msg_id *id,
                                              const struct proto_msg_view *view)
{
    if (!reserve_one((void **)&fs->snapshots, &fs->snapshot_capacity, fs->snapshot_count,
                     sizeof *fs->snapshots))
        return refusal(PROTO_MSG_ERR_INTERNAL, "out of memory");
    if (!session_snapshot_reserve(session)) {
        return refusal(PROTO_MSG_ERR_LIMIT_REACHED,
                       "at most %d snapshots may be pending per connection", SESSION_MAX_SNAPSHOTS);
    }
    fs->snapshots[fs->snapshot_count++] =
        (struct pending_snapshot){ .session = session_ref(session), .id = *id, .view = *view };
    return (struct frame_refusal){ .code = PROTO_MSG_OK };
}

void frame_scheduler_session_closed(struct frame_scheduler *fs, struct session *session)
{
    for (size_t i = fs->subscription_count; i-- > 0;)
        if (fs->subscriptions[i].session == session)
            remove_subscription(fs, i);
    for (size_t i = fs->snapshot_count; i-- > 0;) {
        if (fs->snapshots[i].session == session) {
            session_unref(&fs->snapshots[i].session);
            fs->snapshots[i] = fs->snapshots[--fs->snapshot_count];
        }
    }
}

void frame_scheduler_fail_snapshots(struct frame_scheduler *fs, const char *message)
{
    for (size_t i = 0; i < fs->snapshot_count; i++) {
        fail_snapshot(fs, fs->snapshots[i].session, &fs->snapshots[i].id, message);
        session_unref(&fs->snapshots[i].session);
    }
    fs->snapshot_count = 0;
    session_hub_wake(fs->hub);
}
