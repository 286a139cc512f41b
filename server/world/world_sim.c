#include "world_sim.h"

#include <cjson/cJSON.h>

#include <math.h>
#include <stddef.h>
#include <stdio.h>
#include <string.h>

#include "ephemeris.h"
#include "weather_autopilot.h"

static const double DEG_TO_RAD = 3.14159265358979323846 / 180.0;

/* clock.utc's range in the schema: 1900-01-01 to 2100-12-31T23:59:59Z. */
#define UTC_MIN_S -2208988800.0
#define UTC_MAX_S 4133980799.0

#define PARAM_COUNT (sizeof(struct sky_weather_params) / sizeof(double))
_Static_assert(sizeof(struct sky_weather_params) == 14 * sizeof(double),
               "weather parameters are 14 doubles");
#define DIRECTION_INDEX (offsetof(struct sky_weather_params, wind_direction_deg) / sizeof(double))

static double clamp(double x, double lo, double hi)
{
    return x < lo ? lo : x > hi ? hi : x;
}

static double *params_array(struct sky_weather_params *p)
{
    return (double *)p;
}

static const double *const_params_array(const struct sky_weather_params *p)
{
    return (const double *)p;
}

static double wrap_degrees(double deg)
{
    double d = fmod(deg, 360.0);
    if (d < 0.0)
        d += 360.0;
    return d >= 360.0 ? 0.0 : d;
}

double world_sim_scaled_dt(const struct sky_world_state *state, double real_dt_s)
{
    if (!(real_dt_s > 0.0))
        return 0.0;
    return real_dt_s * state->clock.time_scale;
}

bool world_sim_transition_active(const struct sky_world_state *state)
{
    const struct sky_transition_state *t = &state->weather.transition;
    return t->duration_s > 0.0 && t->progress < 1.0;
}

void world_sim_mix_weather(const struct sky_weather_params *from,
                           const struct sky_weather_params *to, double s,
                           struct sky_weather_params *out)
{
    s = clamp(s, 0.0, 1.0);
    double eased = s * s * (3.0 - 2.0 * s); /* smoothstep: monotonic, flat at both ends */
    const double *a = const_params_array(from), *b = const_params_array(to);
    struct sky_weather_params mixed;
    double *m = params_array(&mixed);
    for (size_t i = 0; i < PARAM_COUNT; i++) {
        /* Exact at eased = 0 and 1; in between, rounding can put the blend one ulp outside
         * its two ends (5 and 5 giving 5.000000000000001), past the field's range when they
         * sit at its bound, so it is kept between them. */
        double mixed_value = a[i] * (1.0 - eased) + b[i] * eased;
        m[i] = fmin(fmax(mixed_value, fmin(a[i], b[i])), fmax(a[i], b[i]));
    }
    double arc = fmod(b[DIRECTION_INDEX] - a[DIRECTION_INDEX] + 540.0, 360.0) - 180.0;
    m[DIRECTION_INDEX] = eased >= 1.0 ? b[DIRECTION_INDEX]
                                      : wrap_degrees(a[DIRECTION_INDEX] + arc * eased);
    *out = mixed;
}

/* Time fraction of the transition at unix_s, in [0, 1]. */
static double transition_fraction(const struct sky_transition_state *t, double unix_s)
{
    return clamp((unix_s - t->start_unix_s) / t->duration_s, 0.0, 1.0);
}

void world_sim_weather_at(const struct sky_world_state *state, double unix_s,
                          struct sky_weather_params *out)
{
    const struct sky_transition_state *t = &state->weather.transition;
    bool autopilot = state->weather.autopilot == SKY_SWITCH_ON;
    struct sky_weather_params target;
    if (autopilot)
        weather_autopilot_sample(state->weather.autopilot_seed, unix_s,
                                 state->location.longitude_deg, &target);
    else
        target = t->to;
    if (world_sim_transition_active(state))
        world_sim_mix_weather(&t->from, &target, transition_fraction(t, unix_s), out);
    else if (autopilot)
        *out = target;
    else
        sky_weather_params_get(state, out);
}

static double wrap_offset(double km)
{
    if (km > WORLD_SIM_OFFSET_LIMIT_KM || km < -WORLD_SIM_OFFSET_LIMIT_KM)
        km -= 2.0 * WORLD_SIM_OFFSET_LIMIT_KM * floor((km + WORLD_SIM_OFFSET_LIMIT_KM) /
                                                      (2.0 * WORLD_SIM_OFFSET_LIMIT_KM));
    return km;
}

