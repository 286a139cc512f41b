/* The message parser's readers of what has no row (the envelope's id, and the members
 * messages.c reads itself): each checks one member (presence, type, range, length) and records
 * a failure under its JSON Pointer. */
#include "field_errors.h"
#include "message_parser.h"
#include "message_names.h"

#include <cjson/cJSON.h>

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

int msg_find_name(const char *const *names, size_t count, const char *name)
{
    for (size_t i = 0; i < count; i++) {
        if (names[i] && strcmp(names[i], name) == 0)
            return (int)i;
    }
    return -1;
}

void msg_join_names(const char *const *names, size_t count, char *out, size_t capacity)
{
    size_t used = 0;
    out[0] = '\0';
    for (size_t i = 0; i < count; i++) {
        if (!names[i])
            continue;
        int written = snprintf(out + used, capacity - used, "%s%s", used ? ", " : "", names[i]);
        if (written < 0 || (size_t)written >= capacity - used)
            return;
        used += (size_t)written;
    }
}

/* "a/b" -> "a~1b" (RFC 6901), appended to parent after a '/'; truncated to fit. */
void msg_child_pointer(char *out, const char *parent, const char *name)
{
    size_t used = (size_t)snprintf(out, PROTO_MSG_POINTER_MAX, "%s/", parent);
    for (const char *c = name; *c && used + 3 < PROTO_MSG_POINTER_MAX; c++) {
        if (*c == '~' || *c == '/') {
            out[used++] = '~';
            out[used++] = *c == '~' ? '0' : '1';
        } else {
            out[used++] = *c;
        }
    }
    out[used < PROTO_MSG_POINTER_MAX ? used : PROTO_MSG_POINTER_MAX - 1] = '\0';
}

void parser_fail(struct parser *p, enum proto_msg_error_code code, const char *pointer,
                 const char *format, ...)
{
    va_list args;
    va_start(args, format);
    proto_field_errors_vaddf(&p->error->fields, (int)code, pointer, format, args);
    va_end(args);
}

bool parser_require(struct parser *p, const cJSON *item, const char *pointer)
{
    if (item)
        return true;
    parser_fail(p, PROTO_MSG_ERR_MISSING_FIELD, pointer, "required");
    return false;
}

static bool parser_read_number(struct parser *p, const cJSON *item, const char *pointer, double min,
                               double max, double *out)
{
    if (!cJSON_IsNumber(item)) {
        parser_fail(p, PROTO_MSG_ERR_WRONG_TYPE, pointer, "expected a number, got %s",
                    proto_json_type_name(item));
        return false;
    }
    double value = item->valuedouble;
    if (!isfinite(value) || value < min || value > max) {
        parser_fail(p, PROTO_MSG_ERR_OUT_OF_RANGE, pointer, "must be in [%.15g, %.15g], got %.15g",
                    min, max, value);
        return false;
    }
    *out = value;
    return true;
}

bool parser_read_integer(struct parser *p, const cJSON *item, const char *pointer, int64_t min,
                         int64_t max, int64_t *out)
{
    double value;
    if (!parser_read_number(p, item, pointer, (double)min, (double)max, &value))
        return false;
    if (value != floor(value)) {
        parser_fail(p, PROTO_MSG_ERR_BAD_VALUE, pointer, "must be an integer, got %.15g", value);
        return false;
    }
    *out = (int64_t)value;
    return true;
}

bool parser_read_string(struct parser *p, const cJSON *item, const char *pointer, size_t min,
                        size_t max, char *out)
{
    if (!cJSON_IsString(item)) {
        parser_fail(p, PROTO_MSG_ERR_WRONG_TYPE, pointer, "expected a string, got %s",
                    proto_json_type_name(item));
        return false;
    }
    size_t length = strlen(item->valuestring);
    if (length < min || length > max) {
        parser_fail(p, PROTO_MSG_ERR_OUT_OF_RANGE, pointer,
                    "must be %zu to %zu bytes long, got %zu", min, max, length);
        return false;
    }
    memcpy(out, item->valuestring, length + 1);
    return true;
}
