#include "world_host.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "config.h"
#include "error_text.h"
#include "field_errors.h"
#include "log.h"
#include "messages.h"
#include "monotonic_clock.h"
#include "wall_clock.h"
#include "state_store.h"
#include "world_codec.h"
#include "wind_drift.h"
#include "world_render.h"
#include "world_sim.h"

enum { MAX_CHANGED = 192 };

/* What the last commit replaced, until the next tick: a renderer that cannot take it undoes
 * it (world_host_undo_commit). */
struct world_undo {
    bool valid;
    struct proto_world_state state, announced;
    struct sky_render_atmosphere atmosphere;
    bool atmosphere_pending;
    uint64_t settled_revision;
    bool map_replaced;
    struct proto_weather_map map;
    uint64_t map_generation;
};

struct world_host {
    char state_file[SKYD_CONFIG_STRING];
    struct proto_world_state state;
    struct proto_weather_map client_map;
    /* The followed forecast's (weather.map_source "forecast"), and whether the file beside the
     * state is older than it. */
    struct proto_weather_map forecast_map;
    bool forecast_map_dirty;
    uint64_t map_generation; /* counts the maps, client and forecast: 0 none yet */
    /* The render input of the live state; atmosphere is its frame atmosphere. */
    struct render_input input;
    struct sky_render_atmosphere atmosphere;
    bool atmosphere_pending;   /* a client's atmosphere change frames do not show fully yet */
    uint64_t settled_revision; /* what frames carry meanwhile */
    bool watched;              /* as the last advance was told */
    struct world_undo undo;
    double save_delay_s;
    bool dirty;           /* a write the daemon owes itself (retried after save_delay_s) */
    double last_change_s; /* when that write was last due */
    bool sim_dirty;       /* the simulation changed the state since the last write */
    double last_save_s;
    double wall_s;            /* the wall instant the state was last brought to */
    struct wind_drift *drift; /* the wind's running sum for the live state */
    /* The state as clients last heard of it (events), and when a simulation event went. */
    struct proto_world_state announced;
    double announced_at_s;
    /* A shared world: commits go to Redis; pending_map is the map set_weather_map commits. */
    struct cluster_store *cluster;
    const struct proto_weather_map *pending_map;
    /* The pointers a commit, an entry or a simulation event names (24 KiB, kept off the render
     * thread's stack); each fills and uses it within one call. */
    char changed[MAX_CHANGED][PROTO_MSG_POINTER_MAX];
};

static void restore_weather_map(struct world_host *h);
static void restore_forecast_map(struct world_host *h);
static void refresh_input(struct world_host *h, bool adopt);

struct world_host *world_host_create(const struct world_host_params *params)
{
    struct world_host *h = calloc(1, sizeof *h);
    if (!h)
        return NULL;
    snprintf(h->state_file, sizeof h->state_file, "%s",
             params->state_file ? params->state_file : "");
    h->drift = wind_drift_create();
    if (!h->drift) {
        free(h);
        return NULL;
    }
    h->state = params->initial_state;
    h->wall_s = params->wall_s;
    if (!world_sim_anchored(&h->state)) {
        world_sim_anchor(&h->state, h->wall_s);
        h->sim_dirty = true; /* written, so that a restart or another node reads this epoch */
    }
    world_sim_run_to(&h->state, h->wall_s, h->drift); /* the clock its epoch gives now */
    h->save_delay_s = params->save_delay_s;
    h->last_save_s = params->now_s;
    h->announced = h->state;
    h->announced_at_s = params->now_s;
    h->cluster = params->cluster;
    if (h->cluster && params->client_map && params->client_map->rgba &&
        !proto_weather_map_copy(params->client_map, &h->client_map)) {
        world_host_destroy(&h);
        return NULL;
    }
    restore_weather_map(h);
    restore_forecast_map(h);
    refresh_input(h, true);
    return h;
}

