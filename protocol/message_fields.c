/* The client messages' members as schema-engine rows: one table per message type over struct
 * proto_client_msg (messages.h), and the view object's over struct proto_msg_view. The engine
 * checks names, duplicates, types, ranges, enum names and required members; messages.c and
 * message_view.c check what a row cannot say (the caller members, the protocol version, the
 * preset name's pattern, a view's aspect). */
#include "field_schema.h"
#include "message_parser.h"
#include "message_names.h"

#include <limits.h>
#include <string.h>

/* The engine writes INT rows through int, INT64 rows through int64_t, ENUM rows through int:
 * the members below are those types or their unsigned twins, which may alias them. */
_Static_assert(sizeof(uint32_t) == sizeof(int), "view sizes are written as int");
_Static_assert(sizeof(uint64_t) == sizeof(int64_t), "subscriptions are written as int64_t");
_Static_assert(sizeof(enum proto_frame_format) == sizeof(int), "enum field size");
_Static_assert(sizeof(enum proto_view_projection) == sizeof(int), "enum field size");
_Static_assert(sizeof(enum proto_probe_quantity) == sizeof(int), "enum field size");
_Static_assert(sizeof(enum proto_preset_kind) == sizeof(int), "enum field size");
_Static_assert(sizeof(enum proto_weather_map_format) == sizeof(int), "enum field size");

static const char *const weather_map_format_names[] = {
    [PROTO_WEATHER_MAP_RGBA8] = "rgba8", [PROTO_WEATHER_MAP_PNG] = "png"
};

/* clang-format off */
#define MSG(member) offsetof(struct proto_client_msg, member)
#define NAMES(array) .enum_names = array, .enum_count = (int)COUNT_OF(array), \
                     .max = (double)COUNT_OF(array) - 1

/* ---- each message's members -------------------------------------------------------------- */

static const struct proto_field_desc hello_rows[] = {
    {.path = "client", .type = PROTO_FIELD_TYPE_STRING, .offset = MSG(hello.client),
     .capacity = PROTO_MSG_CLIENT_MAX + 1,
     .description = "the client's name and version; other clients' events name it in \"by\""},
    {.path = "protocol", .type = PROTO_FIELD_TYPE_INT, .offset = MSG(hello.protocol), .min = 1,
     .max = INT_MAX, .description = "the protocol version the client speaks; this server speaks 1"},
    {.path = "simulation_events", .type = PROTO_FIELD_TYPE_BOOL,
     .offset = MSG(hello.simulation_events),
     .description = "also send `simulation` events: at most once a second, the fields the "
                    "simulation moved (clock, sun, moon, transitions) with their values"},
};

static const struct proto_field_desc auth_rows[] = {
    {.path = "token", .type = PROTO_FIELD_TYPE_STRING, .offset = MSG(auth.token), .min = 1,
     .capacity = PROTO_MSG_TOKEN_MAX + 1, .required = true,
     .description = "the controller token of the server's configuration"},
};

static const struct proto_field_desc unsubscribe_rows[] = {
    {.path = "subscription", .type = PROTO_FIELD_TYPE_INT64, .offset = MSG(unsubscribe.subscription),
     .min = 1, .max = (double)PROTO_MSG_MAX_SAFE_INTEGER, .required = true,
     .description = "the number a subscribed reply gave"},
};

#define PRESET_KIND                                                                              \
    {.path = "kind", .type = PROTO_FIELD_TYPE_ENUM, .offset = MSG(preset.kind),                    \
     NAMES(proto_msg_preset_kind_names), .required = true,                                         \
     .description = "atmosphere: presets of atmosphere.*; weather: of clouds.* and weather.*"}

static const struct proto_field_desc list_presets_rows[] = {PRESET_KIND};

static const struct proto_field_desc observation_rows[] = {
    {.path = "metar", .type = PROTO_FIELD_TYPE_STRING, .offset = MSG(observation.metar), .min = 1,
     .capacity = PROTO_MSG_METAR_MAX + 1, .required = true,
     .description = "a METAR or SPECI report (WMO FM 15 / FM 16), decoded and applied to the "
                    "weather"},
};

static const struct proto_field_desc apply_preset_rows[] = {
    PRESET_KIND,
    {.path = "transition_s", .type = PROTO_FIELD_TYPE_NUMBER, .offset = MSG(preset.transition_s),
     .max = PROTO_MSG_MAX_TRANSITION_S,
     .description = "weather presets only: simulated seconds the weather takes to reach the "
                    "preset's; 0 or absent: at once, s"},
};

/* The probe's parameters, each required by the quantities that use it and unknown to the
 * others: one table per quantity, and one with all of them, none required, for a message whose
 * quantity is missing or not a name. */
