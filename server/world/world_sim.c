#include "world_sim.h"

#include <cjson/cJSON.h>

#include <math.h>
#include <stddef.h>
#include <stdio.h>
#include <string.h>

#include "ephemeris.h"
#include "error_text.h"
#include "field_errors.h"
#include "field_schema.h"
#include "utc_time.h"
#include "weather_autopilot.h"
#include "weather_timeline.h"
#include "wind_drift.h"

/* clock.utc's range in the schema: 1900-01-01 to 2100-12-31T23:59:59Z. */
#define UTC_MIN_S -2208988800.0
#define UTC_MAX_S 4133980799.0

static double clamp(double x, double lo, double hi)
{
    return x < lo ? lo : x > hi ? hi : x;
}

static double wrap_degrees(double deg)
{
    double d = fmod(deg, 360.0);
    if (d < 0.0)
        d += 360.0;
    return d >= 360.0 ? 0.0 : d;
}

/* What a time's ISO 8601 text in the state's JSON keeps of it: whole milliseconds. A time
 * the state anchors on is stored so, so that a node reading the JSON gets the same double. */
static double time_kept(double unix_s)
{
    char text[48];
    error_text err;
    double kept;
    proto_time_format_iso8601(unix_s, text, sizeof text);
    return proto_time_parse_iso8601(text, &kept, err, sizeof err) ? kept : unix_s;
}

static void update_sky_bodies(struct proto_world_state *state)
{
    if (state->clock.sky_bodies != PROTO_BODIES_EPHEMERIS)
        return;
    struct world_site site = { state->location.latitude_deg, state->location.longitude_deg,
                               state->location.altitude_m, WORLD_SITE_PRESSURE_MBAR,
                               WORLD_SITE_TEMPERATURE_C };
    struct world_body_position sun, moon;
    world_sun_position(state->clock.utc_unix_s, &site, true, &sun);
    world_moon_position(state->clock.utc_unix_s, &site, true, &moon, NULL, NULL);
    state->sun.azimuth_deg = wrap_degrees(sun.azimuth_deg);
    state->sun.elevation_deg = clamp(sun.elevation_deg, -90.0, 90.0);
    state->moon.azimuth_deg = wrap_degrees(moon.azimuth_deg);
    state->moon.elevation_deg = clamp(moon.elevation_deg, -90.0, 90.0);
}

bool world_sim_anchored(const struct proto_world_state *state)
{
    return state->clock.epoch.wall_unix_s != 0.0;
}

double world_sim_clock_at(const struct proto_world_state *state, double wall_s)
{
    const struct proto_clock_state *c = &state->clock;
    if (!world_sim_anchored(state))
        return c->utc_unix_s;
    return clamp(c->epoch.utc_unix_s + (wall_s - c->epoch.wall_unix_s) * c->time_scale, UTC_MIN_S,
                 UTC_MAX_S);
}

void world_sim_anchor_wind(struct proto_world_state *state)
{
    struct proto_wind_anchor *a = &state->weather.anchor;
    a->utc_unix_s = time_kept(state->clock.utc_unix_s);
    a->offset_east_km = state->weather.offset_east_km;
    a->offset_north_km = state->weather.offset_north_km;
}

void world_sim_anchor(struct proto_world_state *state, double wall_s)
{
    struct proto_clock_state *c = &state->clock;
    /* clock.utc is the reading at wall_s; the epoch's wall instant is kept to the millisecond
     * and its reading follows the clock's pace to it. */
    double wall = time_kept(wall_s);
    c->epoch.wall_unix_s = wall;
    c->epoch.utc_unix_s =
        time_kept(clamp(c->utc_unix_s + (wall - wall_s) * c->time_scale, UTC_MIN_S, UTC_MAX_S));
    c->utc_unix_s = world_sim_clock_at(state, wall_s);
    world_sim_anchor_wind(state);
}

