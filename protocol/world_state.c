/* World state schema: one descriptor row per leaf field drives validation, JSON patching,
 * dotted-path assignment and serialization. */
#include "world_state.h"
#include "world_fields.h"
#include "utc_time.h"

#include <cjson/cJSON.h>

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>


#define POINTER_CAPACITY sizeof(((struct sky_field_error *)NULL)->pointer)
#define REASON_CAPACITY sizeof(((struct sky_field_error *)NULL)->reason)
#define DOTTED_PATH_CAPACITY 128
#define NUMBER_TEXT_CAPACITY 32
#define TIME_TEXT_CAPACITY 40

static const double MAX_ATMOSPHERE_THICKNESS_KM = 1000.0;

#define FIELD_COUNT sky_world_field_count
#define fields sky_world_field_table

/* ---- schema lookup ---------------------------------------------------------------------- */

const struct sky_field_desc *sky_world_state_fields(size_t *count)
{
    if (count)
        *count = FIELD_COUNT;
    return fields;
}

const struct sky_field_desc *sky_world_state_find_field(const char *dotted_path)
{
    if (!dotted_path)
        return NULL;
    for (size_t i = 0; i < FIELD_COUNT; i++) {
        if (strcmp(fields[i].path, dotted_path) == 0)
            return &fields[i];
    }
    return NULL;
}

static int element_count(enum sky_field_type type)
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
static bool is_group(const char *dotted_path)
{
    if (dotted_path[0] == '\0')
        return false;
    const char *segment;
    size_t length;
    for (size_t i = 0; i < FIELD_COUNT; i++) {
        if (child_segment(fields[i].path, dotted_path, &segment, &length))
            return true;
    }
    return false;
}

/* ---- bounded text building -------------------------------------------------------------- */

/* Appends `length` bytes only if they all fit, so escapes are never split. */
static bool append_bytes(char *buffer, size_t capacity, size_t *used, const char *bytes,
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
    append_bytes(buffer, capacity, used, text, strlen(text));
}

static void copy_text(char *buffer, size_t capacity, const char *text)
{
    size_t used = 0;
    buffer[0] = '\0';
    size_t length = strlen(text);
    if (length >= capacity)
        length = capacity - 1;
    append_bytes(buffer, capacity, &used, text, length);
}

/* JSON Pointer escaping (RFC 6901): '~' becomes "~0", '/' becomes "~1". */
static void append_pointer_char(char *pointer, size_t capacity, size_t *used, char c)
{
    if (c == '~')
        append_bytes(pointer, capacity, used, "~0", 2);
    else if (c == '/')
        append_bytes(pointer, capacity, used, "~1", 2);
    else
        append_bytes(pointer, capacity, used, &c, 1);
}

static void pointer_append(char *pointer, size_t capacity, const char *segment)
{
    size_t used = strlen(pointer);
    if (!append_bytes(pointer, capacity, &used, "/", 1))
        return;
    for (const char *c = segment; *c; c++)
        append_pointer_char(pointer, capacity, &used, *c);
}

static void pointer_append_index(char *pointer, size_t capacity, int index)
{
    char segment[16];
    snprintf(segment, sizeof segment, "%d", index);
    pointer_append(pointer, capacity, segment);
}

static void pointer_from_dotted(const char *dotted_path, char *pointer, size_t capacity)
{
    size_t used = 0;
    pointer[0] = '\0';
    append_bytes(pointer, capacity, &used, "/", 1);
    for (const char *c = dotted_path; *c; c++) {
        if (*c == '.')
            append_bytes(pointer, capacity, &used, "/", 1);
        else
            append_pointer_char(pointer, capacity, &used, *c);
    }
}

/* Shortest text that reads back as the same double. */
static void format_number(double value, char *text, size_t capacity)
{
    snprintf(text, capacity, "%.15g", value);
    if (strtod(text, NULL) != value)
        snprintf(text, capacity, "%.17g", value);
}

static void list_enum_names(const struct sky_field_desc *field, char *text, size_t capacity)
{
    size_t used = 0;
    text[0] = '\0';
    for (int i = 0; i < field->enum_count; i++) {
        if (i > 0)
            append_text(text, capacity, &used, ", ");
        append_text(text, capacity, &used, field->enum_names[i]);
    }
}

