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

#include "error_text.h"
#include "log.h"
#include "render_commands.h"
#include "monotonic_clock.h"
#include "shared_world_internal.h"
#include "wall_clock.h"

/* While only the simulation changes the state, it is written at most this often. */
static const double SIM_SAVE_PERIOD_S = 30.0;
/* Free memory is given back to the system at most this often (give_back_free_memory). */
static const double TRIM_PERIOD_S = 10.0;
/* Clients that asked hear of the simulation's own changes this often at most. */
static const double SIMULATION_EVENT_PERIOD_S = 1.0;
/* How soon a change deferred for a shared world's stream is tried again (the feed's arrival
 * wakes the loop sooner). */
static const double DEFERRED_RETRY_S = 0.002;

enum command_kind { COMMAND_MESSAGE, COMMAND_REPLY, COMMAND_SESSION_CLOSED };

struct command {
    struct command *next;
    enum command_kind kind;
    struct session *session; /* a reference */
    struct proto_client_msg msg;
    char *reply;
    double first_tried_s; /* a change to a shared world tried again: when it was first tried */
};

struct render_loop {
    struct render_context ctx; /* the owners: what the command handlers reach */
    pthread_t thread;
    pthread_mutex_t lock;
    pthread_cond_t wake;
    struct command *head, *tail;
    /* The render thread's own: a change that found the shared world moved on, and every
     * command after it, tried again at the next tick, after the world's stream is applied. */
    struct command *deferred;
    bool notified, stopping;
    bool started; /* the thread runs (set before it starts; destroy joins it) */
    double last_trim_s;
    void (*on_failure)(void *user);
    void *failure_user;
    error_text failure; /* why the loop stopped on its own; "" while it runs (under lock) */
    /* report_tick's scratch (10 KiB, kept off the stack): the render thread's, and the
     * creating thread's before the render thread starts. */
    struct proto_msg_subscription_stats traffic[SERVICE_METRICS_MAX_SUBSCRIPTIONS];
};

