/* The schema engine's patching: a JSON object applied to the struct a table describes,
 * member by member, each value checked against its row as it is written. */
#include "schema_text.h"
#include "utc_time.h"

#include <cjson/cJSON.h>

#include <stdint.h>
#include <stdio.h>
#include <string.h>

struct patch_context {
    const struct proto_schema *schema;
    void *target; /* a scratch copy: written freely, discarded on error */
    struct proto_field_errors *errors;
    bool *named; /* per row: the object names it */
};

static void *field_address(void *target, const struct proto_field_desc *field)
{
    return (char *)target + field->offset;
}

static void apply_number(struct patch_context *context, const struct proto_field_desc *field,
                         const cJSON *value, const char *pointer)
{
    if (!cJSON_IsNumber(value)) {
        proto_field_errors_addf(context->errors, PROTO_FIELD_WRONG_TYPE, pointer,
                                "expected a number, got %s", proto_json_type_name(value));
        return;
    }
    if (schema_check_number(context->errors, field, value->valuedouble, pointer))
        *(double *)field_address(context->target, field) = value->valuedouble;
}

static bool check_array_length(struct patch_context *context, const cJSON *value, int expected,
                               const char *element_kind, const char *pointer)
{
    int length = cJSON_GetArraySize(value);
    if (length == expected)
        return true;
    proto_field_errors_addf(context->errors, PROTO_FIELD_BAD_VALUE, pointer,
                            "expected an array of %d %s, got %d element%s", expected, element_kind,
                            length, length == 1 ? "" : "s");
    return false;
}

static void apply_rgb_array(struct patch_context *context, const struct proto_field_desc *field,
                            const cJSON *value, const char *pointer)
{
    if (!check_array_length(context, value, 3, "numbers", pointer))
        return;
    double *channels = field_address(context->target, field);
    int index = 0;
    for (const cJSON *element = value->child; element; element = element->next, index++) {
        char item_pointer[POINTER_CAPACITY];
        schema_element_pointer(pointer, index, item_pointer, sizeof item_pointer);
        if (!cJSON_IsNumber(element)) {
            proto_field_errors_addf(context->errors, PROTO_FIELD_WRONG_TYPE, item_pointer,
                                    "expected a number, got %s", proto_json_type_name(element));
        } else if (schema_check_number(context->errors, field, element->valuedouble,
                                       item_pointer)) {
            channels[index] = element->valuedouble;
        }
    }
}

static void apply_rgb(struct patch_context *context, const struct proto_field_desc *field,
                      const cJSON *value, const char *pointer)
{
    if (cJSON_IsArray(value)) {
        apply_rgb_array(context, field, value, pointer);
    } else if (cJSON_IsNumber(value)) {
        if (schema_check_number(context->errors, field, value->valuedouble, pointer)) {
            double *channels = field_address(context->target, field);
            channels[0] = channels[1] = channels[2] = value->valuedouble;
        }
    } else {
        proto_field_errors_addf(context->errors, PROTO_FIELD_WRONG_TYPE, pointer,
                                "expected a number or an array of 3 numbers, got %s",
                                proto_json_type_name(value));
    }
}

static void apply_int_array(struct patch_context *context, const struct proto_field_desc *field,
                            const cJSON *value, const char *pointer)
{
    int expected = schema_element_count(field->type);
    if (!cJSON_IsArray(value)) {
        proto_field_errors_addf(context->errors, PROTO_FIELD_WRONG_TYPE, pointer,
                                "expected an array of %d integers, got %s", expected,
                                proto_json_type_name(value));
        return;
    }
    if (!check_array_length(context, value, expected, "integers", pointer))
        return;
    int *elements = field_address(context->target, field);
    int index = 0;
    for (const cJSON *element = value->child; element; element = element->next, index++) {
        char item_pointer[POINTER_CAPACITY];
        schema_element_pointer(pointer, index, item_pointer, sizeof item_pointer);
        if (!cJSON_IsNumber(element)) {
            proto_field_errors_addf(context->errors, PROTO_FIELD_WRONG_TYPE, item_pointer,
                                    "expected an integer, got %s", proto_json_type_name(element));
        } else if (schema_check_integer(context->errors, field, element->valuedouble,
                                        item_pointer)) {
            elements[index] = (int)element->valuedouble;
        }
    }
}

static int find_enum_value(const struct proto_field_desc *field, const char *name)
{
    for (int i = 0; i < field->enum_count; i++) {
        if (field->enum_names[i] && strcmp(field->enum_names[i], name) == 0)
            return i;
    }
    return -1;
}

