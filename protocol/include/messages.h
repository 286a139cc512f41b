/* WebSocket protocol, version 1: parsing and validation of client text messages and
 * construction of server text messages. See PROTOCOL.md for the wire format.
 *
 * Pure functions on cJSON: no sockets, no I/O, no globals except constant tables. The caller
 * owns transport concerns: it turns binary messages (or text frames its WebSocket library found
 * not to be UTF-8) into an PROTO_MSG_ERR_INVALID_ENCODING error itself, enforces roles with
 * proto_msg_needs_controller(), rate limits, and applies validated patches to the live
 * state with proto_world_state_apply_json() at the next tick.
 */
#ifndef SKYD_MESSAGES_H
#define SKYD_MESSAGES_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "field_errors.h"
#include "frame_header.h"
#include "weather_map.h"
#include "world_state.h"

struct cJSON;

#define PROTO_PROTOCOL_VERSION 1

#define PROTO_MSG_ID_MAX 64          /* bytes of a string id */
#define PROTO_MSG_CLIENT_MAX 64      /* bytes of the client name in hello */
#define PROTO_MSG_TOKEN_MAX 256      /* bytes of an auth token */
#define PROTO_MSG_PRESET_NAME_MAX 64 /* [a-z0-9_-]{1,64} */
#define PROTO_MSG_METAR_MAX 1024  /* bytes of a METAR report (metar.h's PROTO_METAR_MAX_LENGTH) */
#define PROTO_MSG_POINTER_MAX 128 /* a JSON Pointer, as in struct proto_field_error */
#define PROTO_MSG_JPEG_QUALITY_DEFAULT 85
#define PROTO_MSG_MAX_KBPS 1e6
#define PROTO_MSG_MAX_PASSES 32   /* entries in a stats message's "passes" */
#define PROTO_MSG_MAX_PRESETS 256 /* names in a presets message */
/* Integers on the wire stay exactly representable in an IEEE double (JavaScript's limit). */
#define PROTO_MSG_MAX_SAFE_INTEGER 9007199254740991LL /* 2^53 - 1 */

/* Stable error codes. The wire carries the names (proto_msg_error_name); the numbers are stable
 * too. 1..6 equal enum proto_field_error_code, so proto_field_error.code holds either. */
enum proto_msg_error_code {
    PROTO_MSG_OK = 0,
    PROTO_MSG_ERR_UNKNOWN_FIELD = 1,     /* "unknown_field" */
    PROTO_MSG_ERR_WRONG_TYPE = 2,        /* "wrong_type" */
    PROTO_MSG_ERR_OUT_OF_RANGE = 3,      /* "out_of_range" */
    PROTO_MSG_ERR_BAD_VALUE = 4,         /* "bad_value": bad enum name, pattern, duplicate */
    PROTO_MSG_ERR_INCONSISTENT = 5,      /* "inconsistent": patch clashes with the live state */
    PROTO_MSG_ERR_MISSING_FIELD = 6,     /* "missing_field" */
    PROTO_MSG_ERR_MALFORMED_JSON = 7,    /* "malformed_json": syntax, trailing bytes, NUL byte */
    PROTO_MSG_ERR_MESSAGE_TOO_LARGE = 8, /* "message_too_large" */
    PROTO_MSG_ERR_NOT_AN_OBJECT = 9,     /* "not_an_object" */
    PROTO_MSG_ERR_UNKNOWN_TYPE = 10,     /* "unknown_type" */
    PROTO_MSG_ERR_INVALID_ENCODING = 11, /* "invalid_encoding": not UTF-8, or a binary message */
    PROTO_MSG_ERR_UNSUPPORTED_PROTOCOL = 12, /* "unsupported_protocol" */
    /* Produced by the server, never by the parser. */
    PROTO_MSG_ERR_FORBIDDEN = 20,     /* "forbidden": needs the controller role */
    PROTO_MSG_ERR_AUTH_FAILED = 21,   /* "auth_failed" */
    PROTO_MSG_ERR_RATE_LIMITED = 22,  /* "rate_limited" */
    PROTO_MSG_ERR_NOT_FOUND = 23,     /* "not_found": subscription or preset */
    PROTO_MSG_ERR_LIMIT_REACHED = 24, /* "limit_reached": too many clients, subscriptions */
    PROTO_MSG_ERR_INTERNAL = 25,      /* "internal" */
    PROTO_MSG_ERR_UNAVAILABLE = 26,   /* "unavailable": a shared world's store is unreachable */
};

