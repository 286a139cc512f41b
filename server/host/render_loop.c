#include "render_loop.h"

#ifdef __GLIBC__
#include <malloc.h>
#endif
#include <math.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "encoder_pool.h"
#include "png_write.h"
#include "render_commands.h"
#include "sky_renderer.h"
#include "state_store.h"
#include "world_render.h"
#include "world_sim.h"
#include "monotonic_clock.h"

/* While only the simulation changes the state, it is written at most this often. */
static const double SIM_SAVE_PERIOD_S = 30.0;
/* Free memory is given back to the system at most this often (give_back_free_memory). */
static const double TRIM_PERIOD_S = 10.0;

enum command_kind { COMMAND_MESSAGE, COMMAND_REPLY, COMMAND_SESSION_CLOSED };

struct command {
    struct command *next;
    enum command_kind kind;
    struct session *session; /* a reference */
    struct sky_client_msg msg;
    char *reply;
};

/* Views that are due this tick, one entry per distinct render view. */
struct render_group {
    struct sky_render_view view;
    struct encode_target *targets;
    size_t count, capacity;
};

struct render_loop {
    struct render_context ctx; /* what the command handlers see and change */
    pthread_t thread;
    pthread_mutex_t lock;
    pthread_cond_t wake;
    struct command *head, *tail;
    bool notified, stopping;
    bool started; /* the thread runs (set before it starts; destroy joins it) */
    struct encoder_pool *encoder;
    double fps_window_start;
    int fps_window_frames;
    double last_trim_s;
    void (*on_failure)(void *user);
    void *failure_user;
    char failure[384]; /* why the loop stopped on its own; "" while it runs (under lock) */
};

static void free_command(struct command *c)
{
    sky_client_msg_free(&c->msg);
    free(c->reply);
    session_unref(&c->session);
    free(c);
}

static void enqueue(struct render_loop *loop, struct command *c)
{
    pthread_mutex_lock(&loop->lock);
    if (loop->stopping) {
        pthread_mutex_unlock(&loop->lock);
        free_command(c);
        return;
    }
    if (loop->tail)
        loop->tail->next = c;
    else
        loop->head = c;
    loop->tail = c;
    pthread_cond_signal(&loop->wake);
    pthread_mutex_unlock(&loop->lock);
}

void render_loop_submit_message(struct render_loop *loop, struct session *session,
                                struct sky_client_msg *msg)
{
    struct command *c = calloc(1, sizeof *c);
    if (!c) {
        sky_client_msg_free(msg);
        return;
    }
    c->kind = COMMAND_MESSAGE;
    c->session = session_ref(session);
    c->msg = *msg;
    memset(msg, 0, sizeof *msg);
    enqueue(loop, c);
}

void render_loop_submit_reply(struct render_loop *loop, struct session *session, char *text)
{
    struct command *c = calloc(1, sizeof *c);
    if (!c) {
        free(text);
        return;
    }
    c->kind = COMMAND_REPLY;
    c->session = session_ref(session);
    c->reply = text;
    enqueue(loop, c);
}

void render_loop_session_closed(struct render_loop *loop, struct session *session)
{
    struct command *c = calloc(1, sizeof *c);
    if (!c)
        return;
    c->kind = COMMAND_SESSION_CLOSED;
    c->session = session_ref(session);
    enqueue(loop, c);
}

void render_loop_notify(struct render_loop *loop)
{
    pthread_mutex_lock(&loop->lock);
    loop->notified = true;
    pthread_cond_signal(&loop->wake);
    pthread_mutex_unlock(&loop->lock);
}

static void encoder_done(void *user)
{
    render_loop_notify(user);
}

/* ---- rendering ---- */

static void resolve_render_view(const struct sky_world_state *state,
                                const struct sky_msg_view *view, struct sky_render_view *out)
{
    struct sky_world_state resolved = *state;
    sky_msg_view_resolve(view, state, &resolved.camera, &resolved.exposure);
    world_to_render_view(&resolved, view->width, view->height,
                         view->format == SKY_FRAME_FORMAT_PNG16 ? SKY_RENDER_OUTPUT_LINEAR
                                                                : SKY_RENDER_OUTPUT_SRGB8,
                         out);
    out->projection = view->projection == SKY_VIEW_PROJECTION_EQUIRECTANGULAR
                          ? SKY_RENDER_PROJECTION_EQUIRECTANGULAR
                          : SKY_RENDER_PROJECTION_PERSPECTIVE;
}

