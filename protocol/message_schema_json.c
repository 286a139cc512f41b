/* The client messages' JSON Schema (2020-12), generated from their rows (message_fields.c):
 * a oneOf over the message types, each closed to other members and told apart by its "type"
 * constant; a type whose discriminator picks a variant table (probe's quantity,
 * set_weather_map's format) is itself a oneOf over its variants. The members the rows leave to
 * code (the id, a set's patch, the view object, a preset's name, the weather map's data) are
 * written here; the patch is the world state's own schema. Built without cJSON's parser, which
 * is not thread-safe (server/base/include/json_guard.h), so any thread may call it. */
#include "field_schema.h"
#include "message_parser.h"
#include "message_names.h"

#include <cjson/cJSON.h>

#include <stdio.h>
#include <string.h>

#define JSON_SCHEMA_DIALECT "https://json-schema.org/draft/2020-12/schema"

/* Adds item to an object, or to an array when name is NULL; takes it, deleting it on failure. */
static bool attach(cJSON *parent, const char *name, cJSON *item)
{
    bool added = parent && item &&
                 (name ? cJSON_AddItemToObject(parent, name, item)
                       : cJSON_AddItemToArray(parent, item));
    if (!added)
        cJSON_Delete(item);
    return added;
}

/* {"name": text} added to `object` (which may be NULL: then nothing). */
static cJSON *with_string(cJSON *object, const char *name, const char *text)
{
    if (object && !cJSON_AddStringToObject(object, name, text)) {
        cJSON_Delete(object);
        return NULL;
    }
    return object;
}

static cJSON *with_number(cJSON *object, const char *name, double value)
{
    if (object && !cJSON_AddNumberToObject(object, name, value)) {
        cJSON_Delete(object);
        return NULL;
    }
    return object;
}

/* {"name": item}, taking item. */
static cJSON *with_item(cJSON *object, const char *name, cJSON *item)
{
    if (!attach(object, name, item)) {
        cJSON_Delete(object);
        return NULL;
    }
    return object;
}

static cJSON *typed(const char *type)
{
    return with_string(cJSON_CreateObject(), "type", type);
}

static cJSON *reference(const char *def)
{
    char ref[64];
    snprintf(ref, sizeof ref, "#/$defs/%s", def);
    return with_string(cJSON_CreateObject(), "$ref", ref);
}

static cJSON *constant(const char *text)
{
    return with_string(cJSON_CreateObject(), "const", text);
}

/* A string of 1 to PROTO_MSG_ID_MAX bytes, or an integer of magnitude at most 2^53 - 1. */
static cJSON *id_schema(void)
{
    cJSON *text = with_number(with_number(typed("string"), "minLength", 1), "maxLength",
                              PROTO_MSG_ID_MAX);
    cJSON *number =
        with_number(with_number(typed("integer"), "minimum", -(double)PROTO_MSG_MAX_SAFE_INTEGER),
                    "maximum", (double)PROTO_MSG_MAX_SAFE_INTEGER);
    cJSON *options = cJSON_CreateArray();
    bool ok = attach(options, NULL, text);
    ok = attach(ok ? options : NULL, NULL, number) && ok;
    if (!ok) {
        cJSON_Delete(options);
        options = NULL;
    }
    return with_item(with_string(cJSON_CreateObject(), "description", "echoed in the reply"),
                     "oneOf", options);
}

static cJSON *preset_name_schema(void)
{
    return with_string(with_string(typed("string"), "pattern", "^[a-z0-9_-]{1,64}$"), "description",
                       "the preset's name, as list_presets gives it");
}

static cJSON *map_data_schema(void)
{
    return with_string(with_string(typed("string"), "contentEncoding", "base64"), "description",
                       "the texels (rgba8) or the PNG file, base64 with padding, no line breaks");
}

/* The members that have no row: a schema of their own, a reference to a $defs entry, or
 * neither (the message's "type" constant); and whether a message must give them. */
static const struct {
    const char *name;
    cJSON *(*schema)(void);
    const char *def;
    bool required;
} caller_members[] = {
    { "type", NULL, NULL, true },
    { "id", NULL, "id", false },
    { "patch", NULL, "patch", true },
    { "view", NULL, "view", true },
    { "name", preset_name_schema, NULL, true },
    { "data", map_data_schema, NULL, true },
};

/* A table's schema as a subschema: no "$schema" of its own. */
static cJSON *subschema(const struct proto_schema *schema, const cJSON *defaults, const char *title)
{
    cJSON *root = proto_schema_json_schema(schema, defaults, title);
    cJSON_DeleteItemFromObjectCaseSensitive(root, "$schema");
    return root;
}

static bool add_required(cJSON *object, const char *name)
{
    cJSON *required = cJSON_GetObjectItemCaseSensitive(object, "required");
    if (!required)
        required = cJSON_AddArrayToObject(object, "required");
    return attach(required, NULL, cJSON_CreateString(name));
}

