/* The weather parameters (struct proto_weather_params) over simulated time: a transition's
 * smoothstep blend from its start values to its end values, the autopilot's weather, or the
 * state's own. The simulation (world_sim.c) settles a state's weather with it and the wind's
 * integral (wind_drift.c) samples it; it depends on neither. Internal to server/world. */
#ifndef SKYD_WEATHER_TIMELINE_H
#define SKYD_WEATHER_TIMELINE_H

#include <stdbool.h>

#include "world_state.h"

#define WEATHER_PARAM_COUNT (sizeof(struct proto_weather_params) / sizeof(double))

/* The weather parameters at simulated time unix_s: the transition's or the autopilot's, or
 * the state's own when neither drives them (the transition's end values when it ends after
 * the state's clock). Depends only on what a client last changed, not on how far the state
 * has run, so any later state of the same anchor gives the same answer. */
void weather_timeline_at(const struct proto_world_state *state, double unix_s,
                         struct proto_weather_params *out);

/* smoothstep(0, 1, x) blend of two parameter sets; the wind direction along the shorter arc.
 * s = 0 gives from and s = 1 gives to exactly. */
void weather_timeline_mix(const struct proto_weather_params *from,
                          const struct proto_weather_params *to, double s,
                          struct proto_weather_params *out);

/* True when a transition is under way at the state's clock: its time fraction is below 1. */
bool weather_timeline_active(const struct proto_world_state *state);

/* True when the state's own weather parameters are still a blend: its transition had not
 * ended by its clock when it was last settled. */
bool weather_timeline_mid_blend(const struct proto_world_state *state);

/* The state's weather parameters and transition progress brought to its clock. */
void weather_timeline_settle(struct proto_world_state *state);

/* During a transition, a weather parameter that a change (before -> after) set holds its new
 * value for the rest of it: both ends of the transition take it. */
void weather_timeline_hold(const struct proto_world_state *before, struct proto_world_state *after);

#endif
