/* World states as JSON, and dotted-path assignments ("sun.elevation_deg=12", the command
 * line's --set) turned into patches applied like a client's. */
#include "field_errors.h"
#include "field_schema.h"
#include "world_state.h"
#include "world_schema.h"
#include "utc_time.h"

#include <cjson/cJSON.h>

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static char *copy_trimmed(const char *text)
{
    const char *blanks = " \t\r\n\v\f";
    text += strspn(text, blanks);
    size_t length = strlen(text);
    while (length > 0 && strchr(blanks, text[length - 1]))
        length--;
    char *copy = malloc(length + 1);
    if (copy) {
        memcpy(copy, text, length);
        copy[length] = '\0';
    }
    return copy;
}

/* Accepts "nan" and "inf" too: validation then rejects them with a clear reason. */
static bool parse_whole_number(const char *text, double *value)
{
    char *end;
    *value = strtod(text, &end);
    return end != text && *end == '\0';
}

static const char *expected_value_text(const struct sky_field_desc *field)
{
    switch (field->type) {
    case SKY_FIELD_TYPE_RGB:
        return "a number or a JSON array like [0.1,0.2,0.3]";
    case SKY_FIELD_TYPE_INT_PAIR:
        return "a JSON array like [256,64]";
    case SKY_FIELD_TYPE_INT_TRIPLE:
        return "a JSON array like [32,32,32]";
    case SKY_FIELD_TYPE_INT:
    case SKY_FIELD_TYPE_INT64:
        return "an integer";
    case SKY_FIELD_TYPE_TIME:
        return "an ISO 8601 UTC time like 2026-06-21T12:00:00Z";
    case SKY_FIELD_TYPE_STRING:
        return "a string";
    case SKY_FIELD_TYPE_BOOL:
        return "true or false";
    case SKY_FIELD_TYPE_NUMBER:
    case SKY_FIELD_TYPE_ENUM:
        break;
    }
    return "a number";
}

/* Turns command-line value text into a JSON value; NULL with an error recorded on failure.
 * `field` is NULL for unknown paths, which the patch walk reports. */
static cJSON *parse_value_text(const struct sky_field_desc *field, const char *value_text,
                               const char *pointer, struct sky_field_errors *errors)
{
    char *text = copy_trimmed(value_text);
    if (!text) {
        sky_field_errors_addf(errors, SKY_FIELD_BAD_VALUE, pointer, "out of memory");
        return NULL;
    }
    cJSON *value = NULL;
    double number;
    int errors_before = errors->total;
    if (text[0] == '\0') {
        sky_field_errors_addf(errors, SKY_FIELD_BAD_VALUE, pointer, "empty value");
    } else if (text[0] == '[' || text[0] == '"') {
        const char *end = NULL;
        value = cJSON_ParseWithOpts(text, &end, true);
        if (!value)
            sky_field_errors_addf(errors, SKY_FIELD_BAD_VALUE, pointer,
                                  "invalid JSON at character %d of %s",
                                  end ? (int)(end - text) + 1 : 1, text);
    } else if (field && field->type == SKY_FIELD_TYPE_TIME) {
        value = cJSON_CreateString(text); /* the patch walk parses and reports it */
    } else if (parse_whole_number(text, &number)) {
        value = schema_new_json_number(number);
    } else if (!field || field->type == SKY_FIELD_TYPE_ENUM) {
        value = cJSON_CreateString(text);
    } else {
        sky_field_errors_addf(errors, SKY_FIELD_BAD_VALUE, pointer, "expected %s, got \"%s\"",
                              expected_value_text(field), text);
    }
    if (!value && errors->total == errors_before)
        sky_field_errors_addf(errors, SKY_FIELD_BAD_VALUE, pointer, "out of memory");
    free(text);
    return value;
}

/* {"a": {"b": value}} for "a.b"; takes ownership of value. */
static cJSON *build_patch(const char *dotted_path, cJSON *value)
{
    cJSON *root = cJSON_CreateObject();
    char *names = malloc(strlen(dotted_path) + 1);
    if (!root || !names)
        goto fail;
    strcpy(names, dotted_path);
    cJSON *node = root;
    char *name = names;
    char *dot;
    while ((dot = strchr(name, '.'))) {
        *dot = '\0';
        cJSON *child = cJSON_CreateObject();
        if (!child || !cJSON_AddItemToObject(node, name, child)) {
            cJSON_Delete(child);
            goto fail;
        }
        node = child;
        name = dot + 1;
    }
    if (!cJSON_AddItemToObject(node, name, value))
        goto fail;
    free(names);
    return root;
fail:
    free(names);
    cJSON_Delete(root);
    cJSON_Delete(value);
    return NULL;
}