/* world_to_render_view zero-fills the struct first, so equal views compare equal bytewise. */
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

static bool group_add(struct render_group *g, struct session *session, uint64_t subscription,
                      const struct sky_msg_id *snapshot_id)
{
    if (g->count == g->capacity) {
        size_t capacity = g->capacity ? g->capacity * 2 : 4;
        struct encode_target *grown = realloc(g->targets, sizeof *grown * capacity);
        if (!grown)
            return false;
        g->targets = grown;
        g->capacity = capacity;
    }
    struct encode_target *t = &g->targets[g->count++];
    memset(t, 0, sizeof *t);
    t->session = session_ref(session);
    t->subscription = subscription;
    if (snapshot_id)
        t->snapshot_id = *snapshot_id;
    return true;
}

/* A view that could not be rendered: its subscriptions skip a frame, its snapshots are
 * answered with `message`. */
static void fail_targets(struct encode_target *targets, size_t count, const char *message)
{
    for (size_t i = 0; i < count; i++) {
        if (targets[i].subscription)
            session_slot_deliver(targets[i].session, targets[i].subscription, NULL);
        else
            session_snapshot_fail(targets[i].session, &targets[i].snapshot_id, message);
        session_unref(&targets[i].session);
    }
    free(targets);
}

static void render_group(struct render_loop *loop, struct render_group *g)
{
    struct render_context *ctx = &loop->ctx;
    bool linear = g->view.output == SKY_RENDER_OUTPUT_LINEAR;
    size_t bytes = (size_t)g->view.width * g->view.height * (linear ? 16 : 4);
    void *pixels = malloc(bytes);
    /* Amortizing map builds only helps a stream: with nobody subscribed a snapshot shows the
     * clouds asked for at once. */
    bool unwatched = ctx->subscription_count == 0;
    struct sky_render_stats stats;
    int rendered = pixels ? renderer_host_render(ctx->renderer, &ctx->state, &ctx->atmosphere,
                                                 &g->view, unwatched, pixels, bytes, &stats)
                          : -1;
    if (rendered != 0) {
        char what[64], message[512];
        snprintf(what, sizeof what, "rendering the %ux%u view", g->view.width, g->view.height);
        if (pixels)
            renderer_host_describe_failure(ctx->renderer, what, message, sizeof message);
        else
            snprintf(message, sizeof message, "%s failed: out of memory for its pixels", what);
        fprintf(stderr, "skyd: %s\n", message);
        free(pixels);
        fail_targets(g->targets, g->count, message);
        session_hub_wake(ctx->hub);
        return;
    }
    ctx->last_stats = stats;
    ctx->has_stats = true;
    /* While an atmosphere change is still being rebuilt, a frame shows the state of the last
     * revision whose atmosphere was on screen: a client waiting for its revision then knows
     * its change is visible when a frame carries it. */
    if (stats.atmosphere_settled || !ctx->atmosphere_pending) {
        ctx->settled_revision = ctx->state.revision;
        ctx->atmosphere_pending = false;
    }
    loop->fps_window_frames++;
    struct encode_job job = {
        .pixels = pixels,
        .full_scale_cd_m2 = linear ? png_linear16_full_scale(stats.exposure) : 0.0,
        .meta = { .render_sequence = ++ctx->render_sequence,
                  .state_revision = ctx->settled_revision,
                  .simulation_time_s = ctx->state.clock.utc_unix_s,
                  .width = g->view.width,
                  .height = g->view.height,
                  .format = linear ? SKY_FRAME_FORMAT_PNG16 : SKY_FRAME_FORMAT_PNG },
        .targets = g->targets,
        .target_count = g->count,
    };
    encoder_pool_submit(loop->encoder, &job);
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
static void schedule_view(struct render_loop *loop, const size_t *members, size_t count,
                          const struct sky_render_view *view, struct render_group **groups,
                          size_t *group_count, double now)
{
    struct render_context *ctx = &loop->ctx;
    enum slot_state states[count];
    bool encoding = false, due = false;
    for (size_t k = 0; k < count; k++) {
        struct subscription *s = &ctx->subscriptions[members[k]];
        states[k] = session_slot_state(s->session, s->id, now, fmax(2.0 * s->period_s, 0.25));
        encoding |= states[k] == SLOT_ENCODING;
        due |= states[k] == SLOT_READY && now >= s->next_due;
        if (states[k] == SLOT_STALLED && now >= s->next_due)
            s->next_due = now + s->period_s; /* look again later; nothing is rendered */
    }
    for (size_t k = 0; k < count; k++)
        ctx->subscriptions[members[k]].waiting_for_encoder = encoding;
    if (encoding || !due)
        return;
    struct render_group *g = group_for(groups, group_count, view);
    for (size_t k = 0; k < count && g; k++) {
        struct subscription *s = &ctx->subscriptions[members[k]];
        if (states[k] != SLOT_READY || now < s->next_due - 0.5 * s->period_s ||
            !session_slot_begin_encode(s->session, s->id))
            continue;
        if (!group_add(g, s->session, s->id, NULL)) {
            session_slot_deliver(s->session, s->id, NULL);
            continue;
        }
        s->next_due = advance_due(s->next_due, s->period_s, now);
    }
}

/* Amortizing a rebuild only helps a stream: with nobody subscribed, the atmosphere is rebuilt
 * at once, so that a snapshot, or the first frames of a new subscription, show it. */
static void settle_atmosphere_if_unwatched(struct render_context *ctx)
{
    if (!ctx->atmosphere_pending || ctx->subscription_count > 0)
        return;
    if (renderer_host_rebuild_atmosphere(ctx->renderer, &ctx->atmosphere) == 0) {
        ctx->atmosphere_pending = false;
        ctx->settled_revision = ctx->state.revision;
    }
}

/* Groups the pending snapshots and the due subscriptions by view, renders each view once, and
 * returns when the loop should next look at the schedule. */
static double render_due(struct render_loop *loop, double now)
{
    struct render_context *ctx = &loop->ctx;
    settle_atmosphere_if_unwatched(ctx);
    struct render_group *groups = NULL;
    size_t group_count = 0;
    double next_wake = now + 1.0;
    bool encoder_full = encoder_pool_backlog(loop->encoder) >= 2 * ctx->config->encoder_threads;

    for (size_t i = 0; i < ctx->snapshot_count; i++) {
        struct pending_snapshot *p = &ctx->snapshots[i];
        struct sky_render_view view;
        resolve_render_view(&ctx->state, &p->view, &view);
        struct render_group *g = group_for(&groups, &group_count, &view);
        if (!g || !group_add(g, p->session, 0, &p->id))
            session_snapshot_deliver(p->session, &p->id, NULL);
        session_unref(&p->session);
    }
    ctx->snapshot_count = 0;

    size_t n = ctx->subscription_count;
    struct sky_render_view *views = n ? malloc(sizeof *views * n) : NULL;
    size_t *members = n ? malloc(sizeof *members * n) : NULL;
    bool *grouped = n ? calloc(n, sizeof *grouped) : NULL;
    if (n && (!views || !members || !grouped))
        encoder_full = true; /* out of memory: try again at the next tick */
    for (size_t i = 0; i < n; i++)
        ctx->subscriptions[i].waiting_for_encoder = encoder_full;
    for (size_t i = 0; i < n && !encoder_full; i++)
        resolve_render_view(&ctx->state, &ctx->subscriptions[i].view, &views[i]);
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
        views[i].history_key = ctx->subscriptions[members[0]].id;
        views[i].live = true; /* a new subscriber's clouds converge live, nobody waits */
        schedule_view(loop, members, count, &views[i], &groups, &group_count, now);
    }
    free(views);
    free(members);
    free(grouped);
    for (size_t i = 0; i < group_count; i++) {
        if (groups[i].count > 0)
            render_group(loop, &groups[i]);
        else
            free(groups[i].targets);
    }
    free(groups);

    double after = monotonic_seconds();
    for (size_t i = 0; i < ctx->subscription_count; i++) {
        struct subscription *s = &ctx->subscriptions[i];
        if (!s->waiting_for_encoder)
            next_wake = fmin(next_wake, fmax(s->next_due, after));
    }
    return next_wake;
}

