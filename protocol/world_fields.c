/* The world state's fields: one descriptor row per leaf (path, type, range, description) and
 * the defaults. The schema engine (field_schema.h) reads the table for world_state.c
 * (patching, validation) and world_state_text.c (JSON, --set, the JSON Schema). */
#include "world_fields.h"
#include "field_schema.h"

#include <string.h>

/* Enum fields are read and written through int lvalues. */
_Static_assert(sizeof(enum proto_limb_darkening) == sizeof(int), "enum field size");
_Static_assert(sizeof(enum proto_exposure_mode) == sizeof(int), "enum field size");
_Static_assert(sizeof(enum proto_tonemap) == sizeof(int), "enum field size");
_Static_assert(sizeof(enum proto_bodies_mode) == sizeof(int), "enum field size");
_Static_assert(sizeof(enum proto_switch) == sizeof(int), "enum field size");
_Static_assert(sizeof(enum proto_cloud_resolution) == sizeof(int), "enum field size");
_Static_assert(sizeof(enum proto_weather_map_source) == sizeof(int), "enum field size");
_Static_assert(sizeof(enum proto_weather_source) == sizeof(int), "enum field size");

static const char *const limb_darkening_names[] = { "none", "neckel96", "hm98" };
static const char *const exposure_mode_names[] = { "auto", "manual" };
static const char *const tonemap_names[] = { "aces", "reinhard", "clamp" };
static const char *const bodies_names[] = { "manual", "ephemeris" };
static const char *const switch_names[] = { "off", "on" };
static const char *const cloud_resolution_names[] = { "full", "quarter", "sixteenth", "sixtyfourth",
                                                      "auto" };
static const char *const weather_map_source_names[] = { "procedural", "client", "forecast" };
static const char *const weather_source_names[] = { "procedural", "client", "metar", "forecast" };

/* clock.utc spans the ephemeris' validity: 1900-01-01T00:00:00Z to 2100-12-31T23:59:59Z. */
#define UTC_MIN_S -2208988800.0
#define UTC_MAX_S 4133980799.0
#define SEED_MAX 2147483647.0
/* The middle etage (WMO International Cloud Atlas: 2-4 km polar, 2-7 km temperate, 2-8 km
 * tropical): where a middle layer's base may lie, and how thick it may grow. */
#define MID_BOTTOM_MIN_KM 2.0
#define MID_BOTTOM_MAX_KM 8.0
#define MID_THICKNESS_MAX_KM 4.0

#define COUNT_OF(array) ((int)(sizeof(array) / sizeof((array)[0])))
#define OFFSET(member) offsetof(struct proto_world_state, member)
/* One row; the members a macro leaves out are zero (not required, inclusive ranges). */
/* clang-format off */
#define ROW(path_, type_, member, lo, hi, names, count, doc, ro) \
    {.path = path_, .type = type_, .offset = OFFSET(member), .min = lo, .max = hi, \
     .enum_names = names, .enum_count = count, .description = doc, .read_only = ro}
#define NUMBER(path, member, lo, hi, doc) \
    ROW(path, PROTO_FIELD_TYPE_NUMBER, member, lo, hi, NULL, 0, doc, false)
#define RGB(path, member, lo, hi, doc) \
    ROW(path, PROTO_FIELD_TYPE_RGB, member, lo, hi, NULL, 0, doc, false)
#define INT_PAIR(path, member, lo, hi, doc) \
    ROW(path, PROTO_FIELD_TYPE_INT_PAIR, member, lo, hi, NULL, 0, doc, false)
#define INT_TRIPLE(path, member, lo, hi, doc) \
    ROW(path, PROTO_FIELD_TYPE_INT_TRIPLE, member, lo, hi, NULL, 0, doc, false)
#define INT(path, member, lo, hi, doc) \
    ROW(path, PROTO_FIELD_TYPE_INT, member, lo, hi, NULL, 0, doc, false)
#define TIME(path, member, lo, hi, doc) \
    ROW(path, PROTO_FIELD_TYPE_TIME, member, lo, hi, NULL, 0, doc, false)
#define ENUM(path, member, names, doc) \
    ROW(path, PROTO_FIELD_TYPE_ENUM, member, 0, COUNT_OF(names) - 1, names, COUNT_OF(names), doc, \
        false)