static void apply_enum(struct patch_context *context, const struct proto_field_desc *field,
                       const cJSON *value, const char *pointer)
{
    char names[REASON_CAPACITY];
    schema_list_enum_names(field, names, sizeof names);
    if (!cJSON_IsString(value)) {
        proto_field_errors_addf(context->errors, PROTO_FIELD_WRONG_TYPE, pointer,
                                "expected one of: %s, got %s", names, proto_json_type_name(value));
        return;
    }
    int found = find_enum_value(field, value->valuestring);
    if (found < 0) {
        proto_field_errors_addf(context->errors, PROTO_FIELD_BAD_VALUE, pointer,
                                "expected one of: %s, got \"%s\"", names, value->valuestring);
        return;
    }
    *(int *)field_address(context->target, field) = found;
}

static void apply_int(struct patch_context *context, const struct proto_field_desc *field,
                      const cJSON *value, const char *pointer)
{
    if (!cJSON_IsNumber(value)) {
        proto_field_errors_addf(context->errors, PROTO_FIELD_WRONG_TYPE, pointer,
                                "expected an integer, got %s", proto_json_type_name(value));
        return;
    }
    if (schema_check_integer(context->errors, field, value->valuedouble, pointer)) {
        if (field->type == PROTO_FIELD_TYPE_INT64)
            *(int64_t *)field_address(context->target, field) = (int64_t)value->valuedouble;
        else
            *(int *)field_address(context->target, field) = (int)value->valuedouble;
    }
}

static void apply_time(struct patch_context *context, const struct proto_field_desc *field,
                       const cJSON *value, const char *pointer)
{
    if (!cJSON_IsString(value)) {
        proto_field_errors_addf(
            context->errors, PROTO_FIELD_WRONG_TYPE, pointer,
            "expected an ISO 8601 UTC time like \"2026-06-21T12:00:00Z\", got %s",
            proto_json_type_name(value));
        return;
    }
    double seconds;
    char why[REASON_CAPACITY];
    if (!proto_time_parse_iso8601(value->valuestring, &seconds, why, sizeof why)) {
        proto_field_errors_addf(context->errors, PROTO_FIELD_BAD_VALUE, pointer, "%s", why);
        return;
    }
    if (schema_check_time(context->errors, field, seconds, pointer))
        *(double *)field_address(context->target, field) = seconds;
}

static void apply_string(struct patch_context *context, const struct proto_field_desc *field,
                         const cJSON *value, const char *pointer)
{
    size_t length = cJSON_IsString(value) ? strlen(value->valuestring) : 0;
    if (!cJSON_IsString(value))
        proto_field_errors_addf(context->errors, PROTO_FIELD_WRONG_TYPE, pointer,
                                "expected a string, got %s", proto_json_type_name(value));
    else if (field->min > 0 && (length < field->min || length >= field->capacity))
        proto_field_errors_addf(context->errors, PROTO_FIELD_OUT_OF_RANGE, pointer,
                                "must be %.0f to %zu bytes long, got %zu", field->min,
                                field->capacity - 1, length);
    else if (length >= field->capacity)
        proto_field_errors_addf(context->errors, PROTO_FIELD_OUT_OF_RANGE, pointer,
                                "longer than %zu characters", field->capacity - 1);
    else
        snprintf(field_address(context->target, field), field->capacity, "%s", value->valuestring);
}

static void apply_bool(struct patch_context *context, const struct proto_field_desc *field,
                       const cJSON *value, const char *pointer)
{
    if (!cJSON_IsBool(value))
        proto_field_errors_addf(context->errors, PROTO_FIELD_WRONG_TYPE, pointer,
                                "expected true or false, got %s", proto_json_type_name(value));
    else
        *(bool *)field_address(context->target, field) = cJSON_IsTrue(value);
}

static void apply_leaf(struct patch_context *context, const struct proto_field_desc *field,
                       const cJSON *value, const char *pointer)
{
    switch (field->type) {
    case PROTO_FIELD_TYPE_NUMBER:
        apply_number(context, field, value, pointer);
        break;
    case PROTO_FIELD_TYPE_RGB:
        apply_rgb(context, field, value, pointer);
        break;
    case PROTO_FIELD_TYPE_INT_PAIR:
    case PROTO_FIELD_TYPE_INT_TRIPLE:
        apply_int_array(context, field, value, pointer);
        break;
    case PROTO_FIELD_TYPE_ENUM:
        apply_enum(context, field, value, pointer);
        break;
    case PROTO_FIELD_TYPE_INT:
    case PROTO_FIELD_TYPE_INT64:
        apply_int(context, field, value, pointer);
        break;
    case PROTO_FIELD_TYPE_TIME:
        apply_time(context, field, value, pointer);
        break;
    case PROTO_FIELD_TYPE_STRING:
        apply_string(context, field, value, pointer);
        break;
    case PROTO_FIELD_TYPE_BOOL:
        apply_bool(context, field, value, pointer);
        break;
    }
}

