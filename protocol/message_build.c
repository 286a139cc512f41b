/* Construction of the server's text messages (PROTOCOL.md, "Server messages"); the parsing
 * of client messages is in messages.c. */
#include "messages.h"
#include "field_errors.h"
#include "field_schema.h"
#include "message_names.h"

#include <cjson/cJSON.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define COUNT_OF(array) (sizeof(array) / sizeof((array)[0]))

/* ---- building --------------------------------------------------------------------------- */

struct builder {
    cJSON *root;
    bool ok; /* false after any refused argument or failed allocation */
};

static const char *name_of(const char *const *names, size_t count, int value)
{
    return value >= 0 && (size_t)value < count ? names[value] : NULL;
}

/* Adds item to an object (or to an array when name is NULL); takes ownership. */
static cJSON *put(struct builder *b, cJSON *parent, const char *name, cJSON *item)
{
    bool added = b->ok && parent && item &&
                 (name ? cJSON_AddItemToObject(parent, name, item)
                       : cJSON_AddItemToArray(parent, item));
    if (!added) {
        b->ok = false;
        cJSON_Delete(item);
        return NULL;
    }
    return item;
}

/* Checked before creating: cJSON_CreateNumber converts to int, undefined for NaN. */
static void put_number(struct builder *b, cJSON *parent, const char *name, double value)
{
    if (isfinite(value))
        put(b, parent, name, cJSON_CreateNumber(value));
    else
        b->ok = false;
}

static void put_count(struct builder *b, cJSON *parent, const char *name, uint64_t value)
{
    if (value <= (uint64_t)PROTO_MSG_MAX_SAFE_INTEGER)
        put_number(b, parent, name, (double)value);
    else
        b->ok = false;
}

/* Bytes that are not UTF-8 (a reason truncated inside a character) become '?'. */
static void put_string(struct builder *b, cJSON *parent, const char *name, const char *text)
{
    cJSON *item = put(b, parent, name, text ? cJSON_CreateString(text) : NULL);
    if (!item)
        return;
    unsigned char *s = (unsigned char *)item->valuestring;
    size_t length = strlen(item->valuestring);
    for (size_t i = 0; i < length;) {
        size_t n = proto_msg_utf8_sequence(s + i, length - i);
        if (n == 0)
            s[i++] = '?';
        else
            i += n;
    }
}

static void begin(struct builder *b, const char *type, const struct proto_msg_id *id)
{
    b->ok = true;
    b->root = cJSON_CreateObject();
    b->ok = b->root != NULL;
    put_string(b, b->root, "type", type);
    if (!id || id->kind == PROTO_MSG_ID_NONE)
        return;
    if (id->kind == PROTO_MSG_ID_STRING && id->text[0] && memchr(id->text, '\0', sizeof id->text))
        put_string(b, b->root, "id", id->text);
    else if (id->kind == PROTO_MSG_ID_INTEGER && id->number >= -PROTO_MSG_MAX_SAFE_INTEGER &&
             id->number <= PROTO_MSG_MAX_SAFE_INTEGER)
        put_number(b, b->root, "id", (double)id->number);
    else
        b->ok = false;
}

/* cJSON prints numbers with 15 digits when they compare equal within an epsilon, which loses
 * integers above 2^50 and the last bits of doubles: write each as the shortest exact text. */
bool proto_json_exact_numbers(cJSON *parent)
{
    for (cJSON *item = parent ? parent->child : NULL; item; item = item->next) {
        if (!cJSON_IsNumber(item)) {
            if (!proto_json_exact_numbers(item))
                return false;
            continue;
        }
        char text[32];
        if (!isfinite(item->valuedouble))
            return false;
        snprintf(text, sizeof text, "%.15g", item->valuedouble);
        if (strtod(text, NULL) != item->valuedouble)
            snprintf(text, sizeof text, "%.17g", item->valuedouble);
        cJSON *raw = cJSON_CreateRaw(text);
        if (!raw)
            return false;
        /* The replacement keeps the member's name; the pointer moves rather than copies. */
        raw->string = item->string;
        raw->type |= item->type & cJSON_StringIsConst;
        item->string = NULL;
        cJSON_ReplaceItemViaPointer(parent, item, raw);
        item = raw;
    }
    return true;
}

