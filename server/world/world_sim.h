/* The world simulation: what happens to the world state as simulated time passes.
 *
 * - The clock (clock.utc) advances by simulated seconds; the daemon passes real elapsed time
 *   times clock.time_scale.
 * - With clock.sky_bodies "ephemeris", sun.* and moon.* azimuth and elevation follow the
 *   clock and location: apparent (refracted, 1010 mbar, 10 C) topocentric positions.
 * - A weather transition (weather.transition.*) moves the 14 weather parameters
 *   (struct sky_weather_params) from its start values to its end values along a smoothstep of
 *   the simulated time; the end values are hit exactly at the end.
 * - The weather autopilot (weather.autopilot on) drives the same parameters from
 *   weather_autopilot_sample(); a transition under way blends into it.
 * - The wind advects the weather map: weather.offset_* grow downwind by speed x time
 *   (direction_deg is where the wind blows from).
 *
 * Everything is a function of the state and the simulated time, so any split of a time span
 * into steps gives the same state (the wind offset to the accuracy of its midpoint
 * integration over sub-steps of at most WORLD_SIM_MAX_SUBSTEP_S). Pure: no I/O, no globals.
 */
#ifndef SKYD_WORLD_SIM_H
#define SKYD_WORLD_SIM_H

#include <stdbool.h>

#include "world_state.h"

struct cJSON;

#define WORLD_SIM_MAX_SUBSTEP_S 60.0
/* When the autopilot is switched on (or reseeded), the weather blends into it over this. */
#define WORLD_SIM_AUTOPILOT_BLEND_S 900.0
/* weather.offset_* wrap within +-this (the field's range). */
#define WORLD_SIM_OFFSET_LIMIT_KM 1e6

/* Simulated seconds for real_dt_s real seconds at the state's time scale. */
double world_sim_scaled_dt(const struct sky_world_state *state, double real_dt_s);

/* Advances the state by sim_dt_s >= 0 simulated seconds, then updates everything the
 * simulation drives at the new time. The clock stops at the end of clock.utc's range. Does
 * not touch the revision. */
void world_sim_advance(struct sky_world_state *state, double sim_dt_s);

/* world_sim_advance(state, 0): the driven fields brought in line with the state as it is. */
void world_sim_settle(struct sky_world_state *state);

/* True when a transition is under way. */
bool world_sim_transition_active(const struct sky_world_state *state);

/* The weather parameters the simulation gives at simulated time unix_s: the transition's
 * or the autopilot's, or the state's own when neither drives them. */
void world_sim_weather_at(const struct sky_world_state *state, double unix_s,
                          struct sky_weather_params *out);

/* Starts a transition from the state's weather to target's over duration_s simulated
 * seconds. duration_s 0 applies target's weather at once. Other fields are not touched. */
void world_sim_start_transition(struct sky_world_state *state,
                                const struct sky_weather_params *target, double duration_s);

/* smoothstep(0, 1, x) blend of two parameter sets; the wind direction along the shorter arc.
 * s = 0 gives from and s = 1 gives to exactly. */
void world_sim_mix_weather(const struct sky_weather_params *from,
                           const struct sky_weather_params *to, double s,
                           struct sky_weather_params *out);

/* The rules of a client `set` beyond the schema, checked on the applied result: a field the
 * patch names may not change when it is read-only, driven by the ephemeris (sun and moon
 * angles while clock.sky_bodies is "ephemeris" after the patch) or by the autopilot (the
 * weather parameters while weather.autopilot is "on" after the patch). Naming such a field
 * with its current value is allowed, so a state read with `get` can be sent back. Pointers
 * are relative to the patch. */
bool world_sim_check_client_patch(const struct sky_world_state *before,
                                  const struct sky_world_state *after,
                                  const struct sky_world_patch *patch,
                                  struct sky_field_errors *errors);

/* Follows an accepted client change (before -> after): a weather parameter set during a
 * transition holds its new value for the rest of it; the autopilot switched on or reseeded
 * blends in over WORLD_SIM_AUTOPILOT_BLEND_S; then the driven fields are settled. */
void world_sim_client_changed(const struct sky_world_state *before,
                              struct sky_world_state *after);

#endif