bool world_sim_clock_changed(const struct proto_world_state *before,
                             const struct proto_world_state *after)
{
    return !world_sim_anchored(after) || before->clock.utc_unix_s != after->clock.utc_unix_s ||
           before->clock.time_scale != after->clock.time_scale;
}

bool world_sim_wind_changed(const struct proto_world_state *before,
                            const struct proto_world_state *after)
{
    const struct proto_weather_state *b = &before->weather, *a = &after->weather;
    struct proto_weather_params pb, pa;
    proto_weather_params_get(before, &pb);
    proto_weather_params_get(after, &pa);
    return before->clock.utc_unix_s != after->clock.utc_unix_s ||
           b->offset_east_km != a->offset_east_km || b->offset_north_km != a->offset_north_km ||
           memcmp(&pb, &pa, sizeof pb) != 0 ||
           memcmp(&b->transition, &a->transition, sizeof b->transition) != 0 ||
           b->autopilot != a->autopilot || b->autopilot_seed != a->autopilot_seed ||
           before->location.longitude_deg != after->location.longitude_deg;
}

void world_sim_commit(const struct proto_world_state *before, struct proto_world_state *after,
                      double wall_s, struct wind_drift *drift)
{
    if (world_sim_clock_changed(before, after)) {
        world_sim_anchor(after, wall_s);
        wind_drift_forget(drift);
    } else if (world_sim_wind_changed(before, after)) {
        world_sim_anchor_wind(after);
        wind_drift_forget(drift);
    }
    world_sim_run_to(after, wall_s, drift);
}

void world_sim_set_time(struct proto_world_state *state, double utc_s, struct wind_drift *drift)
{
    double t = clamp(utc_s, UTC_MIN_S, UTC_MAX_S);
    /* The offsets first: the wind's integral reads the weather of the state as it was. */
    wind_drift_offsets(drift, state, t, &state->weather.offset_east_km,
                       &state->weather.offset_north_km);
    state->clock.utc_unix_s = t;
    world_sim_settle(state);
}

void world_sim_run_to(struct proto_world_state *state, double wall_s, struct wind_drift *drift)
{
    world_sim_set_time(state, world_sim_clock_at(state, wall_s), drift);
}

void world_sim_advance(struct proto_world_state *state, double sim_dt_s)
{
    world_sim_set_time(state, state->clock.utc_unix_s + (sim_dt_s > 0.0 ? sim_dt_s : 0.0), NULL);
}

void world_sim_settle(struct proto_world_state *state)
{
    weather_timeline_settle(state);
    update_sky_bodies(state);
}

void world_sim_start_transition(struct proto_world_state *state,
                                const struct proto_weather_params *target, double duration_s)
{
    struct proto_transition_state *t = &state->weather.transition;
    proto_weather_params_get(state, &t->from);
    t->to = *target;
    t->start_unix_s = time_kept(state->clock.utc_unix_s);
    if (duration_s > 0.0) {
        t->duration_s = duration_s;
        t->progress = 0.0;
    } else {
        t->duration_s = 0.0;
        t->progress = 1.0;
        proto_weather_params_put(state, target);
    }
}

/* ---- client changes ----------------------------------------------------------------------- */

static const char *const ephemeris_fields[] = {
    "sun.azimuth_deg",
    "sun.elevation_deg",
    "moon.azimuth_deg",
    "moon.elevation_deg",
};

/* The schema paths of struct proto_weather_params, in its member order. */
static const char *const weather_fields[] = {
    "clouds.low.coverage",
    "clouds.low.type",
    "clouds.low.density",
    "clouds.low.bottom_km",
    "clouds.low.thickness_km",
    "clouds.mid.coverage",
    "clouds.mid.type",
    "clouds.mid.density",
    "clouds.mid.bottom_km",
    "clouds.mid.thickness_km",
    "clouds.high.coverage",
    "clouds.high.type",
    "clouds.high.density",
    "clouds.high.bottom_km",
    "clouds.high.thickness_km",
    "clouds.precipitation",
    "weather.humidity",
    "weather.wind.speed_m_s",
    "weather.wind.direction_deg",
};
_Static_assert(sizeof weather_fields / sizeof weather_fields[0] == WEATHER_PARAM_COUNT,
               "one path per weather parameter");

