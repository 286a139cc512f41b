/* World state: the plain struct the daemon keeps, its defaults, and its table of field rows
 * (proto_world_schema, on the schema engine of field_schema.h).
 *
 * Pure C on cJSON: no sockets, no Vulkan, no globals. Every field has a JSON path
 * (e.g. "atmosphere.mie.g" with dots, "/atmosphere/mie/g" as a JSON Pointer), a type and a
 * validation range. Patches are validated completely before anything changes and are applied
 * all-or-nothing; failures are field errors (field_errors.h). Units are in the field names:
 * km, per_km, deg, lux.
 */
#ifndef SKYD_WORLD_STATE_H
#define SKYD_WORLD_STATE_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

struct cJSON;
struct proto_field_desc;
struct proto_field_errors;
struct proto_schema;

enum proto_limb_darkening {
    PROTO_LIMB_DARKENING_NONE = 0,
    PROTO_LIMB_DARKENING_NECKEL96 = 1, /* seed 001 appendix B, listing 6 */
    PROTO_LIMB_DARKENING_HM98 = 2,     /* seed 001 appendix B, listing 7 */
};

/* Who places the sun and moon: the clock and location through the ephemeris, or the
 * sun.* and moon.* angles as set. */
enum proto_bodies_mode {
    PROTO_BODIES_MANUAL = 0,
    PROTO_BODIES_EPHEMERIS = 1,
};

enum proto_switch {
    PROTO_SWITCH_OFF = 0,
    PROTO_SWITCH_ON = 1,
};

/* How many of the cloud pixels are ray-marched each frame; the rest come from the
 * reprojected history. */
enum proto_cloud_resolution {
    PROTO_CLOUD_RESOLUTION_FULL = 0,        /* every pixel every frame */
    PROTO_CLOUD_RESOLUTION_QUARTER = 1,     /* one pixel of each 2x2 block per frame */
    PROTO_CLOUD_RESOLUTION_SIXTEENTH = 2,   /* one pixel of each 4x4 block per frame */
    PROTO_CLOUD_RESOLUTION_SIXTYFOURTH = 3, /* half-size clouds, one of each 4x4 per frame */
    PROTO_CLOUD_RESOLUTION_AUTO = 4,        /* the finest whose frames fit the frame budget */
};

/* Where the weather map comes from. */
enum proto_weather_map_source {
    PROTO_WEATHER_MAP_PROCEDURAL = 0, /* generated from weather.* and clouds.* */
    PROTO_WEATHER_MAP_CLIENT = 1,     /* uploaded by a client */
    PROTO_WEATHER_MAP_FORECAST = 2,   /* the followed forecast's coverage grid */
};

/* What the weather (clouds, humidity, fog, wind, precipitation) last came from: the daemon's own
 * weather (the default; presets and the autopilot), a client that drives it, an observation
 * applied with apply_observation, or a forecast (skyd render --forecast). A label clients may
 * set; apply_observation sets "metar". */
enum proto_weather_source {
    PROTO_WEATHER_SOURCE_PROCEDURAL = 0,
    PROTO_WEATHER_SOURCE_CLIENT = 1,
    PROTO_WEATHER_SOURCE_METAR = 2,
    PROTO_WEATHER_SOURCE_FORECAST = 3,
};

enum proto_exposure_mode {
    PROTO_EXPOSURE_AUTO = 0,
    PROTO_EXPOSURE_MANUAL = 1,
};

enum proto_tonemap {
    PROTO_TONEMAP_ACES = 0,     /* Narkowicz's fitted ACES filmic curve */
    PROTO_TONEMAP_REINHARD = 1, /* L / (1 + L) per channel */
    PROTO_TONEMAP_CLAMP = 2,    /* linear, clamped to [0, 1] */
};

