/* The values a table's rows read from their struct, as nested JSON. */
#include "schema_text.h"
#include "utc_time.h"

#include <cjson/cJSON.h>

#include <stdint.h>
#include <string.h>

static cJSON *number_array_to_json(const double *values, int count)
{
    cJSON *array = cJSON_CreateArray();
    for (int i = 0; array && i < count; i++) {
        cJSON *element = schema_new_json_number(values[i]);
        if (!element || !cJSON_AddItemToArray(array, element)) {
            cJSON_Delete(element);
            cJSON_Delete(array);
            return NULL;
        }
    }
    return array;
}

cJSON *proto_field_to_json(const struct proto_field_desc *field, const void *base)
{
    const void *address = (const char *)base + field->offset;
    switch (field->type) {
    case PROTO_FIELD_TYPE_NUMBER:
        return schema_new_json_number(*(const double *)address);
    case PROTO_FIELD_TYPE_RGB:
        return number_array_to_json(address, 3);
    case PROTO_FIELD_TYPE_INT_PAIR:
    case PROTO_FIELD_TYPE_INT_TRIPLE:
        return cJSON_CreateIntArray(address, schema_element_count(field->type));
    case PROTO_FIELD_TYPE_INT:
        return cJSON_CreateNumber(*(const int *)address);
    case PROTO_FIELD_TYPE_INT64:
        return schema_new_json_number((double)*(const int64_t *)address);
    case PROTO_FIELD_TYPE_TIME: {
        char text[TIME_TEXT_CAPACITY];
        proto_time_format_iso8601(*(const double *)address, text, sizeof text);
        return cJSON_CreateString(text);
    }
    case PROTO_FIELD_TYPE_ENUM: {
        int value = *(const int *)address;
        if (value >= 0 && value < field->enum_count && field->enum_names[value])
            return cJSON_CreateString(field->enum_names[value]);
        return schema_new_json_number(value); /* invalid state: keep the evidence */
    }
    case PROTO_FIELD_TYPE_STRING:
        return cJSON_CreateString(address);
    case PROTO_FIELD_TYPE_BOOL:
        return cJSON_CreateBool(*(const bool *)address);
    }
    return NULL;
}

/* Adds the leaf at its dotted path, creating the groups above it as needed. */
static bool add_at_path(cJSON *root, const char *dotted_path, cJSON *value)
{
    cJSON *node = root;
    const char *name = dotted_path;
    const char *dot;
    while ((dot = strchr(name, '.'))) {
        char group[DOTTED_PATH_CAPACITY];
        size_t length = (size_t)(dot - name);
        if (length >= sizeof group)
            return false;
        memcpy(group, name, length);
        group[length] = '\0';
        cJSON *child = cJSON_GetObjectItemCaseSensitive(node, group);
        if (!child) {
            child = cJSON_CreateObject();
            if (!child || !cJSON_AddItemToObject(node, group, child)) {
                cJSON_Delete(child);
                return false;
            }
        }
        node = child;
        name = dot + 1;
    }
    return cJSON_AddItemToObject(node, name, value);
}

bool proto_schema_add_to_json(const struct proto_schema *schema, const void *base, cJSON *root)
{
    for (size_t i = 0; i < schema->count; i++) {
        cJSON *value = proto_field_to_json(&schema->fields[i], base);
        if (!value || !add_at_path(root, schema->fields[i].path, value)) {
            cJSON_Delete(value);
            return false;
        }
    }
    return true;
}

cJSON *proto_schema_to_json(const struct proto_schema *schema, const void *base)
{
    cJSON *root = cJSON_CreateObject();
    if (root && !proto_schema_add_to_json(schema, base, root)) {
        cJSON_Delete(root);
        return NULL;
    }
    return root;
}
