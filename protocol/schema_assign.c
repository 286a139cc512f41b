/* Dotted-path assignments ("sun.elevation_deg=12", the command line's --set) turned into the
 * JSON patch a client would send, so that they are applied and checked the same way. */
#include "schema_text.h"

#include <cjson/cJSON.h>

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

static const char *expected_value_text(const struct proto_field_desc *field)
{
    switch (field->type) {
    case PROTO_FIELD_TYPE_RGB:
        return "a number or a JSON array like [0.1,0.2,0.3]";
    case PROTO_FIELD_TYPE_INT_PAIR:
        return "a JSON array like [256,64]";
    case PROTO_FIELD_TYPE_INT_TRIPLE:
        return "a JSON array like [32,32,32]";
    case PROTO_FIELD_TYPE_INT:
    case PROTO_FIELD_TYPE_INT64:
        return "an integer";
    case PROTO_FIELD_TYPE_TIME:
        return "an ISO 8601 UTC time like 2026-06-21T12:00:00Z";
    case PROTO_FIELD_TYPE_STRING:
        return "a string";
    case PROTO_FIELD_TYPE_BOOL:
        return "true or false";
    case PROTO_FIELD_TYPE_NUMBER:
    case PROTO_FIELD_TYPE_ENUM:
        break;
    }
    return "a number";
}

/* Turns command-line value text into a JSON value; NULL with an error recorded on failure.
 * `field` is NULL for unknown paths, which the patch walk reports. */
static cJSON *parse_value_text(const struct proto_field_desc *field, const char *value_text,
                               const char *pointer, struct proto_field_errors *errors)
{
    char *text = copy_trimmed(value_text);
    if (!text) {
        proto_field_errors_addf(errors, PROTO_FIELD_BAD_VALUE, pointer, "out of memory");
        return NULL;
    }
    cJSON *value = NULL;
    double number;
    int errors_before = errors->total;
    if (text[0] == '\0') {
        proto_field_errors_addf(errors, PROTO_FIELD_BAD_VALUE, pointer, "empty value");
    } else if (text[0] == '[' || text[0] == '"') {
        const char *end = NULL;
        value = cJSON_ParseWithOpts(text, &end, true);
        if (!value)
            proto_field_errors_addf(errors, PROTO_FIELD_BAD_VALUE, pointer,
                                    "invalid JSON at character %d of %s",
                                    end ? (int)(end - text) + 1 : 1, text);
    } else if (field && field->type == PROTO_FIELD_TYPE_TIME) {
        value = cJSON_CreateString(text); /* the patch walk parses and reports it */
    } else if (parse_whole_number(text, &number)) {
        value = schema_new_json_number(number);
    } else if (!field || field->type == PROTO_FIELD_TYPE_ENUM) {
        value = cJSON_CreateString(text);
    } else {
        proto_field_errors_addf(errors, PROTO_FIELD_BAD_VALUE, pointer, "expected %s, got \"%s\"",
                                expected_value_text(field), text);
    }
    if (!value && errors->total == errors_before)
        proto_field_errors_addf(errors, PROTO_FIELD_BAD_VALUE, pointer, "out of memory");
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

cJSON *proto_schema_assignment(const struct proto_schema *schema, const char *path,
                               const char *value_text, struct proto_field_errors *errors)
{
    char pointer[POINTER_CAPACITY];
    schema_pointer_from_dotted(path, pointer, sizeof pointer);
    if (schema_is_group(schema, path)) {
        char children[REASON_CAPACITY];
        schema_list_children(schema, path, children, sizeof children);
        proto_field_errors_addf(errors, PROTO_FIELD_UNKNOWN, pointer,
                                "%s is a group, not a field; set one of: %s", path, children);
        return NULL;
    }
    cJSON *value = parse_value_text(proto_schema_find(schema, path), value_text, pointer, errors);
    if (!value)
        return NULL;
    cJSON *patch = build_patch(path, value);
    if (!patch)
        proto_field_errors_addf(errors, PROTO_FIELD_BAD_VALUE, pointer, "out of memory");
    return patch;
}
