#include "render_commands.h"

#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include <cjson/cJSON.h>

#include "error_text.h"
#include "field_errors.h"
#include "json_guard.h"
#include "log.h"
#include "metar.h"
#include "monotonic_clock.h"
#include "presets.h"
#include "weather_observation.h"
#include "world_render.h"
#include "world_sim.h"

/* Preset folders under the config directory, by enum proto_preset_kind. */
static const char *const preset_folders[] = {
    [PROTO_PRESET_ATMOSPHERE] = "atmosphere",
    [PROTO_PRESET_WEATHER] = "weather",
};

/* Every error the commands answer is built, counted and queued here. */
static void send_error(struct render_context *ctx, struct session *session,
                       const struct proto_msg_id *id, enum proto_msg_error_code code,
                       const char *message, const struct proto_field_errors *fields)
{
    char *text = proto_msg_build_error(id, code, message, fields);
    if (!text) {
        code = PROTO_MSG_ERR_INTERNAL;
        text = proto_msg_build_error(id, code, "the reply could not be built", NULL);
    }
    if (!text)
        return;
    service_metrics_error(ctx->metrics, code);
    session_push_text(session, text);
    free(text);
}

/* Queues a built message (NULL only when building failed, which the client hears of). */
static void reply(struct render_context *ctx, struct session *session,
                  const struct proto_msg_id *id, char *text)
{
    if (!text) {
        send_error(ctx, session, id, PROTO_MSG_ERR_INTERNAL, "the reply could not be built", NULL);
        return;
    }
    session_push_text(session, text);
    free(text);
}

/* An auth failure or a refused change is logged once, with who sent it; never the token. */
static void log_refusal(const struct render_context *ctx, struct session *session,
                        const char *message)
{
    const struct proto_client_msg *handling = ctx->handling;
    if (!handling ||
        (handling->type != PROTO_MSG_AUTH && !proto_msg_needs_controller(handling->type)))
        return;
    char name[PROTO_MSG_CLIENT_MAX + 1];
    session_client_name(session, name, sizeof name);
    skyd_log(SKYD_LOG_WARNING, "%s %s from %s%s%s: %s", proto_msg_type_name(handling->type),
             handling->type == PROTO_MSG_AUTH ? "failed" : "refused", name[0] ? "client \"" : "a ",
             name[0] ? name : "client without a name", name[0] ? "\"" : "", message);
}

/* clang-format off */
#if defined(__GNUC__)
__attribute__((format(printf, 5, 6)))
#endif
static void reply_error(struct render_context *ctx, struct session *session,
                        const struct proto_msg_id *id, enum proto_msg_error_code code,
                        const char *format, ...)
/* clang-format on */
{
    error_text message;
    va_list args;
    va_start(args, format);
    vsnprintf(message, sizeof message, format, args);
    va_end(args);
    log_refusal(ctx, session, message);
    send_error(ctx, session, id, code, message, NULL);
}

/* A failed apply: pointers are into the message, so they gain the "/patch" prefix. */
static void reply_field_errors(struct render_context *ctx, struct session *session,
                               const struct proto_msg_id *id, const char *prefix,
                               const struct proto_field_errors *errors)
{
    struct proto_field_errors prefixed = *errors;
    for (int i = 0; i < prefixed.count; i++)
        snprintf(prefixed.items[i].pointer, sizeof prefixed.items[i].pointer, "%s%s", prefix,
                 errors->items[i].pointer);
    enum proto_msg_error_code code = prefixed.count
                                         ? (enum proto_msg_error_code)prefixed.items[0].code
                                         : PROTO_MSG_ERR_BAD_VALUE;
    error_text message;
    if (prefixed.count)
        snprintf(message, sizeof message, "%s: %s", prefixed.items[0].pointer,
                 prefixed.items[0].reason);
    else
        snprintf(message, sizeof message, "the patch was rejected");
    log_refusal(ctx, session, message);
    send_error(ctx, session, id, code, message, &prefixed);
}