#define QUANTITY(required_)                                                                      \
    {.path = "quantity", .type = PROTO_FIELD_TYPE_ENUM, .offset = MSG(probe.quantity),             \
     NAMES(proto_msg_quantity_names), .required = required_,                                       \
     .description = "transmittance to the top of the atmosphere, luminance of the sky before "  \
                    "exposure, or illuminance on the ground"}
#define ALTITUDE(required_)                                                                      \
    {.path = "altitude_km", .type = PROTO_FIELD_TYPE_NUMBER, .offset = MSG(probe.altitude_km),     \
     .max = 1e5, .required = required_, .description = "altitude above the ground, km"}
#define MU(required_)                                                                            \
    {.path = "mu", .type = PROTO_FIELD_TYPE_NUMBER, .offset = MSG(probe.mu), .min = -1, .max = 1, \
     .required = required_, .description = "cosine of the view direction's zenith angle"}
#define VIEW_ZENITH(required_)                                                                   \
    {.path = "view_zenith_deg", .type = PROTO_FIELD_TYPE_NUMBER,                                   \
     .offset = MSG(probe.view_zenith_deg), .max = 180, .required = required_,                    \
     .description = "zenith angle of the view direction, degrees"}
#define VIEW_AZIMUTH(required_)                                                                  \
    {.path = "view_azimuth_deg", .type = PROTO_FIELD_TYPE_NUMBER,                                  \
     .offset = MSG(probe.view_azimuth_deg), .min = -360, .max = 360, .required = required_,      \
     .description = "azimuth of the view direction from north through east, degrees"}
#define SUN_ZENITH(required_)                                                                    \
    {.path = "sun_zenith_deg", .type = PROTO_FIELD_TYPE_NUMBER,                                    \
     .offset = MSG(probe.sun_zenith_deg), .max = 180, .required = required_,                     \
     .description = "zenith angle of the sun, degrees"}

static const struct proto_field_desc probe_rows[] = {
    QUANTITY(true), ALTITUDE(false), MU(false), VIEW_ZENITH(false), VIEW_AZIMUTH(false),
    SUN_ZENITH(false),
};
static const struct proto_field_desc transmittance_rows[] = {QUANTITY(true), ALTITUDE(true),
                                                           MU(true)};
static const struct proto_field_desc luminance_rows[] = {
    QUANTITY(true), ALTITUDE(true), VIEW_ZENITH(true), VIEW_AZIMUTH(true), SUN_ZENITH(true),
};
static const struct proto_field_desc illuminance_rows[] = {QUANTITY(true), SUN_ZENITH(true)};

/* width and height: required for raw texels, read from the file (and checked) for a PNG. */
#define MAP_SIDE(name, member, required_, what)                                                  \
    {.path = name, .type = PROTO_FIELD_TYPE_INT, .offset = MSG(member), .min = 1,                  \
     .max = PROTO_WEATHER_MAP_MAX_SIDE, .required = required_,                                     \
     .description = what "; required for rgba8, for png the file's own if given"}
#define MAP_FORMAT                                                                               \
    {.path = "format", .type = PROTO_FIELD_TYPE_ENUM, .offset = MSG(weather_map_format),           \
     NAMES(weather_map_format_names), .required = true,                                          \
     .description = "rgba8: width x height x 4 bytes of texels; png: a PNG file"}
static const struct proto_field_desc weather_map_rows[] = {
    MAP_FORMAT, MAP_SIDE("width", weather_map_width, false, "texels per row"),
    MAP_SIDE("height", weather_map_height, false, "rows of texels"),
};
static const struct proto_field_desc rgba8_map_rows[] = {
    MAP_FORMAT, MAP_SIDE("width", weather_map_width, true, "texels per row"),
    MAP_SIDE("height", weather_map_height, true, "rows of texels"),
};
/* clang-format on */

/* ---- the tables as schemas --------------------------------------------------------------- */

static const char *const envelope[] = { "type", "id" };
static const char *const with_patch[] = { "type", "id", "patch" };
static const char *const with_view[] = { "type", "id", "view" };
static const char *const with_name[] = { "type", "id", "name" };
static const char *const with_data[] = { "type", "id", "data" };

/* clang-format off */
#define SCHEMA(rows, callers)                                                                    \
    {.fields = rows, .count = COUNT_OF(rows), .caller_members = callers,                        \
     .caller_member_count = COUNT_OF(callers), .unique_members = true}
#define NO_ROWS(callers)                                                                         \
    {.caller_members = callers, .caller_member_count = COUNT_OF(callers), .unique_members = true}
