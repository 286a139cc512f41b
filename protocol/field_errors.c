/* The field-error list every schema check fills, and the texts its reasons are made of. */
#include "field_errors.h"
#include "schema_text.h"

#include <cjson/cJSON.h>

#include <stdarg.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

void proto_field_errors_clear(struct proto_field_errors *errors)
{
    if (errors)
        memset(errors, 0, sizeof *errors);
}

void proto_field_errors_add(struct proto_field_errors *errors, int code, const char *pointer,
                            const char *reason)
{
    if (!errors)
        return;
    errors->total++;
    if (errors->count < 0 || errors->count >= PROTO_MAX_FIELD_ERRORS)
        return;
    struct proto_field_error *item = &errors->items[errors->count++];
    item->code = code;
    schema_copy_text(item->pointer, sizeof item->pointer, pointer ? pointer : "");
    schema_copy_text(item->reason, sizeof item->reason, reason ? reason : "");
}

void proto_field_errors_vaddf(struct proto_field_errors *errors, int code, const char *pointer,
                              const char *format, va_list args)
{
    char reason[REASON_CAPACITY];
    vsnprintf(reason, sizeof reason, format, args);
    proto_field_errors_add(errors, code, pointer, reason);
}

void proto_field_errors_addf(struct proto_field_errors *errors, int code, const char *pointer,
                             const char *format, ...)
{
    va_list args;
    va_start(args, format);
    proto_field_errors_vaddf(errors, code, pointer, format, args);
    va_end(args);
}

void proto_field_errors_format(const struct proto_field_errors *errors, char *buf, size_t buflen)
{
    if (!buf || buflen == 0)
        return;
    buf[0] = '\0';
    if (!errors)
        return;
    int count = errors->count;
    if (count > PROTO_MAX_FIELD_ERRORS)
        count = PROTO_MAX_FIELD_ERRORS;
    size_t used = 0;
    bool complete = true;
    char line[POINTER_CAPACITY + REASON_CAPACITY + 16];
    for (int i = 0; i < count && complete; i++) {
        const struct proto_field_error *item = &errors->items[i];
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

const char *proto_json_type_name(const struct cJSON *value)
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

void proto_field_format_number(double value, char *text, size_t capacity)
{
    snprintf(text, capacity, "%.15g", value);
    if (strtod(text, NULL) != value)
        snprintf(text, capacity, "%.17g", value);
}
