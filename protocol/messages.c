#include "messages.h"
#include "field_errors.h"
#include "field_schema.h"
#include "message_names.h"
#include "message_parser.h"
#include "metar.h"

#include <cjson/cJSON.h>

#include <float.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

_Static_assert((int)PROTO_MSG_ERR_UNKNOWN_FIELD == (int)PROTO_FIELD_UNKNOWN, "shared code");
_Static_assert(PROTO_MSG_METAR_MAX == PROTO_METAR_MAX_LENGTH, "apply_observation's report");
_Static_assert((int)PROTO_MSG_ERR_WRONG_TYPE == (int)PROTO_FIELD_WRONG_TYPE, "shared code");
_Static_assert((int)PROTO_MSG_ERR_OUT_OF_RANGE == (int)PROTO_FIELD_OUT_OF_RANGE, "shared code");
_Static_assert((int)PROTO_MSG_ERR_BAD_VALUE == (int)PROTO_FIELD_BAD_VALUE, "shared code");
_Static_assert((int)PROTO_MSG_ERR_INCONSISTENT == (int)PROTO_FIELD_INCONSISTENT, "shared code");
_Static_assert((int)PROTO_MSG_ERR_MISSING_FIELD == (int)PROTO_FIELD_MISSING, "shared code");
_Static_assert(PROTO_MSG_POINTER_MAX == sizeof(((struct proto_field_error *)NULL)->pointer),
               "pointer capacity");

/* ---- constant tables -------------------------------------------------------------------- */

static const char *const error_names[] = {
    [PROTO_MSG_OK] = "ok",
    [PROTO_MSG_ERR_UNKNOWN_FIELD] = "unknown_field",
    [PROTO_MSG_ERR_WRONG_TYPE] = "wrong_type",
    [PROTO_MSG_ERR_OUT_OF_RANGE] = "out_of_range",
    [PROTO_MSG_ERR_BAD_VALUE] = "bad_value",
    [PROTO_MSG_ERR_INCONSISTENT] = "inconsistent",
    [PROTO_MSG_ERR_MISSING_FIELD] = "missing_field",
    [PROTO_MSG_ERR_MALFORMED_JSON] = "malformed_json",
    [PROTO_MSG_ERR_MESSAGE_TOO_LARGE] = "message_too_large",
    [PROTO_MSG_ERR_NOT_AN_OBJECT] = "not_an_object",
    [PROTO_MSG_ERR_UNKNOWN_TYPE] = "unknown_type",
    [PROTO_MSG_ERR_INVALID_ENCODING] = "invalid_encoding",
    [PROTO_MSG_ERR_UNSUPPORTED_PROTOCOL] = "unsupported_protocol",
    [PROTO_MSG_ERR_FORBIDDEN] = "forbidden",
    [PROTO_MSG_ERR_AUTH_FAILED] = "auth_failed",
    [PROTO_MSG_ERR_RATE_LIMITED] = "rate_limited",
    [PROTO_MSG_ERR_NOT_FOUND] = "not_found",
    [PROTO_MSG_ERR_LIMIT_REACHED] = "limit_reached",
    [PROTO_MSG_ERR_INTERNAL] = "internal",
    [PROTO_MSG_ERR_UNAVAILABLE] = "unavailable",
};

static const char *const type_names[] = {
    [PROTO_MSG_HELLO] = "hello",
    [PROTO_MSG_AUTH] = "auth",
    [PROTO_MSG_GET_STATE] = "get_state",
    [PROTO_MSG_SET] = "set",
    [PROTO_MSG_SUBSCRIBE] = "subscribe",
    [PROTO_MSG_UNSUBSCRIBE] = "unsubscribe",
    [PROTO_MSG_SNAPSHOT] = "snapshot",
    [PROTO_MSG_PROBE] = "probe",
    [PROTO_MSG_LIST_PRESETS] = "list_presets",
    [PROTO_MSG_APPLY_PRESET] = "apply_preset",
    [PROTO_MSG_STATS] = "stats",
    [PROTO_MSG_SET_WEATHER_MAP] = "set_weather_map",
    [PROTO_MSG_DESCRIBE] = "describe",
    [PROTO_MSG_APPLY_OBSERVATION] = "apply_observation",
};

static const char *const capabilities[] = {
    "hello",        "auth",
    "get_state",    "set",
    "subscribe",    "unsubscribe",
    "snapshot",     "probe",
    "list_presets", "apply_preset",
    "stats",        "set_weather_map",
    "describe",     "apply_observation",
    "png",          "png16",
    "jpeg",         "equirectangular",
};

