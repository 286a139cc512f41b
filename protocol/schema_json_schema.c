/* A table's JSON Schema (2020-12): one property per row with its type, range, enum names,
 * unit, default and description, nested like the struct's JSON, no other members allowed. */
#include "schema_text.h"

#include <cjson/cJSON.h>

#include <stdio.h>
#include <string.h>

#define JSON_SCHEMA_DIALECT "https://json-schema.org/draft/2020-12/schema"

/* Units by the field name's suffix, longest first: the names carry them ("bottom_km",
 * "scattering_per_km", "elevation_deg"), so the table needs no second copy. */
static const struct {
    const char *suffix, *unit;
} unit_suffixes[] = {
    { "_per_km", "1/km" }, { "_cd_m2", "cd/m2" }, { "_m_s", "m/s" }, { "_lux", "lx" },
    { "_deg", "deg" },     { "_km", "km" },       { "_ev", "EV" },   { ".ev100", "EV" },
    { "_ms", "ms" },       { "_s", "s" },         { "_m", "m" },
};

const char *proto_field_unit(const struct proto_field_desc *field)
{
    if (field->type == PROTO_FIELD_TYPE_TIME)
        return "UTC";
    size_t length = strlen(field->path);
    for (size_t i = 0; i < sizeof unit_suffixes / sizeof unit_suffixes[0]; i++) {
        size_t n = strlen(unit_suffixes[i].suffix);
        if (length > n && strcmp(field->path + length - n, unit_suffixes[i].suffix) == 0)
            return unit_suffixes[i].unit;
    }
    return NULL;
}

/* The object under `root` for the groups of `dotted_path` (all but its last segment), made as
 * needed: {"type": "object", "properties": {...}, "additionalProperties": false}. *leaf_name
 * receives the last segment. */
static cJSON *group_properties(cJSON *root, const char *dotted_path, char *leaf_name,
                               size_t capacity)
{
    cJSON *properties = cJSON_GetObjectItemCaseSensitive(root, "properties");
    const char *segment = dotted_path;
    for (const char *dot; (dot = strchr(segment, '.')) != NULL; segment = dot + 1) {
        char name[DOTTED_PATH_CAPACITY];
        snprintf(name, sizeof name, "%.*s", (int)(dot - segment), segment);
        cJSON *group = cJSON_GetObjectItemCaseSensitive(properties, name);
        if (!group) {
            group = cJSON_AddObjectToObject(properties, name);
            if (!group || !cJSON_AddStringToObject(group, "type", "object") ||
                !cJSON_AddObjectToObject(group, "properties") ||
                !cJSON_AddFalseToObject(group, "additionalProperties"))
                return NULL;
        }
        properties = cJSON_GetObjectItemCaseSensitive(group, "properties");
    }
    snprintf(leaf_name, capacity, "%s", segment);
    return properties;
}

/* The value at a dotted path of a struct's JSON (proto_schema_to_json). */
static const cJSON *value_at(const cJSON *state, const char *dotted_path)
{
    const cJSON *node = state;
    const char *segment = dotted_path;
    for (;;) {
        const char *dot = strchr(segment, '.');
        char name[DOTTED_PATH_CAPACITY];
        snprintf(name, sizeof name, "%.*s", dot ? (int)(dot - segment) : (int)strlen(segment),
                 segment);
        node = cJSON_GetObjectItemCaseSensitive(node, name);
        if (!node || !dot)
            return node;
        segment = dot + 1;
    }
}

static bool add_range(cJSON *schema, const struct proto_field_desc *field)
{
    return cJSON_AddNumberToObject(schema, field->exclusive_min ? "exclusiveMinimum" : "minimum",
                                   field->min) &&
           cJSON_AddNumberToObject(schema, "maximum", field->max);
}

/* {"type": type}, or NULL. */
static cJSON *typed(const char *type)
{
    cJSON *schema = cJSON_CreateObject();
    if (schema && !cJSON_AddStringToObject(schema, "type", type)) {
        cJSON_Delete(schema);
        return NULL;
    }
    return schema;
}

/* `schema` when everything was added to it (ok), else nothing: it is deleted. */
static cJSON *kept(cJSON *schema, bool ok)
{
    if (!ok) {
        cJSON_Delete(schema);
        return NULL;
    }
    return schema;
}

static cJSON *scalar_schema(const struct proto_field_desc *field, const char *type)
{
    cJSON *schema = typed(type);
    return kept(schema, schema && add_range(schema, field));
}

/* {"type": "array", "items": {element}, "minItems": n, "maxItems": n}; takes `element`. */
static cJSON *array_schema(cJSON *element, int count)
{
    cJSON *schema = typed("array");
    bool added = schema && element && cJSON_AddItemToObject(schema, "items", element);
    if (!added)
        cJSON_Delete(element);
    return kept(schema, added && cJSON_AddNumberToObject(schema, "minItems", count) &&
                            cJSON_AddNumberToObject(schema, "maxItems", count));
}