void world_host_destroy(struct world_host **host)
{
    struct world_host *h = host ? *host : NULL;
    if (!h)
        return;
    proto_weather_map_free(&h->client_map);
    proto_weather_map_free(&h->forecast_map);
    proto_weather_map_free(&h->undo.map);
    wind_drift_destroy(&h->drift);
    free(h);
    *host = NULL;
}

const struct proto_world_state *world_host_state(const struct world_host *h)
{
    return &h->state;
}

const struct render_input *world_host_render_input(const struct world_host *h)
{
    return &h->input;
}

static void save_forecast_map(struct world_host *h)
{
    error_text err;
    if (!h->state_file[0] || !h->forecast_map_dirty)
        return;
    if (state_store_save_forecast_map(h->state_file, &h->forecast_map, err, sizeof err) == 0)
        h->forecast_map_dirty = false;
    else
        skyd_log(SKYD_LOG_ERROR, "cannot save the forecast's weather map: %s", err);
}

/* Writes `state` before anything acknowledges it, so that a restart, even after kill -9, comes
 * back to the last acknowledged state (disk full, a read-only or vanished directory: false). */
static bool persist(struct world_host *h, const struct proto_world_state *state, char *why,
                    size_t whylen)
{
    if (!h->state_file[0])
        return true;
    error_text err;
    if (state_store_save(h->state_file, state, err, sizeof err) != 0) {
        skyd_log(SKYD_LOG_ERROR, "cannot save the state: %s", err);
        error_text_mark_cut(why, whylen,
                            snprintf(why, whylen,
                                     "the state cannot be saved (%s); the change is not applied",
                                     err));
        return false;
    }
    h->dirty = h->sim_dirty = false;
    h->last_save_s = monotonic_seconds();
    save_forecast_map(h);
    return true;
}

/* After a failure past persist(): the file goes back to the live state. */
static void unpersist(struct world_host *h)
{
    error_text err;
    if (h->state_file[0] && state_store_save(h->state_file, &h->state, err, sizeof err) != 0) {
        h->dirty = true; /* written again after save_delay_s */
        h->last_change_s = monotonic_seconds();
    }
}

/* A shared world: the change goes to Redis, checked against the revision it was made from;
 * with the changed pointers ('\n' between them) and the map being set, if any. */
static bool commit_to_cluster(struct world_host *h, const struct proto_world_state *next,
                              const char *const *pointers, size_t count, const char *by,
                              struct world_commit *out)
{
    size_t joined_length = 1;
    for (size_t i = 0; i < count; i++)
        joined_length += strlen(pointers[i]) + 1;
    char *joined = malloc(joined_length);
    char *text = world_codec_state_text(next);
    size_t map_length = 0;
    unsigned char *map = h->pending_map ? world_codec_map_bytes(h->pending_map, &map_length) : NULL;
    if (!joined || !text || (h->pending_map && !map)) {
        free(joined);
        free(text);
        free(map);
        out->status = WORLD_COMMIT_FAILED;
        snprintf(out->error, sizeof out->error, "out of memory; the state is unchanged");
        return false;
    }
    joined[0] = '\0';
    for (size_t i = 0; i < count; i++) {
        strcat(joined, pointers[i]);
        if (i + 1 < count)
            strcat(joined, "\n");
    }
    char id[CLUSTER_ID_MAX], why[448];
    enum cluster_commit_result result = cluster_store_commit(h->cluster, h->state.revision, text,
                                                             by ? by : "", joined, map, map_length,
                                                             &out->current, id, why, sizeof why);
    free(joined);
    free(text);
    free(map);
    switch (result) {
    case CLUSTER_COMMITTED:
        return true;
    case CLUSTER_CONFLICT:
        out->status = WORLD_COMMIT_CONFLICT;
        snprintf(out->error, sizeof out->error, "the shared world moved on to revision %llu",
                 (unsigned long long)out->current);
        return false;
    case CLUSTER_UNAVAILABLE:
        break;
    }
    out->status = WORLD_COMMIT_UNAVAILABLE;
    snprintf(out->error, sizeof out->error, "%s; the change is not applied", why);
    return false;
}