struct proto_atmosphere_state {
    double bottom_radius_km; /* planet radius */
    double top_radius_km;    /* radius of the top of the atmosphere, > bottom */
    double rayleigh_scattering_per_km[3];
    double rayleigh_scale_height_km;
    double mie_scattering_per_km[3];
    double mie_absorption_per_km[3];
    double mie_scale_height_km;
    double mie_g[3]; /* Cornette-Shanks asymmetry per channel */
    double ozone_absorption_per_km[3];
    double ozone_peak_altitude_km; /* centre of the tent layer */
    double ozone_width_km;         /* full width of the tent layer */
    double ground_albedo[3];
    double fog_density_per_km;  /* height fog: grey extra aerosol scattering at the ground */
    double fog_scale_height_km; /* its exponential falloff */
};

struct proto_sun_state {
    double illuminance_lux; /* ground illuminance with the sun at zenith (seed 001, 4.1) */
    double angular_diameter_deg;
    double azimuth_deg; /* from north through east */
    double elevation_deg;
    enum proto_limb_darkening limb_darkening;
};

struct proto_camera_state {
    double altitude_km; /* above the planet surface; may be above the atmosphere */
    double yaw_deg;     /* view azimuth from north through east */
    double pitch_deg;   /* view elevation above the local horizon */
    double fov_deg;     /* vertical field of view */
};

struct proto_exposure_state {
    enum proto_exposure_mode mode;
    double ev100;           /* used when mode is manual */
    double compensation_ev; /* added to the automatic exposure */
    enum proto_tonemap tonemap;
    enum proto_switch
        night_adaptation; /* auto exposure leaves dark scenes dark, as eyes see them */
};

/* The clock's epoch: the simulated time utc_unix_s read at the real (wall-clock, CLOCK_REALTIME)
 * instant wall_unix_s. The simulated time at wall instant w is
 * utc_unix_s + (w - wall_unix_s) x time_scale, so every node that holds the state reads the same
 * clock. Read-only for clients; moved when a change sets clock.utc or clock.time_scale. Both
 * are whole milliseconds, what their ISO 8601 text keeps. wall_unix_s 0: not anchored yet. */
struct proto_clock_epoch {
    double wall_unix_s; /* "clock.epoch.wall" */
    double utc_unix_s;  /* "clock.epoch.utc" */
};

struct proto_clock_state {
    double utc_unix_s;                 /* "clock.utc": ISO 8601 text in JSON */
    double time_scale;                 /* simulated seconds per real second; 0 pauses */
    enum proto_bodies_mode sky_bodies; /* ephemeris: sun and moon follow clock and location */
    struct proto_clock_epoch epoch;
};

struct proto_location_state {
    double latitude_deg;  /* north positive */
    double longitude_deg; /* east positive */
    double altitude_m;    /* of the site above sea level, for the ephemeris */
};

struct proto_moon_state {
    double azimuth_deg; /* from north through east */
    double elevation_deg;
    double angular_diameter_deg;
};

struct proto_night_state {
    double airglow_luminance_cd_m2; /* natural night-sky background at the zenith */
    double star_brightness;         /* multiplier of the catalogue's star illuminance */
};

/* One cloud layer between bottom_km and bottom_km + thickness_km above the ground. */
struct proto_cloud_layer_state {
    double coverage; /* 0..1, fraction of the sky covered */
    double type;     /* low: 0 stratus, 1/3 stratocumulus, 2/3 cumulus, 1 cumulonimbus;
                        mid: 0 altostratus .. 1 altocumulus; high: 0 cirrostratus .. 1 cirrus */
    double density;  /* multiplier of clouds.extinction_per_km */
    double bottom_km;
    double thickness_km;
};

