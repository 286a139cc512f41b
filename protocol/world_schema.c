/* The world-state schema engine's shared parts: one descriptor row per leaf field (the table
 * of world_fields.c) looked up by dotted path, the field-error list, the bounded text and
 * JSON Pointer building that patching, validation and serialization share, and the checks of
 * one value against its row. */
#include "world_schema.h"
#include "utc_time.h"

#include <cjson/cJSON.h>

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* ---- schema lookup ---------------------------------------------------------------------- */

const struct sky_field_desc *sky_world_state_fields(size_t *count)
{
    if (count)
        *count = sky_world_field_count;
    return sky_world_field_table;
}

const struct sky_field_desc *sky_world_state_find_field(const char *dotted_path)
{
    return schema_find(sky_world_schema(), dotted_path);
}

size_t sky_field_size(const struct sky_field_desc *field)
{
    switch (field->type) {
    case SKY_FIELD_TYPE_NUMBER:
    case SKY_FIELD_TYPE_TIME: return sizeof(double);
    case SKY_FIELD_TYPE_RGB: return 3 * sizeof(double);
    case SKY_FIELD_TYPE_INT_PAIR: return 2 * sizeof(int);
    case SKY_FIELD_TYPE_INT_TRIPLE: return 3 * sizeof(int);
    case SKY_FIELD_TYPE_STRING: return field->capacity;
    case SKY_FIELD_TYPE_BOOL: return sizeof(bool);
    case SKY_FIELD_TYPE_INT64: return sizeof(int64_t);
    case SKY_FIELD_TYPE_ENUM:
    case SKY_FIELD_TYPE_INT: break;
    }
    return sizeof(int);
}

int schema_element_count(enum sky_field_type type)
{
    switch (type) {
    case SKY_FIELD_TYPE_RGB:
    case SKY_FIELD_TYPE_INT_TRIPLE:
        return 3;
    case SKY_FIELD_TYPE_INT_PAIR:
        return 2;
    case SKY_FIELD_TYPE_NUMBER:
    case SKY_FIELD_TYPE_ENUM:
    case SKY_FIELD_TYPE_INT:
    case SKY_FIELD_TYPE_TIME:
    case SKY_FIELD_TYPE_STRING:
    case SKY_FIELD_TYPE_BOOL:
    case SKY_FIELD_TYPE_INT64:
        break;
    }
    return 1;
}

/* True when `path` lies below `prefix` ("" is the root); *segment is the next name under it. */
static bool child_segment(const char *path, const char *prefix, const char **segment,
                          size_t *segment_length)
{
    size_t prefix_length = strlen(prefix);
    if (prefix_length > 0) {
        if (strncmp(path, prefix, prefix_length) != 0 || path[prefix_length] != '.')
            return false;
        path += prefix_length + 1;
    }
    *segment = path;
    *segment_length = strcspn(path, ".");
    return true;
}

/* A group is a dotted path with leaf fields below it ("atmosphere", "atmosphere.mie"). */
bool schema_is_group(const struct sky_schema *schema, const char *dotted_path)
{
    if (dotted_path[0] == '\0')
        return false;
    const char *segment;
    size_t length;
    for (size_t i = 0; i < schema->count; i++) {
        if (child_segment(schema->fields[i].path, dotted_path, &segment, &length))
            return true;
    }
    return false;
}

const struct sky_field_desc *schema_find(const struct sky_schema *schema, const char *dotted_path)
{
    for (size_t i = 0; dotted_path && i < schema->count; i++) {
        if (strcmp(schema->fields[i].path, dotted_path) == 0)
            return &schema->fields[i];
    }
    return NULL;
}


/* ---- bounded text building -------------------------------------------------------------- */

/* Appends `length` bytes only if they all fit, so escapes are never split. */
bool schema_append_bytes(char *buffer, size_t capacity, size_t *used, const char *bytes,
                         size_t length)
{
    if (*used + length >= capacity)
        return false;
    memcpy(buffer + *used, bytes, length);
    *used += length;
    buffer[*used] = '\0';
    return true;
}

static void append_text(char *buffer, size_t capacity, size_t *used, const char *text)
{
    schema_append_bytes(buffer, capacity, used, text, strlen(text));
}

void schema_copy_text(char *buffer, size_t capacity, const char *text)
{
    size_t used = 0;
    buffer[0] = '\0';
    size_t length = strlen(text);
    if (length >= capacity)
        length = capacity - 1;
    schema_append_bytes(buffer, capacity, &used, text, length);
}

/* JSON Pointer escaping (RFC 6901): '~' becomes "~0", '/' becomes "~1". */
static void append_pointer_char(char *pointer, size_t capacity, size_t *used, char c)
{
    if (c == '~')
        schema_append_bytes(pointer, capacity, used, "~0", 2);
    else if (c == '/')
        schema_append_bytes(pointer, capacity, used, "~1", 2);
    else
        schema_append_bytes(pointer, capacity, used, &c, 1);
}

