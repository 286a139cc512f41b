/* skyd render --metar and --forecast: an observed or forecast sky applied to the world state
 * the render starts from (weather_observation.h, forecast.h). */
#ifndef SKYD_CLI_OBSERVATION_H
#define SKYD_CLI_OBSERVATION_H

#include <stdbool.h>

#include "weather_map.h"
#include "world_state.h"

struct forecast;

/* Decodes the METAR and applies its patch; prints the groups left unmapped to stderr. False
 * after a message that names the refused group or field; the state is then untouched. */
bool cli_apply_metar(struct proto_world_state *state, const char *text);

/* Reads the GRIB2 file around the state's location over weather.map_extent_km; NULL after a
 * message saying why. */
struct forecast *cli_open_forecast(const struct proto_world_state *state, const char *path);

/* Applies the forecast at the state's clock.utc (held at the first or last step outside the
 * file's range when `hold` is true, refused otherwise), its cover grid into *map (replaced;
 * weather.map_source "forecast" selects it). False after a message. */
bool cli_apply_forecast(struct proto_world_state *state, const struct forecast *forecast, bool hold,
                        bool quiet, struct proto_weather_map *map);

#endif