/* clang-format on */

static const struct proto_schema hello_schema = SCHEMA(hello_rows, envelope);
static const struct proto_schema auth_schema = SCHEMA(auth_rows, envelope);
static const struct proto_schema envelope_schema = NO_ROWS(envelope);
static const struct proto_schema set_schema = NO_ROWS(with_patch);
static const struct proto_schema view_message_schema = NO_ROWS(with_view);
static const struct proto_schema unsubscribe_schema = SCHEMA(unsubscribe_rows, envelope);
static const struct proto_schema probe_schema = SCHEMA(probe_rows, envelope);
static const struct proto_schema probe_variants[] = {
    [PROTO_PROBE_TRANSMITTANCE] = SCHEMA(transmittance_rows, envelope),
    [PROTO_PROBE_LUMINANCE] = SCHEMA(luminance_rows, envelope),
    [PROTO_PROBE_ILLUMINANCE] = SCHEMA(illuminance_rows, envelope),
};
static const struct proto_schema list_presets_schema = SCHEMA(list_presets_rows, envelope);
static const struct proto_schema apply_preset_schema = SCHEMA(apply_preset_rows, with_name);
static const struct proto_schema observation_schema = SCHEMA(observation_rows, envelope);
static const struct proto_schema weather_map_schema = SCHEMA(weather_map_rows, with_data);
static const struct proto_schema weather_map_variants[] = {
    [PROTO_WEATHER_MAP_RGBA8] = SCHEMA(rgba8_map_rows, with_data),
    [PROTO_WEATHER_MAP_PNG] = SCHEMA(weather_map_rows, with_data),
};

_Static_assert(COUNT_OF(probe_variants) == PROTO_MSG_QUANTITY_NAMES, "a table per quantity");
_Static_assert(COUNT_OF(weather_map_variants) == COUNT_OF(weather_map_format_names),
               "a table per format");

/* clang-format off */
static const struct msg_schema message_schemas[] = {
    [PROTO_MSG_HELLO] = {&hello_schema, NULL, NULL, 0, false},
    [PROTO_MSG_AUTH] = {&auth_schema, NULL, NULL, 0, false},
    [PROTO_MSG_GET_STATE] = {&envelope_schema, NULL, NULL, 0, false},
    [PROTO_MSG_SET] = {&set_schema, NULL, NULL, 0, false},
    [PROTO_MSG_SUBSCRIBE] = {&view_message_schema, NULL, NULL, 0, false},
    [PROTO_MSG_UNSUBSCRIBE] = {&unsubscribe_schema, NULL, NULL, 0, false},
    [PROTO_MSG_SNAPSHOT] = {&view_message_schema, NULL, NULL, 0, true},
    [PROTO_MSG_PROBE] = {&probe_schema, "quantity", probe_variants, COUNT_OF(probe_variants),
                         false},
    [PROTO_MSG_LIST_PRESETS] = {&list_presets_schema, NULL, NULL, 0, false},
    [PROTO_MSG_APPLY_PRESET] = {&apply_preset_schema, NULL, NULL, 0, false},
    [PROTO_MSG_STATS] = {&envelope_schema, NULL, NULL, 0, false},
    [PROTO_MSG_SET_WEATHER_MAP] = {&weather_map_schema, "format", weather_map_variants,
                                 COUNT_OF(weather_map_variants), false},
    [PROTO_MSG_DESCRIBE] = {&envelope_schema, NULL, NULL, 0, false},
    [PROTO_MSG_APPLY_OBSERVATION] = {&observation_schema, NULL, NULL, 0, false},
};
/* clang-format on */

const struct msg_schema *msg_schema_of(enum proto_msg_type type)
{
    if ((int)type <= 0 || (size_t)type >= COUNT_OF(message_schemas))
        return NULL;
    return &message_schemas[type];
}

const struct proto_schema *msg_schema_variant(const struct msg_schema *kind, const cJSON *message)
{
    if (!kind->discriminator)
        return kind->schema;
    const cJSON *value = cJSON_GetObjectItemCaseSensitive(message, kind->discriminator);
    const struct proto_field_desc *row = NULL;
    for (size_t i = 0; i < kind->schema->count && !row; i++)
        if (strcmp(kind->schema->fields[i].path, kind->discriminator) == 0)
            row = &kind->schema->fields[i];
    for (size_t i = 0; row && cJSON_IsString(value) && i < kind->variant_count; i++)
        if (row->enum_names[i] && strcmp(row->enum_names[i], value->valuestring) == 0)
            return &kind->variants[i];
    return kind->schema;
}

/* ---- the view object --------------------------------------------------------------------- */