const char *const proto_msg_role_names[PROTO_MSG_ROLE_NAMES] = {
    [PROTO_ROLE_VIEWER] = "viewer", [PROTO_ROLE_CONTROLLER] = "controller"
};
const char *const proto_msg_quantity_names[PROTO_MSG_QUANTITY_NAMES] = { "transmittance",
                                                                         "luminance",
                                                                         "illuminance" };
const char *const proto_msg_preset_kind_names[PROTO_MSG_PRESET_KIND_NAMES] = { "atmosphere",
                                                                               "weather" };
const char *const proto_msg_format_names[PROTO_MSG_FORMAT_NAMES] = {
    [PROTO_FRAME_FORMAT_PNG] = "png",
    [PROTO_FRAME_FORMAT_PNG16] = "png16",
    [PROTO_FRAME_FORMAT_JPEG] = "jpeg"
};
const char *const proto_msg_projection_names[PROTO_MSG_PROJECTION_NAMES] = {
    [PROTO_VIEW_PROJECTION_PERSPECTIVE] = "perspective",
    [PROTO_VIEW_PROJECTION_EQUIRECTANGULAR] = "equirectangular"
};

/* ---- small helpers ---------------------------------------------------------------------- */

const char *proto_msg_error_name(int code)
{
    if (code < 0 || (size_t)code >= COUNT_OF(error_names))
        return NULL;
    return error_names[code];
}

enum proto_msg_error_code proto_msg_error_code_named(const char *name, size_t length)
{
    for (size_t i = 1; i < COUNT_OF(error_names); i++)
        if (error_names[i] && strlen(error_names[i]) == length &&
            memcmp(error_names[i], name, length) == 0)
            return (enum proto_msg_error_code)i;
    return PROTO_MSG_OK;
}

const char *proto_msg_type_name(enum proto_msg_type type)
{
    if ((int)type <= 0 || (size_t)type >= COUNT_OF(type_names))
        return NULL;
    return type_names[type];
}

bool proto_msg_needs_controller(enum proto_msg_type type)
{
    return type == PROTO_MSG_SET || type == PROTO_MSG_APPLY_PRESET ||
           type == PROTO_MSG_SET_WEATHER_MAP || type == PROTO_MSG_APPLY_OBSERVATION;
}

void proto_msg_limits_default(struct proto_msg_limits *limits)
{
    limits->max_message_bytes = 65536;
    limits->max_clients = 64;
    limits->max_width = 3840;
    limits->max_height = 2160;
    limits->max_fps = 60;
    limits->control_messages_per_second = 20;
    limits->max_upload_bytes = 2u << 20;
}

const char *const *proto_msg_default_capabilities(size_t *count)
{
    if (count)
        *count = COUNT_OF(capabilities);
    return capabilities;
}

bool proto_msg_preset_name_is_valid(const char *name)
{
    size_t length = strlen(name);
    if (length < 1 || length > PROTO_MSG_PRESET_NAME_MAX)
        return false;
    return strspn(name, "abcdefghijklmnopqrstuvwxyz0123456789_-") == length;
}

/* Length of the valid UTF-8 sequence at s (at most `left` bytes), 0 when invalid. Rejects
 * overlong forms, surrogates and code points above U+10FFFF. */
size_t proto_msg_utf8_sequence(const unsigned char *s, size_t left)
{
    if (s[0] < 0x80)
        return 1;
    size_t length;
    unsigned min, max;
    if (s[0] >= 0xC2 && s[0] <= 0xDF)
        length = 2, min = 0x80, max = 0xBF;
    else if (s[0] >= 0xE0 && s[0] <= 0xEF)
        length = 3, min = s[0] == 0xE0 ? 0xA0 : 0x80, max = s[0] == 0xED ? 0x9F : 0xBF;
    else if (s[0] >= 0xF0 && s[0] <= 0xF4)
        length = 4, min = s[0] == 0xF0 ? 0x90 : 0x80, max = s[0] == 0xF4 ? 0x8F : 0xBF;
    else
        return 0;
    if (left < length || s[1] < min || s[1] > max)
        return 0;
    for (size_t i = 2; i < length; i++) {
        if ((s[i] & 0xC0) != 0x80)
            return 0;
    }
    return length;
}

/* Offset of the first byte that is not valid UTF-8, or `length` when all are. */
static size_t utf8_invalid_offset(const char *text, size_t length)
{
    size_t i = 0;
    while (i < length) {
        size_t n = proto_msg_utf8_sequence((const unsigned char *)text + i, length - i);
        if (n == 0)
            return i;
        i += n;
    }
    return length;
}