void schema_pointer_append(char *pointer, size_t capacity, const char *segment)
{
    size_t used = strlen(pointer);
    if (!schema_append_bytes(pointer, capacity, &used, "/", 1))
        return;
    for (const char *c = segment; *c; c++)
        append_pointer_char(pointer, capacity, &used, *c);
}

void schema_pointer_append_index(char *pointer, size_t capacity, int index)
{
    char segment[16];
    snprintf(segment, sizeof segment, "%d", index);
    schema_pointer_append(pointer, capacity, segment);
}

void schema_pointer_from_dotted(const char *dotted_path, char *pointer, size_t capacity)
{
    size_t used = 0;
    pointer[0] = '\0';
    schema_append_bytes(pointer, capacity, &used, "/", 1);
    for (const char *c = dotted_path; *c; c++) {
        if (*c == '.')
            schema_append_bytes(pointer, capacity, &used, "/", 1);
        else
            append_pointer_char(pointer, capacity, &used, *c);
    }
}

void sky_field_pointer(const struct sky_field_desc *field, char *pointer, size_t capacity)
{
    schema_pointer_from_dotted(field->path, pointer, capacity);
}

/* Shortest text that reads back as the same double. */
void schema_format_number(double value, char *text, size_t capacity)
{
    snprintf(text, capacity, "%.15g", value);
    if (strtod(text, NULL) != value)
        snprintf(text, capacity, "%.17g", value);
}

void schema_list_enum_names(const struct sky_field_desc *field, char *text, size_t capacity)
{
    size_t used = 0;
    text[0] = '\0';
    for (int i = 0; i < field->enum_count; i++) {
        if (!field->enum_names[i])
            continue;
        if (used > 0)
            append_text(text, capacity, &used, ", ");
        append_text(text, capacity, &used, field->enum_names[i]);
    }
}

/* Names directly below a group, e.g. "rayleigh, mie, ..." for "atmosphere". */
void schema_list_children(const struct sky_schema *schema, const char *prefix, char *text,
                          size_t capacity)
{
    size_t used = 0;
    text[0] = '\0';
    for (size_t i = 0; i < schema->count; i++) {
        const char *segment;
        size_t length;
        if (!child_segment(schema->fields[i].path, prefix, &segment, &length))
            continue;
        bool seen = false;
        for (size_t j = 0; j < i && !seen; j++) {
            const char *earlier;
            size_t earlier_length;
            seen = child_segment(schema->fields[j].path, prefix, &earlier, &earlier_length) &&
                   earlier_length == length && memcmp(earlier, segment, length) == 0;
        }
        if (seen)
            continue;
        if (used > 0)
            append_text(text, capacity, &used, ", ");
        schema_append_bytes(text, capacity, &used, segment, length);
    }
    for (size_t i = 0; prefix[0] == '\0' && i < schema->caller_member_count; i++) {
        if (used > 0)
            append_text(text, capacity, &used, ", ");
        append_text(text, capacity, &used, schema->caller_members[i]);
    }
}

const char *sky_json_type_name(const struct cJSON *value)
{
    if (cJSON_IsNumber(value))
        return "a number";
    if (cJSON_IsString(value))
        return "a string";
    if (cJSON_IsBool(value))
        return "a boolean";
    if (cJSON_IsNull(value))
        return "null";
    if (cJSON_IsArray(value))
        return "an array";
    if (cJSON_IsObject(value))
        return "an object";
    return "an invalid value";
}

/* cJSON_CreateNumber converts to int internally, which is undefined for NaN. */
cJSON *schema_new_json_number(double value)
{
    if (isfinite(value))
        return cJSON_CreateNumber(value);
    cJSON *number = cJSON_CreateNumber(0);
    if (number)
        number->valuedouble = value;
    return number;
}

/* ---- value checks shared by patching and validation (world_state.c) --------------------- */

bool schema_check_number(struct sky_field_errors *errors, const struct sky_field_desc *field,
                         double value, const char *pointer)
{
    char got[NUMBER_TEXT_CAPACITY];
    schema_format_number(value, got, sizeof got);
    if (!isfinite(value)) {
        sky_field_errors_addf(errors, SKY_FIELD_OUT_OF_RANGE, pointer,
                              "must be a finite number, got %s", got);
        return false;
    }
    char min[NUMBER_TEXT_CAPACITY], max[NUMBER_TEXT_CAPACITY];
    schema_format_number(field->min, min, sizeof min);
    schema_format_number(field->max, max, sizeof max);
    if (field->exclusive_min && value <= field->min) {
        if (value > field->max)
            sky_field_errors_addf(errors, SKY_FIELD_OUT_OF_RANGE, pointer,
                                  "must be in (%s, %s], got %s", min, max, got);
        else
            sky_field_errors_addf(errors, SKY_FIELD_OUT_OF_RANGE, pointer,
                                  "must be greater than %s, got %s", min, got);
        return false;
    }
    if (value < field->min || value > field->max) {
        sky_field_errors_addf(errors, SKY_FIELD_OUT_OF_RANGE, pointer,
                              "must be in %s%s, %s], got %s", field->exclusive_min ? "(" : "[",
                              min, max, got);
        return false;
    }
    return true;
}