/* The type part of a leaf's schema. */
static cJSON *type_schema(const struct proto_field_desc *field)
{
    cJSON *schema = NULL;
    bool ok = false;
    switch (field->type) {
    case PROTO_FIELD_TYPE_NUMBER:
        return scalar_schema(field, "number");
    case PROTO_FIELD_TYPE_INT:
    case PROTO_FIELD_TYPE_INT64:
        return scalar_schema(field, "integer");
    case PROTO_FIELD_TYPE_INT_PAIR:
        return array_schema(scalar_schema(field, "integer"), 2);
    case PROTO_FIELD_TYPE_INT_TRIPLE:
        return array_schema(scalar_schema(field, "integer"), 3);
    case PROTO_FIELD_TYPE_BOOL:
        return typed("boolean");
    case PROTO_FIELD_TYPE_RGB: {
        /* Three numbers, or one for all three. */
        schema = cJSON_CreateObject();
        cJSON *any = schema ? cJSON_AddArrayToObject(schema, "oneOf") : NULL;
        cJSON *one = scalar_schema(field, "number");
        cJSON *three = array_schema(scalar_schema(field, "number"), 3);
        bool one_added = any && one && cJSON_AddItemToArray(any, one);
        bool three_added = one_added && three && cJSON_AddItemToArray(any, three);
        if (!one_added)
            cJSON_Delete(one);
        if (!three_added)
            cJSON_Delete(three);
        return kept(schema, three_added);
    }
    case PROTO_FIELD_TYPE_ENUM: {
        schema = typed("string");
        cJSON *names = schema ? cJSON_AddArrayToObject(schema, "enum") : NULL;
        ok = names != NULL;
        for (int i = 0; ok && i < field->enum_count; i++)
            ok = !field->enum_names[i] ||
                 cJSON_AddItemToArray(names, cJSON_CreateString(field->enum_names[i]));
        break;
    }
    case PROTO_FIELD_TYPE_STRING:
        schema = typed("string");
        ok = schema && cJSON_AddNumberToObject(schema, "maxLength", (double)field->capacity - 1) &&
             (field->min <= 0 || cJSON_AddNumberToObject(schema, "minLength", field->min));
        break;
    case PROTO_FIELD_TYPE_TIME:
        schema = typed("string");
        ok = schema && cJSON_AddStringToObject(schema, "format", "date-time");
        break;
    }
    return kept(schema, ok);
}

/* Lists a required leaf in its object's "required". */
static bool add_required(cJSON *root, const struct proto_field_desc *field, const char *name)
{
    cJSON *object = root;
    const char *segment = field->path;
    for (const char *dot; (dot = strchr(segment, '.')) != NULL; segment = dot + 1) {
        char group[DOTTED_PATH_CAPACITY];
        snprintf(group, sizeof group, "%.*s", (int)(dot - segment), segment);
        object = cJSON_GetObjectItemCaseSensitive(
            cJSON_GetObjectItemCaseSensitive(object, "properties"), group);
    }
    cJSON *required = cJSON_GetObjectItemCaseSensitive(object, "required");
    if (!required)
        required = cJSON_AddArrayToObject(object, "required");
    return required && cJSON_AddItemToArray(required, cJSON_CreateString(name));
}

static bool add_leaf(cJSON *root, const cJSON *defaults, const struct proto_field_desc *field)
{
    char name[DOTTED_PATH_CAPACITY];
    cJSON *properties = group_properties(root, field->path, name, sizeof name);
    cJSON *leaf = type_schema(field);
    if (!properties || !leaf || !cJSON_AddItemToObject(properties, name, leaf)) {
        cJSON_Delete(leaf);
        return false;
    }
    if (field->required && !add_required(root, field, name))
        return false;
    const char *unit = proto_field_unit(field);
    const cJSON *value = value_at(defaults, field->path);
    return cJSON_AddStringToObject(leaf, "description", field->description) &&
           (!unit || cJSON_AddStringToObject(leaf, "x-unit", unit)) &&
           (!value || cJSON_AddItemToObject(leaf, "default", cJSON_Duplicate(value, true))) &&
           (!field->read_only || cJSON_AddTrueToObject(leaf, "readOnly"));
}

cJSON *proto_schema_json_schema(const struct proto_schema *schema, const cJSON *defaults,
                                const char *title)
{
    cJSON *root = cJSON_CreateObject();
    bool ok = root && cJSON_AddStringToObject(root, "$schema", JSON_SCHEMA_DIALECT) &&
              cJSON_AddStringToObject(root, "title", title) &&
              cJSON_AddStringToObject(root, "type", "object") &&
              cJSON_AddObjectToObject(root, "properties") &&
              cJSON_AddFalseToObject(root, "additionalProperties");
    for (size_t i = 0; ok && i < schema->count; i++)
        ok = add_leaf(root, defaults, &schema->fields[i]);
    if (!ok) {
        cJSON_Delete(root);
        return NULL;
    }
    return root;
}
