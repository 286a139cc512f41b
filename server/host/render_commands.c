#include "render_commands.h"

#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "json_guard.h"
#include "presets.h"
#include "state_store.h"
#include "world_render.h"
#include "world_sim.h"
#include "monotonic_clock.h"

/* Preset folders under the config directory, by enum sky_preset_kind. */
static const char *const preset_folders[] = {
    [SKY_PRESET_ATMOSPHERE] = "atmosphere",
    [SKY_PRESET_WEATHER] = "weather",
};

/* Queues a built message (NULL only when building failed, which the client hears of). */
static void reply(struct session *session, const struct sky_msg_id *id, char *text)
{
    if (!text)
        text = sky_msg_build_error(id, SKY_MSG_ERR_INTERNAL, "the reply could not be built",
                                   NULL);
    if (text)
        session_push_text(session, text);
    free(text);
}

#if defined(__GNUC__)
__attribute__((format(printf, 4, 5)))
#endif
static void reply_error(struct session *session, const struct sky_msg_id *id,
                        enum sky_msg_error_code code, const char *format, ...)
{
    char message[512];
    va_list args;
    va_start(args, format);
    vsnprintf(message, sizeof message, format, args);
    va_end(args);
    reply(session, id, sky_msg_build_error(id, code, message, NULL));
}

/* A failed apply: pointers are into the message, so they gain the "/patch" prefix. */
static void reply_field_errors(struct session *session, const struct sky_msg_id *id,
                               const char *prefix, const struct sky_field_errors *errors)
{
    struct sky_field_errors prefixed = *errors;
    for (int i = 0; i < prefixed.count; i++)
        snprintf(prefixed.items[i].pointer, sizeof prefixed.items[i].pointer, "%s%s", prefix,
                 errors->items[i].pointer);
    enum sky_msg_error_code code = prefixed.count ? (enum sky_msg_error_code)prefixed.items[0].code
                                                  : SKY_MSG_ERR_BAD_VALUE;
    char message[320];
    if (prefixed.count)
        snprintf(message, sizeof message, "%s: %s", prefixed.items[0].pointer,
                 prefixed.items[0].reason);
    else
        snprintf(message, sizeof message, "the patch was rejected");
    reply(session, id, sky_msg_build_error(id, code, message, &prefixed));
}

/* Writes `state` to the state file before anything acknowledges it, so that a restart, even
 * after kill -9, comes back to the last acknowledged state. On failure (disk full, a read-only
 * or vanished directory) the sender hears why and false says not to apply the change. */
static bool persist(struct render_context *ctx, struct session *session,
                    const struct sky_msg_id *id, const struct sky_world_state *state)
{
    if (!ctx->state_file[0])
        return true;
    char err[512];
    if (state_store_save(ctx->state_file, state, err, sizeof err) != 0) {
        fprintf(stderr, "skyd: cannot save the state: %s\n", err);
        reply_error(session, id, SKY_MSG_ERR_INTERNAL, "the state cannot be saved (%s); the "
                    "change is not applied", err);
        return false;
    }
    ctx->dirty = ctx->sim_dirty = false;
    ctx->last_save_s = monotonic_seconds();
    return true;
}

/* After a failure past persist(): the file goes back to the live state. */
static void unpersist(struct render_context *ctx)
{
    char err[512];
    if (ctx->state_file[0] &&
        state_store_save(ctx->state_file, &ctx->state, err, sizeof err) != 0) {
        ctx->dirty = true; /* the loop tries again after state_save_delay_s */
        ctx->last_change_s = monotonic_seconds();
    }
}

/* Makes `next` the live state: a new revision when anything differs (or when `also_changed`,
 * a pointer outside the schema, names something else that did), written to the state file,
 * then an ack to the sender and an event naming the changed fields to everyone. A renderer
 * whose device is lost need not take the change: the one made after the tick takes the whole
 * state. */