/* The wire name of a code, or NULL for a value that is not a code. */
const char *proto_msg_error_name(int code);
/* The code whose wire name is the `length` bytes at `name` ("auth_failed"), or PROTO_MSG_OK for
 * none. The codes are not contiguous (12 is followed by 20). */
enum proto_msg_error_code proto_msg_error_code_named(const char *name, size_t length);

enum proto_msg_type {
    PROTO_MSG_NONE = 0, /* parse failed before the type was known */
    PROTO_MSG_HELLO,
    PROTO_MSG_AUTH,
    PROTO_MSG_GET_STATE,
    PROTO_MSG_SET,
    PROTO_MSG_SUBSCRIBE,
    PROTO_MSG_UNSUBSCRIBE,
    PROTO_MSG_SNAPSHOT,
    PROTO_MSG_PROBE,
    PROTO_MSG_LIST_PRESETS,
    PROTO_MSG_APPLY_PRESET,
    PROTO_MSG_STATS,
    PROTO_MSG_SET_WEATHER_MAP,
    PROTO_MSG_DESCRIBE,
    PROTO_MSG_APPLY_OBSERVATION,
};

/* "hello", "set", ...; NULL for PROTO_MSG_NONE or out-of-range values. */
const char *proto_msg_type_name(enum proto_msg_type type);

/* True for the types only a controller may send (set, apply_preset, set_weather_map,
 * apply_observation). */
bool proto_msg_needs_controller(enum proto_msg_type type);

enum proto_msg_role {
    PROTO_ROLE_NONE = 0, /* "no role given" where a role is optional */
    PROTO_ROLE_VIEWER = 1,
    PROTO_ROLE_CONTROLLER = 2,
};

enum proto_preset_kind {
    PROTO_PRESET_ATMOSPHERE = 0, /* config/atmosphere/: atmosphere.* */
    PROTO_PRESET_WEATHER = 1,    /* config/weather/: clouds.* and weather.*, with a transition */
};

/* The longest weather transition apply_preset accepts: a week of simulated time. */
#define PROTO_MSG_MAX_TRANSITION_S 604800.0

enum proto_probe_quantity {
    PROTO_PROBE_TRANSMITTANCE = 0,
    PROTO_PROBE_LUMINANCE = 1,
    PROTO_PROBE_ILLUMINANCE = 2,
};

struct proto_msg_limits {
    size_t max_message_bytes;
    int max_clients;
    uint32_t max_width, max_height;
    double max_fps;
    double control_messages_per_second;
    /* A set_weather_map message may be this large (a controller's only; others stay within
     * max_message_bytes). Below max_message_bytes it changes nothing. */
    size_t max_upload_bytes;
};

/* 65536 bytes, 64 clients, 3840x2160, 60 fps, 20 control messages per second, 2 MiB uploads. */
void proto_msg_limits_default(struct proto_msg_limits *limits);

/* The largest message a controller may send: max_upload_bytes, or max_message_bytes when that
 * is larger. */
size_t proto_msg_upload_limit(const struct proto_msg_limits *limits);

enum proto_msg_id_kind {
    PROTO_MSG_ID_NONE = 0,
    PROTO_MSG_ID_STRING = 1,
    PROTO_MSG_ID_INTEGER = 2,
};

/* A request id, echoed verbatim in the reply. */
struct proto_msg_id {
    enum proto_msg_id_kind kind;
    char text[PROTO_MSG_ID_MAX + 1]; /* STRING */
    int64_t number;                  /* INTEGER, |number| <= 2^53 - 1 */
};