struct proto_cloud_state {
    struct proto_cloud_layer_state low;  /* cumulus-type layer (WMO low etage) */
    struct proto_cloud_layer_state mid;  /* altostratus, altocumulus (middle etage, 2-8 km) */
    struct proto_cloud_layer_state high; /* thin high layer (cirrus, cirrostratus) */
    double extinction_per_km;            /* at density 1 */
    double albedo;                       /* single-scattering albedo */
    double precipitation;                /* 0..1: darkens and thickens cloud bases */
    double phase_g0, phase_g1, phase_w;  /* dual-lobe Henyey-Greenstein (seed 000 eq. 14.17) */
    double multiscatter_a, multiscatter_b, multiscatter_c; /* octaves (seed 000 eq. 14.18) */
    int multiscatter_octaves;
    double multiscatter_powder; /* the octaves' build-up below a lit surface, 1/depth */
    double ambient_scale;       /* sky ambient on the clouds, 0..1 */
    int noise_seed;             /* seeds the noise volumes */
    int primary_steps;          /* ray-march steps through a layer */
    int light_steps;            /* secondary march toward the sun */
    enum proto_cloud_resolution resolution;
    enum proto_switch temporal; /* temporal reprojection of the history */
};

/* The weather parameters that transitions interpolate and the autopilot drives. */
struct proto_weather_params {
    struct proto_cloud_layer_state low, mid, high;
    double precipitation;      /* clouds.precipitation */
    double humidity;           /* weather.humidity */
    double wind_speed_m_s;     /* weather.wind.speed_m_s */
    double wind_direction_deg; /* weather.wind.direction_deg, along the shorter arc */
};

/* A weather transition: the parameters move from `from` to `to` along a smoothstep of the
 * simulated time from start over duration. Read-only for clients (apply_preset starts one);
 * persisted with the state. Active while duration_s > 0 and progress < 1. */
struct proto_transition_state {
    double start_unix_s; /* "weather.transition.start": ISO 8601 text in JSON */
    double duration_s;   /* simulated seconds; 0: no transition */
    double progress;     /* 0..1, the time fraction elapsed */
    struct proto_weather_params from, to;
};

struct proto_wind_state {
    double speed_m_s;
    double direction_deg; /* where the wind blows from, north through east */
};

/* Where the wind's integral starts: weather.offset_* at simulated time utc_unix_s (whole
 * milliseconds). The offsets at a later time are these plus the wind integrated from here
 * (world_sim.h). Read-only for clients; moved by a change to the wind, the weather that drives
 * it, the offsets or the clock. */
struct proto_wind_anchor {
    double utc_unix_s; /* "weather.anchor.utc" */
    double offset_east_km;
    double offset_north_km;
};

struct proto_weather_state {
    double humidity; /* 0..1; haze and fog grow with it */
    struct proto_wind_state wind;
    double offset_east_km; /* weather map advected by the wind so far */
    double offset_north_km;
    struct proto_wind_anchor anchor;
    int seed;             /* of the procedural weather map */
    double map_extent_km; /* side of the square weather map around the camera */
    enum proto_weather_map_source map_source;
    enum proto_weather_source source;
    enum proto_switch autopilot; /* stochastic, deterministic weather evolution */
    int autopilot_seed;
    struct proto_transition_state transition;
};

struct proto_render_settings {
    int transmittance_lut[2]; /* width, height */
    int multiscattering_lut[2];
    int skyview_lut[2];
    int aerial_perspective_lut[3];    /* width, height, depth slices */
    double aerial_perspective_max_km; /* depth covered by the froxel volume */
};

struct proto_world_state {
    uint64_t revision;
    struct proto_clock_state clock;
    struct proto_location_state location;
    struct proto_atmosphere_state atmosphere;
    struct proto_sun_state sun;
    struct proto_moon_state moon;
    struct proto_night_state night;
    struct proto_cloud_state clouds;
    struct proto_weather_state weather;
    struct proto_camera_state camera;
    struct proto_exposure_state exposure;
    struct proto_render_settings render;
};

/* The weather parameters of a state, and writing them back. */
void proto_weather_params_get(const struct proto_world_state *state,
                              struct proto_weather_params *out);
