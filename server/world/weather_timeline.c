#include "weather_timeline.h"

#include <math.h>
#include <stddef.h>

#include "weather_autopilot.h"

_Static_assert(sizeof(struct proto_weather_params) == 19 * sizeof(double),
               "weather parameters are 19 doubles");
#define DIRECTION_INDEX (offsetof(struct proto_weather_params, wind_direction_deg) / sizeof(double))

static double clamp(double x, double lo, double hi)
{
    return x < lo ? lo : x > hi ? hi : x;
}

static double *params_array(struct proto_weather_params *p)
{
    return (double *)p;
}

static const double *const_params_array(const struct proto_weather_params *p)
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

/* Time fraction of the transition at unix_s, in [0, 1]. */
static double transition_fraction(const struct proto_transition_state *t, double unix_s)
{
    return clamp((unix_s - t->start_unix_s) / t->duration_s, 0.0, 1.0);
}

/* Whether the transition blends the weather at unix_s (a time before its start counts: it
 * shows its start values there). */
static bool blending_at(const struct proto_transition_state *t, double unix_s)
{
    return t->duration_s > 0.0 && transition_fraction(t, unix_s) < 1.0;
}

static bool mid_blend(const struct proto_transition_state *t)
{
    return t->duration_s > 0.0 && t->progress < 1.0;
}

bool weather_timeline_active(const struct proto_world_state *state)
{
    return blending_at(&state->weather.transition, state->clock.utc_unix_s);
}

bool weather_timeline_mid_blend(const struct proto_world_state *state)
{
    return mid_blend(&state->weather.transition);
}

void weather_timeline_mix(const struct proto_weather_params *from,
                          const struct proto_weather_params *to, double s,
                          struct proto_weather_params *out)
{
    s = clamp(s, 0.0, 1.0);
    double eased = s * s * (3.0 - 2.0 * s); /* smoothstep: monotonic, flat at both ends */
    const double *a = const_params_array(from), *b = const_params_array(to);
    struct proto_weather_params mixed;
    double *m = params_array(&mixed);
    for (size_t i = 0; i < WEATHER_PARAM_COUNT; i++) {
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

void weather_timeline_at(const struct proto_world_state *state, double unix_s,
                         struct proto_weather_params *out)
{
    const struct proto_transition_state *t = &state->weather.transition;
    bool autopilot = state->weather.autopilot == PROTO_SWITCH_ON;
    struct proto_weather_params target;
    if (autopilot)
        weather_autopilot_sample(state->weather.autopilot_seed, unix_s,
                                 state->location.longitude_deg, &target);
    else
        target = t->to;
    if (blending_at(t, unix_s))
        weather_timeline_mix(&t->from, &target, transition_fraction(t, unix_s), out);
    else if (autopilot)
        *out = target;
    else if (mid_blend(t))
        *out = t->to; /* it ends between the state's clock and unix_s */
    else
        proto_weather_params_get(state, out);
}

void weather_timeline_settle(struct proto_world_state *state)
{
    struct proto_transition_state *t = &state->weather.transition;
    double now_s = state->clock.utc_unix_s;
    bool autopilot = state->weather.autopilot == PROTO_SWITCH_ON;
    if (!autopilot && !mid_blend(t) && !blending_at(t, now_s))
        return; /* the parameters are the state's own */
    struct proto_weather_params now;
    weather_timeline_at(state, now_s, &now); /* before progress moves: it reads it */
    if (t->duration_s > 0.0)
        t->progress = transition_fraction(t, now_s);
    proto_weather_params_put(state, &now);
}

void weather_timeline_hold(const struct proto_world_state *before, struct proto_world_state *after)
{
    struct proto_transition_state *t = &after->weather.transition;
    struct proto_weather_params old_values, new_values;
    proto_weather_params_get(before, &old_values);
    proto_weather_params_get(after, &new_values);
    const double *o = const_params_array(&old_values), *n = const_params_array(&new_values);
    double *from = params_array(&t->from), *to = params_array(&t->to);
    for (size_t i = 0; i < WEATHER_PARAM_COUNT; i++) {
        if (o[i] != n[i])
            from[i] = to[i] = n[i];
    }
}