/* Read-only rows: kept by the simulation, restored from a saved state, refused in a `set`. */
#define RO_NUMBER(path, member, lo, hi, doc) \
    ROW(path, PROTO_FIELD_TYPE_NUMBER, member, lo, hi, NULL, 0, doc, true)
#define RO_TIME(path, member, lo, hi, doc) \
    ROW(path, PROTO_FIELD_TYPE_TIME, member, lo, hi, NULL, 0, doc, true)

/* The interpolated weather parameters of one end of a transition, under
 * "weather.transition.<end>." with the paths of the live fields they stand for. */
#define TRANSITION_END(end, what)                                                                 \
    RO_NUMBER("weather.transition." #end ".clouds.low.coverage", weather.transition.end.low.coverage, \
              0, 1, "low layer coverage " what),                                                 \
    RO_NUMBER("weather.transition." #end ".clouds.low.type", weather.transition.end.low.type, 0, 1, \
              "low layer cloud type " what),                                                     \
    RO_NUMBER("weather.transition." #end ".clouds.low.density", weather.transition.end.low.density, \
              0, 10, "low layer density " what),                                                 \
    RO_NUMBER("weather.transition." #end ".clouds.low.bottom_km",                                 \
              weather.transition.end.low.bottom_km, 0, 20, "low layer base " what ", km"),       \
    RO_NUMBER("weather.transition." #end ".clouds.low.thickness_km",                              \
              weather.transition.end.low.thickness_km, 0.05, 15,                                 \
              "low layer thickness " what ", km"),                                               \
    RO_NUMBER("weather.transition." #end ".clouds.mid.coverage",                                  \
              weather.transition.end.mid.coverage, 0, 1, "middle layer coverage " what),         \
    RO_NUMBER("weather.transition." #end ".clouds.mid.type", weather.transition.end.mid.type,    \
              0, 1, "middle layer cloud type " what),                                            \
    RO_NUMBER("weather.transition." #end ".clouds.mid.density",                                   \
              weather.transition.end.mid.density, 0, 10, "middle layer density " what),          \
    RO_NUMBER("weather.transition." #end ".clouds.mid.bottom_km",                                 \
              weather.transition.end.mid.bottom_km, MID_BOTTOM_MIN_KM, MID_BOTTOM_MAX_KM,         \
              "middle layer base " what ", km"),                                                 \
    RO_NUMBER("weather.transition." #end ".clouds.mid.thickness_km",                              \
              weather.transition.end.mid.thickness_km, 0.05, MID_THICKNESS_MAX_KM,               \
              "middle layer thickness " what ", km"),                                            \
    RO_NUMBER("weather.transition." #end ".clouds.high.coverage",                                 \
              weather.transition.end.high.coverage, 0, 1, "high layer coverage " what),          \
    RO_NUMBER("weather.transition." #end ".clouds.high.type", weather.transition.end.high.type,  \
              0, 1, "high layer cloud type " what),                                              \
    RO_NUMBER("weather.transition." #end ".clouds.high.density",                                  \
              weather.transition.end.high.density, 0, 10, "high layer density " what),           \
    RO_NUMBER("weather.transition." #end ".clouds.high.bottom_km",                                \
              weather.transition.end.high.bottom_km, 0, 30, "high layer base " what ", km"),     \
    RO_NUMBER("weather.transition." #end ".clouds.high.thickness_km",                             \
              weather.transition.end.high.thickness_km, 0.05, 5,                                 \
              "high layer thickness " what ", km"),                                              \
    RO_NUMBER("weather.transition." #end ".clouds.precipitation",                                 \
              weather.transition.end.precipitation, 0, 1, "precipitation " what),                \
    RO_NUMBER("weather.transition." #end ".weather.humidity", weather.transition.end.humidity,   \
              0, 1, "relative humidity " what),                                                  \
    RO_NUMBER("weather.transition." #end ".weather.wind.speed_m_s",                               \
              weather.transition.end.wind_speed_m_s, 0, 100, "wind speed " what ", m/s"),        \
    RO_NUMBER("weather.transition." #end ".weather.wind.direction_deg",                           \
              weather.transition.end.wind_direction_deg, 0, 360,                                 \
              "wind direction (from) " what ", degrees")