static char *finish(struct builder *b)
{
    char *text = b->ok && proto_json_exact_numbers(b->root) ? cJSON_PrintUnformatted(b->root)
                                                            : NULL;
    cJSON_Delete(b->root);
    return text;
}

char *proto_msg_build_hello(const char *server_version, enum proto_msg_role role,
                            const char *const *caps, size_t capability_count,
                            const struct proto_msg_limits *limits)
{
    struct builder b;
    begin(&b, "hello", NULL);
    put_number(&b, b.root, "protocol", PROTO_PROTOCOL_VERSION);
    char server[96];
    if (!server_version ||
        (size_t)snprintf(server, sizeof server, "skyd %s", server_version) >= sizeof server)
        b.ok = false;
    else
        put_string(&b, b.root, "server", server);
    put_string(&b, b.root, "role",
               name_of(proto_msg_role_names, COUNT_OF(proto_msg_role_names), (int)role));
    cJSON *list = put(&b, b.root, "capabilities", cJSON_CreateArray());
    for (size_t i = 0; i < capability_count; i++)
        put_string(&b, list, NULL, caps ? caps[i] : NULL);
    cJSON *json = put(&b, b.root, "limits", limits ? cJSON_CreateObject() : NULL);
    if (limits) {
        put_count(&b, json, "max_message_bytes", limits->max_message_bytes);
        put_count(&b, json, "max_clients", (uint64_t)(int64_t)limits->max_clients);
        put_count(&b, json, "max_width", limits->max_width);
        put_count(&b, json, "max_height", limits->max_height);
        put_number(&b, json, "max_fps", limits->max_fps);
        put_number(&b, json, "control_messages_per_second", limits->control_messages_per_second);
        put_count(&b, json, "max_upload_bytes", limits->max_upload_bytes);
    }
    return finish(&b);
}

char *proto_msg_build_state(const struct proto_msg_id *id, const struct proto_world_state *state)
{
    struct builder b;
    begin(&b, "state", id);
    cJSON *json = state ? proto_world_state_to_json(state) : NULL;
    /* Without its revision the state object is a complete, valid patch for "set". */
    cJSON_DeleteItemFromObjectCaseSensitive(json, "revision");
    put_count(&b, b.root, "revision", state ? state->revision : 0);
    put(&b, b.root, "state", json);
    return finish(&b);
}

char *proto_msg_build_schema(const struct proto_msg_id *id, const struct proto_msg_limits *limits)
{
    struct builder b;
    begin(&b, "schema", id);
    put(&b, b.root, "state", proto_world_state_json_schema());
    put(&b, b.root, "messages", limits ? proto_msg_json_schema(limits) : NULL);
    return finish(&b);
}

char *proto_msg_build_observation(const struct proto_msg_id *id, uint64_t revision,
                                  const cJSON *report, const cJSON *patch, const cJSON *unmapped)
{
    struct builder b;
    begin(&b, "observation", id);
    put_count(&b, b.root, "revision", revision);
    put(&b, b.root, "report", report ? cJSON_Duplicate(report, true) : NULL);
    put(&b, b.root, "patch", patch ? cJSON_Duplicate(patch, true) : NULL);
    put(&b, b.root, "unmapped", unmapped ? cJSON_Duplicate(unmapped, true) : NULL);
    return finish(&b);
}

char *proto_msg_build_ack(const struct proto_msg_id *id, uint64_t revision,
                          enum proto_msg_role role)
{
    struct builder b;
    begin(&b, "ack", id);
    put_count(&b, b.root, "revision", revision);
    if (role != PROTO_ROLE_NONE)
        put_string(&b, b.root, "role",
                   name_of(proto_msg_role_names, COUNT_OF(proto_msg_role_names), (int)role));
    return finish(&b);
}