/* cJSON decodes "\u0000" to a terminator, silently truncating the string; find one in valid
 * JSON text. Returns its offset or `length`. */
static size_t escaped_nul_offset(const char *text, size_t length)
{
    bool in_string = false;
    for (size_t i = 0; i < length; i++) {
        if (!in_string) {
            in_string = text[i] == '"';
        } else if (text[i] == '"') {
            in_string = false;
        } else if (text[i] == '\\') {
            if (i + 5 < length && text[i + 1] == 'u' && memcmp(text + i + 2, "0000", 4) == 0)
                return i;
            i++;
        }
    }
    return length;
}

static size_t nul_offset(const char *text, size_t length)
{
    const char *nul = memchr(text, '\0', length);
    return nul ? (size_t)(nul - text) : length;
}

/* ---- parsing ---------------------------------------------------------------------------- */

static void parse_id(struct parser *p, const cJSON *item, struct proto_msg_id *id)
{
    if (cJSON_IsString(item)) {
        if (parser_read_string(p, item, "/id", 1, PROTO_MSG_ID_MAX, id->text))
            id->kind = PROTO_MSG_ID_STRING;
    } else if (cJSON_IsNumber(item)) {
        if (parser_read_integer(p, item, "/id", -PROTO_MSG_MAX_SAFE_INTEGER,
                                PROTO_MSG_MAX_SAFE_INTEGER, &id->number))
            id->kind = PROTO_MSG_ID_INTEGER;
    } else {
        parser_fail(p, PROTO_MSG_ERR_WRONG_TYPE, "/id", "expected a string or an integer, got %s",
                    proto_json_type_name(item));
    }
}

/* [a-z0-9_-]{1,64}: a pattern, which rows do not have. */
static void parse_preset_name(struct parser *p, struct proto_client_msg *msg)
{
    const cJSON *item = cJSON_GetObjectItemCaseSensitive(p->root, "name");
    if (!parser_require(p, item, "/name"))
        return;
    if (!cJSON_IsString(item))
        parser_fail(p, PROTO_MSG_ERR_WRONG_TYPE, "/name", "expected a string, got %s",
                    proto_json_type_name(item));
    else if (!proto_msg_preset_name_is_valid(item->valuestring))
        parser_fail(p, PROTO_MSG_ERR_BAD_VALUE, "/name", "must match [a-z0-9_-]{1,64}");
    else
        memcpy(msg->preset.name, item->valuestring, strlen(item->valuestring) + 1);
}

/* What the rows cannot say about each type, once they ran. */
static void check_members(struct parser *p, struct proto_client_msg *msg)
{
    const cJSON *item;
    int kind;
    switch (msg->type) {
    case PROTO_MSG_HELLO:
        msg->hello.has_client = cJSON_GetObjectItemCaseSensitive(p->root, "client") != NULL;
        if (msg->hello.protocol != 0 && msg->hello.protocol != PROTO_PROTOCOL_VERSION)
            parser_fail(p, PROTO_MSG_ERR_UNSUPPORTED_PROTOCOL, "/protocol",
                        "this server speaks protocol %d, got %d", PROTO_PROTOCOL_VERSION,
                        msg->hello.protocol);
        break;
    case PROTO_MSG_SET:
        item = cJSON_GetObjectItemCaseSensitive(p->root, "patch");
        if (!parser_require(p, item, "/patch"))
            break;
        if (!cJSON_IsObject(item)) {
            parser_fail(p, PROTO_MSG_ERR_WRONG_TYPE, "/patch", "expected an object, got %s",
                        proto_json_type_name(item));
        } else {
            struct proto_world_patch *patch = malloc(sizeof *patch);
            if (!patch)
                parser_fail(p, PROTO_MSG_ERR_BAD_VALUE, "/patch", "out of memory");
            else if (proto_world_patch_compile(item, "/patch", patch, &p->error->fields) &&
                     p->error->fields.total == 0)
                msg->set.patch = patch;
            else
                free(patch);
        }
        break;
    case PROTO_MSG_SUBSCRIBE:
    case PROTO_MSG_SNAPSHOT:
        item = cJSON_GetObjectItemCaseSensitive(p->root, "view");
        if (parser_require(p, item, "/view"))
            msg_parse_view(p, item, "/view", &msg->view);
        break;
    case PROTO_MSG_APPLY_PRESET:
        parse_preset_name(p, msg);
        item = cJSON_GetObjectItemCaseSensitive(p->root, "kind");
        kind = cJSON_IsString(item)
                   ? msg_find_name(proto_msg_preset_kind_names,
                                   COUNT_OF(proto_msg_preset_kind_names), item->valuestring)
                   : -1;
        msg->preset.has_transition = cJSON_GetObjectItemCaseSensitive(p->root, "transition_s") !=
                                     NULL;
        if (msg->preset.has_transition && kind >= 0 && kind != PROTO_PRESET_WEATHER)
            parser_fail(p, PROTO_MSG_ERR_BAD_VALUE, "/transition_s",
                        "only weather presets have a transition");
        break;
    case PROTO_MSG_SET_WEATHER_MAP:
        msg_parse_weather_map(p, msg);
        break;
    case PROTO_MSG_NONE:
    case PROTO_MSG_AUTH:
    case PROTO_MSG_GET_STATE:
    case PROTO_MSG_UNSUBSCRIBE:
    case PROTO_MSG_PROBE:
    case PROTO_MSG_LIST_PRESETS:
    case PROTO_MSG_STATS:
    case PROTO_MSG_DESCRIBE:
    case PROTO_MSG_APPLY_OBSERVATION:
        break;
    }
}