/* Who a state_changed names: the sender's hello name, else its role (only a controller
 * changes the state). */
static void changer(struct session *session, char *name, size_t capacity)
{
    session_client_name(session, name, capacity);
    if (!name[0])
        snprintf(name, capacity, "controller");
}

/* A refused commit: a shared world that moved on is caught up and the change made again
 * (render_commands_handle); anything else is the sender's error. */
static void commit_refused(struct render_context *ctx, struct session *session,
                           const struct proto_msg_id *id, const struct world_commit *commit)
{
    if (commit->status == WORLD_COMMIT_CONFLICT) {
        ctx->conflict_revision = commit->current;
        return;
    }
    reply_error(ctx, session, id,
                commit->status == WORLD_COMMIT_UNAVAILABLE ? PROTO_MSG_ERR_UNAVAILABLE
                                                           : PROTO_MSG_ERR_INTERNAL,
                "%s", commit->error);
}

/* The renderer takes a commit's new input, all or nothing (new LUT sizes, clouds, a client
 * weather map); when it cannot, the commit is undone (world_host_undo_commit). false: it was. */
static bool renderer_takes(struct render_context *ctx, struct world_commit *commit)
{
    error_text why;
    if (!commit->input || renderer_host_take(ctx->renderer, commit->input, why, sizeof why) == 0)
        return true;
    return !world_host_undo_commit(ctx->world, why, commit);
}

/* What the sender hears of an accepted observation (NULL: an ack). */
struct observation_reply {
    const cJSON *report, *patch, *unmapped;
};

/* A commit the world host made: the renderer takes it, then the sender and every client hear
 * of it. */
static bool announce_commit_with(struct render_context *ctx, struct session *session,
                                 const struct proto_msg_id *id, struct world_commit *commit,
                                 const struct observation_reply *observation)
{
    if (!renderer_takes(ctx, commit)) {
        commit_refused(ctx, session, id, commit);
        return false;
    }
    reply(ctx, session, id,
          observation ? proto_msg_build_observation(id, commit->revision, observation->report,
                                                    observation->patch, observation->unmapped)
                      : proto_msg_build_ack(id, commit->revision, PROTO_ROLE_NONE));
    if (commit->event)
        session_hub_broadcast(ctx->hub, commit->event);
    free(commit->event);
    return true;
}

static bool announce_commit(struct render_context *ctx, struct session *session,
                            const struct proto_msg_id *id, struct world_commit *commit)
{
    return announce_commit_with(ctx, session, id, commit, NULL);
}

/* Commits `next` through the world host and tells the sender (an ack, or the observation's
 * reply) and every client. */
static bool commit_state_with(struct render_context *ctx, struct session *session,
                              const struct proto_msg_id *id, struct proto_world_state *next,
                              const struct observation_reply *observation)
{
    struct world_commit commit;
    char by[PROTO_MSG_CLIENT_MAX + 1];
    changer(session, by, sizeof by);
    if (!world_host_commit(ctx->world, next, NULL, by, &commit)) {
        commit_refused(ctx, session, id, &commit);
        return false;
    }
    return announce_commit_with(ctx, session, id, &commit, observation);
}

static bool commit_state(struct render_context *ctx, struct session *session,
                         const struct proto_msg_id *id, struct proto_world_state *next)
{
    return commit_state_with(ctx, session, id, next, NULL);
}

static bool external_source(const struct proto_world_state *state)
{
    return state->weather.source == PROTO_WEATHER_SOURCE_METAR ||
           state->weather.source == PROTO_WEATHER_SOURCE_FORECAST;
}

/* A client's change of the weather parameters makes it the weather's source, and the autopilot
 * switched on the daemon's own, unless the patch names weather.source itself; weather.source
 * "forecast" needs a forecast to follow. */