char *proto_msg_build_error(const struct proto_msg_id *id, enum proto_msg_error_code code,
                            const char *message, const struct proto_field_errors *fields)
{
    struct builder b;
    begin(&b, "error", id);
    if (code == PROTO_MSG_OK)
        b.ok = false;
    put_string(&b, b.root, "code", proto_msg_error_name(code));
    put_string(&b, b.root, "message", message ? message : "");
    cJSON *list = put(&b, b.root, "fields", cJSON_CreateArray());
    int count = fields ? fields->count : 0;
    if (count < 0 || count > PROTO_MAX_FIELD_ERRORS)
        b.ok = false;
    for (int i = 0; i < count; i++) {
        const struct proto_field_error *item = &fields->items[i];
        cJSON *entry = put(&b, list, NULL, cJSON_CreateObject());
        put_string(&b, entry, "pointer",
                   memchr(item->pointer, '\0', sizeof item->pointer) ? item->pointer : NULL);
        put_string(&b, entry, "reason",
                   memchr(item->reason, '\0', sizeof item->reason) ? item->reason : NULL);
        put_string(&b, entry, "code",
                   item->code != PROTO_MSG_OK ? proto_msg_error_name(item->code) : NULL);
    }
    if (fields && fields->total > count)
        put_count(&b, b.root, "fields_omitted", (uint64_t)(fields->total - count));
    return finish(&b);
}

char *proto_msg_build_parse_error(const struct proto_client_msg *msg,
                                  const struct proto_msg_parse_error *error)
{
    if (!error)
        return NULL;
    return proto_msg_build_error(msg ? &msg->id : NULL, error->code, error->message,
                                 &error->fields);
}

char *proto_msg_build_subscribed(const struct proto_msg_id *id, uint64_t subscription,
                                 const struct proto_msg_view *v)
{
    struct builder b;
    begin(&b, "subscribed", id);
    if (subscription == 0 || !v || v->width == 0 || v->height == 0 || !(v->fps > 0)) {
        b.ok = false;
        return finish(&b);
    }
    put_count(&b, b.root, "subscription", subscription);
    cJSON *view = put(&b, b.root, "view", cJSON_CreateObject());
    cJSON *camera = put(&b, view, "camera", cJSON_CreateObject());
    if (v->has_altitude_km)
        put_number(&b, camera, "altitude_km", v->altitude_km);
    if (v->has_yaw_deg)
        put_number(&b, camera, "yaw_deg", v->yaw_deg);
    if (v->has_pitch_deg)
        put_number(&b, camera, "pitch_deg", v->pitch_deg);
    if (v->has_fov_deg)
        put_number(&b, camera, "fov_deg", v->fov_deg);
    put_count(&b, view, "width", v->width);
    put_count(&b, view, "height", v->height);
    put_number(&b, view, "fps", v->fps);
    cJSON *exposure = put(&b, view, "exposure", cJSON_CreateObject());
    const struct proto_field_desc *mode = proto_world_state_find_field("exposure.mode");
    if (v->has_exposure_mode)
        put_string(&b, exposure, "mode",
                   mode ? name_of(mode->enum_names, (size_t)mode->enum_count, (int)v->exposure_mode)
                        : NULL);
    if (v->has_ev100)
        put_number(&b, exposure, "ev100", v->ev100);
    if (v->has_compensation_ev)
        put_number(&b, exposure, "compensation_ev", v->compensation_ev);
    put_string(&b, view, "format",
               name_of(proto_msg_format_names, COUNT_OF(proto_msg_format_names), (int)v->format));
    if (v->format == PROTO_FRAME_FORMAT_JPEG)
        put_count(&b, view, "quality", (uint64_t)v->quality);
    if (v->max_kbps > 0)
        put_number(&b, view, "max_kbps", v->max_kbps);
    put_string(&b, view, "projection",
               name_of(proto_msg_projection_names, COUNT_OF(proto_msg_projection_names),
                       (int)v->projection));
    return finish(&b);
}

char *proto_msg_build_frame(const struct proto_msg_id *id, uint64_t subscription,
                            uint64_t frame_number)
{
    struct builder b;
    bool snapshot = id && id->kind != PROTO_MSG_ID_NONE;
    begin(&b, "frame", id);
    if (snapshot == (subscription != 0))
        b.ok = false;
    if (!snapshot)
        put_count(&b, b.root, "subscription", subscription);
    put_count(&b, b.root, "frame_number", frame_number);
    return finish(&b);
}