/* Moves the weather map downwind: the wind blows from direction_deg, so the map moves toward
 * direction_deg + 180. */
static void advect(struct sky_world_state *state, double speed_m_s, double from_deg, double dt_s)
{
    double to_rad = (from_deg + 180.0) * DEG_TO_RAD;
    double distance_km = speed_m_s * dt_s / 1000.0;
    state->weather.offset_east_km = wrap_offset(state->weather.offset_east_km +
                                                distance_km * sin(to_rad));
    state->weather.offset_north_km = wrap_offset(state->weather.offset_north_km +
                                                 distance_km * cos(to_rad));
}

static void update_sky_bodies(struct sky_world_state *state)
{
    if (state->clock.sky_bodies != SKY_BODIES_EPHEMERIS)
        return;
    struct sky_site site = { state->location.latitude_deg, state->location.longitude_deg,
                             state->location.altitude_m, SKY_SITE_PRESSURE_MBAR,
                             SKY_SITE_TEMPERATURE_C };
    struct sky_body_position sun, moon;
    sky_sun_position(state->clock.utc_unix_s, &site, true, &sun);
    sky_moon_position(state->clock.utc_unix_s, &site, true, &moon, NULL, NULL);
    state->sun.azimuth_deg = wrap_degrees(sun.azimuth_deg);
    state->sun.elevation_deg = clamp(sun.elevation_deg, -90.0, 90.0);
    state->moon.azimuth_deg = wrap_degrees(moon.azimuth_deg);
    state->moon.elevation_deg = clamp(moon.elevation_deg, -90.0, 90.0);
}

static void update_weather(struct sky_world_state *state)
{
    struct sky_transition_state *t = &state->weather.transition;
    bool transition = world_sim_transition_active(state);
    if (!transition && state->weather.autopilot != SKY_SWITCH_ON)
        return;
    struct sky_weather_params now;
    world_sim_weather_at(state, state->clock.utc_unix_s, &now);
    if (transition) {
        t->progress = transition_fraction(t, state->clock.utc_unix_s);
        if (t->progress >= 1.0) {
            t->progress = 1.0;
            if (state->weather.autopilot != SKY_SWITCH_ON)
                now = t->to; /* the end values, exactly */
        }
    }
    sky_weather_params_put(state, &now);
}

void world_sim_advance(struct sky_world_state *state, double sim_dt_s)
{
    double remaining = sim_dt_s > 0.0 ? sim_dt_s : 0.0;
    while (remaining > 0.0 && state->clock.utc_unix_s < UTC_MAX_S) {
        double step = remaining < WORLD_SIM_MAX_SUBSTEP_S ? remaining : WORLD_SIM_MAX_SUBSTEP_S;
        double start = state->clock.utc_unix_s;
        step = fmin(step, UTC_MAX_S - start);
        /* Midpoint rule: second-order in the step for a wind that changes with time. */
        struct sky_weather_params mid;
        world_sim_weather_at(state, start + 0.5 * step, &mid);
        advect(state, mid.wind_speed_m_s, mid.wind_direction_deg, step);
        state->clock.utc_unix_s = start + step;
        remaining -= step;
    }
    state->clock.utc_unix_s = clamp(state->clock.utc_unix_s, UTC_MIN_S, UTC_MAX_S);
    update_weather(state);
    update_sky_bodies(state);
}

void world_sim_settle(struct sky_world_state *state)
{
    world_sim_advance(state, 0.0);
}

void world_sim_start_transition(struct sky_world_state *state,
                                const struct sky_weather_params *target, double duration_s)
{
    struct sky_transition_state *t = &state->weather.transition;
    sky_weather_params_get(state, &t->from);
    t->to = *target;
    t->start_unix_s = state->clock.utc_unix_s;
    if (duration_s > 0.0) {
        t->duration_s = duration_s;
        t->progress = 0.0;
    } else {
        t->duration_s = 0.0;
        t->progress = 1.0;
        sky_weather_params_put(state, target);
    }
}

/* ---- client changes ----------------------------------------------------------------------- */

static const char *const ephemeris_fields[] = {
    "sun.azimuth_deg", "sun.elevation_deg", "moon.azimuth_deg", "moon.elevation_deg",
};