static bool weather_source_after_set(const struct render_context *ctx,
                                     const struct proto_world_state *live,
                                     const struct proto_world_patch *patch,
                                     struct proto_world_state *next,
                                     struct proto_field_errors *errors)
{
    if (!proto_world_patch_names(patch, proto_world_state_find_field("weather.source"))) {
        struct proto_weather_params before, after;
        proto_weather_params_get(live, &before);
        proto_weather_params_get(next, &after);
        if (!external_source(live))
            return true;
        if (next->weather.autopilot == PROTO_SWITCH_ON &&
            live->weather.autopilot != PROTO_SWITCH_ON)
            next->weather.source = PROTO_WEATHER_SOURCE_PROCEDURAL;
        else if (memcmp(&before, &after, sizeof before) != 0)
            next->weather.source = PROTO_WEATHER_SOURCE_CLIENT;
        return true;
    }
    error_text why;
    if (next->weather.source != PROTO_WEATHER_SOURCE_FORECAST ||
        live->weather.source == PROTO_WEATHER_SOURCE_FORECAST)
        return true;
    if (forecast_feed_loaded(ctx->forecast, why, sizeof why)) {
        /* Following starts: the forecast's cover grid becomes the weather map, unless the
         * patch names one. */
        if (!proto_world_patch_names(patch, proto_world_state_find_field("weather.map_source")))
            next->weather.map_source = PROTO_WEATHER_MAP_FORECAST;
        return true;
    }
    proto_field_errors_clear(errors);
    proto_field_errors_add(errors, PROTO_FIELD_BAD_VALUE, "/weather/source", why);
    return false;
}

static void handle_set(struct render_context *ctx, struct session *session,
                       const struct proto_client_msg *msg)
{
    const struct proto_world_state *live = world_host_state(ctx->world);
    struct proto_world_state next = *live;
    struct proto_field_errors errors;
    if (!proto_world_state_apply_patch(&next, msg->set.patch, &errors) ||
        !weather_source_after_set(ctx, live, msg->set.patch, &next, &errors)) {
        reply_field_errors(ctx, session, &msg->id, "/patch", &errors);
        return;
    }
    proto_field_errors_clear(&errors);
    if (!world_sim_check_client_patch(live, &next, msg->set.patch, &errors)) {
        reply_field_errors(ctx, session, &msg->id, "/patch", &errors);
        return;
    }
    if (world_host_client_map_missing(ctx->world, &next, &errors)) {
        reply_field_errors(ctx, session, &msg->id, "/patch", &errors);
        return;
    }
    world_sim_client_changed(live, &next);
    commit_state(ctx, session, &msg->id, &next);
}

/* A METAR decoded, mapped (weather_observation.h) and applied as one change; a report the
 * decoder refuses, or a NIL one, is a bad_value at /metar with the decoder's message (the
 * group, its index and offset) and leaves the state as it was. */
static void handle_apply_observation(struct render_context *ctx, struct session *session,
                                     const struct proto_client_msg *msg)
{
    const char *text = msg->observation.metar;
    struct proto_metar_report report;
    struct proto_metar_error error;
    struct proto_field_errors errors;
    proto_field_errors_clear(&errors);
    if (!proto_metar_decode(text, strlen(text), &report, &error)) {
        proto_field_errors_add(&errors, PROTO_FIELD_BAD_VALUE, "/metar", error.message);
        log_refusal(ctx, session, error.message);
        send_error(ctx, session, &msg->id, PROTO_MSG_ERR_BAD_VALUE, error.message, &errors);
        return;
    }
    cJSON *patch = NULL, *unmapped = NULL;
    error_text why;
    if (!proto_obs_metar_patch(&report, &patch, &unmapped, why, sizeof why)) {
        proto_field_errors_add(&errors, PROTO_FIELD_BAD_VALUE, "/metar", why);
        log_refusal(ctx, session, why);
        send_error(ctx, session, &msg->id, PROTO_MSG_ERR_BAD_VALUE, why, &errors);
        return;
    }
    const struct proto_world_state *live = world_host_state(ctx->world);
    struct proto_world_state next = *live;
    cJSON *decoded = proto_metar_to_json(&report);
    if (!decoded) {
        reply_error(ctx, session, &msg->id, PROTO_MSG_ERR_INTERNAL, "out of memory");
    } else if (!proto_world_state_apply_json(&next, patch, &errors)) {
        reply_field_errors(ctx, session, &msg->id, "/patch", &errors);
    } else {
        world_sim_client_changed(live, &next);
        const struct observation_reply observation = { decoded, patch, unmapped };
        commit_state_with(ctx, session, &msg->id, &next, &observation);
    }
    cJSON_Delete(decoded);
    cJSON_Delete(patch);
    cJSON_Delete(unmapped);
}

