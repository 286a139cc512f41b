/* The schema engine's shared parts, internal to its files (field_errors.c, schema_*.c): bounded
 * text and JSON Pointer building, the tree of dotted paths a table spells, the checks of one
 * value against its row, and the limits of the texts they make. The world state, the
 * configuration and the messages use the engine through field_schema.h and field_errors.h. */
#ifndef SKYD_SCHEMA_TEXT_H
#define SKYD_SCHEMA_TEXT_H

#include <stdbool.h>
#include <stddef.h>

#include "field_errors.h"
#include "field_schema.h"

struct cJSON;

#define POINTER_CAPACITY sizeof(((struct proto_field_error *)NULL)->pointer)
#define REASON_CAPACITY sizeof(((struct proto_field_error *)NULL)->reason)
#define DOTTED_PATH_CAPACITY 128
#define TIME_TEXT_CAPACITY 40

/* ---- bounded text and JSON Pointers (schema_text.c) ---- */

/* Appends `length` bytes only if they all fit, so escapes are never split. */
bool schema_append_bytes(char *buffer, size_t capacity, size_t *used, const char *bytes,
                         size_t length);
void schema_append_text(char *buffer, size_t capacity, size_t *used, const char *text);
void schema_copy_text(char *buffer, size_t capacity, const char *text);
void schema_pointer_append(char *pointer, size_t capacity, const char *segment);
void schema_pointer_from_dotted(const char *dotted_path, char *pointer, size_t capacity);
/* `pointer` with "/index" appended. */
void schema_element_pointer(const char *pointer, int index, char *out, size_t capacity);
/* A JSON number that keeps a NaN or an infinity (cJSON_CreateNumber would not). */
struct cJSON *schema_new_json_number(double value);

/* ---- the table's tree (schema_lookup.c) ---- */

int schema_element_count(enum proto_field_type type);
/* A group is a dotted path with leaf fields below it ("atmosphere", "atmosphere.mie"). */
bool schema_is_group(const struct proto_schema *schema, const char *dotted_path);
/* Names directly below a group, e.g. "rayleigh, mie, ..." for "atmosphere". */
void schema_list_children(const struct proto_schema *schema, const char *prefix, char *text,
                          size_t capacity);
void schema_list_enum_names(const struct proto_field_desc *field, char *text, size_t capacity);

/* ---- one value against its row (schema_check.c) ---- */

/* A value against a row's range (and for INT rows, being whole; for TIME rows, as a time):
 * false with the failure added under `pointer`. */
bool schema_check_number(struct proto_field_errors *errors, const struct proto_field_desc *field,
                         double value, const char *pointer);
bool schema_check_integer(struct proto_field_errors *errors, const struct proto_field_desc *field,
                          double value, const char *pointer);
bool schema_check_time(struct proto_field_errors *errors, const struct proto_field_desc *field,
                       double seconds, const char *pointer);

#endif
