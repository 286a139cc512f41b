#include "wind_drift.h"

#include <math.h>
#include <stdbool.h>
#include <stdlib.h>

#include "weather_timeline.h"

static const double DEG_TO_RAD = 3.14159265358979323846 / 180.0;

struct wind_drift {
    bool valid;
    struct proto_wind_anchor anchor; /* the anchor the running sum starts from */
    double at_s;                     /* a cell boundary at or after the anchor's time */
    double east_km, north_km;        /* the offsets there */
    long cells;                      /* summed by the last call */
};

struct wind_drift *wind_drift_create(void)
{
    return calloc(1, sizeof(struct wind_drift));
}

void wind_drift_destroy(struct wind_drift **drift)
{
    if (drift) {
        free(*drift);
        *drift = NULL;
    }
}

void wind_drift_forget(struct wind_drift *drift)
{
    if (drift)
        drift->valid = false;
}

long wind_drift_cells_summed(const struct wind_drift *drift)
{
    return drift ? drift->cells : 0;
}

static double wrap_offset(double km)
{
    if (km > WIND_DRIFT_OFFSET_LIMIT_KM || km < -WIND_DRIFT_OFFSET_LIMIT_KM)
        km -= 2.0 * WIND_DRIFT_OFFSET_LIMIT_KM *
              floor((km + WIND_DRIFT_OFFSET_LIMIT_KM) / (2.0 * WIND_DRIFT_OFFSET_LIMIT_KM));
    return km;
}

/* Adds the wind's displacement from simulated time `from` to `to` (either order): the wind at
 * the midpoint blows from direction_deg, so the map moves toward direction_deg + 180. */
static void add_cell(const struct proto_world_state *state, double from, double to, double *east,
                     double *north)
{
    struct proto_weather_params mid;
    weather_timeline_at(state, from + 0.5 * (to - from), &mid);
    double to_rad = (mid.wind_direction_deg + 180.0) * DEG_TO_RAD;
    double distance_km = mid.wind_speed_m_s * (to - from) / 1000.0;
    *east = wrap_offset(*east + distance_km * sin(to_rad));
    *north = wrap_offset(*north + distance_km * cos(to_rad));
}

/* The first multiple of the cell length after t, and the last one before it. */
static double boundary_after(double t)
{
    double b = floor(t / WIND_DRIFT_CELL_S) * WIND_DRIFT_CELL_S;
    while (b <= t)
        b += WIND_DRIFT_CELL_S;
    while (b - WIND_DRIFT_CELL_S > t)
        b -= WIND_DRIFT_CELL_S;
    return b;
}

static double boundary_before(double t)
{
    double b = ceil(t / WIND_DRIFT_CELL_S) * WIND_DRIFT_CELL_S;
    while (b >= t)
        b -= WIND_DRIFT_CELL_S;
    while (b + WIND_DRIFT_CELL_S < t)
        b += WIND_DRIFT_CELL_S;
    return b;
}

static bool same_anchor(const struct proto_wind_anchor *a, const struct proto_wind_anchor *b)
{
    return a->utc_unix_s == b->utc_unix_s && a->offset_east_km == b->offset_east_km &&
           a->offset_north_km == b->offset_north_km;
}

void wind_drift_offsets(struct wind_drift *drift, const struct proto_world_state *state,
                        double utc_s, double *east_km, double *north_km)
{
    const struct proto_wind_anchor *anchor = &state->weather.anchor;
    double at = anchor->utc_unix_s;
    double east = anchor->offset_east_km, north = anchor->offset_north_km;
    long cells = 0;
    if (utc_s < at) {
        for (double b = boundary_before(at); b > utc_s; b = boundary_before(b), cells++) {
            add_cell(state, at, b, &east, &north);
            at = b;
        }
    } else {
        if (drift && drift->valid && same_anchor(&drift->anchor, anchor) && drift->at_s <= utc_s) {
            at = drift->at_s;
            east = drift->east_km;
            north = drift->north_km;
        }
        for (double b = boundary_after(at); b <= utc_s; b = boundary_after(b), cells++) {
            add_cell(state, at, b, &east, &north);
            at = b;
        }
        if (drift) {
            drift->valid = true;
            drift->anchor = *anchor;
            drift->at_s = at;
            drift->east_km = east;
            drift->north_km = north;
        }
    }
    if (drift)
        drift->cells = cells;
    add_cell(state, at, utc_s, &east, &north);
    *east_km = east;
    *north_km = north;
}