/* The folder's preset names into ctx->preset_names; -1 when the folder cannot be read. */
static int list_presets(struct render_context *ctx, enum proto_preset_kind kind)
{
    return world_preset_list(ctx->config_dir, preset_folders[kind], ctx->preset_names,
                             PROTO_MSG_MAX_PRESETS);
}

/* A weather preset: its weather parameters are reached through a transition (at once for
 * transition_s 0 or absent), anything else it sets applies at once, and the autopilot stops
 * (the preset names the weather wanted). A transition under way is replaced, starting from
 * the weather as it stands. */
static void start_weather_preset(const struct proto_world_state *live,
                                 const struct proto_world_state *applied, double transition_s,
                                 struct proto_world_state *next)
{
    struct proto_weather_params now, goal;
    proto_weather_params_get(live, &now);
    proto_weather_params_get(applied, &goal);
    *next = *applied;
    proto_weather_params_put(next, &now);
    next->weather.autopilot = PROTO_SWITCH_OFF;
    world_sim_start_transition(next, &goal, transition_s);
}

static void handle_apply_preset(struct render_context *ctx, struct session *session,
                                const struct proto_client_msg *msg)
{
    const char *folder = preset_folders[msg->preset.kind];
    int count = list_presets(ctx, msg->preset.kind);
    bool known = false;
    for (int i = 0; i < count && !known; i++)
        known = strcmp(ctx->preset_names[i], msg->preset.name) == 0;
    if (!known) {
        reply_error(ctx, session, &msg->id, PROTO_MSG_ERR_NOT_FOUND,
                    "no %s preset \"%s\" (list_presets names them)", folder, msg->preset.name);
        return;
    }
    const struct proto_world_state *live = world_host_state(ctx->world);
    struct proto_world_state next = *live;
    struct proto_field_errors errors;
    error_text why;
    json_guard_lock();
    bool applied = world_preset_apply(ctx->config_dir, folder, msg->preset.name, &next, &errors,
                                      why, sizeof why);
    json_guard_unlock();
    if (!applied) {
        skyd_log(SKYD_LOG_ERROR, "preset %s: %s", msg->preset.name, why);
        reply_error(ctx, session, &msg->id, PROTO_MSG_ERR_INTERNAL,
                    "preset \"%s\" cannot be applied: %s", msg->preset.name, why);
        return;
    }
    if (msg->preset.kind == PROTO_PRESET_WEATHER) {
        if (external_source(live) && next.weather.source == live->weather.source)
            next.weather.source =
                PROTO_WEATHER_SOURCE_PROCEDURAL; /* a preset is the daemon's own */
        struct proto_world_state applied = next;
        start_weather_preset(live, &applied,
                             msg->preset.has_transition ? msg->preset.transition_s : 0.0, &next);
    }
    if (world_host_client_map_missing(ctx->world, &next, &errors)) {
        reply_field_errors(ctx, session, &msg->id, "", &errors);
        return;
    }
    commit_state(ctx, session, &msg->id, &next);
}

/* The map is written to disk first, then selected by the state (weather.map_source "client")
 * in one revision whose event names "/weather/map", which the renderer then takes. */