/* Joins prefix and name with a dot; false for names that cannot be a schema segment. */
static bool join_dotted(char *dotted, size_t capacity, const char *prefix, const char *name)
{
    if (!name || name[0] == '\0' || strchr(name, '.'))
        return false;
    size_t used = 0;
    dotted[0] = '\0';
    if (prefix[0] != '\0') {
        if (!schema_append_bytes(dotted, capacity, &used, prefix, strlen(prefix)) ||
            !schema_append_bytes(dotted, capacity, &used, ".", 1))
            return false;
    }
    return schema_append_bytes(dotted, capacity, &used, name, strlen(name));
}

static void report_unknown_member(struct patch_context *context, const char *prefix,
                                  const char *pointer)
{
    char children[REASON_CAPACITY];
    schema_list_children(context->schema, prefix, children, sizeof children);
    proto_field_errors_addf(context->errors, PROTO_FIELD_UNKNOWN, pointer,
                            "unknown field; expected one of: %s", children);
}

static void apply_object(struct patch_context *context, const cJSON *object, const char *prefix,
                         const char *pointer);

static bool given_before(const cJSON *object, const cJSON *member)
{
    for (const cJSON *earlier = object->child; earlier != member; earlier = earlier->next)
        if (earlier->string && member->string && strcmp(earlier->string, member->string) == 0)
            return true;
    return false;
}

static void apply_member(struct patch_context *context, const cJSON *object, const cJSON *member,
                         const char *prefix, const char *parent_pointer)
{
    const char *name = member->string ? member->string : "";
    char pointer[POINTER_CAPACITY];
    schema_copy_text(pointer, sizeof pointer, parent_pointer);
    schema_pointer_append(pointer, sizeof pointer, name);

    const struct proto_schema *schema = context->schema;
    if (schema->unique_members && given_before(object, member)) {
        proto_field_errors_addf(context->errors, PROTO_FIELD_BAD_VALUE, pointer, "duplicate field");
        return;
    }
    for (size_t i = 0; prefix[0] == '\0' && i < schema->caller_member_count; i++)
        if (strcmp(name, schema->caller_members[i]) == 0)
            return;
    const char *reserved = schema->read_only_member;
    if (prefix[0] == '\0' && reserved && strcmp(name, reserved) == 0) {
        proto_field_errors_addf(context->errors, PROTO_FIELD_BAD_VALUE, pointer, "read-only");
        return;
    }
    char dotted[DOTTED_PATH_CAPACITY];
    if (!join_dotted(dotted, sizeof dotted, prefix, name)) {
        report_unknown_member(context, prefix, pointer);
        return;
    }
    const struct proto_field_desc *field = proto_schema_find(context->schema, dotted);
    if (field) {
        apply_leaf(context, field, member, pointer);
        if (field - schema->fields < PROTO_SCHEMA_MAX_ROWS)
            context->named[field - schema->fields] = true;
    } else if (!schema_is_group(context->schema, dotted)) {
        report_unknown_member(context, prefix, pointer);
    } else if (cJSON_IsObject(member)) {
        apply_object(context, member, dotted, pointer);
    } else {
        proto_field_errors_addf(context->errors, PROTO_FIELD_WRONG_TYPE, pointer,
                                "expected an object, got %s", proto_json_type_name(member));
    }
}

/* Recursion depth is bounded by the schema: only known groups are descended into. */
static void apply_object(struct patch_context *context, const cJSON *object, const char *prefix,
                         const char *pointer)
{
    for (const cJSON *member = object->child; member; member = member->next)
        apply_member(context, object, member, prefix, pointer);
}

static void report_missing(const struct proto_schema *schema, const bool *named,
                           const char *pointer_prefix, struct proto_field_errors *errors)
{
    for (size_t i = 0; i < schema->count; i++) {
        if (!schema->fields[i].required || named[i])
            continue;
        char pointer[POINTER_CAPACITY], relative[POINTER_CAPACITY];
        schema_pointer_from_dotted(schema->fields[i].path, relative, sizeof relative);
        snprintf(pointer, sizeof pointer, "%s%s", pointer_prefix, relative);
        proto_field_errors_add(errors, PROTO_FIELD_MISSING, pointer, "required");
    }
}

bool proto_schema_apply_json(const struct proto_schema *schema, void *target, const cJSON *json,
                             const char *pointer_prefix, struct proto_field_errors *errors,
                             bool *named)
{
    int before = errors->total;
    if (!cJSON_IsObject(json)) {
        proto_field_errors_addf(errors, PROTO_FIELD_WRONG_TYPE, pointer_prefix,
                                "expected a JSON object, got %s",
                                json ? proto_json_type_name(json) : "nothing");
        return false;
    }
    bool scratch[PROTO_SCHEMA_MAX_ROWS];
    if (!named)
        named = scratch;
    size_t rows = schema->count < PROTO_SCHEMA_MAX_ROWS ? schema->count : PROTO_SCHEMA_MAX_ROWS;
    memset(named, 0, rows * sizeof *named);
    struct patch_context context = { schema, target, errors, named };
    apply_object(&context, json, "", pointer_prefix);
    report_missing(schema, named, pointer_prefix, errors);
    return errors->total == before;
}