/* The render input's flags and map after the state or the frame atmosphere changed. Nobody
 * watching, the renderer builds the frame atmosphere at once: nothing stays pending. */
static void finish_input(struct world_host *h)
{
    if (!h->watched)
        h->atmosphere_pending = false;
    h->input.frame_atmosphere = h->atmosphere;
    h->input.atmosphere_at_once = !h->watched;
    h->input.atmosphere_pending = h->atmosphere_pending;
    h->input.settled_revision = h->atmosphere_pending ? h->settled_revision : h->state.revision;
    bool forecast = h->state.weather.map_source == PROTO_WEATHER_MAP_FORECAST;
    h->input.client_map = forecast ? &h->forecast_map : &h->client_map;
    /* Another map, or the other one selected: the renderer takes it. */
    h->input.map_generation = h->map_generation * 2 + (forecast ? 1 : 0);
}

/* The live state's render input; adopt: the frame atmosphere may follow the state's own (a
 * client's change waits for nothing; the simulation's haze, watched, for frames to show the
 * previous one). */
static void refresh_input(struct world_host *h, bool adopt)
{
    world_render_input(&h->state, &h->input);
    if (adopt && !h->atmosphere_pending)
        h->atmosphere = h->input.atmosphere;
    finish_input(h);
}

static void drop_undo(struct world_host *h)
{
    proto_weather_map_free(&h->undo.map);
    h->undo.valid = h->undo.map_replaced = false;
}

/* `next` (settled, with its revision) becomes the live state: its render input is made, and
 * the event names `pointers`. What it replaces is kept for world_host_undo_commit. */
static void install(struct world_host *h, struct proto_world_state *next,
                    const char *const *pointers, size_t count, const char *by, char **event)
{
    drop_undo(h);
    h->undo = (struct world_undo){ .valid = true,
                                   .state = h->state,
                                   .announced = h->announced,
                                   .atmosphere = h->atmosphere,
                                   .atmosphere_pending = h->atmosphere_pending,
                                   .settled_revision = h->settled_revision };
    struct sky_render_atmosphere before = h->input.atmosphere;
    if (!h->atmosphere_pending)
        h->settled_revision = h->state.revision;
    h->state = *next;
    h->announced = h->state; /* this commit's event tells everything up to here */
    world_render_input(&h->state, &h->input);
    if (memcmp(&before, &h->input.atmosphere, sizeof before) != 0)
        h->atmosphere_pending = true;
    h->atmosphere = h->input.atmosphere; /* a client's change is shown at once */
    finish_input(h);
    *event = proto_msg_build_state_changed(h->state.revision, pointers, count, &h->state, by);
}

bool world_host_commit(struct world_host *h, struct proto_world_state *next,
                       const char *also_changed, const char *by, struct world_commit *out)
{
    memset(out, 0, sizeof *out);
    out->revision = h->state.revision;
    /* The forecast's map goes with following it: whatever stops that (a client's weather, a
     * preset, an observation) brings the procedural map back, the client's kept for later. */
    if (next->weather.source != PROTO_WEATHER_SOURCE_FORECAST &&
        next->weather.map_source == PROTO_WEATHER_MAP_FORECAST)
        next->weather.map_source = PROTO_WEATHER_MAP_PROCEDURAL;
    world_sim_commit(&h->state, next, h->wall_s, h->drift);
    size_t count = proto_msg_state_diff(&h->state, next, h->changed, MAX_CHANGED - 1);
    if (count > MAX_CHANGED - 1)
        count = MAX_CHANGED - 1;
    if (also_changed)
        snprintf(h->changed[count++], PROTO_MSG_POINTER_MAX, "%s", also_changed);
    if (count == 0)
        return true;
    const char *pointers[MAX_CHANGED];
    for (size_t i = 0; i < count; i++)
        pointers[i] = h->changed[i];
    next->revision = h->state.revision + 1;
    if (h->cluster) {
        /* Redis has it before anything acknowledges it. */
        if (!commit_to_cluster(h, next, pointers, count, by, out))
            return false;
    } else if (!persist(h, next, out->error, sizeof out->error)) {
        out->status = WORLD_COMMIT_FAILED;
        return false;
    }
    install(h, next, pointers, count, by, &out->event);
    out->revision = h->state.revision;
    out->input = &h->input;
    return true;
}