enum proto_view_projection {
    PROTO_VIEW_PROJECTION_PERSPECTIVE = 0,     /* the camera's yaw, pitch and fov */
    PROTO_VIEW_PROJECTION_EQUIRECTANGULAR = 1, /* the whole sphere, 2:1, the yaw at the centre */
};

/* Each camera and exposure field is optional; an absent one follows the world state. */
struct proto_msg_view {
    bool has_altitude_km, has_yaw_deg, has_pitch_deg, has_fov_deg;
    double altitude_km, yaw_deg, pitch_deg, fov_deg;
    bool has_exposure_mode, has_ev100, has_compensation_ev;
    enum proto_exposure_mode exposure_mode;
    double ev100, compensation_ev;
    uint32_t width, height;
    double fps; /* default min(10, max_fps) already applied */
    enum proto_frame_format format;
    int quality;     /* JPEG quality 1..100 (PROTO_MSG_JPEG_QUALITY_DEFAULT when absent); 0 else */
    double max_kbps; /* a subscription's bandwidth bound, kilobits per second; 0: none */
    enum proto_view_projection projection;
};

struct proto_msg_probe {
    enum proto_probe_quantity quantity;
    /* Only those the quantity uses are set (others are 0): transmittance altitude_km, mu;
     * luminance altitude_km, view_zenith_deg, view_azimuth_deg, sun_zenith_deg; illuminance
     * sun_zenith_deg. */
    double altitude_km, mu, view_zenith_deg, view_azimuth_deg, sun_zenith_deg;
};

struct proto_client_msg {
    enum proto_msg_type type;
    struct proto_msg_id id; /* filled when valid, even when the rest of the message is not */
    union {
        struct {
            bool has_client;
            char client[PROTO_MSG_CLIENT_MAX + 1];
            int protocol;           /* 0 when absent */
            bool simulation_events; /* wants `simulation` events (false when absent) */
        } hello;
        struct {
            char token[PROTO_MSG_TOKEN_MAX + 1];
        } auth;
        struct {
            /* Owned (malloc'd): the patch validated field by field as it was parsed; the
             * caller applies it with proto_world_state_apply_patch, which checks the result
             * across fields. Set it to NULL to take ownership. */
            struct proto_world_patch *patch;
        } set;
        struct proto_msg_view view; /* subscribe, snapshot */
        struct {
            uint64_t subscription;
        } unsubscribe;
        struct proto_msg_probe probe;
        struct {
            enum proto_preset_kind kind;
            char name[PROTO_MSG_PRESET_NAME_MAX + 1]; /* apply_preset only */
            bool has_transition; /* apply_preset of a weather preset: "transition_s" given */
            double transition_s; /* simulated seconds, [0, PROTO_MSG_MAX_TRANSITION_S] */
        } preset;
        struct {
            /* Owned, decoded and validated; proto_client_msg_free frees it. */
            struct proto_weather_map weather_map;
            /* The members as given: the map's format and, 0 when absent, its size. */
            enum proto_weather_map_format weather_map_format;
            int weather_map_width, weather_map_height;
        };
        struct {
            char metar[PROTO_MSG_METAR_MAX + 1]; /* the report as sent, decoded by the server */
        } observation;
    };
};

struct proto_msg_parse_error {
    enum proto_msg_error_code code;   /* PROTO_MSG_OK on success; else the first failure's code */
    size_t offset;                    /* byte offset for malformed_json and invalid_encoding */
    char message[320];                /* one line for people; do not match on it */
    struct proto_field_errors fields; /* {JSON Pointer, reason, code} per failure */
};

/* Parses one client text message of `length` bytes (no terminator needed). Checks, in order:
 * size against limits->max_message_bytes (before parsing; a set_weather_map may reach
 * max_upload_bytes), NUL bytes, UTF-8, JSON syntax and
 * trailing bytes, object shape, "id", "type", then every field of that type. On success
 * returns PROTO_MSG_OK and fills *msg; otherwise returns the error code and fills *error, with
 * msg->type and msg->id set when they were readable. Always call proto_client_msg_free. */