/* ---- the world simulation ---- */

/* Advances the world by the real time since the last tick times clock.time_scale. The
 * revision stays: it counts accepted client changes. A haze change the simulation makes is
 * handed to the renderer once the previous one has settled, so a humidity that changes every
 * tick cannot keep restarting the amortized LUT rebuild; with nobody watching it is rebuilt
 * at once. */
static void simulate(struct render_context *ctx, double now)
{
    double real_dt = now - ctx->last_tick_s;
    ctx->last_tick_s = now;
    struct sky_world_state before;
    memcpy(&before, &ctx->state, sizeof before);
    world_sim_advance(&ctx->state, world_sim_scaled_dt(&ctx->state, real_dt));
    if (memcmp(&before, &ctx->state, sizeof before) != 0)
        ctx->sim_dirty = true;
    struct sky_render_atmosphere fresh;
    world_to_render_atmosphere(&ctx->state, &fresh);
    if (memcmp(&fresh, &ctx->atmosphere, sizeof fresh) == 0 || ctx->atmosphere_pending)
        return;
    if (ctx->subscription_count == 0) {
        if (renderer_host_rebuild_atmosphere(ctx->renderer, &fresh) == 0)
            ctx->atmosphere = fresh;
    } else if (!ctx->has_stats || ctx->last_stats.atmosphere_settled) {
        ctx->atmosphere = fresh;
    }
}