#define VIEW(member) offsetof(struct proto_msg_view, member)
/* A camera or exposure member: its range, names and description are the world state's row of
 * the same path (filled in by msg_view_schema). */
/* clang-format off */
#define TWIN(path_, type_, member)                                                               \
    {.path = path_, .type = type_, .offset = VIEW(member)}

static const struct proto_field_desc view_rows[MSG_VIEW_ROWS] = {
    [MSG_VIEW_ALTITUDE] = TWIN("camera.altitude_km", PROTO_FIELD_TYPE_NUMBER, altitude_km),
    [MSG_VIEW_YAW] = TWIN("camera.yaw_deg", PROTO_FIELD_TYPE_NUMBER, yaw_deg),
    [MSG_VIEW_PITCH] = TWIN("camera.pitch_deg", PROTO_FIELD_TYPE_NUMBER, pitch_deg),
    [MSG_VIEW_FOV] = TWIN("camera.fov_deg", PROTO_FIELD_TYPE_NUMBER, fov_deg),
    [MSG_VIEW_WIDTH] = {.path = "width", .type = PROTO_FIELD_TYPE_INT, .offset = VIEW(width),
                        .min = 1, .required = true, .description = "pixels, up to max_width"},
    [MSG_VIEW_HEIGHT] = {.path = "height", .type = PROTO_FIELD_TYPE_INT, .offset = VIEW(height),
                         .min = 1, .required = true, .description = "pixels, up to max_height"},
    [MSG_VIEW_FPS] = {.path = "fps", .type = PROTO_FIELD_TYPE_NUMBER, .offset = VIEW(fps),
                      .exclusive_min = true,
                      .description = "frames per second, up to max_fps; absent: 10 or max_fps"},
    [MSG_VIEW_EXPOSURE_MODE] = TWIN("exposure.mode", PROTO_FIELD_TYPE_ENUM, exposure_mode),
    [MSG_VIEW_EV100] = TWIN("exposure.ev100", PROTO_FIELD_TYPE_NUMBER, ev100),
    [MSG_VIEW_COMPENSATION] = TWIN("exposure.compensation_ev", PROTO_FIELD_TYPE_NUMBER,
                                   compensation_ev),
    [MSG_VIEW_FORMAT] = {.path = "format", .type = PROTO_FIELD_TYPE_ENUM, .offset = VIEW(format),
                         NAMES(proto_msg_format_names),
                         .description = "png: 8-bit sRGB, exposed; png16: 16-bit linear light; "
                                        "jpeg: the 8-bit frame as a JPEG"},
    [MSG_VIEW_QUALITY] = {.path = "quality", .type = PROTO_FIELD_TYPE_INT, .offset = VIEW(quality),
                          .min = 1, .max = 100,
                          .description = "JPEG quality, only with format jpeg; absent: 85"},
    [MSG_VIEW_MAX_KBPS] = {.path = "max_kbps", .type = PROTO_FIELD_TYPE_NUMBER,
                           .offset = VIEW(max_kbps), .exclusive_min = true,
                           .max = PROTO_MSG_MAX_KBPS,
                           .description = "a subscription's bound on the frames' bandwidth, "
                                          "kilobits per second: the server lowers the frame rate "
                                          "(and a JPEG's quality, down to 50) to keep within it"},
    [MSG_VIEW_PROJECTION] = {.path = "projection", .type = PROTO_FIELD_TYPE_ENUM,
                             .offset = VIEW(projection), NAMES(proto_msg_projection_names),
                             .description = "perspective: the camera's; equirectangular: the "
                                            "whole sphere, 2:1"},
};
/* clang-format on */

void msg_view_schema(const struct proto_msg_limits *limits, struct msg_view_schema *out)
{
    memcpy(out->rows, view_rows, sizeof view_rows);
    for (size_t i = 0; i < MSG_VIEW_ROWS; i++) {
        struct proto_field_desc *row = &out->rows[i];
        const struct proto_field_desc *twin = row->description
                                                  ? NULL
                                                  : proto_world_state_find_field(row->path);
        if (twin) {
            row->min = twin->min;
            row->max = twin->max;
            row->enum_names = twin->enum_names;
            row->enum_count = twin->enum_count;
            row->description = twin->description;
        }
    }
    out->rows[MSG_VIEW_WIDTH].max = limits->max_width;
    out->rows[MSG_VIEW_HEIGHT].max = limits->max_height;
    out->rows[MSG_VIEW_FPS].max = limits->max_fps;
    out->schema = (struct proto_schema){ .fields = out->rows,
                                         .count = MSG_VIEW_ROWS,
                                         .unique_members = true };
}