enum proto_msg_error_code proto_msg_parse(const char *text, size_t length,
                                          const struct proto_msg_limits *limits,
                                          struct proto_client_msg *msg,
                                          struct proto_msg_parse_error *error);

void proto_client_msg_free(struct proto_client_msg *msg);

/* The client messages' JSON Schema (draft 2020-12), generated from the rows that parse them:
 * a oneOf over the message types keyed by "type", views sized by `limits`, a set's patch as
 * the world state's schema (proto_world_state_json_schema). What rows cannot say is left to the
 * server: hello's protocol version other than 1, a view's 2:1 equirectangular aspect and its
 * quality with a format other than jpeg. NULL
 * when memory is out; the caller deletes it. */
struct cJSON *proto_msg_json_schema(const struct proto_msg_limits *limits);

/* The camera and exposure a view renders with: the state's, overridden by the view's. */
void proto_msg_view_resolve(const struct proto_msg_view *view,
                            const struct proto_world_state *state,
                            struct proto_camera_state *camera,
                            struct proto_exposure_state *exposure);

/* JSON Pointers of the schema fields that differ between two states, in schema order. Fills
 * at most `max` and returns how many differ. */
size_t proto_msg_state_diff(const struct proto_world_state *before,
                            const struct proto_world_state *after,
                            char pointers[][PROTO_MSG_POINTER_MAX], size_t max);

/* ---- server messages ---------------------------------------------------------------------
 * Each builder returns a malloc'd, NUL-terminated compact JSON text, or NULL when an argument
 * is invalid (a non-finite number, an integer above 2^53 - 1, an unknown enum value, a name
 * that breaks its pattern) or memory runs out. `id` may be NULL or PROTO_MSG_ID_NONE: the
 * member is then left out. Free the text with free(). */

/* Replaces every number in a tree by raw text that reads back as the same double (cJSON's own
 * printing rounds to 15 digits: 2^53 - 1 would print as 9.00719925474099e+15). The tree is for
 * printing afterwards: its numbers are no longer cJSON numbers. false when a number is not
 * finite or memory is out. */
bool proto_json_exact_numbers(struct cJSON *json);

/* The capabilities this module can describe: every client message type and "png". */
const char *const *proto_msg_default_capabilities(size_t *count);

char *proto_msg_build_hello(const char *server_version, enum proto_msg_role role,
                            const char *const *capabilities, size_t capability_count,
                            const struct proto_msg_limits *limits);

char *proto_msg_build_state(const struct proto_msg_id *id, const struct proto_world_state *state);

/* The reply to describe: "schema" with the world state's JSON Schema (proto_world_state_json_schema)
 * as "state" and the client messages' (proto_msg_json_schema, for `limits`) as "messages". */
char *proto_msg_build_schema(const struct proto_msg_id *id, const struct proto_msg_limits *limits);

/* role: PROTO_ROLE_NONE leaves it out; the reply to a successful auth carries the new role. */
/* The reply to apply_observation: the new revision, the decoded report, the patch applied
 * and the groups left unmapped (each copied). */
char *proto_msg_build_observation(const struct proto_msg_id *id, uint64_t revision,
                                  const struct cJSON *report, const struct cJSON *patch,
                                  const struct cJSON *unmapped);
char *proto_msg_build_ack(const struct proto_msg_id *id, uint64_t revision,
                          enum proto_msg_role role);

/* fields may be NULL. Field codes must be proto_msg_error_code values. */
char *proto_msg_build_error(const struct proto_msg_id *id, enum proto_msg_error_code code,
                            const char *message, const struct proto_field_errors *fields);

/* The error reply for a failed proto_msg_parse, echoing msg->id when it was readable. */
char *proto_msg_build_parse_error(const struct proto_client_msg *msg,
                                  const struct proto_msg_parse_error *error);

/* The view is written normalized: fps and format resolved, absent camera and exposure fields
 * left out (they follow the world state). */