/* Names directly below a group, e.g. "rayleigh, mie, ..." for "atmosphere". */
static void list_children(const char *prefix, char *text, size_t capacity)
{
    size_t used = 0;
    text[0] = '\0';
    for (size_t i = 0; i < FIELD_COUNT; i++) {
        const char *segment;
        size_t length;
        if (!child_segment(fields[i].path, prefix, &segment, &length))
            continue;
        bool seen = false;
        for (size_t j = 0; j < i && !seen; j++) {
            const char *earlier;
            size_t earlier_length;
            seen = child_segment(fields[j].path, prefix, &earlier, &earlier_length) &&
                   earlier_length == length && memcmp(earlier, segment, length) == 0;
        }
        if (seen)
            continue;
        if (used > 0)
            append_text(text, capacity, &used, ", ");
        append_bytes(text, capacity, &used, segment, length);
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
static cJSON *new_json_number(double value)
{
    if (isfinite(value))
        return cJSON_CreateNumber(value);
    cJSON *number = cJSON_CreateNumber(0);
    if (number)
        number->valuedouble = value;
    return number;
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
    copy_text(item->pointer, sizeof item->pointer, pointer ? pointer : "");
    copy_text(item->reason, sizeof item->reason, reason ? reason : "");
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
        complete = append_bytes(buf, buflen, &used, line, strlen(line));
    }
    if (complete && errors->total > count) {
        snprintf(line, sizeof line, "%s(and %d more)", count > 0 ? "\n" : "",
                 errors->total - count);
        complete = append_bytes(buf, buflen, &used, line, strlen(line));
    }
    if (!complete) {
        /* Fill what is left with the start of the line that did not fit, ending in "...". */
        append_bytes(buf, buflen, &used, line, buflen - 1 - used);
        if (used >= 3)
            memcpy(buf + used - 3, "...", 3);
    }
}

/* ---- value checks shared by patching and validation ------------------------------------- */

static bool check_number(struct sky_field_errors *errors, const struct sky_field_desc *field,
                         double value, const char *pointer)
{
    char got[NUMBER_TEXT_CAPACITY];
    format_number(value, got, sizeof got);
    if (!isfinite(value)) {
        sky_field_errors_addf(errors, SKY_FIELD_OUT_OF_RANGE, pointer,
                              "must be a finite number, got %s", got);
        return false;
    }
    if (value < field->min || value > field->max) {
        char min[NUMBER_TEXT_CAPACITY], max[NUMBER_TEXT_CAPACITY];
        format_number(field->min, min, sizeof min);
        format_number(field->max, max, sizeof max);
        sky_field_errors_addf(errors, SKY_FIELD_OUT_OF_RANGE, pointer,
                              "must be in [%s, %s], got %s", min, max, got);
        return false;
    }
    return true;
}

/* The range check comes first, so an integral value is known to fit an int. */
static bool check_integer(struct sky_field_errors *errors, const struct sky_field_desc *field,
                          double value, const char *pointer)
{
    if (!check_number(errors, field, value, pointer))
        return false;
    if (value != (double)(int)value) {
        char got[NUMBER_TEXT_CAPACITY];
        format_number(value, got, sizeof got);
        sky_field_errors_addf(errors, SKY_FIELD_BAD_VALUE, pointer, "must be an integer, got %s",
                              got);
        return false;
    }
    return true;
}

static void element_pointer(const char *pointer, int index, char *out, size_t capacity)
{
    copy_text(out, capacity, pointer);
    pointer_append_index(out, capacity, index);
}

/* ---- patch application ------------------------------------------------------------------ */

struct patch_context {
    struct sky_world_state *target; /* a scratch copy: written freely, discarded on error */
    struct sky_field_errors *errors;
};

static void *field_address(struct sky_world_state *state, const struct sky_field_desc *field)
{
    return (char *)state + field->offset;
}

static const void *const_field_address(const struct sky_world_state *state,
                                       const struct sky_field_desc *field)
{
    return (const char *)state + field->offset;
}

static void apply_number(struct patch_context *context, const struct sky_field_desc *field,
                         const cJSON *value, const char *pointer)
{
    if (!cJSON_IsNumber(value)) {
        sky_field_errors_addf(context->errors, SKY_FIELD_WRONG_TYPE, pointer,
                              "expected a number, got %s", sky_json_type_name(value));
        return;
    }
    if (check_number(context->errors, field, value->valuedouble, pointer))
        *(double *)field_address(context->target, field) = value->valuedouble;
}

static bool check_array_length(struct patch_context *context, const cJSON *value, int expected,
                               const char *element_kind, const char *pointer)
{
    int length = cJSON_GetArraySize(value);
    if (length == expected)
        return true;
    sky_field_errors_addf(context->errors, SKY_FIELD_BAD_VALUE, pointer,
                          "expected an array of %d %s, got %d element%s", expected, element_kind,
                          length, length == 1 ? "" : "s");
    return false;
}

static void apply_rgb_array(struct patch_context *context, const struct sky_field_desc *field,
                            const cJSON *value, const char *pointer)
{
    if (!check_array_length(context, value, 3, "numbers", pointer))
        return;
    double *channels = field_address(context->target, field);
    int index = 0;
    for (const cJSON *element = value->child; element; element = element->next, index++) {
        char item_pointer[POINTER_CAPACITY];
        element_pointer(pointer, index, item_pointer, sizeof item_pointer);
        if (!cJSON_IsNumber(element)) {
            sky_field_errors_addf(context->errors, SKY_FIELD_WRONG_TYPE, item_pointer,
                                  "expected a number, got %s", sky_json_type_name(element));
        } else if (check_number(context->errors, field, element->valuedouble, item_pointer)) {
            channels[index] = element->valuedouble;
        }
    }
}

static void apply_rgb(struct patch_context *context, const struct sky_field_desc *field,
                      const cJSON *value, const char *pointer)
{
    if (cJSON_IsArray(value)) {
        apply_rgb_array(context, field, value, pointer);
    } else if (cJSON_IsNumber(value)) {
        if (check_number(context->errors, field, value->valuedouble, pointer)) {
            double *channels = field_address(context->target, field);
            channels[0] = channels[1] = channels[2] = value->valuedouble;
        }
    } else {
        sky_field_errors_addf(context->errors, SKY_FIELD_WRONG_TYPE, pointer,
                              "expected a number or an array of 3 numbers, got %s",
                              sky_json_type_name(value));
    }
}

static void apply_int_array(struct patch_context *context, const struct sky_field_desc *field,
                            const cJSON *value, const char *pointer)
{
    int expected = element_count(field->type);
    if (!cJSON_IsArray(value)) {
        sky_field_errors_addf(context->errors, SKY_FIELD_WRONG_TYPE, pointer,
                              "expected an array of %d integers, got %s", expected,
                              sky_json_type_name(value));
        return;
    }
    if (!check_array_length(context, value, expected, "integers", pointer))
        return;
    int *elements = field_address(context->target, field);
    int index = 0;
    for (const cJSON *element = value->child; element; element = element->next, index++) {
        char item_pointer[POINTER_CAPACITY];
        element_pointer(pointer, index, item_pointer, sizeof item_pointer);
        if (!cJSON_IsNumber(element)) {
            sky_field_errors_addf(context->errors, SKY_FIELD_WRONG_TYPE, item_pointer,
                                  "expected an integer, got %s", sky_json_type_name(element));
        } else if (check_integer(context->errors, field, element->valuedouble, item_pointer)) {
            elements[index] = (int)element->valuedouble;
        }
    }
}

static int find_enum_value(const struct sky_field_desc *field, const char *name)
{
    for (int i = 0; i < field->enum_count; i++) {
        if (strcmp(field->enum_names[i], name) == 0)
            return i;
    }
    return -1;
}

static void apply_enum(struct patch_context *context, const struct sky_field_desc *field,
                       const cJSON *value, const char *pointer)
{
    char names[REASON_CAPACITY];
    list_enum_names(field, names, sizeof names);
    if (!cJSON_IsString(value)) {
        sky_field_errors_addf(context->errors, SKY_FIELD_WRONG_TYPE, pointer,
                              "expected one of: %s, got %s", names, sky_json_type_name(value));
        return;
    }
    int found = find_enum_value(field, value->valuestring);
    if (found < 0) {
        sky_field_errors_addf(context->errors, SKY_FIELD_BAD_VALUE, pointer,
                              "expected one of: %s, got \"%s\"", names, value->valuestring);
        return;
    }
    *(int *)field_address(context->target, field) = found;
}

static void apply_int(struct patch_context *context, const struct sky_field_desc *field,
                      const cJSON *value, const char *pointer)
{
    if (!cJSON_IsNumber(value)) {
        sky_field_errors_addf(context->errors, SKY_FIELD_WRONG_TYPE, pointer,
                              "expected an integer, got %s", sky_json_type_name(value));
        return;
    }
    if (check_integer(context->errors, field, value->valuedouble, pointer))
        *(int *)field_address(context->target, field) = (int)value->valuedouble;
}

static bool check_time(struct sky_field_errors *errors, const struct sky_field_desc *field,
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

static void apply_time(struct patch_context *context, const struct sky_field_desc *field,
                       const cJSON *value, const char *pointer)
{
    if (!cJSON_IsString(value)) {
        sky_field_errors_addf(context->errors, SKY_FIELD_WRONG_TYPE, pointer,
                              "expected an ISO 8601 UTC time like \"2026-06-21T12:00:00Z\", got %s",
                              sky_json_type_name(value));
        return;
    }
    double seconds;
    char why[REASON_CAPACITY];
    if (!sky_time_parse_iso8601(value->valuestring, &seconds, why, sizeof why)) {
        sky_field_errors_addf(context->errors, SKY_FIELD_BAD_VALUE, pointer, "%s", why);
        return;
    }
    if (check_time(context->errors, field, seconds, pointer))
        *(double *)field_address(context->target, field) = seconds;
}

static void apply_leaf(struct patch_context *context, const struct sky_field_desc *field,
                       const cJSON *value, const char *pointer)
{
    switch (field->type) {
    case SKY_FIELD_TYPE_NUMBER:
        apply_number(context, field, value, pointer);
        break;
    case SKY_FIELD_TYPE_RGB:
        apply_rgb(context, field, value, pointer);
        break;
    case SKY_FIELD_TYPE_INT_PAIR:
    case SKY_FIELD_TYPE_INT_TRIPLE:
        apply_int_array(context, field, value, pointer);
        break;
    case SKY_FIELD_TYPE_ENUM:
        apply_enum(context, field, value, pointer);
        break;
    case SKY_FIELD_TYPE_INT:
        apply_int(context, field, value, pointer);
        break;
    case SKY_FIELD_TYPE_TIME:
        apply_time(context, field, value, pointer);
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
        if (!append_bytes(dotted, capacity, &used, prefix, strlen(prefix)) ||
            !append_bytes(dotted, capacity, &used, ".", 1))
            return false;
    }
    return append_bytes(dotted, capacity, &used, name, strlen(name));
}

static void report_unknown_member(struct patch_context *context, const char *prefix,
                                  const char *pointer)
{
    char children[REASON_CAPACITY];
    list_children(prefix, children, sizeof children);
    sky_field_errors_addf(context->errors, SKY_FIELD_UNKNOWN, pointer,
                          "unknown field; expected one of: %s", children);
}

static void apply_object(struct patch_context *context, const cJSON *object, const char *prefix,
                         const char *pointer);

static void apply_member(struct patch_context *context, const cJSON *member, const char *prefix,
                         const char *parent_pointer)
{
    const char *name = member->string ? member->string : "";
    char pointer[POINTER_CAPACITY];
    copy_text(pointer, sizeof pointer, parent_pointer);
    pointer_append(pointer, sizeof pointer, name);

    if (prefix[0] == '\0' && strcmp(name, "revision") == 0) {
        sky_field_errors_addf(context->errors, SKY_FIELD_BAD_VALUE, pointer, "read-only");
        return;
    }
    char dotted[DOTTED_PATH_CAPACITY];
    if (!join_dotted(dotted, sizeof dotted, prefix, name)) {
        report_unknown_member(context, prefix, pointer);
        return;
    }
    const struct sky_field_desc *field = sky_world_state_find_field(dotted);
    if (field) {
        apply_leaf(context, field, member, pointer);
    } else if (!is_group(dotted)) {
        report_unknown_member(context, prefix, pointer);
    } else if (cJSON_IsObject(member)) {
        apply_object(context, member, dotted, pointer);
    } else {
        sky_field_errors_addf(context->errors, SKY_FIELD_WRONG_TYPE, pointer,
                              "expected an object, got %s", sky_json_type_name(member));
    }
}

/* Recursion depth is bounded by the schema: only known groups are descended into. */
static void apply_object(struct patch_context *context, const cJSON *object, const char *prefix,
                         const char *pointer)
{
    for (const cJSON *member = object->child; member; member = member->next)
        apply_member(context, member, prefix, pointer);
}

/* ---- whole-state validation ------------------------------------------------------------- */

static void check_stored_field(const struct sky_world_state *state,
                               const struct sky_field_desc *field, struct sky_field_errors *errors)
{
    char pointer[POINTER_CAPACITY];
    char item_pointer[POINTER_CAPACITY];
    pointer_from_dotted(field->path, pointer, sizeof pointer);
    const void *address = const_field_address(state, field);
    int count = element_count(field->type);

    switch (field->type) {
    case SKY_FIELD_TYPE_NUMBER:
        check_number(errors, field, *(const double *)address, pointer);
        break;
    case SKY_FIELD_TYPE_RGB:
        for (int i = 0; i < count; i++) {
            element_pointer(pointer, i, item_pointer, sizeof item_pointer);
            check_number(errors, field, ((const double *)address)[i], item_pointer);
        }
        break;
    case SKY_FIELD_TYPE_INT_PAIR:
    case SKY_FIELD_TYPE_INT_TRIPLE:
        for (int i = 0; i < count; i++) {
            element_pointer(pointer, i, item_pointer, sizeof item_pointer);
            check_number(errors, field, ((const int *)address)[i], item_pointer);
        }
        break;
    case SKY_FIELD_TYPE_INT:
        check_number(errors, field, *(const int *)address, pointer);
        break;
    case SKY_FIELD_TYPE_TIME:
        check_time(errors, field, *(const double *)address, pointer);
        break;
    case SKY_FIELD_TYPE_ENUM: {
        int value = *(const int *)address;
        if (value < 0 || value >= field->enum_count) {
            char names[REASON_CAPACITY];
            list_enum_names(field, names, sizeof names);
            sky_field_errors_addf(errors, SKY_FIELD_OUT_OF_RANGE, pointer,
                                  "must be one of: %s, got %d", names, value);
        }
        break;
    }
    }
}

static void check_consistency(const struct sky_world_state *state,
                              struct sky_field_errors *errors)
{
    double bottom = state->atmosphere.bottom_radius_km;
    double top = state->atmosphere.top_radius_km;
    if (!isfinite(bottom) || !isfinite(top))
        return;
    char bottom_text[NUMBER_TEXT_CAPACITY], top_text[NUMBER_TEXT_CAPACITY];
    char limit_text[NUMBER_TEXT_CAPACITY], thickness_text[NUMBER_TEXT_CAPACITY];
    format_number(bottom, bottom_text, sizeof bottom_text);
    format_number(top, top_text, sizeof top_text);
    if (top <= bottom) {
        sky_field_errors_addf(errors, SKY_FIELD_INCONSISTENT, "/atmosphere/top_radius_km",
                              "must be greater than bottom_radius_km (%s), got %s", bottom_text,
                              top_text);
    } else if (top - bottom > MAX_ATMOSPHERE_THICKNESS_KM) {
        format_number(MAX_ATMOSPHERE_THICKNESS_KM, limit_text, sizeof limit_text);
        format_number(top - bottom, thickness_text, sizeof thickness_text);
        sky_field_errors_addf(errors, SKY_FIELD_INCONSISTENT, "/atmosphere/top_radius_km",
                              "must be at most %s km above bottom_radius_km (%s), got %s km above",
                              limit_text, bottom_text, thickness_text);
    }
}

static void validate_into(const struct sky_world_state *state, struct sky_field_errors *errors)
{
    for (size_t i = 0; i < FIELD_COUNT; i++)
        check_stored_field(state, &fields[i], errors);
    check_consistency(state, errors);
}

bool sky_world_state_validate(const struct sky_world_state *state, struct sky_field_errors *errors)
{
    struct sky_field_errors scratch;
    if (!errors)
        errors = &scratch;
    sky_field_errors_clear(errors);
    if (!state) {
        sky_field_errors_addf(errors, SKY_FIELD_BAD_VALUE, "", "no state");
        return false;
    }
    validate_into(state, errors);
    return errors->total == 0;
}

/* ---- public entry points ---------------------------------------------------------------- */

bool sky_world_state_apply_json(struct sky_world_state *state, const struct cJSON *patch,
                                struct sky_field_errors *errors)
{
    struct sky_field_errors scratch;
    if (!errors)
        errors = &scratch;
    sky_field_errors_clear(errors);
    if (!state) {
        sky_field_errors_addf(errors, SKY_FIELD_BAD_VALUE, "", "no state");
        return false;
    }
    if (!cJSON_IsObject(patch)) {
        sky_field_errors_addf(errors, SKY_FIELD_WRONG_TYPE, "", "expected a JSON object, got %s",
                              patch ? sky_json_type_name(patch) : "nothing");
        return false;
    }
    /* memcpy rather than assignment keeps padding bytes identical, so callers can memcmp. */
    struct sky_world_state candidate;
    memcpy(&candidate, state, sizeof candidate);
    struct patch_context context = {&candidate, errors};
    apply_object(&context, patch, "", "");
    if (errors->total == 0)
        validate_into(&candidate, errors);
    if (errors->total != 0)
        return false;
    memcpy(state, &candidate, sizeof *state);
    return true;
}

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
        return "an integer";
    case SKY_FIELD_TYPE_TIME:
        return "an ISO 8601 UTC time like 2026-06-21T12:00:00Z";
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
        value = new_json_number(number);
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
    pointer_from_dotted(path, pointer, sizeof pointer);
    if (is_group(path)) {
        char children[REASON_CAPACITY];
        list_children(path, children, sizeof children);
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
        cJSON *element = new_json_number(values[i]);
        if (!element || !cJSON_AddItemToArray(array, element)) {
            cJSON_Delete(element);
            cJSON_Delete(array);
            return NULL;
        }
    }
    return array;
}

static cJSON *field_to_json(const struct sky_world_state *state,
                            const struct sky_field_desc *field)
{
    const void *address = const_field_address(state, field);
    switch (field->type) {
    case SKY_FIELD_TYPE_NUMBER:
        return new_json_number(*(const double *)address);
    case SKY_FIELD_TYPE_RGB:
        return number_array_to_json(address, 3);
    case SKY_FIELD_TYPE_INT_PAIR:
    case SKY_FIELD_TYPE_INT_TRIPLE:
        return cJSON_CreateIntArray(address, element_count(field->type));
    case SKY_FIELD_TYPE_INT:
        return cJSON_CreateNumber(*(const int *)address);
    case SKY_FIELD_TYPE_TIME: {
        char text[TIME_TEXT_CAPACITY];
        sky_time_format_iso8601(*(const double *)address, text, sizeof text);
        return cJSON_CreateString(text);
    }
    case SKY_FIELD_TYPE_ENUM: {
        int value = *(const int *)address;
        if (value >= 0 && value < field->enum_count)
            return cJSON_CreateString(field->enum_names[value]);
        return new_json_number(value); /* invalid state: keep the evidence */
    }
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

cJSON *sky_world_state_to_json(const struct sky_world_state *state)
{
    if (!state)
        return NULL;
    cJSON *root = cJSON_CreateObject();
    cJSON *revision = new_json_number((double)state->revision);
    if (!root || !revision || !cJSON_AddItemToObject(root, "revision", revision)) {
        cJSON_Delete(revision);
        cJSON_Delete(root);
        return NULL;
    }
    for (size_t i = 0; i < FIELD_COUNT; i++) {
        cJSON *value = field_to_json(state, &fields[i]);
        if (!value || !add_at_path(root, fields[i].path, value)) {
            cJSON_Delete(value);
            cJSON_Delete(root);
            return NULL;
        }
    }
    return root;
}