static bool commit_state(struct render_context *ctx, struct session *session,
                         const struct sky_msg_id *id, struct sky_world_state *next,
                         const char *also_changed)
{
    enum { MAX_CHANGED = 192 };
    static char changed[MAX_CHANGED][SKY_MSG_POINTER_MAX];
    world_sim_settle(next);
    size_t count = sky_msg_state_diff(&ctx->state, next, changed, MAX_CHANGED - 1);
    if (count > MAX_CHANGED - 1)
        count = MAX_CHANGED - 1;
    if (also_changed)
        snprintf(changed[count++], SKY_MSG_POINTER_MAX, "%s", also_changed);
    if (count == 0) {
        reply(session, id, sky_msg_build_ack(id, ctx->state.revision, SKY_ROLE_NONE));
        return true;
    }
    next->revision = ctx->state.revision + 1;
    if (!persist(ctx, session, id, next))
        return false;
    char why[512];
    if (renderer_host_apply_change(ctx->renderer, &ctx->state, next, why, sizeof why) != 0) {
        reply_error(session, id, SKY_MSG_ERR_INTERNAL, "%s; the state is unchanged", why);
        unpersist(ctx);
        return false;
    }
    struct sky_render_atmosphere before, after;
    world_to_render_atmosphere(&ctx->state, &before);
    world_to_render_atmosphere(next, &after);
    if (memcmp(&before, &after, sizeof before) != 0)
        ctx->atmosphere_pending = true;
    ctx->state = *next;
    ctx->atmosphere = after; /* a client's change is shown at once, not paced like the sim's */
    reply(session, id, sky_msg_build_ack(id, ctx->state.revision, SKY_ROLE_NONE));
    const char *pointers[MAX_CHANGED];
    for (size_t i = 0; i < count; i++)
        pointers[i] = changed[i];
    char *event = sky_msg_build_state_changed(ctx->state.revision, pointers, count);
    if (event)
        session_hub_broadcast(ctx->hub, event);
    free(event);
    return true;
}

/* A state that samples the client weather map needs one. */
static bool client_map_missing(const struct render_context *ctx,
                               const struct sky_world_state *next, struct sky_field_errors *errors)
{
    if (next->weather.map_source != SKY_WEATHER_MAP_CLIENT || ctx->client_map.rgba)
        return false;
    sky_field_errors_clear(errors);
    sky_field_errors_add(errors, SKY_FIELD_INCONSISTENT, "/weather/map_source",
                         "no client weather map has been sent: send set_weather_map first");
    return true;
}

static void handle_set(struct render_context *ctx, struct session *session,
                       const struct sky_client_msg *msg)
{
    struct sky_world_state next = ctx->state;
    struct sky_field_errors errors;
    if (!sky_world_state_apply_json(&next, msg->set.patch, &errors)) {
        reply_field_errors(session, &msg->id, "/patch", &errors);
        return;
    }
    sky_field_errors_clear(&errors);
    if (!world_sim_check_client_patch(&ctx->state, &next, msg->set.patch, &errors)) {
        reply_field_errors(session, &msg->id, "/patch", &errors);
        return;
    }
    if (client_map_missing(ctx, &next, &errors)) {
        reply_field_errors(session, &msg->id, "/patch", &errors);
        return;
    }
    world_sim_client_changed(&ctx->state, &next);
    commit_state(ctx, session, &msg->id, &next, NULL);
}

static int list_presets(struct render_context *ctx, enum sky_preset_kind kind,
                        char names[][SKY_PRESET_NAME_MAX + 1], int max)
{
    return sky_preset_list(ctx->config_dir, preset_folders[kind], names, max);
}

/* A weather preset: its weather parameters are reached through a transition (at once for
 * transition_s 0 or absent), anything else it sets applies at once, and the autopilot stops
 * (the preset names the weather wanted). A transition under way is replaced, starting from
 * the weather as it stands. */
static void start_weather_preset(const struct sky_world_state *live,
                                 const struct sky_world_state *applied, double transition_s,
                                 struct sky_world_state *next)
{
    struct sky_weather_params now, goal;
    sky_weather_params_get(live, &now);
    sky_weather_params_get(applied, &goal);
    *next = *applied;
    sky_weather_params_put(next, &now);
    next->weather.autopilot = SKY_SWITCH_OFF;
    world_sim_start_transition(next, &goal, transition_s);
}