/* One table of one message type: its rows, "type" as a constant, its caller members. */
static cJSON *message_schema(const char *type, const struct proto_schema *schema, const char *title)
{
    cJSON *root = subschema(schema, NULL, title);
    cJSON *properties = cJSON_GetObjectItemCaseSensitive(root, "properties");
    bool ok = properties != NULL;
    for (size_t i = 0; ok && i < schema->caller_member_count; i++) {
        const char *name = schema->caller_members[i];
        for (size_t j = 0; ok && j < sizeof caller_members / sizeof caller_members[0]; j++) {
            if (strcmp(caller_members[j].name, name) != 0)
                continue;
            cJSON *member = caller_members[j].schema ? caller_members[j].schema()
                            : caller_members[j].def  ? reference(caller_members[j].def)
                                                     : constant(type);
            ok = attach(properties, name, member) &&
                 (!caller_members[j].required || add_required(root, name));
        }
    }
    if (!ok) {
        cJSON_Delete(root);
        return NULL;
    }
    return root;
}

/* A type with variant tables: a oneOf over them, each with its discriminator's value. */
static cJSON *variants_schema(const char *type, const struct msg_schema *kind)
{
    cJSON *root = cJSON_CreateObject();
    cJSON *options = root && cJSON_AddStringToObject(root, "title", type)
                         ? cJSON_AddArrayToObject(root, "oneOf")
                         : NULL;
    const struct proto_field_desc *row = NULL;
    for (size_t i = 0; i < kind->schema->count && !row; i++)
        if (strcmp(kind->schema->fields[i].path, kind->discriminator) == 0)
            row = &kind->schema->fields[i];
    bool ok = options && row;
    for (size_t i = 0; ok && i < kind->variant_count; i++) {
        char title[96];
        snprintf(title, sizeof title, "%s, %s %s", type, kind->discriminator, row->enum_names[i]);
        cJSON *option = message_schema(type, &kind->variants[i], title);
        cJSON *member = cJSON_GetObjectItemCaseSensitive(
            cJSON_GetObjectItemCaseSensitive(option, "properties"), kind->discriminator);
        ok = attach(options, NULL, option) && member &&
             cJSON_AddStringToObject(member, "const", row->enum_names[i]);
    }
    if (!ok) {
        cJSON_Delete(root);
        return NULL;
    }
    return root;
}

static cJSON *view_schema(const struct proto_msg_limits *limits)
{
    struct msg_view_schema view;
    msg_view_schema(limits, &view);
    cJSON *defaults = cJSON_CreateObject();
    bool ok = defaults &&
              cJSON_AddNumberToObject(defaults, "fps",
                                      limits->max_fps < 10 ? limits->max_fps : 10) &&
              cJSON_AddStringToObject(defaults, "format", "png") &&
              cJSON_AddStringToObject(defaults, "projection", "perspective");
    cJSON *root = ok ? subschema(&view.schema, defaults, "view") : NULL;
    cJSON_Delete(defaults);
    return root;
}

/* The world state's schema, without what a patch may not name. */
static cJSON *patch_schema(void)
{
    cJSON *root = proto_world_state_json_schema();
    cJSON_DeleteItemFromObjectCaseSensitive(root, "$schema");
    cJSON_DeleteItemFromObjectCaseSensitive(cJSON_GetObjectItemCaseSensitive(root, "properties"),
                                            "revision");
    cJSON_ReplaceItemInObjectCaseSensitive(root, "title",
                                           cJSON_CreateString("a subset of the world state"));
    return root;
}

/* transition_s only with kind "weather". */
static bool add_weather_only_transition(cJSON *apply_preset)
{
    cJSON *kind = with_item(cJSON_CreateObject(), "kind", constant("weather"));
    cJSON *rule = with_item(cJSON_CreateObject(), "properties", kind);
    return attach(apply_preset, "dependentSchemas",
                  with_item(cJSON_CreateObject(), "transition_s", rule));
}

cJSON *proto_msg_json_schema(const struct proto_msg_limits *limits)
{
    cJSON *root = cJSON_CreateObject();
    cJSON *options = cJSON_CreateArray();
    cJSON *defs = cJSON_CreateObject();
    bool ok = root && cJSON_AddStringToObject(root, "$schema", JSON_SCHEMA_DIALECT) &&
              cJSON_AddStringToObject(root, "title", "skyd client messages");
    ok = attach(ok ? root : NULL, "oneOf", options) && ok;
    ok = attach(ok ? root : NULL, "$defs", defs) && ok;
    ok = ok && attach(defs, "id", id_schema()) && attach(defs, "view", view_schema(limits)) &&
         attach(defs, "patch", patch_schema());
    for (int type = PROTO_MSG_HELLO; ok && msg_schema_of((enum proto_msg_type)type); type++) {
        const char *name = proto_msg_type_name((enum proto_msg_type)type);
        const struct msg_schema *kind = msg_schema_of((enum proto_msg_type)type);
        cJSON *def = kind->discriminator ? variants_schema(name, kind)
                                         : message_schema(name, kind->schema, name);
        cJSON *option = reference(name);
        ok = attach(defs, name, def) && (!kind->id_required || add_required(def, "id")) &&
             (type != PROTO_MSG_APPLY_PRESET || add_weather_only_transition(def));
        ok = attach(ok ? options : NULL, NULL, option) && ok;
    }
    if (!ok) {
        cJSON_Delete(root);
        return NULL;
    }
    return root;
}
