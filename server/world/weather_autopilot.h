/* The weather autopilot: the weather as a pure function of a seed, the simulated time and the
 * site's longitude, so it is deterministic and independent of how time was stepped. Fronts
 * (a slow "wetness" signal) bring cirrus ahead of them, then thickening low cloud, stratus,
 * rain and a veering wind; unstable afternoons build cumulus after late morning local solar
 * time and dissipate it in the evening, and turn to cumulonimbus when a front is wet. */
#ifndef SKYD_WEATHER_AUTOPILOT_H
#define SKYD_WEATHER_AUTOPILOT_H

#include "world_state.h"

/* The weather at simulated time unix_s (UTC seconds) for seed, at longitude_deg (east
 * positive). Every value lies inside its field's range. */
void weather_autopilot_sample(int seed, double unix_s, double longitude_deg,
                              struct proto_weather_params *out);

/* Apparent local solar time in hours [0, 24) (mean solar time plus the equation of time). */
double weather_local_solar_hour(double unix_s, double longitude_deg);

/* The signals underneath, for tests: front wetness and afternoon convection, each 0..1. */
double weather_autopilot_wetness(int seed, double unix_s);
double weather_autopilot_convection(int seed, double unix_s, double longitude_deg);

#endif