static void handle_apply_preset(struct render_context *ctx, struct session *session,
                                const struct sky_client_msg *msg)
{
    static char names[SKY_MSG_MAX_PRESETS][SKY_PRESET_NAME_MAX + 1];
    const char *folder = preset_folders[msg->preset.kind];
    int count = list_presets(ctx, msg->preset.kind, names, SKY_MSG_MAX_PRESETS);
    bool known = false;
    for (int i = 0; i < count && !known; i++)
        known = strcmp(names[i], msg->preset.name) == 0;
    if (!known) {
        reply_error(session, &msg->id, SKY_MSG_ERR_NOT_FOUND,
                    "no %s preset \"%s\" (list_presets names them)", folder, msg->preset.name);
        return;
    }
    struct sky_world_state next = ctx->state;
    struct sky_field_errors errors;
    char why[320];
    json_guard_lock();
    bool applied = sky_preset_apply(ctx->config_dir, folder, msg->preset.name, &next, &errors,
                                    why, sizeof why);
    json_guard_unlock();
    if (!applied) {
        fprintf(stderr, "skyd: preset %s: %s\n", msg->preset.name, why);
        reply_error(session, &msg->id, SKY_MSG_ERR_INTERNAL, "preset \"%s\" cannot be applied: %s",
                    msg->preset.name, why);
        return;
    }
    if (msg->preset.kind == SKY_PRESET_WEATHER) {
        struct sky_world_state applied = next;
        start_weather_preset(&ctx->state, &applied,
                             msg->preset.has_transition ? msg->preset.transition_s : 0.0, &next);
    }
    if (client_map_missing(ctx, &next, &errors)) {
        reply_field_errors(session, &msg->id, "", &errors);
        return;
    }
    commit_state(ctx, session, &msg->id, &next, NULL);
}

static bool copy_map(const struct sky_weather_map *from, struct sky_weather_map *to)
{
    size_t bytes = (size_t)from->width * from->height * 4;
    memset(to, 0, sizeof *to);
    if (!(to->rgba = malloc(bytes)))
        return false;
    memcpy(to->rgba, from->rgba, bytes);
    to->width = from->width;
    to->height = from->height;
    return true;
}

/* The map is written to disk first, then handed to the renderer, then selected by the state
 * (weather.map_source "client") in one revision whose event names "/weather/map". A failure at
 * any step leaves the disk, the renderer and the state as they were. */
static void handle_set_weather_map(struct render_context *ctx, struct session *session,
                                   const struct sky_client_msg *msg)
{
    const struct sky_weather_map *map = &msg->weather_map;
    struct sky_weather_map kept;
    if (!copy_map(map, &kept)) {
        reply_error(session, &msg->id, SKY_MSG_ERR_INTERNAL, "out of memory for the weather "
                    "map; the state is unchanged");
        return;
    }
    char err[512];
    if (ctx->state_file[0] &&
        state_store_save_weather_map(ctx->state_file, map, err, sizeof err) != 0) {
        fprintf(stderr, "skyd: cannot save the weather map: %s\n", err);
        reply_error(session, &msg->id, SKY_MSG_ERR_INTERNAL, "the weather map cannot be saved "
                    "(%s); the state is unchanged", err);
        sky_weather_map_free(&kept);
        return;
    }
    /* A renderer whose device is lost is made again with this map after the tick. */
    if (renderer_host_set_weather_map(ctx->renderer, map) != 0) {
        if (ctx->state_file[0] &&
            state_store_save_weather_map(ctx->state_file, &ctx->client_map, err, sizeof err) != 0)
            fprintf(stderr, "skyd: cannot restore the saved weather map: %s\n", err);
        char why[512];
        renderer_host_describe_failure(ctx->renderer, "uploading the weather map", why, sizeof why);
        reply_error(session, &msg->id, SKY_MSG_ERR_INTERNAL, "%s; the state is unchanged", why);
        sky_weather_map_free(&kept);
        return;
    }
    struct sky_world_state next = ctx->state;
    next.weather.map_source = SKY_WEATHER_MAP_CLIENT;
    if (!commit_state(ctx, session, &msg->id, &next, "/weather/map")) {
        /* The state was not saved: the old map goes back on disk and to the renderer. */
        if (ctx->state_file[0])
            state_store_save_weather_map(ctx->state_file, &ctx->client_map, err, sizeof err);
        renderer_host_set_weather_map(ctx->renderer, &ctx->client_map);
        sky_weather_map_free(&kept);
        return;
    }
    sky_weather_map_free(&ctx->client_map);
    ctx->client_map = kept;
}

static void handle_list_presets(struct render_context *ctx, struct session *session,
                                const struct sky_client_msg *msg)
{
    static char names[SKY_MSG_MAX_PRESETS][SKY_PRESET_NAME_MAX + 1];
    int count = list_presets(ctx, msg->preset.kind, names, SKY_MSG_MAX_PRESETS);
    if (count < 0) {
        reply_error(session, &msg->id, SKY_MSG_ERR_INTERNAL, "the preset folder cannot be read");
        return;
    }
    const char *list[SKY_MSG_MAX_PRESETS];
    for (int i = 0; i < count; i++)
        list[i] = names[i];
    reply(session, &msg->id,
          sky_msg_build_presets(&msg->id, msg->preset.kind, list, (size_t)count));
}

