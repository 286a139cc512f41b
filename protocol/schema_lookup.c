/* A table's rows looked up by dotted path, the groups their paths spell, and the sizes of
 * their values. */
#include "schema_text.h"

#include <stdint.h>
#include <string.h>

const struct proto_field_desc *proto_schema_find(const struct proto_schema *schema,
                                                 const char *dotted_path)
{
    for (size_t i = 0; dotted_path && i < schema->count; i++) {
        if (strcmp(schema->fields[i].path, dotted_path) == 0)
            return &schema->fields[i];
    }
    return NULL;
}

size_t proto_field_size(const struct proto_field_desc *field)
{
    switch (field->type) {
    case PROTO_FIELD_TYPE_NUMBER:
    case PROTO_FIELD_TYPE_TIME:
        return sizeof(double);
    case PROTO_FIELD_TYPE_RGB:
        return 3 * sizeof(double);
    case PROTO_FIELD_TYPE_INT_PAIR:
        return 2 * sizeof(int);
    case PROTO_FIELD_TYPE_INT_TRIPLE:
        return 3 * sizeof(int);
    case PROTO_FIELD_TYPE_STRING:
        return field->capacity;
    case PROTO_FIELD_TYPE_BOOL:
        return sizeof(bool);
    case PROTO_FIELD_TYPE_INT64:
        return sizeof(int64_t);
    case PROTO_FIELD_TYPE_ENUM:
    case PROTO_FIELD_TYPE_INT:
        break;
    }
    return sizeof(int);
}

int schema_element_count(enum proto_field_type type)
{
    switch (type) {
    case PROTO_FIELD_TYPE_RGB:
    case PROTO_FIELD_TYPE_INT_TRIPLE:
        return 3;
    case PROTO_FIELD_TYPE_INT_PAIR:
        return 2;
    case PROTO_FIELD_TYPE_NUMBER:
    case PROTO_FIELD_TYPE_ENUM:
    case PROTO_FIELD_TYPE_INT:
    case PROTO_FIELD_TYPE_TIME:
    case PROTO_FIELD_TYPE_STRING:
    case PROTO_FIELD_TYPE_BOOL:
    case PROTO_FIELD_TYPE_INT64:
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

bool schema_is_group(const struct proto_schema *schema, const char *dotted_path)
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

void schema_list_children(const struct proto_schema *schema, const char *prefix, char *text,
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
            schema_append_text(text, capacity, &used, ", ");
        schema_append_bytes(text, capacity, &used, segment, length);
    }
    for (size_t i = 0; prefix[0] == '\0' && i < schema->caller_member_count; i++) {
        if (used > 0)
            schema_append_text(text, capacity, &used, ", ");
        schema_append_text(text, capacity, &used, schema->caller_members[i]);
    }
}

void schema_list_enum_names(const struct proto_field_desc *field, char *text, size_t capacity)
{
    size_t used = 0;
    text[0] = '\0';
    for (int i = 0; i < field->enum_count; i++) {
        if (!field->enum_names[i])
            continue;
        if (used > 0)
            schema_append_text(text, capacity, &used, ", ");
        schema_append_text(text, capacity, &used, field->enum_names[i]);
    }
}
