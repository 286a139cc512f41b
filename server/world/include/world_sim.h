/* The world simulation: the world state as a function of time.
 *
 * - The clock is an epoch (clock.epoch: the simulated time at a wall-clock instant) and the
 *   time scale: the simulated time at wall instant w is epoch.utc + (w - epoch.wall) x
 *   time_scale (world_sim_clock_at), so every node holding the state reads the same clock,
 *   however often it ticks and whenever it started. A time scale of 0 pauses it.
 * - With clock.sky_bodies "ephemeris", sun.* and moon.* azimuth and elevation follow the
 *   clock and location: apparent (refracted, 1010 mbar, 10 C) topocentric positions.
 * - A weather transition (weather.transition.*) moves the 14 weather parameters
 *   (struct proto_weather_params) from its start values to its end values along a smoothstep of
 *   the simulated time; the end values are hit exactly at the end.
 * - The weather autopilot (weather.autopilot on) drives the same parameters from
 *   weather_autopilot_sample(); a transition under way blends into it. Both are the weather
 *   over time of server/world's weather_timeline.c.
 * - The wind advects the weather map: weather.offset_* grow downwind by speed x time
 *   (direction_deg is where the wind blows from). The offsets at simulated time t are those of
 *   weather.anchor plus the wind integrated from the anchor's time to t over cells bounded by
 *   the multiples of WIND_DRIFT_CELL_S of simulated time (midpoint rule in each), summed in
 *   order (wind_drift.h).
 *
 * Everything is a function of the state as last changed by a client (its anchors) and the
 * simulated time, bit for bit: any split of a time span into ticks, and a state read back from
 * its JSON at any later moment, give the same state at the same instant. Pure: no I/O, no
 * globals; the wall-clock time is an argument.
 */
#ifndef SKYD_WORLD_SIM_H
#define SKYD_WORLD_SIM_H

#include <stdbool.h>

#include "world_state.h"

struct cJSON;
struct wind_drift;

/* When the autopilot is switched on (or reseeded), the weather blends into it over this. */
#define WORLD_SIM_AUTOPILOT_BLEND_S 900.0

/* Whether the clock has an epoch (clock.epoch.wall is not 0). */
bool world_sim_anchored(const struct proto_world_state *state);

/* The simulated time at wall instant wall_s (CLOCK_REALTIME, unix seconds) by the state's
 * epoch, within clock.utc's range; clock.utc itself when the clock is not anchored. */
double world_sim_clock_at(const struct proto_world_state *state, double wall_s);

/* The state as it is becomes the anchor of everything at wall instant wall_s: the clock's
 * epoch (wall_s and clock.utc, both to the millisecond, the clock keeping its pace) and the
 * wind's anchor. clock.utc becomes the epoch's reading at wall_s. */
void world_sim_anchor(struct proto_world_state *state, double wall_s);

/* The wind's anchor only: weather.anchor becomes clock.utc (to the millisecond) and the
 * offsets as they are. */
void world_sim_anchor_wind(struct proto_world_state *state);

/* Whether a change from before to after needs new anchors: the clock's (clock.utc or
 * time_scale changed, or no epoch yet) and the wind's (the clock, the offsets, the weather
 * parameters, the transition, the autopilot, or the longitude it samples changed). */
bool world_sim_clock_changed(const struct proto_world_state *before,
                             const struct proto_world_state *after);
bool world_sim_wind_changed(const struct proto_world_state *before,
                            const struct proto_world_state *after);

/* After a committed change (before: the live state, after: the change, at wall instant
 * wall_s): new anchors where world_sim_*_changed says so, then the state brought to wall_s.
 * A state not yet anchored is anchored. */
void world_sim_commit(const struct proto_world_state *before, struct proto_world_state *after,
                      double wall_s, struct wind_drift *drift);

/* Brings the state to simulated time utc_s (clamped to clock.utc's range): clock.utc, the
 * offsets from the wind's anchor, and everything the simulation drives. drift (may be NULL)
 * remembers the wind's running sum between calls. Does not touch the revision or anchors. */
void world_sim_set_time(struct proto_world_state *state, double utc_s, struct wind_drift *drift);

/* world_sim_set_time at world_sim_clock_at(state, wall_s): the state at a wall instant. */
void world_sim_run_to(struct proto_world_state *state, double wall_s, struct wind_drift *drift);

/* world_sim_set_time at clock.utc + sim_dt_s (sim_dt_s < 0 counts as 0), without a drift:
 * for offline time-lapses. */
void world_sim_advance(struct proto_world_state *state, double sim_dt_s);

/* The driven fields (transition progress, driven weather, sun and moon) brought in line with
 * the state's clock as it is; the offsets are left alone. */
void world_sim_settle(struct proto_world_state *state);

/* Starts a transition from the state's weather to target's over duration_s simulated
 * seconds, from clock.utc to the millisecond. duration_s 0 applies target's weather at once.
 * Other fields are not touched. */
void world_sim_start_transition(struct proto_world_state *state,
                                const struct proto_weather_params *target, double duration_s);

/* The rules of a client `set` beyond the schema, checked on the applied result: a field the
 * patch names may not change when it is read-only, driven by the ephemeris (sun and moon
 * angles while clock.sky_bodies is "ephemeris" after the patch) or by the autopilot (the
 * weather parameters while weather.autopilot is "on" after the patch). Naming such a field
 * with its current value is allowed, so a state read with `get` can be sent back. Pointers
 * are relative to the patch. */
bool world_sim_check_client_patch(const struct proto_world_state *before,
                                  const struct proto_world_state *after,
                                  const struct proto_world_patch *patch,
                                  struct proto_field_errors *errors);

/* Follows an accepted client change (before -> after): a weather parameter set during a
 * transition holds its new value for the rest of it; the autopilot switched on or reseeded
 * blends in over WORLD_SIM_AUTOPILOT_BLEND_S; switched off, the weather stays and a blend
 * under way ends there; a clock set back into a finished transition does not replay it. Then
 * the wind is re-anchored when world_sim_wind_changed says so, and the driven fields are
 * settled. */
void world_sim_client_changed(const struct proto_world_state *before,
                              struct proto_world_state *after);

#endif
