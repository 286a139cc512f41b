/* The weather map's drift: weather.offset_* at a simulated time, as a pure function of the
 * state's wind anchor (weather.anchor) and of the weather over time (the transition's, the
 * autopilot's or the state's own wind). From the anchor's time, the simulated time is cut at
 * every multiple of WIND_DRIFT_CELL_S; each whole cell adds the wind at its midpoint times its
 * length, in order, wrapping within +-WIND_DRIFT_OFFSET_LIMIT_KM, and the last, partial cell is
 * added on top. The cells do not depend on the times asked for, so any sequence of questions gets
 * bit-identical answers.
 *
 * A wind_drift only remembers the running sum at the last cell boundary reached, so a clock
 * that moves forward costs the cells it crosses rather than every cell since the anchor. It
 * holds no state of the world: forget it, or not, the answers are the same. */
#ifndef SKYD_WIND_DRIFT_H
#define SKYD_WIND_DRIFT_H

#include "world_state.h"

#define WIND_DRIFT_CELL_S 60.0
/* weather.offset_* wrap within +-this (the field's range). */
#define WIND_DRIFT_OFFSET_LIMIT_KM 1e6

struct wind_drift;

struct wind_drift *wind_drift_create(void);
void wind_drift_destroy(struct wind_drift **drift);

/* Drops the running sum (the state was replaced, or its wind re-anchored). */
void wind_drift_forget(struct wind_drift *drift);

/* weather.offset_east_km and offset_north_km of `state` at simulated time utc_s. Before the
 * anchor's time the cells are summed backwards from the anchor. drift may be NULL. */
void wind_drift_offsets(struct wind_drift *drift, const struct proto_world_state *state,
                        double utc_s, double *east_km, double *north_km);

/* How many cells the last call summed (for tests of the running sum). */
long wind_drift_cells_summed(const struct wind_drift *drift);

#endif