static void handle_set_weather_map(struct render_context *ctx, struct session *session,
                                   const struct proto_client_msg *msg)
{
    struct world_commit commit;
    char by[PROTO_MSG_CLIENT_MAX + 1];
    changer(session, by, sizeof by);
    if (!world_host_set_weather_map(ctx->world, &msg->weather_map, by, &commit)) {
        commit_refused(ctx, session, &msg->id, &commit);
        return;
    }
    announce_commit(ctx, session, &msg->id, &commit);
}

static void handle_list_presets(struct render_context *ctx, struct session *session,
                                const struct proto_client_msg *msg)
{
    int count = list_presets(ctx, msg->preset.kind);
    if (count < 0) {
        reply_error(ctx, session, &msg->id, PROTO_MSG_ERR_INTERNAL,
                    "the preset folder cannot be read");
        return;
    }
    const char *list[PROTO_MSG_MAX_PRESETS];
    for (int i = 0; i < count; i++)
        list[i] = ctx->preset_names[i];
    reply(ctx, session, &msg->id,
          proto_msg_build_presets(&msg->id, msg->preset.kind, list, (size_t)count));
}

static void handle_auth(struct render_context *ctx, struct session *session,
                        const struct proto_client_msg *msg)
{
    switch (live_settings_check_token(ctx->settings, msg->auth.token)) {
    case LIVE_TOKEN_MATCHES:
        break;
    case LIVE_TOKEN_READ_ONLY:
        reply_error(ctx, session, &msg->id, PROTO_MSG_ERR_AUTH_FAILED, "%s",
                    "this server is read-only (read_only in its configuration): "
                    "nobody can control it");
        return;
    case LIVE_TOKEN_NONE:
        reply_error(ctx, session, &msg->id, PROTO_MSG_ERR_AUTH_FAILED, "%s",
                    "this server has no controller token: nobody can control it");
        return;
    case LIVE_TOKEN_WRONG:
        reply_error(ctx, session, &msg->id, PROTO_MSG_ERR_AUTH_FAILED, "wrong token");
        return;
    }
    session_set_role(session, PROTO_ROLE_CONTROLLER);
    reply(ctx, session, &msg->id,
          proto_msg_build_ack(&msg->id, world_host_state(ctx->world)->revision,
                              PROTO_ROLE_CONTROLLER));
}

static void handle_subscribe(struct render_context *ctx, struct session *session,
                             const struct proto_client_msg *msg)
{
    uint64_t id = 0;
    struct frame_refusal refused = frame_scheduler_subscribe(ctx->frames, session, &msg->view, &id);
    if (refused.code != PROTO_MSG_OK) {
        reply_error(ctx, session, &msg->id, refused.code, "%s", refused.message);
        return;
    }
    reply(ctx, session, &msg->id, proto_msg_build_subscribed(&msg->id, id, &msg->view));
}

static void handle_unsubscribe(struct render_context *ctx, struct session *session,
                               const struct proto_client_msg *msg)
{
    if (frame_scheduler_unsubscribe(ctx->frames, session, msg->unsubscribe.subscription)) {
        reply(
            ctx, session, &msg->id,
            proto_msg_build_ack(&msg->id, world_host_state(ctx->world)->revision, PROTO_ROLE_NONE));
        return;
    }
    reply_error(ctx, session, &msg->id, PROTO_MSG_ERR_NOT_FOUND,
                "this connection has no subscription %llu",
                (unsigned long long)msg->unsubscribe.subscription);
}

static void handle_snapshot(struct render_context *ctx, struct session *session,
                            const struct proto_client_msg *msg)
{
    struct frame_refusal refused = frame_scheduler_snapshot(ctx->frames, session, &msg->id,
                                                            &msg->view);
    if (refused.code != PROTO_MSG_OK)
        reply_error(ctx, session, &msg->id, refused.code, "%s", refused.message);
}