void proto_weather_params_put(struct proto_world_state *state,
                              const struct proto_weather_params *in);

/* Earth defaults (DESIGN.md constants); revision 0. */
void proto_world_state_defaults(struct proto_world_state *state);

/* The name clouds.quality.resolution gives a resolution ("full" .. "auto"); NULL out of range. */
const char *proto_cloud_resolution_name(enum proto_cloud_resolution resolution);

/* Validates `patch` (a JSON object, any subset of the state's tree) against the schema and
 * applies it to *state only when every field is valid and the result is consistent. Unknown
 * fields are errors. Returns true when applied; on false *state is untouched and *errors
 * lists each failure. Does not change the revision. */
bool proto_world_state_apply_json(struct proto_world_state *state, const struct cJSON *patch,
                                  struct proto_field_errors *errors);

/* Applies one "dotted.path=value" assignment (value text as on a command line: a number,
 * a JSON array "[1,2,3]", a bare number for an RGB field meaning all three channels, or an
 * enum name). Same all-or-nothing contract as proto_world_state_apply_json. */
bool proto_world_state_set_path(struct proto_world_state *state, const char *path,
                                const char *value_text, struct proto_field_errors *errors);

/* Serializes the whole state (including "revision") as a new cJSON object; NULL on OOM. */
struct cJSON *proto_world_state_to_json(const struct proto_world_state *state);
/* The same as compact JSON text (malloc'd; free() it); NULL on OOM. */
char *proto_world_state_to_text(const struct proto_world_state *state);

/* Checks cross-field consistency of a complete state; fills errors. */
bool proto_world_state_validate(const struct proto_world_state *state,
                                struct proto_field_errors *errors);

/* Splits "dotted.path=value" at the first '=' (surrounding blanks ignored) and calls
 * proto_world_state_set_path. */
bool proto_world_state_set_assignment(struct proto_world_state *state, const char *assignment,
                                      struct proto_field_errors *errors);

/* The world state's schema: the table of proto_world_state_fields. */
const struct proto_schema *proto_world_schema(void);

/* The descriptor table, in serialization order; *count receives its length. */
const struct proto_field_desc *proto_world_state_fields(size_t *count);

/* The descriptor of a leaf field by dotted path, or NULL (also for group paths like "sun"). */
const struct proto_field_desc *proto_world_state_find_field(const char *dotted_path);

/* A client's world-state patch, validated once, when it is parsed: the fields it names (row
 * indices of proto_world_state_fields, in table order) with their values converted and range-
 * checked, held in `values` (the defaults elsewhere). Applying it later copies those fields;
 * only the checks across fields, which need the live state, remain. */
#define PROTO_WORLD_PATCH_MAX_FIELDS 256
struct proto_world_patch {
    struct proto_world_state values;
    size_t count;
    unsigned short fields[PROTO_WORLD_PATCH_MAX_FIELDS];
};

/* Reads a JSON patch into *out: unknown members, wrong types and values out of range are
 * appended to `errors` under `pointer_prefix` ("/patch"). Returns whether none was. */
bool proto_world_patch_compile(const struct cJSON *json, const char *pointer_prefix,
                               struct proto_world_patch *out, struct proto_field_errors *errors);
/* Whether the patch names the field. */
bool proto_world_patch_names(const struct proto_world_patch *patch,
                             const struct proto_field_desc *field);
/* Writes the patch's fields into *state and checks the result across fields (errors cleared
 * first, pointers without a prefix); all or nothing. */
bool proto_world_state_apply_patch(struct proto_world_state *state,
                                   const struct proto_world_patch *patch,
                                   struct proto_field_errors *errors);

/* The world state's JSON Schema (draft 2020-12) generated from the descriptor table: types,
 * ranges, enum names, units ("x-unit"), defaults, descriptions, read-only fields; every object
 * closed to other members. NULL when memory is out. The caller deletes it. */
struct cJSON *proto_world_state_json_schema(void);

#endif