/* clang-format on */

/* Rows sharing a group stay together: serialization and error messages follow this order. */
const struct proto_field_desc proto_world_field_table[] = {
    TIME("clock.utc", clock.utc_unix_s, UTC_MIN_S, UTC_MAX_S,
         "simulated date and time, ISO 8601 UTC (1900-01-01 to 2100-12-31)"),
    NUMBER("clock.time_scale", clock.time_scale, 0, 100000,
           "simulated seconds per real second: 0 pauses, 1 is real time, more is a time-lapse"),
    ENUM("clock.sky_bodies", clock.sky_bodies, bodies_names,
         "ephemeris: sun and moon follow the clock and location; manual: sun.* and moon.* angles"),
    RO_TIME("clock.epoch.wall", clock.epoch.wall_unix_s, 0, UTC_MAX_S,
            "read-only: the real UTC instant (wall clock) at which the simulated clock read "
            "clock.epoch.utc; clock.utc = epoch.utc + (now - epoch.wall) x time_scale. "
            "1970-01-01T00:00:00Z: not anchored yet"),
    RO_TIME("clock.epoch.utc", clock.epoch.utc_unix_s, UTC_MIN_S, UTC_MAX_S,
            "read-only: the simulated time at clock.epoch.wall, ISO 8601 UTC"),
    NUMBER("location.latitude_deg", location.latitude_deg, -90, 90,
           "latitude of the site, north positive, degrees"),
    NUMBER("location.longitude_deg", location.longitude_deg, -180, 180,
           "longitude of the site, east positive, degrees"),
    NUMBER("location.altitude_m", location.altitude_m, -500, 9000,
           "elevation of the site above sea level for the ephemeris, m"),
    NUMBER("atmosphere.bottom_radius_km", atmosphere.bottom_radius_km, 100, 100000,
           "planet radius, km"),
    NUMBER("atmosphere.top_radius_km", atmosphere.top_radius_km, 100.1, 101000,
           "radius of the top of the atmosphere, km; above the bottom by at most 1000 km"),
    RGB("atmosphere.rayleigh.scattering_per_km", atmosphere.rayleigh_scattering_per_km, 0, 10,
        "Rayleigh scattering coefficient at the ground per RGB channel, 1/km"),
    NUMBER("atmosphere.rayleigh.scale_height_km", atmosphere.rayleigh_scale_height_km, 0.1, 100,
           "Rayleigh density scale height, km"),
    RGB("atmosphere.mie.scattering_per_km", atmosphere.mie_scattering_per_km, 0, 10,
        "aerosol (Mie) scattering coefficient at the ground per RGB channel, 1/km"),
    RGB("atmosphere.mie.absorption_per_km", atmosphere.mie_absorption_per_km, 0, 10,
        "aerosol (Mie) absorption coefficient at the ground per RGB channel, 1/km"),
    NUMBER("atmosphere.mie.scale_height_km", atmosphere.mie_scale_height_km, 0.01, 100,
           "aerosol density scale height, km"),
    RGB("atmosphere.mie.g", atmosphere.mie_g, -0.99, 0.99,
        "Cornette-Shanks asymmetry parameter per RGB channel, unitless"),
    RGB("atmosphere.ozone.absorption_per_km", atmosphere.ozone_absorption_per_km, 0, 1,
        "ozone absorption coefficient at the layer peak per RGB channel, 1/km"),
    NUMBER("atmosphere.ozone.peak_altitude_km", atmosphere.ozone_peak_altitude_km, 0, 1000,
           "altitude of the centre of the ozone tent layer, km"),
    NUMBER("atmosphere.ozone.width_km", atmosphere.ozone_width_km, 0.1, 1000,
           "full width of the ozone tent layer, km"),
    RGB("atmosphere.ground_albedo", atmosphere.ground_albedo, 0, 1,
        "Lambertian ground albedo per RGB channel, unitless"),
    NUMBER("atmosphere.fog.density_per_km", atmosphere.fog_density_per_km, 0, 100,
           "height fog: grey aerosol scattering added at the ground, 1/km"),
    NUMBER("atmosphere.fog.scale_height_km", atmosphere.fog_scale_height_km, 0.01, 50,
           "height fog exponential falloff, km"),
    NUMBER("sun.illuminance_lux", sun.illuminance_lux, 0, 1e6,
           "ground illuminance with the sun at zenith, lux"),
    NUMBER("sun.angular_diameter_deg", sun.angular_diameter_deg, 0.01, 20,
           "apparent diameter of the solar disc, degrees"),
    NUMBER("sun.azimuth_deg", sun.azimuth_deg, -360, 360,
           "sun azimuth from north through east, degrees"),
    NUMBER("sun.elevation_deg", sun.elevation_deg, -90, 90,
           "sun elevation above the horizon, degrees"),
    ENUM("sun.limb_darkening", sun.limb_darkening, limb_darkening_names,
         "limb darkening model of the solar disc"),
    NUMBER("moon.azimuth_deg", moon.azimuth_deg, -360, 360,
           "moon azimuth from north through east, degrees"),
    NUMBER("moon.elevation_deg", moon.elevation_deg, -90, 90,
           "moon elevation above the horizon, degrees"),
    NUMBER("moon.angular_diameter_deg", moon.angular_diameter_deg, 0.01, 20,
           "apparent diameter of the lunar disc, degrees"),
    NUMBER("night.airglow_luminance_cd_m2", night.airglow_luminance_cd_m2, 0, 0.1,
           "natural night-sky background (airglow, zodiacal light) at the zenith, cd/m2"),
    NUMBER("night.star_brightness", night.star_brightness, 0, 100,
           "multiplier of the star catalogue's brightness, unitless"),
    NUMBER("clouds.low.coverage", clouds.low.coverage, 0, 1,
           "low cloud layer: fraction of the sky covered, 0..1"),
    NUMBER("clouds.low.type", clouds.low.type, 0, 1,
           "low layer cloud type: 0 stratus, 0.33 stratocumulus, 0.67 cumulus, 1 cumulonimbus"),
    NUMBER("clouds.low.density", clouds.low.density, 0, 10,
           "low layer density, multiplier of clouds.extinction_per_km"),
    NUMBER("clouds.low.bottom_km", clouds.low.bottom_km, 0, 20,
           "low layer cloud base above the ground, km"),
    NUMBER("clouds.low.thickness_km", clouds.low.thickness_km, 0.05, 15, "low layer thickness, km"),
    NUMBER("clouds.mid.coverage", clouds.mid.coverage, 0, 1,
           "middle cloud layer (altostratus, altocumulus): fraction of the sky covered, 0..1"),
    NUMBER("clouds.mid.type", clouds.mid.type, 0, 1,
           "middle layer cloud type: 0 altostratus (a sheet) .. 1 altocumulus (cells, rolls)"),
    NUMBER("clouds.mid.density", clouds.mid.density, 0, 10,
           "middle layer density, multiplier of clouds.extinction_per_km"),
    NUMBER("clouds.mid.bottom_km", clouds.mid.bottom_km, MID_BOTTOM_MIN_KM, MID_BOTTOM_MAX_KM,
           "middle layer base above the ground, km: within the middle etage (WMO: 2-7 km in "
           "temperate regions, 2-8 km in the tropics)"),
    NUMBER("clouds.mid.thickness_km", clouds.mid.thickness_km, 0.05, MID_THICKNESS_MAX_KM,
           "middle layer thickness, km"),
    NUMBER("clouds.high.coverage", clouds.high.coverage, 0, 1,
           "high thin layer: fraction of the sky covered, 0..1"),
    NUMBER("clouds.high.type", clouds.high.type, 0, 1,
           "high layer cloud type, as for the low layer (usually 0: sheets and streaks)"),
    NUMBER("clouds.high.density", clouds.high.density, 0, 10,
           "high layer density, multiplier of clouds.extinction_per_km"),
    NUMBER("clouds.high.bottom_km", clouds.high.bottom_km, 0, 30,
           "high layer base above the ground, km"),
    NUMBER("clouds.high.thickness_km", clouds.high.thickness_km, 0.05, 5,
           "high layer thickness, km"),
    NUMBER("clouds.extinction_per_km", clouds.extinction_per_km, 0.1, 1000,
           "cloud extinction coefficient at density 1, 1/km"),
    NUMBER("clouds.albedo", clouds.albedo, 0, 1,
           "single-scattering albedo of cloud droplets, unitless"),
    NUMBER("clouds.precipitation", clouds.precipitation, 0, 1,
           "0..1: darker, denser cloud bases and rain shafts"),
    NUMBER("clouds.phase.g0", clouds.phase_g0, -0.99, 0.99,
           "forward lobe asymmetry of the dual-lobe Henyey-Greenstein phase"),
    NUMBER("clouds.phase.g1", clouds.phase_g1, -0.99, 0.99,
           "backward lobe asymmetry of the dual-lobe Henyey-Greenstein phase"),
    NUMBER("clouds.phase.w", clouds.phase_w, 0, 1,
           "blend toward the g1 lobe: (1 - w) p(g0) + w p(g1), seed 000 eq. 14.17"),
    NUMBER("clouds.multiscatter.a", clouds.multiscatter_a, 0, 1,
           "scattering attenuation per multiple-scattering octave (a <= b conserves energy)"),
    NUMBER("clouds.multiscatter.b", clouds.multiscatter_b, 0, 1,
           "extinction attenuation per multiple-scattering octave, through the sun's column"),
    NUMBER("clouds.multiscatter.c", clouds.multiscatter_c, 0, 1,
           "phase eccentricity attenuation per multiple-scattering octave"),
    INT("clouds.multiscatter.octaves", clouds.multiscatter_octaves, 1, 8,
        "number of multiple-scattering octaves"),
    NUMBER("clouds.multiscatter.powder", clouds.multiscatter_powder, 0, 64,
           "how fast multiply scattered light builds up below a lit surface, per optical "
           "depth (the powder darkening of sun-facing creases); 0: no build-up"),
    NUMBER("clouds.ambient_scale", clouds.ambient_scale, 0, 1,
           "scale of the sky's ambient light on the clouds, unitless"),
    INT("clouds.noise_seed", clouds.noise_seed, 0, SEED_MAX, "seed of the cloud noise volumes"),
    INT("clouds.quality.primary_steps", clouds.primary_steps, 4, 512,
        "ray-march steps through a cloud layer"),
    INT("clouds.quality.light_steps", clouds.light_steps, 1, 32,
        "steps of the secondary march toward the sun"),
    ENUM("clouds.quality.resolution", clouds.resolution, cloud_resolution_names,
         "share of the pixels ray-marched per frame: full, quarter (2x2 cycle), sixteenth "
         "(4x4 cycle), sixtyfourth (clouds at half size, 4x4 cycle), or auto: the finest whose "
         "frames fit the daemon's render.frame_budget_ms, from their measured GPU time, with "
         "primary_steps halved below sixtyfourth and doubled above full"),
    ENUM("clouds.quality.temporal", clouds.temporal, switch_names,
         "temporal reprojection: frames accumulate into a history"),
    NUMBER("weather.humidity", weather.humidity, 0, 1,
           "relative humidity 0..1; haze (Mie density) and fog grow with it"),
    NUMBER("weather.wind.speed_m_s", weather.wind.speed_m_s, 0, 100,
           "wind speed at the cloud layers, m/s"),
    NUMBER("weather.wind.direction_deg", weather.wind.direction_deg, 0, 360,
           "direction the wind blows from, north through east, degrees"),
    NUMBER("weather.offset_east_km", weather.offset_east_km, -1e6, 1e6,
           "weather map displacement by the wind so far, east, km"),
    NUMBER("weather.offset_north_km", weather.offset_north_km, -1e6, 1e6,
           "weather map displacement by the wind so far, north, km"),
    RO_TIME("weather.anchor.utc", weather.anchor.utc_unix_s, UTC_MIN_S, UTC_MAX_S,
            "read-only: simulated time of the last change to the wind, the weather driving it, "
            "the offsets or the clock; the offsets are the anchor's plus the wind since"),
    RO_NUMBER("weather.anchor.offset_east_km", weather.anchor.offset_east_km, -1e6, 1e6,
              "read-only: weather.offset_east_km at weather.anchor.utc, km"),
    RO_NUMBER("weather.anchor.offset_north_km", weather.anchor.offset_north_km, -1e6, 1e6,
              "read-only: weather.offset_north_km at weather.anchor.utc, km"),
    INT("weather.seed", weather.seed, 0, SEED_MAX, "seed of the procedural weather map"),
    NUMBER("weather.map_extent_km", weather.map_extent_km, 4, 400,
           "side of the square weather map centred on the camera, km"),
    ENUM("weather.map_source", weather.map_source, weather_map_source_names,
         "procedural (from weather.* and clouds.*), client (an uploaded map) or forecast (the "
         "followed forecast's cloud cover over the map's square)"),
    ENUM("weather.source", weather.source, weather_source_names,
         "what the weather last came from: procedural (the daemon's, presets, autopilot), "
         "client, metar (apply_observation sets it) or forecast"),
    ENUM("weather.autopilot", weather.autopilot, switch_names,
         "evolve the weather stochastically (deterministic from autopilot_seed)"),
    INT("weather.autopilot_seed", weather.autopilot_seed, 0, SEED_MAX,
        "seed of the weather autopilot"),
    RO_TIME("weather.transition.start", weather.transition.start_unix_s, UTC_MIN_S, UTC_MAX_S,
            "read-only: simulated time the last weather transition started, ISO 8601 UTC"),
    RO_NUMBER("weather.transition.duration_s", weather.transition.duration_s, 0, 1e7,
              "read-only: its length in simulated seconds; 0: none"),
    RO_NUMBER("weather.transition.progress", weather.transition.progress, 0, 1,
              "read-only: fraction of its time elapsed; below 1 while it runs"),
    TRANSITION_END(from, "where the transition started"),
    TRANSITION_END(to, "where the transition ends"),
    NUMBER("camera.altitude_km", camera.altitude_km, 0, 100000,
           "camera altitude above the planet surface, km"),
    NUMBER("camera.yaw_deg", camera.yaw_deg, -360, 360,
           "view azimuth from north through east, degrees"),
    NUMBER("camera.pitch_deg", camera.pitch_deg, -90, 90,
           "view elevation above the local horizon, degrees"),
    NUMBER("camera.fov_deg", camera.fov_deg, 1, 170, "vertical field of view, degrees"),
    ENUM("exposure.mode", exposure.mode, exposure_mode_names,
         "auto: metered from the sky; manual: from ev100"),
    NUMBER("exposure.ev100", exposure.ev100, -10, 25,
           "exposure value at ISO 100, used when mode is manual, EV"),
    NUMBER("exposure.compensation_ev", exposure.compensation_ev, -10, 10,
           "added to the automatic exposure, EV"),
    ENUM("exposure.tonemap", exposure.tonemap, tonemap_names, "tone mapping curve"),
    ENUM("exposure.night_adaptation", exposure.night_adaptation, switch_names,
         "on: auto exposure keeps a dark scene dark, as a dark-adapted eye sees it (Krawczyk "
         "et al. 2005); off: every scene is metered to mid grey, as a camera would"),
    INT_PAIR("render.transmittance_lut", render.transmittance_lut, 8, 4096,
             "transmittance LUT size, [width, height] texels"),
    INT_PAIR("render.multiscattering_lut", render.multiscattering_lut, 4, 1024,
             "multiple-scattering LUT size, [width, height] texels"),
    INT_PAIR("render.skyview_lut", render.skyview_lut, 8, 4096,
             "sky-view LUT size, [width, height] texels"),
    INT_TRIPLE("render.aerial_perspective_lut", render.aerial_perspective_lut, 4, 512,
               "aerial perspective volume size, [width, height, depth slices] texels"),
    NUMBER("render.aerial_perspective_max_km", render.aerial_perspective_max_km, 1, 1000,
           "distance covered by the aerial perspective volume, km"),
};