static void handle_probe(struct render_context *ctx, struct session *session,
                         const struct proto_client_msg *msg)
{
    struct proto_msg_probe_result result;
    if (renderer_host_probe(ctx->renderer, world_host_render_input(ctx->world), &msg->probe,
                            &result) != 0) {
        error_text why;
        renderer_host_describe_failure(ctx->renderer, "the probe", why, sizeof why);
        reply_error(ctx, session, &msg->id, PROTO_MSG_ERR_INTERNAL, "%s", why);
        return;
    }
    reply(ctx, session, &msg->id, proto_msg_build_probe_result(&msg->id, &result));
}

static void handle_stats(struct render_context *ctx, struct session *session,
                         const struct proto_client_msg *msg)
{
    struct proto_msg_pass_time passes[PROTO_MSG_MAX_PASSES];
    size_t pass_count = 0;
    const struct sky_render_stats *last = frame_scheduler_last_stats(ctx->frames);
    if (last) {
        for (int i = 0; i < last->pass_count && pass_count < PROTO_MSG_MAX_PASSES; i++)
            passes[pass_count++] = (struct proto_msg_pass_time){ last->pass_names[i],
                                                                 last->pass_ms[i] };
    }
    struct proto_msg_subscription_stats subscriptions[SESSION_MAX_SUBSCRIPTIONS];
    size_t subscription_count = frame_scheduler_session_stats(ctx->frames, session, subscriptions,
                                                              SESSION_MAX_SUBSCRIPTIONS);
    struct proto_msg_multiple_scattering ms = { 0.0, 0.0, 0 };
    if (last)
        ms = (struct proto_msg_multiple_scattering){ last->multiple_scattering.weight,
                                                     last->multiple_scattering.progress,
                                                     last->multiple_scattering.order };
    enum proto_cloud_resolution traced = last
                                             ? world_render_cloud_resolution(last->cloud_resolution)
                                             : PROTO_CLOUD_RESOLUTION_AUTO;
    struct proto_msg_stats stats = {
        .fps = frame_scheduler_fps(ctx->frames),
        .clients = session_hub_count(ctx->hub),
        .passes = passes,
        .pass_count = pass_count,
        .lut_rebuild_progress = last ? last->lut_rebuild_progress : 1.0,
        .simulation_time_s = world_host_state(ctx->world)->clock.utc_unix_s,
        .subscriptions = subscriptions,
        .subscription_count = subscription_count,
        .multiple_scattering = &ms,
        .cloud_resolution = traced != PROTO_CLOUD_RESOLUTION_AUTO ? &traced : NULL,
        .cloud_primary_steps =
            last && traced != PROTO_CLOUD_RESOLUTION_AUTO ? last->cloud_primary_steps : 0,
    };
    reply(ctx, session, &msg->id, proto_msg_build_stats(&msg->id, &stats));
}

static void handle_describe(struct render_context *ctx, struct session *session,
                            const struct proto_client_msg *msg)
{
    struct proto_msg_limits limits;
    live_settings_limits(ctx->settings, &limits);
    reply(ctx, session, &msg->id, proto_msg_build_schema(&msg->id, &limits));
}