/* ---- persistence and statistics ---- */

static void save_state(struct render_context *ctx)
{
    if (!ctx->state_file[0] || !(ctx->dirty || ctx->sim_dirty))
        return;
    char err[512];
    ctx->last_save_s = monotonic_seconds();
    if (state_store_save(ctx->state_file, &ctx->state, err, sizeof err) == 0) {
        ctx->dirty = false;
        ctx->sim_dirty = false;
    } else {
        fprintf(stderr, "skyd: cannot save the state: %s\n", err);
        ctx->last_change_s = monotonic_seconds(); /* try again after another delay */
    }
}

static void update_fps(struct render_loop *loop, double now)
{
    double elapsed = now - loop->fps_window_start;
    if (elapsed < 1.0)
        return;
    loop->ctx.fps = loop->fps_window_frames / elapsed;
    loop->fps_window_frames = 0;
    loop->fps_window_start = now;
}

/* ---- the thread ---- */

static void run_command(struct render_loop *loop, struct command *c)
{
    switch (c->kind) {
    case COMMAND_MESSAGE:
        render_commands_handle(&loop->ctx, c->session, &c->msg);
        break;
    case COMMAND_REPLY:
        session_push_text(c->session, c->reply);
        break;
    case COMMAND_SESSION_CLOSED:
        render_commands_session_closed(&loop->ctx, c->session);
        break;
    }
    free_command(c);
}

/* Rendering cannot go on (the device was lost and no renderer could be made again): the
 * snapshots still waiting hear why, the loop takes no more commands, and the owner is told to
 * stop serving; the thread then saves the state and ends. */
static void stop_on_failure(struct render_loop *loop, const char *why)
{
    struct render_context *ctx = &loop->ctx;
    fprintf(stderr, "skyd: error: %s; saving the state and stopping\n", why);
    char message[448];
    snprintf(message, sizeof message, "the daemon is stopping: %s", why);
    for (size_t i = 0; i < ctx->snapshot_count; i++) {
        session_snapshot_fail(ctx->snapshots[i].session, &ctx->snapshots[i].id, message);
        session_unref(&ctx->snapshots[i].session);
    }
    ctx->snapshot_count = 0;
    session_hub_wake(ctx->hub);
    pthread_mutex_lock(&loop->lock);
    snprintf(loop->failure, sizeof loop->failure, "%s", why);
    loop->stopping = true;
    pthread_mutex_unlock(&loop->lock);
    if (loop->on_failure)
        loop->on_failure(loop->failure_user);
}

/* After work that used the renderer: false when its device was lost for good. */
static bool renderer_usable(struct render_loop *loop)
{
    struct render_context *ctx = &loop->ctx;
    char why[384];
    switch (renderer_host_check(ctx->renderer, &ctx->state, &ctx->atmosphere, why, sizeof why)) {
    case RENDERER_HOST_OK:
        return true;
    case RENDERER_HOST_REBUILT:
        /* The LUTs were built at once for the atmosphere frames are asked to show. */
        ctx->atmosphere_pending = false;
        ctx->settled_revision = ctx->state.revision;
        return true;
    case RENDERER_HOST_FAILED:
        break;
    }
    stop_on_failure(loop, why);
    return false;
}