static void parse_object(struct parser *p, struct proto_client_msg *msg)
{
    const cJSON *type = cJSON_GetObjectItemCaseSensitive(p->root, "type");
    const cJSON *id = cJSON_GetObjectItemCaseSensitive(p->root, "id");
    if (id)
        parse_id(p, id, &msg->id);
    if (!parser_require(p, type, "/type"))
        return;
    if (!cJSON_IsString(type)) {
        parser_fail(p, PROTO_MSG_ERR_WRONG_TYPE, "/type", "expected a string, got %s",
                    proto_json_type_name(type));
        return;
    }
    int index = msg_find_name(type_names, COUNT_OF(type_names), type->valuestring);
    if (index < 0) {
        char expected[REASON_MAX];
        msg_join_names(type_names, COUNT_OF(type_names), expected, sizeof expected);
        parser_fail(p, PROTO_MSG_ERR_UNKNOWN_TYPE, "/type", "expected one of: %s", expected);
        return;
    }
    msg->type = (enum proto_msg_type)index;
    if (p->length > p->limits->max_message_bytes && msg->type != PROTO_MSG_SET_WEATHER_MAP) {
        parser_fail(p, PROTO_MSG_ERR_MESSAGE_TOO_LARGE, "",
                    "message is %zu bytes, the limit is %zu (only set_weather_map may be larger)",
                    p->length, p->limits->max_message_bytes);
        return;
    }
    const struct msg_schema *kind = msg_schema_of(msg->type);
    const struct proto_schema *schema = msg_schema_variant(kind, p->root);
    struct proto_field_errors *errors = &p->error->fields;
    int before = errors->count;
    proto_schema_apply_json(schema, msg, p->root, "", errors, NULL);
    /* A variant's required member is required by the discriminator's value: say which. */
    const cJSON *discriminator = cJSON_GetObjectItemCaseSensitive(p->root, kind->discriminator);
    for (int i = before; schema != kind->schema && i < errors->count; i++)
        if (errors->items[i].code == PROTO_MSG_ERR_MISSING_FIELD)
            snprintf(errors->items[i].reason, sizeof errors->items[i].reason, "required for %s",
                     discriminator->valuestring);
    check_members(p, msg);
    if (kind->id_required)
        parser_require(p, id, "/id");
}

size_t proto_msg_upload_limit(const struct proto_msg_limits *limits)
{
    return limits->max_upload_bytes > limits->max_message_bytes ? limits->max_upload_bytes
                                                                : limits->max_message_bytes;
}

static void summarize(struct proto_msg_parse_error *error)
{
    const struct proto_field_errors *fields = &error->fields;
    if (fields->total == 0) {
        error->code = PROTO_MSG_OK;
        return;
    }
    const struct proto_field_error *first = &fields->items[0];
    error->code = (enum proto_msg_error_code)first->code;
    char more[24] = "";
    if (fields->total > 1)
        snprintf(more, sizeof more, " (and %d more)", fields->total - 1);
    snprintf(error->message, sizeof error->message, "%s%s%s%s", first->pointer,
             first->pointer[0] ? ": " : "", first->reason, more);
}