/* The schema paths of struct sky_weather_params, in its member order. */
static const char *const weather_fields[] = {
    "clouds.low.coverage",  "clouds.low.type",         "clouds.low.density",
    "clouds.low.bottom_km", "clouds.low.thickness_km", "clouds.high.coverage",
    "clouds.high.type",     "clouds.high.density",     "clouds.high.bottom_km",
    "clouds.high.thickness_km", "clouds.precipitation", "weather.humidity",
    "weather.wind.speed_m_s",   "weather.wind.direction_deg",
};
_Static_assert(sizeof weather_fields / sizeof weather_fields[0] == PARAM_COUNT,
               "one path per weather parameter");

static bool listed(const char *path, const char *const *list, size_t count)
{
    for (size_t i = 0; i < count; i++)
        if (strcmp(path, list[i]) == 0)
            return true;
    return false;
}

bool world_sim_check_client_patch(const struct sky_world_state *before,
                                  const struct sky_world_state *after,
                                  const struct sky_world_patch *patch,
                                  struct sky_field_errors *errors)
{
    size_t count;
    const struct sky_field_desc *fields = sky_world_state_fields(&count);
    int failures = 0;
    for (size_t i = 0; i < count; i++) {
        const struct sky_field_desc *f = &fields[i];
        if (memcmp((const char *)before + f->offset, (const char *)after + f->offset,
                   sky_field_size(f)) == 0 || !sky_world_patch_names(patch, f))
            continue;
        char pointer[128];
        sky_field_pointer(f, pointer, sizeof pointer);
        if (f->read_only) {
            sky_field_errors_add(errors, SKY_FIELD_BAD_VALUE, pointer,
                                 "read-only: kept by the simulation (apply_preset with "
                                 "transition_s starts a weather transition)");
        } else if (after->clock.sky_bodies == SKY_BODIES_EPHEMERIS &&
                   listed(f->path, ephemeris_fields, sizeof ephemeris_fields / sizeof *ephemeris_fields)) {
            sky_field_errors_add(errors, SKY_FIELD_INCONSISTENT, pointer,
                                 "follows the ephemeris while clock.sky_bodies is \"ephemeris\"; "
                                 "set clock.sky_bodies to \"manual\" in the same patch");
        } else if (after->weather.autopilot == SKY_SWITCH_ON &&
                   listed(f->path, weather_fields, PARAM_COUNT)) {
            sky_field_errors_add(errors, SKY_FIELD_INCONSISTENT, pointer,
                                 "driven by the autopilot while weather.autopilot is \"on\"; "
                                 "set weather.autopilot to \"off\" in the same patch");
        } else {
            continue;
        }
        failures++;
    }
    return failures == 0;
}

void world_sim_client_changed(const struct sky_world_state *before,
                              struct sky_world_state *after)
{
    struct sky_transition_state *t = &after->weather.transition;
    bool was_on = before->weather.autopilot == SKY_SWITCH_ON;
    bool is_on = after->weather.autopilot == SKY_SWITCH_ON;
    if (is_on && (!was_on || before->weather.autopilot_seed != after->weather.autopilot_seed)) {
        struct sky_weather_params end;
        weather_autopilot_sample(after->weather.autopilot_seed,
                                 after->clock.utc_unix_s + WORLD_SIM_AUTOPILOT_BLEND_S,
                                 after->location.longitude_deg, &end);
        world_sim_start_transition(after, &end, WORLD_SIM_AUTOPILOT_BLEND_S);
    } else if (was_on && !is_on && world_sim_transition_active(after)) {
        /* Switched off mid-blend: the weather stays where it is. */
        sky_weather_params_get(after, &t->to);
        t->progress = 1.0;
    } else if (world_sim_transition_active(after)) {
        struct sky_weather_params old_values, new_values;
        sky_weather_params_get(before, &old_values);
        sky_weather_params_get(after, &new_values);
        const double *o = const_params_array(&old_values), *n = const_params_array(&new_values);
        double *from = params_array(&t->from), *to = params_array(&t->to);
        for (size_t i = 0; i < PARAM_COUNT; i++) {
            if (o[i] != n[i])
                from[i] = to[i] = n[i]; /* a value set during a transition holds */
        }
    }
    world_sim_settle(after);
}