bool sky_world_state_set_path(struct sky_world_state *state, const char *path,
                              const char *value_text, struct sky_field_errors *errors)
{
    struct sky_field_errors scratch;
    if (!errors)
        errors = &scratch;
    sky_field_errors_clear(errors);
    if (!path || !value_text) {
        sky_field_errors_addf(errors, SKY_FIELD_BAD_VALUE, "", "missing path or value");
        return false;
    }
    char pointer[POINTER_CAPACITY];
    schema_pointer_from_dotted(path, pointer, sizeof pointer);
    if (schema_is_group(sky_world_schema(), path)) {
        char children[REASON_CAPACITY];
        schema_list_children(sky_world_schema(), path, children, sizeof children);
        sky_field_errors_addf(errors, SKY_FIELD_UNKNOWN, pointer,
                              "%s is a group, not a field; set one of: %s", path, children);
        return false;
    }
    const struct sky_field_desc *field = sky_world_state_find_field(path);
    cJSON *value = parse_value_text(field, value_text, pointer, errors);
    if (!value)
        return false;
    cJSON *patch = build_patch(path, value);
    if (!patch) {
        sky_field_errors_addf(errors, SKY_FIELD_BAD_VALUE, pointer, "out of memory");
        return false;
    }
    bool applied = sky_world_state_apply_json(state, patch, errors);
    cJSON_Delete(patch);
    return applied;
}

bool sky_world_state_set_assignment(struct sky_world_state *state, const char *assignment,
                                    struct sky_field_errors *errors)
{
    const char *equals = assignment ? strchr(assignment, '=') : NULL;
    if (!equals) {
        sky_field_errors_clear(errors);
        sky_field_errors_addf(errors, SKY_FIELD_BAD_VALUE, "",
                              "expected dotted.path=value, got \"%s\"",
                              assignment ? assignment : "");
        return false;
    }
    size_t length = (size_t)(equals - assignment);
    char *raw_path = malloc(length + 1);
    if (!raw_path) {
        sky_field_errors_clear(errors);
        sky_field_errors_addf(errors, SKY_FIELD_BAD_VALUE, "", "out of memory");
        return false;
    }
    memcpy(raw_path, assignment, length);
    raw_path[length] = '\0';
    char *path = copy_trimmed(raw_path);
    free(raw_path);
    if (!path) {
        sky_field_errors_clear(errors);
        sky_field_errors_addf(errors, SKY_FIELD_BAD_VALUE, "", "out of memory");
        return false;
    }
    bool applied = sky_world_state_set_path(state, path, equals + 1, errors);
    free(path);
    return applied;
}

/* ---- serialization ---------------------------------------------------------------------- */

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

cJSON *sky_field_to_json(const struct sky_field_desc *field, const void *base)
{
    const void *address = schema_const_field_address(base, field);
    switch (field->type) {
    case SKY_FIELD_TYPE_NUMBER:
        return schema_new_json_number(*(const double *)address);
    case SKY_FIELD_TYPE_RGB:
        return number_array_to_json(address, 3);
    case SKY_FIELD_TYPE_INT_PAIR:
    case SKY_FIELD_TYPE_INT_TRIPLE:
        return cJSON_CreateIntArray(address, schema_element_count(field->type));
    case SKY_FIELD_TYPE_INT:
        return cJSON_CreateNumber(*(const int *)address);
    case SKY_FIELD_TYPE_INT64:
        return schema_new_json_number((double)*(const int64_t *)address);
    case SKY_FIELD_TYPE_TIME: {
        char text[TIME_TEXT_CAPACITY];
        sky_time_format_iso8601(*(const double *)address, text, sizeof text);
        return cJSON_CreateString(text);
    }
    case SKY_FIELD_TYPE_ENUM: {
        int value = *(const int *)address;
        if (value >= 0 && value < field->enum_count && field->enum_names[value])
            return cJSON_CreateString(field->enum_names[value]);
        return schema_new_json_number(value); /* invalid state: keep the evidence */
    }
    case SKY_FIELD_TYPE_STRING:
        return cJSON_CreateString(address);
    case SKY_FIELD_TYPE_BOOL:
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

cJSON *sky_schema_to_json(const struct sky_schema *schema, const void *base)
{
    cJSON *root = cJSON_CreateObject();
    for (size_t i = 0; root && i < schema->count; i++) {
        cJSON *value = sky_field_to_json(&schema->fields[i], base);
        if (!value || !add_at_path(root, schema->fields[i].path, value)) {
            cJSON_Delete(value);
            cJSON_Delete(root);
            return NULL;
        }
    }
    return root;
}

cJSON *sky_world_state_to_json(const struct sky_world_state *state)
{
    if (!state)
        return NULL;
    cJSON *root = cJSON_CreateObject();
    cJSON *revision = schema_new_json_number((double)state->revision);
    if (!root || !revision || !cJSON_AddItemToObject(root, "revision", revision)) {
        cJSON_Delete(revision);
        cJSON_Delete(root);
        return NULL;
    }
    for (size_t i = 0; i < sky_world_field_count; i++) {
        cJSON *value = sky_field_to_json(&sky_world_field_table[i], state);
        if (!value || !add_at_path(root, sky_world_field_table[i].path, value)) {
            cJSON_Delete(value);
            cJSON_Delete(root);
            return NULL;
        }
    }
    return root;
}

char *sky_world_state_to_text(const struct sky_world_state *state)
{
    cJSON *json = sky_world_state_to_json(state);
    char *text = json ? cJSON_PrintUnformatted(json) : NULL;
    cJSON_Delete(json);
    return text;
}