static bool listed(const char *path, const char *const *list, size_t count)
{
    for (size_t i = 0; i < count; i++)
        if (strcmp(path, list[i]) == 0)
            return true;
    return false;
}

bool world_sim_check_client_patch(const struct proto_world_state *before,
                                  const struct proto_world_state *after,
                                  const struct proto_world_patch *patch,
                                  struct proto_field_errors *errors)
{
    size_t count;
    const struct proto_field_desc *fields = proto_world_state_fields(&count);
    int failures = 0;
    for (size_t i = 0; i < count; i++) {
        const struct proto_field_desc *f = &fields[i];
        if (memcmp((const char *)before + f->offset, (const char *)after + f->offset,
                   proto_field_size(f)) == 0 ||
            !proto_world_patch_names(patch, f))
            continue;
        char pointer[128];
        proto_field_pointer(f, pointer, sizeof pointer);
        if (f->read_only) {
            proto_field_errors_add(errors, PROTO_FIELD_BAD_VALUE, pointer,
                                   "read-only: kept by the simulation (apply_preset with "
                                   "transition_s starts a weather transition)");
        } else if (after->clock.sky_bodies == PROTO_BODIES_EPHEMERIS &&
                   listed(f->path, ephemeris_fields,
                          sizeof ephemeris_fields / sizeof *ephemeris_fields)) {
            proto_field_errors_add(errors, PROTO_FIELD_INCONSISTENT, pointer,
                                   "follows the ephemeris while clock.sky_bodies is \"ephemeris\"; "
                                   "set clock.sky_bodies to \"manual\" in the same patch");
        } else if (after->weather.autopilot == PROTO_SWITCH_ON &&
                   listed(f->path, weather_fields, WEATHER_PARAM_COUNT)) {
            proto_field_errors_add(errors, PROTO_FIELD_INCONSISTENT, pointer,
                                   "driven by the autopilot while weather.autopilot is \"on\"; "
                                   "set weather.autopilot to \"off\" in the same patch");
        } else {
            continue;
        }
        failures++;
    }
    return failures == 0;
}

void world_sim_client_changed(const struct proto_world_state *before,
                              struct proto_world_state *after)
{
    struct proto_transition_state *t = &after->weather.transition;
    bool was_on = before->weather.autopilot == PROTO_SWITCH_ON;
    bool is_on = after->weather.autopilot == PROTO_SWITCH_ON;
    if (is_on && (!was_on || before->weather.autopilot_seed != after->weather.autopilot_seed)) {
        struct proto_weather_params end;
        weather_autopilot_sample(after->weather.autopilot_seed,
                                 after->clock.utc_unix_s + WORLD_SIM_AUTOPILOT_BLEND_S,
                                 after->location.longitude_deg, &end);
        world_sim_start_transition(after, &end, WORLD_SIM_AUTOPILOT_BLEND_S);
    } else if (was_on && !is_on && weather_timeline_active(after)) {
        /* Switched off mid-blend: the weather stays where it is, and the blend ends now. */
        proto_weather_params_get(after, &t->to);
        t->duration_s = fmax(after->clock.utc_unix_s - t->start_unix_s, 0.0);
        t->progress = 1.0;
    } else if (!weather_timeline_mid_blend(before) && before->weather.transition.duration_s > 0.0 &&
               weather_timeline_active(after)) {
        /* The clock set back into a transition that had ended: the weather stays. */
        t->duration_s = 0.0;
        t->progress = 1.0;
    } else if (weather_timeline_active(after)) {
        weather_timeline_hold(before, after);
    }
    if (world_sim_wind_changed(before, after))
        world_sim_anchor_wind(after);
    world_sim_settle(after);
}