enum proto_msg_error_code proto_msg_parse(const char *text, size_t length,
                                          const struct proto_msg_limits *limits,
                                          struct proto_client_msg *msg,
                                          struct proto_msg_parse_error *error)
{
    memset(msg, 0, sizeof *msg);
    memset(error, 0, sizeof *error);
    struct parser parser = { limits, error, NULL, length };
    struct parser *p = &parser;
    size_t offset;
    char *copy = NULL;
    if (!text || !limits) {
        parser_fail(p, PROTO_MSG_ERR_INTERNAL, "", "no message or no limits");
    } else if (length > proto_msg_upload_limit(limits)) {
        parser_fail(p, PROTO_MSG_ERR_MESSAGE_TOO_LARGE, "",
                    "message is %zu bytes, the limit is %zu", length,
                    proto_msg_upload_limit(limits));
    } else if ((offset = nul_offset(text, length)) < length) {
        error->offset = offset;
        parser_fail(p, PROTO_MSG_ERR_MALFORMED_JSON, "", "NUL byte at offset %zu", offset);
    } else if ((offset = utf8_invalid_offset(text, length)) < length) {
        error->offset = offset;
        parser_fail(p, PROTO_MSG_ERR_INVALID_ENCODING, "", "invalid UTF-8 at offset %zu", offset);
    } else if (!(copy = malloc(length + 1))) {
        parser_fail(p, PROTO_MSG_ERR_INTERNAL, "", "out of memory");
    } else {
        /* A terminated copy: cJSON then never needs to honour the length bound itself. */
        memcpy(copy, text, length);
        copy[length] = '\0';
        const char *end = NULL;
        p->root = cJSON_ParseWithOpts(copy, &end, false);
        offset = end ? (size_t)(end - copy) : 0;
        if (p->root && end)
            offset += strspn(end, " \t\r\n");
        if (!p->root || offset < length) {
            error->offset = offset;
            parser_fail(p, PROTO_MSG_ERR_MALFORMED_JSON, "", "%s at offset %zu",
                        p->root ? "unexpected text after the JSON value" : "invalid JSON", offset);
        } else if ((offset = escaped_nul_offset(copy, length)) < length) {
            error->offset = offset;
            parser_fail(p, PROTO_MSG_ERR_BAD_VALUE, "", "\\u0000 at offset %zu: NUL is not allowed",
                        offset);
        } else if (!cJSON_IsObject(p->root)) {
            parser_fail(p, PROTO_MSG_ERR_NOT_AN_OBJECT, "", "expected a JSON object, got %s",
                        proto_json_type_name(p->root));
        } else {
            parse_object(p, msg);
        }
    }
    cJSON_Delete(p->root);
    free(copy);
    summarize(error);
    if (error->code != PROTO_MSG_OK)
        proto_client_msg_free(msg);
    return error->code;
}

void proto_client_msg_free(struct proto_client_msg *msg)
{
    if (msg && msg->type == PROTO_MSG_SET) {
        free(msg->set.patch);
        msg->set.patch = NULL;
    }
    if (msg && msg->type == PROTO_MSG_SET_WEATHER_MAP)
        proto_weather_map_free(&msg->weather_map);
}

void proto_msg_view_resolve(const struct proto_msg_view *view,
                            const struct proto_world_state *state,
                            struct proto_camera_state *camera,
                            struct proto_exposure_state *exposure)
{
    *camera = state->camera;
    *exposure = state->exposure;
    if (view->has_altitude_km)
        camera->altitude_km = view->altitude_km;
    if (view->has_yaw_deg)
        camera->yaw_deg = view->yaw_deg;
    if (view->has_pitch_deg)
        camera->pitch_deg = view->pitch_deg;
    if (view->has_fov_deg)
        camera->fov_deg = view->fov_deg;
    if (view->has_exposure_mode)
        exposure->mode = view->exposure_mode;
    if (view->has_ev100)
        exposure->ev100 = view->ev100;
    if (view->has_compensation_ev)
        exposure->compensation_ev = view->compensation_ev;
}

size_t proto_msg_state_diff(const struct proto_world_state *before,
                            const struct proto_world_state *after,
                            char pointers[][PROTO_MSG_POINTER_MAX], size_t max)
{
    size_t field_count, changed = 0;
    const struct proto_field_desc *fields = proto_world_state_fields(&field_count);
    for (size_t i = 0; i < field_count; i++) {
        size_t size = proto_field_size(&fields[i]);
        if (memcmp((const char *)before + fields[i].offset, (const char *)after + fields[i].offset,
                   size) == 0)
            continue;
        if (changed < max)
            proto_field_pointer(&fields[i], pointers[changed], PROTO_MSG_POINTER_MAX);
        changed++;
    }
    return changed;
}