char *proto_msg_build_subscribed(const struct proto_msg_id *id, uint64_t subscription,
                                 const struct proto_msg_view *view);

/* Announces the binary frame sent right after it: for a subscription (subscription >= 1, id
 * NULL) or for a snapshot request (subscription 0, id the request's). */
char *proto_msg_build_frame(const struct proto_msg_id *id, uint64_t subscription,
                            uint64_t frame_number);

/* `pointers` name the changed fields (JSON Pointers into the state, "/sun/elevation_deg"); the
 * event's "values" holds each one's new value read from `state`, written as get_state writes
 * it. A pointer that is no field of the state ("/weather/map") is listed in "changed" only.
 * `by` names who changed it (a client's hello name, or its role). */
char *proto_msg_build_state_changed(uint64_t revision, const char *const *pointers, size_t count,
                                    const struct proto_world_state *state, const char *by);

/* The fields the simulation itself moved since the last such event (the clock, the sun and
 * moon from the ephemeris, a transition's progress), as "changed" and "values" are in
 * state_changed, with the revision they belong to and the simulated time. Sent only to
 * clients whose hello asked for simulation_events. */
char *proto_msg_build_simulation_event(uint64_t revision, const char *const *pointers, size_t count,
                                       const struct proto_world_state *state);

char *proto_msg_build_presets(const struct proto_msg_id *id, enum proto_preset_kind kind,
                              const char *const *names, size_t count);

struct proto_msg_probe_result {
    enum proto_probe_quantity quantity;
    double rgb[3];           /* transmittance (unitless) or luminance (cd/m^2) */
    double sun_lux, sky_lux; /* illuminance */
    /* Luminance and illuminance: the multiple scattering they were computed with, "fast",
     * "blending" or "converged" (NULL: left out). */
    const char *multiple_scattering;
};

char *proto_msg_build_probe_result(const struct proto_msg_id *id,
                                   const struct proto_msg_probe_result *result);

struct proto_msg_pass_time {
    const char *name; /* [a-z0-9_-]{1,64}, unique */
    double ms;        /* >= 0 */
};

/* One of the asking connection's subscriptions: what its frames cost and the rate and JPEG
 * quality they are made at now (lowered under max_kbps). */
struct proto_msg_subscription_stats {
    uint64_t subscription; /* >= 1 */
    uint64_t bytes_sent;   /* binary messages, headers included */
    double fps;            /* > 0: the effective rate */
    int quality;           /* the effective JPEG quality; 0 for other formats */
    double max_kbps;       /* 0: none */
};

/* Where the converged multiple scattering stands: its weight in frames [0, 1], the progress of
 * its build [0, 1], and the order being computed (0: none). */
struct proto_msg_multiple_scattering {
    double weight, progress;
    int order;
};

struct proto_msg_stats {
    double fps;  /* >= 0 */
    int clients; /* >= 0 */
    const struct proto_msg_pass_time *passes;
    size_t pass_count;           /* <= PROTO_MSG_MAX_PASSES */
    double lut_rebuild_progress; /* [0, 1]; 1 when no rebuild is under way */
    double simulation_time_s;    /* the simulated clock, seconds since 1970 UTC */
    const struct proto_msg_subscription_stats *subscriptions;
    size_t subscription_count;
    /* The converged multiple scattering's refinement (NULL: left out). */
    const struct proto_msg_multiple_scattering *multiple_scattering;
    /* The resolution the last frame's clouds were traced at, the level clouds.quality.resolution
     * "auto" chose (PROTO_CLOUD_RESOLUTION_FULL .. SIXTYFOURTH; NULL: left out). */
    const enum proto_cloud_resolution *cloud_resolution;
    /* The low layer's march steps of that frame (clouds.quality.primary_steps, or what "auto"
     * chose); 0: left out. */
    int cloud_primary_steps;
};

char *proto_msg_build_stats(const struct proto_msg_id *id, const struct proto_msg_stats *stats);

#endif