const size_t proto_world_field_count = sizeof proto_world_field_table /
                                       sizeof proto_world_field_table[0];

_Static_assert(sizeof proto_world_field_table / sizeof proto_world_field_table[0] <=
                   PROTO_WORLD_PATCH_MAX_FIELDS,
               "a patch can name every field");

static const struct proto_schema world_schema = {
    .fields = proto_world_field_table,
    .count = sizeof proto_world_field_table / sizeof proto_world_field_table[0],
    .read_only_member = "revision",
};

const struct proto_schema *proto_world_schema(void)
{
    return &world_schema;
}

const struct proto_field_desc *proto_world_state_fields(size_t *count)
{
    if (count)
        *count = proto_world_field_count;
    return proto_world_field_table;
}

const struct proto_field_desc *proto_world_state_find_field(const char *dotted_path)
{
    return proto_schema_find(&world_schema, dotted_path);
}

static void set_rgb(double channels[3], double r, double g, double b)
{
    channels[0] = r;
    channels[1] = g;
    channels[2] = b;
}

static void set_pair(int values[2], int first, int second)
{
    values[0] = first;
    values[1] = second;
}

/* Member by member after the memset: copying whole compound literals would also copy their
 * indeterminate padding, and states are compared with memcmp. */
void proto_world_state_defaults(struct proto_world_state *state)
{
    memset(state, 0, sizeof *state);

    state->clock.utc_unix_s = 1782043200.0; /* 2026-06-21T12:00:00Z */
    state->clock.time_scale = 1.0;
    state->clock.sky_bodies = PROTO_BODIES_MANUAL;
    state->clock.epoch.wall_unix_s = 0.0; /* anchored by the first world host that runs it */
    state->clock.epoch.utc_unix_s = state->clock.utc_unix_s;
    state->location.latitude_deg = 45.0;
    state->location.longitude_deg = 6.0;
    state->location.altitude_m = 200.0;

    struct proto_atmosphere_state *atmosphere = &state->atmosphere;
    atmosphere->bottom_radius_km = 6360.0;
    atmosphere->top_radius_km = 6460.0;
    set_rgb(atmosphere->rayleigh_scattering_per_km, 5.802e-3, 13.558e-3, 33.1e-3);
    atmosphere->rayleigh_scale_height_km = 8.0;
    set_rgb(atmosphere->mie_scattering_per_km, 3.996e-3, 3.996e-3, 3.996e-3);
    set_rgb(atmosphere->mie_absorption_per_km, 0.444e-3, 0.444e-3, 0.444e-3);
    atmosphere->mie_scale_height_km = 1.2;
    set_rgb(atmosphere->mie_g, 0.8, 0.8, 0.8);
    set_rgb(atmosphere->ozone_absorption_per_km, 0.650e-3, 1.881e-3, 0.085e-3);
    atmosphere->ozone_peak_altitude_km = 25.0;
    atmosphere->ozone_width_km = 30.0;
    set_rgb(atmosphere->ground_albedo, 0.3, 0.3, 0.3);
    atmosphere->fog_density_per_km = 0.0;
    atmosphere->fog_scale_height_km = 0.5;

    state->sun.illuminance_lux = 120000.0;
    state->sun.angular_diameter_deg = 0.545;
    state->sun.azimuth_deg = 180.0;
    state->sun.elevation_deg = 45.0;
    state->sun.limb_darkening = PROTO_LIMB_DARKENING_HM98;

    state->moon.azimuth_deg = 90.0;
    state->moon.elevation_deg = -30.0;
    state->moon.angular_diameter_deg = 0.518;
    state->night.airglow_luminance_cd_m2 = 2.0e-4;
    state->night.star_brightness = 1.0;

    struct proto_cloud_state *clouds = &state->clouds;
    clouds->low.coverage = 0.0;
    clouds->low.type = 0.67;
    clouds->low.density = 1.0;
    clouds->low.bottom_km = 1.5;
    clouds->low.thickness_km = 3.0;
    clouds->mid.coverage = 0.0;
    clouds->mid.type = 0.0;
    clouds->mid.density = 0.5;
    clouds->mid.bottom_km = 4.0;
    clouds->mid.thickness_km = 1.0;
    clouds->high.coverage = 0.0;
    clouds->high.type = 0.0;
    clouds->high.density = 0.2;
    clouds->high.bottom_km = 8.0;
    clouds->high.thickness_km = 0.6;
    clouds->extinction_per_km = 40.0;
    clouds->albedo = 0.99;
    clouds->precipitation = 0.0;
    clouds->phase_g0 = 0.8;
    clouds->phase_g1 = -0.3;
    /* A forward-dominated phase (mean cosine 0.53: silver linings on backlit edges) and the
     * octaves fitted to it against Monte Carlo (docs/ACCURACY.md, tests/reference/test_cloud_accuracy.c). */
    clouds->phase_w = 0.25;
    clouds->multiscatter_a = 0.5;
    clouds->multiscatter_b = 0.8;
    clouds->multiscatter_c = 0.2;
    clouds->multiscatter_octaves = 4;
    clouds->multiscatter_powder = 16.0;
    clouds->ambient_scale = 1.0;
    clouds->noise_seed = 1;
    clouds->primary_steps = 64;
    clouds->light_steps = 6;
    clouds->resolution = PROTO_CLOUD_RESOLUTION_SIXTYFOURTH;
    clouds->temporal = PROTO_SWITCH_ON;

    state->weather.humidity = 0.5;
    state->weather.wind.speed_m_s = 10.0;
    state->weather.wind.direction_deg = 270.0;
    state->weather.offset_east_km = 0.0;
    state->weather.offset_north_km = 0.0;
    state->weather.anchor.utc_unix_s = state->clock.utc_unix_s;
    state->weather.anchor.offset_east_km = 0.0;
    state->weather.anchor.offset_north_km = 0.0;
    state->weather.seed = 1;
    state->weather.map_extent_km = 60.0;
    state->weather.map_source = PROTO_WEATHER_MAP_PROCEDURAL;
    state->weather.source = PROTO_WEATHER_SOURCE_PROCEDURAL;
    state->weather.autopilot = PROTO_SWITCH_OFF;
    state->weather.autopilot_seed = 1;
    state->weather.transition.start_unix_s = state->clock.utc_unix_s;
    state->weather.transition.duration_s = 0.0;
    state->weather.transition.progress = 1.0;
    proto_weather_params_get(state, &state->weather.transition.from);
    proto_weather_params_get(state, &state->weather.transition.to);

    state->camera.altitude_km = 0.2;
    state->camera.yaw_deg = 180.0;
    state->camera.pitch_deg = 10.0;
    state->camera.fov_deg = 70.0;

    state->exposure.mode = PROTO_EXPOSURE_AUTO;
    state->exposure.ev100 = 14.0;
    state->exposure.compensation_ev = 0.0;
    state->exposure.tonemap = PROTO_TONEMAP_ACES;
    state->exposure.night_adaptation = PROTO_SWITCH_ON;

    set_pair(state->render.transmittance_lut, 256, 64);
    set_pair(state->render.multiscattering_lut, 32, 32);
    set_pair(state->render.skyview_lut, 192, 108);
    state->render.aerial_perspective_lut[0] = 32;
    state->render.aerial_perspective_lut[1] = 32;
    state->render.aerial_perspective_lut[2] = 32;
    state->render.aerial_perspective_max_km = 64.0;
}

void proto_weather_params_get(const struct proto_world_state *state,
                              struct proto_weather_params *out)
{
    memset(out, 0, sizeof *out);
    out->low = state->clouds.low;
    out->mid = state->clouds.mid;
    out->high = state->clouds.high;
    out->precipitation = state->clouds.precipitation;
    out->humidity = state->weather.humidity;
    out->wind_speed_m_s = state->weather.wind.speed_m_s;
    out->wind_direction_deg = state->weather.wind.direction_deg;
}

void proto_weather_params_put(struct proto_world_state *state,
                              const struct proto_weather_params *in)
{
    state->clouds.low = in->low;
    state->clouds.mid = in->mid;
    state->clouds.high = in->high;
    state->clouds.precipitation = in->precipitation;
    state->weather.humidity = in->humidity;
    state->weather.wind.speed_m_s = in->wind_speed_m_s;
    state->weather.wind.direction_deg = in->wind_direction_deg;
}

const char *proto_cloud_resolution_name(enum proto_cloud_resolution resolution)
{
    size_t count = sizeof cloud_resolution_names / sizeof cloud_resolution_names[0];
    return (size_t)resolution < count ? cloud_resolution_names[resolution] : NULL;
}