bool world_host_undo_commit(struct world_host *h, const char *why, struct world_commit *out)
{
    if (h->cluster || !h->undo.valid) {
        /* A shared world's revision is the world's: a renderer made again takes it. */
        skyd_log(SKYD_LOG_ERROR, "the renderer did not take revision %llu: %s",
                 (unsigned long long)h->state.revision, why);
        return false;
    }
    struct world_undo *u = &h->undo;
    h->state = u->state;
    h->announced = u->announced;
    h->atmosphere = u->atmosphere;
    h->atmosphere_pending = u->atmosphere_pending;
    h->settled_revision = u->settled_revision;
    if (u->map_replaced) {
        error_text err;
        if (h->state_file[0] &&
            state_store_save_weather_map(h->state_file, &u->map, err, sizeof err) != 0)
            skyd_log(SKYD_LOG_ERROR, "cannot restore the saved weather map: %s", err);
        proto_weather_map_free(&h->client_map);
        h->client_map = u->map;
        h->map_generation = u->map_generation;
        memset(&u->map, 0, sizeof u->map);
    }
    drop_undo(h);
    unpersist(h);
    refresh_input(h, false);
    free(out->event);
    out->event = NULL;
    out->status = WORLD_COMMIT_FAILED;
    out->revision = h->state.revision;
    out->input = NULL;
    snprintf(out->error, sizeof out->error, "%s; the state is unchanged", why);
    return true;
}

/* An entry's map becomes the client map; false when it is not a map. */
static bool adopt_map(struct world_host *h, const struct cluster_entry *e)
{
    struct proto_weather_map map;
    if (!world_codec_parse_map(e->map, e->map_length, &map)) {
        skyd_log(SKYD_LOG_ERROR, "cluster revision %llu carries a weather map that cannot be read",
                 (unsigned long long)e->revision);
        return false;
    }
    proto_weather_map_free(&h->client_map);
    h->client_map = map;
    h->map_generation++;
    return true;
}

bool world_host_apply_entry(struct world_host *h, const struct cluster_entry *e, char **event)
{
    *event = NULL;
    if (e->revision <= h->state.revision && !(e->snapshot && e->revision < h->state.revision))
        return true;
    struct proto_world_state next;
    error_text why;
    if (!world_codec_parse_state(e->state, &next, why, sizeof why)) {
        skyd_log(SKYD_LOG_ERROR, "cluster revision %llu cannot be read: %s",
                 (unsigned long long)e->revision, why);
        return false;
    }
    if (e->snapshot && e->revision < h->state.revision)
        skyd_log(SKYD_LOG_WARNING,
                 "the shared world went back from revision %llu to %llu (Redis lost changes)",
                 (unsigned long long)h->state.revision, (unsigned long long)e->revision);
    next.revision = e->revision;
    /* The entry's state holds its epoch and anchors: brought to this node's wall instant, it
     * is the instant every node computes. The wind's running sum was the old state's. */
    wind_drift_forget(h->drift);
    world_sim_run_to(&next, wall_clock_seconds(), h->drift);
    bool map_changed = e->map && adopt_map(h, e);
    size_t count = 0;
    if (e->snapshot) {
        count = proto_msg_state_diff(&h->state, &next, h->changed, MAX_CHANGED - 1);
        if (count > MAX_CHANGED - 1)
            count = MAX_CHANGED - 1;
        if (map_changed)
            snprintf(h->changed[count++], PROTO_MSG_POINTER_MAX, "/weather/map");
    } else {
        for (const char *p = e->changed; *p && count < MAX_CHANGED;) {
            size_t length = strcspn(p, "\n");
            if (length > 0 && length < PROTO_MSG_POINTER_MAX) {
                memcpy(h->changed[count], p, length);
                h->changed[count++][length] = '\0';
            }
            p += length + (p[length] == '\n');
        }
    }
    const char *pointers[MAX_CHANGED];
    for (size_t i = 0; i < count; i++)
        pointers[i] = h->changed[i];
    install(h, &next, pointers, count, e->snapshot ? "cluster" : e->by, event);
    return true;
}