static bool tokens_equal(const char *given, const char *expected)
{
    size_t a = strlen(given), b = strlen(expected);
    unsigned char diff = (unsigned char)(a != b);
    for (size_t i = 0; i < b; i++)
        diff |= (unsigned char)(expected[i] ^ (i < a ? given[i] : 0));
    return diff == 0;
}

static void handle_auth(struct render_context *ctx, struct session *session,
                        const struct sky_client_msg *msg)
{
    const char *token = ctx->config->controller_token;
    if (!token[0]) {
        reply_error(session, &msg->id, SKY_MSG_ERR_AUTH_FAILED,
                    "this server has no controller token: nobody can control it");
        return;
    }
    if (!tokens_equal(msg->auth.token, token)) {
        reply_error(session, &msg->id, SKY_MSG_ERR_AUTH_FAILED, "wrong token");
        return;
    }
    session_set_role(session, SKY_ROLE_CONTROLLER);
    reply(session, &msg->id,
          sky_msg_build_ack(&msg->id, ctx->state.revision, SKY_ROLE_CONTROLLER));
}

/* Makes room for one more item in a growing array; false (and a reply) when memory is out. */
static bool reserve_one(void **items, size_t *capacity, size_t count, size_t item_size,
                        struct session *session, const struct sky_msg_id *id)
{
    if (count < *capacity)
        return true;
    size_t grown_capacity = *capacity ? *capacity * 2 : 8;
    void *grown = realloc(*items, item_size * grown_capacity);
    if (!grown) {
        reply_error(session, id, SKY_MSG_ERR_INTERNAL, "out of memory");
        return false;
    }
    *items = grown;
    *capacity = grown_capacity;
    return true;
}

static void handle_subscribe(struct render_context *ctx, struct session *session,
                             const struct sky_client_msg *msg)
{
    if (!reserve_one((void **)&ctx->subscriptions, &ctx->subscription_capacity,
                     ctx->subscription_count, sizeof *ctx->subscriptions, session, &msg->id))
        return;
    uint64_t id = ctx->last_subscription_id + 1;
    if (!session_add_slot(session, id)) {
        reply_error(session, &msg->id, SKY_MSG_ERR_LIMIT_REACHED,
                    "at most %d subscriptions per connection", SESSION_MAX_SUBSCRIPTIONS);
        return;
    }
    ctx->last_subscription_id = id;
    struct subscription *s = &ctx->subscriptions[ctx->subscription_count++];
    *s = (struct subscription){ .id = id,
                                .session = session_ref(session),
                                .view = msg->view,
                                .period_s = 1.0 / msg->view.fps,
                                .next_due = monotonic_seconds() };
    reply(session, &msg->id, sky_msg_build_subscribed(&msg->id, id, &msg->view));
}

static void remove_subscription(struct render_context *ctx, size_t index)
{
    struct subscription *s = &ctx->subscriptions[index];
    session_remove_slot(s->session, s->id);
    session_unref(&s->session);
    ctx->subscriptions[index] = ctx->subscriptions[--ctx->subscription_count];
}

static void handle_unsubscribe(struct render_context *ctx, struct session *session,
                               const struct sky_client_msg *msg)
{
    for (size_t i = 0; i < ctx->subscription_count; i++) {
        if (ctx->subscriptions[i].session == session &&
            ctx->subscriptions[i].id == msg->unsubscribe.subscription) {
            remove_subscription(ctx, i);
            reply(session, &msg->id, sky_msg_build_ack(&msg->id, ctx->state.revision,
                                                       SKY_ROLE_NONE));
            return;
        }
    }
    reply_error(session, &msg->id, SKY_MSG_ERR_NOT_FOUND,
                "this connection has no subscription %llu",
                (unsigned long long)msg->unsubscribe.subscription);
}

static void handle_snapshot(struct render_context *ctx, struct session *session,
                            const struct sky_client_msg *msg)
{
    if (!reserve_one((void **)&ctx->snapshots, &ctx->snapshot_capacity, ctx->snapshot_count,
                     sizeof *ctx->snapshots, session, &msg->id))
        return;
    if (!session_snapshot_reserve(session)) {
        reply_error(session, &msg->id, SKY_MSG_ERR_LIMIT_REACHED,
                    "at most %d snapshots may be pending per connection", SESSION_MAX_SNAPSHOTS);
        return;
    }
    ctx->snapshots[ctx->snapshot_count++] = (struct pending_snapshot){
        .session = session_ref(session), .id = msg->id, .view = msg->view
    };
}