/* glibc keeps what is freed in its arenas, and gives back only the free space at the top of
 * the main heap: the space between live blocks, and most of the other threads' arenas, stay
 * resident. Views, cloud histories, snapshots and lavapipe's command buffers and compiles free
 * a lot of it: at the end of a soak 77 of the daemon's 291 MiB were such free memory, and
 * malloc_trim gave it back. It takes 8-12 ms on a 2-core machine, so it runs only when the
 * next frame is not yet due, and at most every TRIM_PERIOD_S. */
static void give_back_free_memory(struct render_loop *loop, double now, double next_frame_at)
{
#ifdef __GLIBC__
    if (now - loop->last_trim_s < TRIM_PERIOD_S || next_frame_at <= now)
        return;
    malloc_trim(0);
    loop->last_trim_s = now;
#else
    (void)loop;
    (void)now;
    (void)next_frame_at;
#endif
}

static void *thread_main(void *arg)
{
    struct render_loop *loop = arg;
    struct render_context *ctx = &loop->ctx;
    double wake_at = monotonic_seconds();
    for (;;) {
        pthread_mutex_lock(&loop->lock);
        while (!loop->head && !loop->notified && !loop->stopping) {
            double now = monotonic_seconds();
            if (now >= wake_at)
                break;
            /* The condition variable runs on CLOCK_MONOTONIC: the deadline is absolute. */
            double whole = floor(wake_at);
            struct timespec deadline = { .tv_sec = (time_t)whole,
                                         .tv_nsec = (long)((wake_at - whole) * 1e9) };
            pthread_cond_timedwait(&loop->wake, &loop->lock, &deadline);
        }
        struct command *commands = loop->head;
        loop->head = loop->tail = NULL;
        loop->notified = false;
        bool stopping = loop->stopping;
        pthread_mutex_unlock(&loop->lock);

        simulate(ctx, monotonic_seconds());

        /* The tick: every queued command in arrival order, then the frames that are due. */
        bool replied = commands != NULL;
        while (commands) {
            struct command *next = commands->next;
            run_command(loop, commands);
            commands = next;
        }
        if (replied)
            session_hub_wake(ctx->hub);
        if (stopping || !renderer_usable(loop))
            break;
        double now = monotonic_seconds();
        wake_at = render_due(loop, now);
        if (!renderer_usable(loop))
            break;
        now = monotonic_seconds();
        update_fps(loop, now);
        if (ctx->dirty) {
            double save_at = ctx->last_change_s + ctx->config->state_save_delay_s;
            if (now >= save_at)
                save_state(ctx);
            else
                wake_at = fmin(wake_at, save_at);
        } else if (ctx->sim_dirty && now - ctx->last_save_s >= SIM_SAVE_PERIOD_S) {
            save_state(ctx);
        }
        give_back_free_memory(loop, monotonic_seconds(), wake_at);
    }
    save_state(ctx);
    return NULL;
}

/* The client weather map saved beside the state, if any. A state that selects it without a
 * usable map falls back to the procedural one (said on stderr): a missing file must not keep
 * the daemon from starting. */
static void restore_weather_map(struct render_context *ctx)
{
    char msg[640];
    enum state_load_result result = STATE_LOAD_ABSENT;
    if (ctx->state_file[0])
        result = state_store_load_weather_map(ctx->state_file, &ctx->client_map, msg, sizeof msg);
    if (result == STATE_LOAD_RESTORED &&
        renderer_host_set_weather_map(ctx->renderer, &ctx->client_map) != 0) {
        snprintf(msg, sizeof msg, "the renderer could not take the saved weather map");
        sky_weather_map_free(&ctx->client_map);
        result = STATE_LOAD_FAILED;
    }
    if (result == STATE_LOAD_RESTORED) {
        fprintf(stderr, "skyd: restored the client weather map (%ux%u)\n", ctx->client_map.width,
                ctx->client_map.height);
    } else if (ctx->state.weather.map_source == SKY_WEATHER_MAP_CLIENT) {
        fprintf(stderr, "skyd: %s; weather.map_source is procedural\n",
                ctx->state_file[0] ? msg : "no state file keeps a client weather map");
        ctx->state.weather.map_source = SKY_WEATHER_MAP_PROCEDURAL;
        ctx->dirty = true;
    } else if (result != STATE_LOAD_ABSENT) {
        fprintf(stderr, "skyd: %s\n", msg);
    }
}