/* The state's field at a JSON Pointer ("/sun/elevation_deg"), or NULL. Field names have no
 * '~' or '/', so no segment needs unescaping. */
static const struct proto_field_desc *field_at(const char *pointer)
{
    char dotted[PROTO_MSG_POINTER_MAX];
    if (pointer[0] != '/' || strlen(pointer) >= sizeof dotted)
        return NULL;
    for (size_t i = 0; pointer[i]; i++)
        dotted[i] = pointer[i + 1] == '/' ? '.' : pointer[i + 1];
    return proto_world_state_find_field(dotted);
}

/* "changed" and "values" of an event. */
static void put_changes(struct builder *b, const char *const *pointers, size_t count,
                        const struct proto_world_state *state)
{
    cJSON *list = put(b, b->root, "changed", cJSON_CreateArray());
    cJSON *values = put(b, b->root, "values", cJSON_CreateObject());
    for (size_t i = 0; i < count && b->ok; i++) {
        const char *pointer = pointers ? pointers[i] : NULL;
        put_string(b, list, NULL, pointer && (!pointer[0] || pointer[0] == '/') ? pointer : NULL);
        const struct proto_field_desc *field = pointer ? field_at(pointer) : NULL;
        if (field && !cJSON_GetObjectItemCaseSensitive(values, pointer))
            put(b, values, pointer, proto_field_to_json(field, state));
    }
}

char *proto_msg_build_state_changed(uint64_t revision, const char *const *pointers, size_t count,
                                    const struct proto_world_state *state, const char *by)
{
    struct builder b;
    begin(&b, "event", NULL);
    if (!state || !by || !by[0])
        b.ok = false;
    put_string(&b, b.root, "event", "state_changed");
    put_count(&b, b.root, "revision", revision);
    put_string(&b, b.root, "by", by);
    put_changes(&b, pointers, count, state);
    return finish(&b);
}

char *proto_msg_build_simulation_event(uint64_t revision, const char *const *pointers, size_t count,
                                       const struct proto_world_state *state)
{
    struct builder b;
    begin(&b, "event", NULL);
    if (!state)
        b.ok = false;
    put_string(&b, b.root, "event", "simulation");
    put_count(&b, b.root, "revision", revision);
    put_number(&b, b.root, "simulation_time_s", state ? state->clock.utc_unix_s : 0);
    put_changes(&b, pointers, count, state);
    return finish(&b);
}

char *proto_msg_build_presets(const struct proto_msg_id *id, enum proto_preset_kind kind,
                              const char *const *names, size_t count)
{
    struct builder b;
    begin(&b, "presets", id);
    put_string(
        &b, b.root, "kind",
        name_of(proto_msg_preset_kind_names, COUNT_OF(proto_msg_preset_kind_names), (int)kind));
    cJSON *list = put(&b, b.root, "names", cJSON_CreateArray());
    if (count > PROTO_MSG_MAX_PRESETS)
        b.ok = false;
    for (size_t i = 0; i < count && b.ok; i++) {
        const char *name = names ? names[i] : NULL;
        put_string(&b, list, NULL, name && proto_msg_preset_name_is_valid(name) ? name : NULL);
    }
    return finish(&b);
}

char *proto_msg_build_probe_result(const struct proto_msg_id *id,
                                   const struct proto_msg_probe_result *result)
{
    struct builder b;
    begin(&b, "probe_result", id);
    int quantity = result ? (int)result->quantity : -1;
    const char *name = name_of(proto_msg_quantity_names, COUNT_OF(proto_msg_quantity_names),
                               quantity);
    put_string(&b, b.root, "quantity", name);
    if (quantity == PROTO_PROBE_TRANSMITTANCE || quantity == PROTO_PROBE_LUMINANCE) {
        cJSON *rgb = put(&b, b.root, name, cJSON_CreateArray());
        for (int i = 0; i < 3; i++)
            put_number(&b, rgb, NULL, result->rgb[i]);
    } else if (quantity == PROTO_PROBE_ILLUMINANCE) {
        put_number(&b, b.root, "sun_lux", result->sun_lux);
        put_number(&b, b.root, "sky_lux", result->sky_lux);
    }
    if (result && result->multiple_scattering &&
        (quantity == PROTO_PROBE_LUMINANCE || quantity == PROTO_PROBE_ILLUMINANCE))
        put_string(&b, b.root, "multiple_scattering", result->multiple_scattering);
    return finish(&b);
}