static void handle_probe(struct render_context *ctx, struct session *session,
                         const struct sky_client_msg *msg)
{
    struct sky_msg_probe_result result;
    if (renderer_host_probe(ctx->renderer, &ctx->state, &msg->probe, &result) != 0) {
        char why[512];
        renderer_host_describe_failure(ctx->renderer, "the probe", why, sizeof why);
        reply_error(session, &msg->id, SKY_MSG_ERR_INTERNAL, "%s", why);
        return;
    }
    reply(session, &msg->id, sky_msg_build_probe_result(&msg->id, &result));
}

static void handle_stats(struct render_context *ctx, struct session *session,
                         const struct sky_client_msg *msg)
{
    struct sky_msg_pass_time passes[SKY_MSG_MAX_PASSES];
    size_t pass_count = 0;
    if (ctx->has_stats) {
        for (int i = 0; i < ctx->last_stats.pass_count && pass_count < SKY_MSG_MAX_PASSES; i++)
            passes[pass_count++] = (struct sky_msg_pass_time){ ctx->last_stats.pass_names[i],
                                                               ctx->last_stats.pass_ms[i] };
    }
    struct sky_msg_stats stats = { .fps = ctx->fps,
                                   .clients = session_hub_count(ctx->hub),
                                   .passes = passes,
                                   .pass_count = pass_count,
                                   .lut_rebuild_progress = ctx->has_stats
                                                               ? ctx->last_stats.lut_rebuild_progress
                                                               : 1.0,
                                   .simulation_time_s = ctx->state.clock.utc_unix_s };
    reply(session, &msg->id, sky_msg_build_stats(&msg->id, &stats));
}

void render_commands_handle(struct render_context *ctx, struct session *session,
                            const struct sky_client_msg *msg)
{
    if (protocol_message_needs_controller(msg->type) &&
        session_role(session) != SKY_ROLE_CONTROLLER) {
        reply_error(session, &msg->id, SKY_MSG_ERR_FORBIDDEN, "%s needs the controller role",
                    sky_msg_type_name(msg->type));
        return;
    }
    switch (msg->type) {
    case SKY_MSG_HELLO:
    case SKY_MSG_NONE:
        reply(session, &msg->id, sky_msg_build_ack(&msg->id, ctx->state.revision,
                                                   SKY_ROLE_NONE));
        break;
    case SKY_MSG_AUTH: handle_auth(ctx, session, msg); break;
    case SKY_MSG_GET_STATE: reply(session, &msg->id, sky_msg_build_state(&msg->id, &ctx->state)); break;
    case SKY_MSG_SET: handle_set(ctx, session, msg); break;
    case SKY_MSG_SUBSCRIBE: handle_subscribe(ctx, session, msg); break;
    case SKY_MSG_UNSUBSCRIBE: handle_unsubscribe(ctx, session, msg); break;
    case SKY_MSG_SNAPSHOT: handle_snapshot(ctx, session, msg); break;
    case SKY_MSG_PROBE: handle_probe(ctx, session, msg); break;
    case SKY_MSG_LIST_PRESETS: handle_list_presets(ctx, session, msg); break;
    case SKY_MSG_APPLY_PRESET: handle_apply_preset(ctx, session, msg); break;
    case SKY_MSG_STATS: handle_stats(ctx, session, msg); break;
    case SKY_MSG_SET_WEATHER_MAP: handle_set_weather_map(ctx, session, msg); break;
    }
}

void render_commands_session_closed(struct render_context *ctx, struct session *session)
{
    for (size_t i = ctx->subscription_count; i-- > 0;)
        if (ctx->subscriptions[i].session == session)
            remove_subscription(ctx, i);
    for (size_t i = ctx->snapshot_count; i-- > 0;) {
        if (ctx->snapshots[i].session == session) {
            session_unref(&ctx->snapshots[i].session);
            ctx->snapshots[i] = ctx->snapshots[--ctx->snapshot_count];
        }
    }
}

void render_commands_release(struct render_context *ctx)
{
    while (ctx->subscription_count > 0)
        remove_subscription(ctx, ctx->subscription_count - 1);
    for (size_t i = 0; i < ctx->snapshot_count; i++)
        session_unref(&ctx->snapshots[i].session);
    free(ctx->subscriptions);
    free(ctx->snapshots);
    ctx->subscriptions = NULL;
    ctx->snapshots = NULL;
    ctx->snapshot_count = ctx->subscription_count = 0;
}