bool world_host_client_map_missing(const struct world_host *h, const struct proto_world_state *next,
                                   struct proto_field_errors *errors)
{
    const char *why = NULL;
    if (next->weather.map_source == PROTO_WEATHER_MAP_CLIENT && !h->client_map.rgba)
        why = "no client weather map has been sent: send set_weather_map first";
    else if (next->weather.map_source == PROTO_WEATHER_MAP_FORECAST &&
             h->state.weather.map_source != PROTO_WEATHER_MAP_FORECAST &&
             next->weather.source != PROTO_WEATHER_SOURCE_FORECAST)
        why = "the forecast's weather map goes with following it: set weather.source "
              "\"forecast\" too";
    if (!why)
        return false;
    proto_field_errors_clear(errors);
    proto_field_errors_add(errors, PROTO_FIELD_INCONSISTENT, "/weather/map_source", why);
    return true;
}

bool world_host_set_forecast_map(struct world_host *h, const struct proto_weather_map *map)
{
    struct proto_weather_map kept;
    if (!proto_weather_map_copy(map, &kept))
        return false;
    proto_weather_map_free(&h->forecast_map);
    h->forecast_map = kept;
    h->forecast_map_dirty = true;
    h->sim_dirty = true; /* written with the state at its next save */
    h->map_generation++;
    finish_input(h);
    return true;
}

bool world_host_set_weather_map(struct world_host *h, const struct proto_weather_map *map,
                                const char *by, struct world_commit *out)
{
    memset(out, 0, sizeof *out);
    out->revision = h->state.revision;
    struct proto_weather_map kept;
    if (!proto_weather_map_copy(map, &kept)) {
        snprintf(out->error, sizeof out->error,
                 "out of memory for the weather map; the state is unchanged");
        return false;
    }
    error_text err;
    if (h->state_file[0] &&
        state_store_save_weather_map(h->state_file, map, err, sizeof err) != 0) {
        skyd_log(SKYD_LOG_ERROR, "cannot save the weather map: %s", err);
        error_text_mark_cut(out->error, sizeof out->error,
                            snprintf(out->error, sizeof out->error,
                                     "the weather map cannot be saved (%s); the state is unchanged",
                                     err));
        proto_weather_map_free(&kept);
        return false;
    }
    struct proto_weather_map old = h->client_map;
    uint64_t old_generation = h->map_generation;
    h->client_map = kept;
    h->map_generation++;
    struct proto_world_state next = h->state;
    next.weather.map_source = PROTO_WEATHER_MAP_CLIENT;
    h->pending_map = map;
    bool committed = world_host_commit(h, &next, "/weather/map", by, out);
    h->pending_map = NULL;
    if (!committed) {
        /* The state was not saved: the old map goes back on disk and to the input. */
        if (h->state_file[0])
            state_store_save_weather_map(h->state_file, &old, err, sizeof err);
        proto_weather_map_free(&h->client_map);
        h->client_map = old;
        h->map_generation = old_generation;
        finish_input(h);
        return false;
    }
    h->undo.map_replaced = true;
    h->undo.map = old;
    h->undo.map_generation = old_generation;
    return true;
}

/* At creation: the client weather map of the shared world, or the one saved beside the state.
 * A state that selects it without one falls back to the procedural map (said on stderr). */