/* The range check comes first, so an integral value is known to fit the field's integer. */
bool schema_check_integer(struct sky_field_errors *errors, const struct sky_field_desc *field,
                          double value, const char *pointer)
{
    if (!schema_check_number(errors, field, value, pointer))
        return false;
    if (value != floor(value)) {
        char got[NUMBER_TEXT_CAPACITY];
        schema_format_number(value, got, sizeof got);
        sky_field_errors_addf(errors, SKY_FIELD_BAD_VALUE, pointer, "must be an integer, got %s",
                              got);
        return false;
    }
    return true;
}

void schema_element_pointer(const char *pointer, int index, char *out, size_t capacity)
{
    schema_copy_text(out, capacity, pointer);
    schema_pointer_append_index(out, capacity, index);
}

bool schema_check_time(struct sky_field_errors *errors, const struct sky_field_desc *field,
                       double seconds, const char *pointer)
{
    if (isfinite(seconds) && seconds >= field->min && seconds <= field->max)
        return true;
    char got[TIME_TEXT_CAPACITY], min[TIME_TEXT_CAPACITY], max[TIME_TEXT_CAPACITY];
    sky_time_format_iso8601(seconds, got, sizeof got);
    sky_time_format_iso8601(field->min, min, sizeof min);
    sky_time_format_iso8601(field->max, max, sizeof max);
    sky_field_errors_addf(errors, SKY_FIELD_OUT_OF_RANGE, pointer, "must be in [%s, %s], got %s",
                          min, max, got);
    return false;
}

/* ---- error collection ------------------------------------------------------------------- */

void sky_field_errors_clear(struct sky_field_errors *errors)
{
    if (errors)
        memset(errors, 0, sizeof *errors);
}

void sky_field_errors_add(struct sky_field_errors *errors, int code, const char *pointer,
                          const char *reason)
{
    if (!errors)
        return;
    errors->total++;
    if (errors->count < 0 || errors->count >= SKY_MAX_FIELD_ERRORS)
        return;
    struct sky_field_error *item = &errors->items[errors->count++];
    item->code = code;
    schema_copy_text(item->pointer, sizeof item->pointer, pointer ? pointer : "");
    schema_copy_text(item->reason, sizeof item->reason, reason ? reason : "");
}

void sky_field_errors_vaddf(struct sky_field_errors *errors, int code, const char *pointer,
                            const char *format, va_list args)
{
    char reason[REASON_CAPACITY];
    vsnprintf(reason, sizeof reason, format, args);
    sky_field_errors_add(errors, code, pointer, reason);
}

void sky_field_errors_addf(struct sky_field_errors *errors, int code, const char *pointer,
                           const char *format, ...)
{
    va_list args;
    va_start(args, format);
    sky_field_errors_vaddf(errors, code, pointer, format, args);
    va_end(args);
}

void sky_field_errors_format(const struct sky_field_errors *errors, char *buf, size_t buflen)
{
    if (!buf || buflen == 0)
        return;
    buf[0] = '\0';
    if (!errors)
        return;
    int count = errors->count;
    if (count > SKY_MAX_FIELD_ERRORS)
        count = SKY_MAX_FIELD_ERRORS;
    size_t used = 0;
    bool complete = true;
    char line[POINTER_CAPACITY + REASON_CAPACITY + 16];
    for (int i = 0; i < count && complete; i++) {
        const struct sky_field_error *item = &errors->items[i];
        snprintf(line, sizeof line, "%s%s: %s", i > 0 ? "\n" : "",
                 item->pointer[0] ? item->pointer : "(root)", item->reason);
        complete = schema_append_bytes(buf, buflen, &used, line, strlen(line));
    }
    if (complete && errors->total > count) {
        snprintf(line, sizeof line, "%s(and %d more)", count > 0 ? "\n" : "",
                 errors->total - count);
        complete = schema_append_bytes(buf, buflen, &used, line, strlen(line));
    }
    if (!complete) {
        /* Fill what is left with the start of the line that did not fit, ending in "...". */
        schema_append_bytes(buf, buflen, &used, line, buflen - 1 - used);
        if (used >= 3)
            memcpy(buf + used - 3, "...", 3);
    }
}

const void *schema_const_field_address(const void *base, const struct sky_field_desc *field)
{
    return (const char *)base + field->offset;
}