/* The renderer is created on the render thread's behalf before it starts: Vulkan objects are
 * not tied to the creating thread, and creating it here lets a failure be reported at once. */
struct render_loop *render_loop_create(const struct render_loop_params *params, char *err,
                                       size_t errlen)
{
    struct render_loop *loop = calloc(1, sizeof *loop);
    if (!loop) {
        snprintf(err, errlen, "out of memory");
        return NULL;
    }
    struct render_context *ctx = &loop->ctx;
    ctx->config = params->config;
    ctx->config_dir = params->config_dir;
    snprintf(ctx->state_file, sizeof ctx->state_file, "%s", params->state_file);
    ctx->state = params->initial_state;
    world_sim_settle(&ctx->state); /* sun and moon at the restored clock */
    world_to_render_atmosphere(&ctx->state, &ctx->atmosphere);
    ctx->hub = params->hub;
    ctx->start_time_s = monotonic_seconds();
    ctx->last_tick_s = ctx->last_save_s = ctx->start_time_s;
    loop->fps_window_start = ctx->start_time_s;
    pthread_mutex_init(&loop->lock, NULL);
    pthread_condattr_t attr;
    pthread_condattr_init(&attr);
    pthread_condattr_setclock(&attr, CLOCK_MONOTONIC);
    pthread_cond_init(&loop->wake, &attr);
    pthread_condattr_destroy(&attr);

    loop->on_failure = params->on_failure;
    loop->failure_user = params->failure_user;
    loop->encoder = encoder_pool_create(params->config->encoder_threads, params->hub,
                                        encoder_done, loop);
    if (!loop->encoder) {
        snprintf(err, errlen, "cannot start the encoder threads");
        render_loop_destroy(&loop);
        return NULL;
    }
    /* The LUTs, the saved weather map, the cloud noise and every pipeline before the first
     * client arrives. */
    struct renderer_host_params host = {
        .device_preference = params->device,
        .validation = params->validation,
        .amortize = true,
        .lut_budget_ms = params->config->lut_budget_ms,
        .lut_budget_fraction = params->config->lut_budget_fraction,
        .lut_blend_frames = params->config->lut_blend_frames,
    };
    ctx->renderer = renderer_host_create(&host, &ctx->state, &ctx->atmosphere, err, errlen);
    if (!ctx->renderer) {
        render_loop_destroy(&loop);
        return NULL;
    }
    restore_weather_map(ctx);
    if (renderer_host_prepare(ctx->renderer, &ctx->state, &ctx->atmosphere, err, errlen) != 0) {
        render_loop_destroy(&loop);
        return NULL;
    }
    ctx->settled_revision = ctx->state.revision;
    loop->started = pthread_create(&loop->thread, NULL, thread_main, loop) == 0;
    if (!loop->started) {
        snprintf(err, errlen, "cannot start the render thread");
        render_loop_destroy(&loop);
        return NULL;
    }
    fprintf(stderr, "skyd: rendering on %s\n", renderer_host_device_name(ctx->renderer));
    return loop;
}

const char *render_loop_failure(struct render_loop *loop)
{
    pthread_mutex_lock(&loop->lock);
    const char *why = loop->failure[0] ? loop->failure : NULL;
    pthread_mutex_unlock(&loop->lock);
    return why;
}

void render_loop_destroy(struct render_loop **loop_ptr)
{
    struct render_loop *loop = *loop_ptr;
    *loop_ptr = NULL;
    if (!loop)
        return;
    pthread_mutex_lock(&loop->lock);
    bool joinable = loop->started;
    loop->stopping = true;
    pthread_cond_broadcast(&loop->wake);
    pthread_mutex_unlock(&loop->lock);
    if (joinable)
        pthread_join(loop->thread, NULL);
    encoder_pool_destroy(&loop->encoder);
    while (loop->head) {
        struct command *c = loop->head;
        loop->head = c->next;
        free_command(c);
    }
    render_commands_release(&loop->ctx);
    sky_weather_map_free(&loop->ctx.client_map);
    renderer_host_destroy(&loop->ctx.renderer);
    pthread_cond_destroy(&loop->wake);
    pthread_mutex_destroy(&loop->lock);
    free(loop);
}