static void restore_weather_map(struct world_host *h)
{
    error_text msg;
    enum state_load_result result = STATE_LOAD_ABSENT;
    if (h->cluster && h->client_map.rgba) {
        skyd_log(SKYD_LOG_INFO, "the shared world's client weather map (%ux%u)",
                 h->client_map.width, h->client_map.height);
        h->map_generation++;
        return;
    }
    if (h->state_file[0])
        result = state_store_load_weather_map(h->state_file, &h->client_map, msg, sizeof msg);
    if (result == STATE_LOAD_RESTORED) {
        skyd_log(SKYD_LOG_INFO, "restored the client weather map (%ux%u)", h->client_map.width,
                 h->client_map.height);
        h->map_generation++;
    } else if (h->state.weather.map_source == PROTO_WEATHER_MAP_CLIENT) {
        skyd_log(SKYD_LOG_WARNING, "%s; weather.map_source is procedural",
                 h->state_file[0] ? msg : "no state file keeps a client weather map");
        h->state.weather.map_source = PROTO_WEATHER_MAP_PROCEDURAL;
        h->dirty = true;
    } else if (result != STATE_LOAD_ABSENT) {
        skyd_log(SKYD_LOG_WARNING, "%s", msg);
    }
}

/* At creation: the forecast's map saved beside the state while it is followed; without one the
 * renderer keeps to the procedural map until the feed makes the forecast's. */
static void restore_forecast_map(struct world_host *h)
{
    if (h->state.weather.map_source != PROTO_WEATHER_MAP_FORECAST)
        return;
    if (h->state.weather.source != PROTO_WEATHER_SOURCE_FORECAST) {
        h->state.weather.map_source = PROTO_WEATHER_MAP_PROCEDURAL;
        h->dirty = true;
        return;
    }
    error_text msg;
    if (h->state_file[0] && state_store_load_forecast_map(h->state_file, &h->forecast_map, msg,
                                                          sizeof msg) == STATE_LOAD_RESTORED) {
        skyd_log(SKYD_LOG_INFO, "restored the forecast's weather map (%ux%u)",
                 h->forecast_map.width, h->forecast_map.height);
        h->map_generation++;
    }
}

void world_host_advance(struct world_host *h, double wall_s, bool watched, bool frames_settled)
{
    h->wall_s = wall_s;
    h->watched = watched;
    drop_undo(h);
    struct proto_world_state before;
    memcpy(&before, &h->state, sizeof before);
    world_sim_run_to(&h->state, wall_s, h->drift);
    if (memcmp(&before, &h->state, sizeof before) != 0)
        h->sim_dirty = true;
    refresh_input(h, !watched || frames_settled);
}

char *world_host_simulation_event(struct world_host *h, double now_s, double period_s)
{
    if (now_s - h->announced_at_s < period_s)
        return NULL;
    size_t count = proto_msg_state_diff(&h->announced, &h->state, h->changed, MAX_CHANGED);
    if (count == 0)
        return NULL;
    if (count > MAX_CHANGED)
        count = MAX_CHANGED;
    const char *pointers[MAX_CHANGED];
    for (size_t i = 0; i < count; i++)
        pointers[i] = h->changed[i];
    char *event = proto_msg_build_simulation_event(h->state.revision, pointers, count, &h->state);
    if (event) {
        h->announced = h->state;
        h->announced_at_s = now_s;
    }
    return event;
}

void world_host_atmosphere_shown(struct world_host *h)
{
    h->atmosphere_pending = false;
    h->settled_revision = h->state.revision;
    finish_input(h);
}

void world_host_save(struct world_host *h, double now_s)
{
    if (!h->state_file[0] || !(h->dirty || h->sim_dirty))
        return;
    error_text err;
    h->last_save_s = now_s;
    if (state_store_save(h->state_file, &h->state, err, sizeof err) == 0) {
        h->dirty = false;
        h->sim_dirty = false;
        save_forecast_map(h);
    } else {
        skyd_log(SKYD_LOG_ERROR, "cannot save the state: %s", err);
        h->last_change_s = monotonic_seconds(); /* try again after another delay */
    }
}

double world_host_save_due(struct world_host *h, double now_s, double sim_period_s)
{
    if (h->dirty) {
        double save_at = h->last_change_s + h->save_delay_s;
        if (now_s < save_at)
            return save_at;
        world_host_save(h, now_s);
    } else if (h->sim_dirty && now_s - h->last_save_s >= sim_period_s) {
        world_host_save(h, now_s);
    }
    return INFINITY;
}
