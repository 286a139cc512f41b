/* A decoded METAR (metar.h) turned into a world-state patch: the cloud groups by étage into the
 * cloud layers, vertical visibility into a fog ceiling, visibility into fog extinction by
 * Koschmieder's law, temperature and dew point into weather.humidity, the surface wind into
 * the wind at the cloud layers, precipitation and thunderstorms, and weather.source "metar".
 * The patch never touches the clock: the report names only a day of the month, and the world
 * may be showing another instant on purpose (the reply carries the observation time).
 *
 * Pure functions on cJSON: no I/O, no globals. The rules, with their sources, are in
 * protocol/PROTOCOL.md, "Observations (METAR) in the world". */
#ifndef SKYD_WEATHER_OBSERVATION_H
#define SKYD_WEATHER_OBSERVATION_H

#include <stdbool.h>
#include <stddef.h>

struct cJSON;
struct proto_metar_report;

/* The étages (WMO International Cloud Atlas, temperate regions): low below 2 km, middle from
 * 2 km, high from 6 km; bases in metres above the station. */
#define PROTO_OBS_MIDDLE_BASE_M 2000.0
#define PROTO_OBS_HIGH_BASE_M 6000.0
/* Extinction of the clear air at the ground, 1/km: what the world's default atmosphere gives
 * (Rayleigh + Mie at sea level, green), a visibility of about 160 km. Fog adds the rest. */
#define PROTO_OBS_CLEAR_EXTINCTION_PER_KM 0.025
/* Koschmieder's constant: V = 3.912 / sigma for a 2 % contrast threshold. */
#define PROTO_OBS_KOSCHMIEDER 3.912
/* The renderer's humidity fog (server/host world_render.h): grey extinction from 0 at this
 * relative humidity to 3.912/km at saturation, smoothstep between. */
#define PROTO_OBS_FOG_ONSET_HUMIDITY 0.9

enum proto_obs_etage {
    PROTO_OBS_ETAGE_LOW = 0,
    PROTO_OBS_ETAGE_MIDDLE = 1,
    PROTO_OBS_ETAGE_HIGH = 2,
};

/* The world layer an étage's groups go to: "low", "high", or NULL where the world has no layer
 * for it yet (the middle étage until clouds.mid exists: its groups go to the low layer when no
 * low group was reported, else they are reported unmapped). */
const char *proto_obs_etage_layer(enum proto_obs_etage etage);
const char *proto_obs_etage_name(enum proto_obs_etage etage);

/* The low layer's type (0 stratus .. 1/3 stratocumulus .. 2/3 cumulus .. 1 cumulonimbus) for a
 * coverage 0..1 and a base in metres, when nothing names the cloud: scattered cells are
 * cumulus, broken sheets stratocumulus, an overcast below 600 m stratus. */
double proto_obs_low_type(double coverage, double base_m);

/* The renderer's humidity fog extinction, 1/km, at relative humidity 0..1. */
double proto_obs_humidity_fog_per_km(double humidity);

/* The patch for a decoded report and the groups it decoded but could not place, as JSON
 * ([{"group":"BKN100","etage":"middle","reason":"..."}]); both new objects the caller deletes.
 * False with `why` filled for a NIL report (nothing observed) or when memory is out. */
bool proto_obs_metar_patch(const struct proto_metar_report *report, struct cJSON **patch,
                           struct cJSON **unmapped, char *why, size_t why_size);

#endif