char *proto_msg_build_stats(const struct proto_msg_id *id, const struct proto_msg_stats *stats)
{
    struct builder b;
    begin(&b, "stats", id);
    if (!stats || !(stats->fps >= 0) || stats->clients < 0 ||
        stats->pass_count > PROTO_MSG_MAX_PASSES || (stats->pass_count > 0 && !stats->passes) ||
        (stats->subscription_count > 0 && !stats->subscriptions) ||
        !(stats->lut_rebuild_progress >= 0) || !(stats->lut_rebuild_progress <= 1) ||
        !isfinite(stats->simulation_time_s)) {
        b.ok = false;
        return finish(&b);
    }
    put_number(&b, b.root, "fps", stats->fps);
    put_count(&b, b.root, "clients", (uint64_t)stats->clients);
    cJSON *passes = put(&b, b.root, "passes", cJSON_CreateObject());
    for (size_t i = 0; i < stats->pass_count && b.ok; i++) {
        const struct proto_msg_pass_time *pass = &stats->passes[i];
        if (!pass->name || !proto_msg_preset_name_is_valid(pass->name) || !(pass->ms >= 0) ||
            cJSON_GetObjectItemCaseSensitive(passes, pass->name))
            b.ok = false;
        else
            put_number(&b, passes, pass->name, pass->ms);
    }
    put_number(&b, b.root, "lut_rebuild_progress", stats->lut_rebuild_progress);
    put_number(&b, b.root, "simulation_time_s", stats->simulation_time_s);
    const struct proto_msg_multiple_scattering *ms = stats->multiple_scattering;
    if (ms && (!(ms->weight >= 0 && ms->weight <= 1) || !(ms->progress >= 0 && ms->progress <= 1) ||
               ms->order < 0)) {
        b.ok = false;
    } else if (ms) {
        cJSON *item = put(&b, b.root, "multiple_scattering", cJSON_CreateObject());
        put_number(&b, item, "weight", ms->weight);
        put_number(&b, item, "progress", ms->progress);
        put_count(&b, item, "order", (uint64_t)ms->order);
    }
    if (stats->cloud_resolution) {
        const char *name = *stats->cloud_resolution < PROTO_CLOUD_RESOLUTION_AUTO
                               ? proto_cloud_resolution_name(*stats->cloud_resolution)
                               : NULL;
        if (name)
            put_string(&b, b.root, "cloud_resolution", name);
        else
            b.ok = false;
    }
    if (stats->cloud_primary_steps > 0)
        put_count(&b, b.root, "cloud_primary_steps", (uint64_t)stats->cloud_primary_steps);
    cJSON *subscriptions = put(&b, b.root, "subscriptions", cJSON_CreateArray());
    for (size_t i = 0; i < stats->subscription_count && b.ok; i++) {
        const struct proto_msg_subscription_stats *s = &stats->subscriptions[i];
        if (s->subscription == 0 || !(s->fps > 0) || s->quality < 0 || !(s->max_kbps >= 0)) {
            b.ok = false;
            break;
        }
        cJSON *item = put(&b, subscriptions, NULL, cJSON_CreateObject());
        put_count(&b, item, "subscription", s->subscription);
        put_count(&b, item, "bytes_sent", s->bytes_sent);
        put_number(&b, item, "fps", s->fps);
        if (s->quality > 0)
            put_count(&b, item, "quality", (uint64_t)s->quality);
        if (s->max_kbps > 0)
            put_number(&b, item, "max_kbps", s->max_kbps);
    }
    return finish(&b);
}