static void free_command(struct command *c)
{
    proto_client_msg_free(&c->msg);
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
                                struct proto_client_msg *msg)
{
    struct command *c = calloc(1, sizeof *c);
    if (!c) {
        proto_client_msg_free(msg);
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

/* ---- the thread ---- */

/* false: the command is to be tried again at the next tick (it is kept). */
static bool run_command(struct render_loop *loop, struct command *c)
{
    switch (c->kind) {
    case COMMAND_MESSAGE: {
        double now = monotonic_seconds();
        if (c->first_tried_s == 0)
            c->first_tried_s = now;
        if (!render_commands_handle(&loop->ctx, c->session, &c->msg, now - c->first_tried_s))
            return false;
        break;
    }
    case COMMAND_REPLY:
        session_push_text(c->session, c->reply);
        break;
    case COMMAND_SESSION_CLOSED:
        render_commands_session_closed(&loop->ctx, c->session);
        break;
    }
    free_command(c);
    return true;
}

/* Rendering cannot go on (the device was lost and no renderer could be made again): the
 * snapshots still waiting hear why, the loop takes no more commands, and the owner is told to
 * stop serving; the thread then saves the state and ends. */
static void stop_on_failure(struct render_loop *loop, const char *why)
{
    skyd_log(SKYD_LOG_ERROR, "%s; saving the state and stopping", why);
    error_text message;
    error_text_mark_cut(message, sizeof message,
                        snprintf(message, sizeof message, "the daemon is stopping: %s", why));
    frame_scheduler_fail_snapshots(loop->ctx.frames, message);
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
    error_text why;
    switch (
        renderer_host_check(ctx->renderer, world_host_render_input(ctx->world), why, sizeof why)) {
    case RENDERER_HOST_OK:
        return true;
    case RENDERER_HOST_REBUILT:
        service_metrics_device_lost(loop->ctx.metrics);
        /* The LUTs were built at once for the input's frame atmosphere. */
        world_host_atmosphere_shown(ctx->world);
        return true;
    case RENDERER_HOST_FAILED:
        service_metrics_device_lost(loop->ctx.metrics);
        break;
    }
    stop_on_failure(loop, why);
    return false;
}

/* glibc keeps what is freed in its arenas, and gives back only the free space at the top of
 * the main heap: the space between live blocks, and most of the other threads' arenas, stay
 * resident. Views, cloud histories, snapshots and lavapipe's command buffers and compiles free
 * a lot of it (a quarter of the daemon's resident memory after a long run), which malloc_trim
 * gives back. It takes 8-12 ms on a 2-core machine, so it runs only when the next frame is not
 * yet due, and at most every TRIM_PERIOD_S. */
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

static void push_if_wanted(struct session *session, void *text)
{
    if (session_wants_simulation_events(session))
        session_push_text(session, text);
}

/* What the simulation moved, to the clients that asked (hello's simulation_events), at most
 * once per SIMULATION_EVENT_PERIOD_S: they need not poll get_state while the clock runs. */
static void announce_simulation(struct render_loop *loop)
{
    char *event = world_host_simulation_event(loop->ctx.world, monotonic_seconds(),
                                              SIMULATION_EVENT_PERIOD_S);
    if (!event)
        return;
    session_hub_for_each(loop->ctx.hub, push_if_wanted, event);
    session_hub_wake(loop->ctx.hub);
    free(event);
}

/* The tick's heartbeat and gauges for /healthz and /metrics. */
static void report_tick(struct render_loop *loop, double now)
{
    const struct sky_render_stats *last = frame_scheduler_last_stats(loop->ctx.frames);
    struct service_metrics_tick tick = {
        .at_s = now,
        .state_revision = world_host_state(loop->ctx.world)->revision,
        .subscriptions = frame_scheduler_subscription_count(loop->ctx.frames),
        .lut_rebuild_progress = last ? last->lut_rebuild_progress : 1.0,
        .cluster_connected = -1,
    };
    if (loop->ctx.cluster)
        tick.cluster_connected = cluster_sync_connected(loop->ctx.cluster,
                                                        &tick.cluster_connections);
    service_metrics_tick(loop->ctx.metrics, &tick);
    size_t count = frame_scheduler_session_stats(loop->ctx.frames, NULL, loop->traffic,
                                                 SERVICE_METRICS_MAX_SUBSCRIPTIONS);
    service_metrics_subscriptions(loop->ctx.metrics, loop->traffic, count);
}

/* The world's input outside a client's commit (another node's): a renderer that cannot take
 * it is said in the log; frames fail until it can, or a renderer made again takes it. */
static void take_input(struct render_loop *loop)
{
    const struct render_input *input = world_host_render_input(loop->ctx.world);
    error_text why;
    if (renderer_host_take(loop->ctx.renderer, input, why, sizeof why) != 0)
        skyd_log(SKYD_LOG_ERROR, "the renderer did not take revision %llu: %s",
                 (unsigned long long)input->state.revision, why);
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
        if (loop->deferred) { /* first, in their order */
            struct command *last = loop->deferred;
            while (last->next)
                last = last->next;
            last->next = commands;
            commands = loop->deferred;
            loop->deferred = NULL;
        }
        loop->notified = false;
        bool stopping = loop->stopping;
        pthread_mutex_unlock(&loop->lock);

        const struct sky_render_stats *last = frame_scheduler_last_stats(ctx->frames);
        world_host_advance(ctx->world, wall_clock_seconds(),
                           frame_scheduler_subscription_count(ctx->frames) > 0,
                           !last || last->atmosphere_settled);
        announce_simulation(loop);
        if (ctx->cluster) { /* the shared world's changes from other nodes, in order */
            cluster_sync_apply(ctx->cluster, ctx->world, ctx->hub);
            take_input(loop);
        }

        /* The tick: every queued command in arrival order, then the frames that are due. */
        bool replied = commands != NULL;
        while (commands) {
            struct command *next = commands->next;
            if (!run_command(loop, commands)) {
                loop->deferred = commands;
                break;
            }
            commands = next;
        }
        if (replied)
            session_hub_wake(ctx->hub);
        double now = monotonic_seconds();
        double forecast_poll_at = INFINITY;
        if (ctx->forecast && !stopping) { /* the folder, then what following it changes */
            forecast_poll_at = forecast_feed_poll(ctx->forecast, now, world_host_state(ctx->world));
            render_commands_follow_forecast(ctx);
        }
        if (stopping || !renderer_usable(loop))
            break;
        now = monotonic_seconds();
        bool atmosphere_shown = false;
        wake_at = frame_scheduler_render_due(ctx->frames, ctx->renderer,
                                             world_host_render_input(ctx->world), now,
                                             &atmosphere_shown);
        if (atmosphere_shown)
            world_host_atmosphere_shown(ctx->world);
        if (!renderer_usable(loop))
            break;
        now = monotonic_seconds();
        frame_scheduler_tick(ctx->frames, now);
        report_tick(loop, now);
        wake_at = fmin(wake_at, world_host_save_due(ctx->world, now, SIM_SAVE_PERIOD_S));
        wake_at = fmin(wake_at, forecast_poll_at);
        if (loop->deferred) /* soon again: the stream it waits for is on its way */
            wake_at = fmin(wake_at, now + DEFERRED_RETRY_S);
        give_back_free_memory(loop, monotonic_seconds(), wake_at);
    }
    world_host_save(ctx->world, monotonic_seconds());
    return NULL;
}

static void wake_loop(void *loop)
{
    render_loop_notify(loop);
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
    ctx->settings = params->settings;
    ctx->hub = params->hub;
    pthread_mutex_init(&loop->lock, NULL);
    pthread_condattr_t attr;
    pthread_condattr_init(&attr);
    pthread_condattr_setclock(&attr, CLOCK_MONOTONIC);
    pthread_cond_init(&loop->wake, &attr);
    pthread_condattr_destroy(&attr);

    loop->on_failure = params->on_failure;
    loop->failure_user = params->failure_user;
    ctx->metrics = params->metrics;
    if (params->config->forecast_dir[0]) {
        struct forecast_feed_params feed = { .dir = params->config->forecast_dir,
                                             .poll_s = params->config->forecast_poll_s,
                                             .metrics = params->metrics,
                                             .ready = wake_loop,
                                             .user = loop };
        if (!(ctx->forecast = forecast_feed_create(&feed, err, errlen))) {
            render_loop_destroy(&loop);
            return NULL;
        }
    }
    struct shared_world *shared = params->shared_world;
    struct world_host_params world = {
        .state_file = params->state_file,
        .initial_state = params->initial_state,
        .save_delay_s = params->config->state_save_delay_s,
        .now_s = monotonic_seconds(),
        .wall_s = wall_clock_seconds(),
        .cluster = shared ? shared_world_store(shared) : NULL,
        .client_map = shared ? shared_world_client_map(shared) : NULL,
    };
    ctx->world = world_host_create(&world);
    if (!ctx->world) {
        snprintf(err, errlen, "out of memory for the world state");
        render_loop_destroy(&loop);
        return NULL;
    }
    struct frame_scheduler_params frames = { .encoder_threads =
                                                 skyd_config_encoder_threads(params->config),
                                             .hub = params->hub,
                                             .encoded = encoder_done,
                                             .user = loop,
                                             .metrics = params->metrics };
    ctx->frames = frame_scheduler_create(&frames);
    if (!ctx->frames) {
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
        .frame_budget_ms = params->config->frame_budget_ms,
        .lut_blend_frames = params->config->lut_blend_frames,
        .warm_up_variants = true,
    };
    ctx->renderer = renderer_host_create(&host, world_host_render_input(ctx->world), err, errlen);
    if (!ctx->renderer) {
        render_loop_destroy(&loop);
        return NULL;
    }
    if (shared &&
        !(ctx->cluster = cluster_sync_create(shared_world_store(shared), shared_world_start(shared),
                                             encoder_done, loop, err, errlen))) {
        render_loop_destroy(&loop);
        return NULL;
    }
    if (renderer_host_prepare(ctx->renderer, world_host_render_input(ctx->world), err, errlen) !=
        0) {
        render_loop_destroy(&loop);
        return NULL;
    }
    report_tick(loop, monotonic_seconds());
    loop->started = pthread_create(&loop->thread, NULL, thread_main, loop) == 0;
    if (!loop->started) {
        snprintf(err, errlen, "cannot start the render thread");
        render_loop_destroy(&loop);
        return NULL;
    }
    skyd_log(SKYD_LOG_INFO, "rendering on %s", renderer_host_device_name(ctx->renderer));
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
    cluster_sync_destroy(&loop->ctx.cluster);
    frame_scheduler_destroy(&loop->ctx.frames);
    while (loop->head) {
        struct command *c = loop->head;
        loop->head = c->next;
        free_command(c);
    }
    while (loop->deferred) {
        struct command *c = loop->deferred;
        loop->deferred = c->next;
        free_command(c);
    }
    world_host_destroy(&loop->ctx.world);
    forecast_feed_destroy(&loop->ctx.forecast);
    renderer_host_destroy(&loop->ctx.renderer);
    pthread_cond_destroy(&loop->wake);
    pthread_mutex_destroy(&loop->lock);
    free(loop);
}
