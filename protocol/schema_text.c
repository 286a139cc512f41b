/* The schema engine's bounded text: what it appends never overruns its buffer and never
 * splits an escape, and JSON Pointers are built from dotted paths and member names. */
#include "schema_text.h"

#include <cjson/cJSON.h>

#include <math.h>
#include <stdio.h>
#include <string.h>

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

void schema_append_text(char *buffer, size_t capacity, size_t *used, const char *text)
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

void schema_element_pointer(const char *pointer, int index, char *out, size_t capacity)
{
    char segment[16];
    snprintf(segment, sizeof segment, "%d", index);
    schema_copy_text(out, capacity, pointer);
    schema_pointer_append(out, capacity, segment);
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

void proto_field_pointer(const struct proto_field_desc *field, char *pointer, size_t capacity)
{
    schema_pointer_from_dotted(field->path, pointer, capacity);
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