static void dispatch(struct render_context *ctx, struct session *session,
                     const struct proto_client_msg *msg)
{
    if (proto_msg_needs_controller(msg->type) && session_role(session) != PROTO_ROLE_CONTROLLER) {
        reply_error(ctx, session, &msg->id, PROTO_MSG_ERR_FORBIDDEN, "%s needs the controller role",
                    proto_msg_type_name(msg->type));
        return;
    }
    switch (msg->type) {
    case PROTO_MSG_HELLO:
        if (msg->hello.has_client)
            session_set_client_name(session, msg->hello.client);
        session_set_simulation_events(session, msg->hello.simulation_events);
        reply(
            ctx, session, &msg->id,
            proto_msg_build_ack(&msg->id, world_host_state(ctx->world)->revision, PROTO_ROLE_NONE));
        break;
    case PROTO_MSG_NONE:
        reply(
            ctx, session, &msg->id,
            proto_msg_build_ack(&msg->id, world_host_state(ctx->world)->revision, PROTO_ROLE_NONE));
        break;
    case PROTO_MSG_AUTH:
        handle_auth(ctx, session, msg);
        break;
    case PROTO_MSG_GET_STATE:
        reply(ctx, session, &msg->id,
              proto_msg_build_state(&msg->id, world_host_state(ctx->world)));
        break;
    case PROTO_MSG_SET:
        handle_set(ctx, session, msg);
        break;
    case PROTO_MSG_SUBSCRIBE:
        handle_subscribe(ctx, session, msg);
        break;
    case PROTO_MSG_UNSUBSCRIBE:
        handle_unsubscribe(ctx, session, msg);
        break;
    case PROTO_MSG_SNAPSHOT:
        handle_snapshot(ctx, session, msg);
        break;
    case PROTO_MSG_PROBE:
        handle_probe(ctx, session, msg);
        break;
    case PROTO_MSG_LIST_PRESETS:
        handle_list_presets(ctx, session, msg);
        break;
    case PROTO_MSG_APPLY_PRESET:
        handle_apply_preset(ctx, session, msg);
        break;
    case PROTO_MSG_STATS:
        handle_stats(ctx, session, msg);
        break;
    case PROTO_MSG_SET_WEATHER_MAP:
        handle_set_weather_map(ctx, session, msg);
        break;
    case PROTO_MSG_DESCRIBE:
        handle_describe(ctx, session, msg);
        break;
    case PROTO_MSG_APPLY_OBSERVATION:
        handle_apply_observation(ctx, session, msg);
        break;
    }
}

bool render_commands_handle(struct render_context *ctx, struct session *session,
                            const struct proto_client_msg *msg, double waited_s)
{
    /* A change to a shared world that another node changed first is made again over the
     * state with that node's change, validated again, at the next tick: the world's changes
     * keep one order and frames go on meanwhile. Each retry follows another node's progress;
     * a node that keeps losing the race (a flood of changes elsewhere) gives up after
     * RETRY_S. */
    static const double RETRY_S = 10.0;
    ctx->handling = msg;
    ctx->conflict_revision = 0;
    dispatch(ctx, session, msg);
    uint64_t wanted = ctx->conflict_revision;
    ctx->conflict_revision = 0;
    bool done = true;
    if (wanted != 0 && waited_s < RETRY_S) {
        done = false;
    } else if (wanted != 0) {
        reply_error(ctx, session, &msg->id, PROTO_MSG_ERR_UNAVAILABLE,
                    "the shared world is at revision %llu and this node could not catch up "
                    "with it within %.0f s; the change is not applied",
                    (unsigned long long)wanted, RETRY_S);
    }
    ctx->handling = NULL;
    return done;
}

void render_commands_follow_forecast(struct render_context *ctx)
{
    struct proto_world_state next;
    struct proto_weather_map map;
    if (ctx->forecast &&
        forecast_feed_map(ctx->forecast, world_host_state(ctx->world), monotonic_seconds(), &map)) {
        if (!world_host_set_forecast_map(ctx->world, &map))
            skyd_log(SKYD_LOG_WARNING, "out of memory for the forecast's weather map");
        proto_weather_map_free(&map);
    }
    if (!ctx->forecast || !forecast_feed_plan(ctx->forecast, world_host_state(ctx->world), &next))
        return;
    struct world_commit commit;
    if (!world_host_commit(ctx->world, &next, NULL, "forecast", &commit) ||
        !renderer_takes(ctx, &commit)) {
        skyd_log(SKYD_LOG_WARNING, "the forecast's weather is not applied: %s", commit.error);
    } else if (commit.event) {
        session_hub_broadcast(ctx->hub, commit.event);
        session_hub_wake(ctx->hub);
    }
    free(commit.event);
    forecast_feed_planned(ctx->forecast, world_host_state(ctx->world)->revision);
}

void render_commands_session_closed(struct render_context *ctx, struct session *session)
{
    frame_scheduler_session_closed(ctx->frames, session);
}
