/* The world-state schema engine's shared parts, internal to protocol/: the field table's
 * lookups, bounded text and JSON Pointer building, and the limits of the texts they make
 * (world_schema.c). world_state.c patches and validates with them; world_state_text.c turns
 * states into JSON and dotted-path assignments into patches. */
#ifndef SKYD_WORLD_SCHEMA_H
#define SKYD_WORLD_SCHEMA_H

#include <stdbool.h>
#include <stddef.h>

#include "field_errors.h"
#include "field_schema.h"
#include "world_fields.h"
#include "world_state.h"

struct cJSON;

#define POINTER_CAPACITY sizeof(((struct sky_field_error *)NULL)->pointer)
#define REASON_CAPACITY sizeof(((struct sky_field_error *)NULL)->reason)
#define DOTTED_PATH_CAPACITY 128
#define NUMBER_TEXT_CAPACITY 32
#define TIME_TEXT_CAPACITY 40


bool schema_append_bytes(char *buffer, size_t capacity, size_t *used, const char *bytes,
                         size_t length);
void schema_copy_text(char *buffer, size_t capacity, const char *text);
int schema_element_count(enum sky_field_type type);
void schema_format_number(double value, char *text, size_t capacity);
bool schema_is_group(const struct sky_schema *schema, const char *dotted_path);
const struct sky_field_desc *schema_find(const struct sky_schema *schema, const char *dotted_path);
void schema_list_children(const struct sky_schema *schema, const char *prefix, char *text,
                          size_t capacity);
void schema_list_enum_names(const struct sky_field_desc *field, char *text, size_t capacity);
void schema_pointer_append(char *pointer, size_t capacity, const char *segment);
void schema_pointer_append_index(char *pointer, size_t capacity, int index);
void schema_pointer_from_dotted(const char *dotted_path, char *pointer, size_t capacity);
const void *schema_const_field_address(const void *base, const struct sky_field_desc *field);
/* A value against a row's range (and for INT rows, being whole; for TIME rows, as a time):
 * false with the failure added under `pointer`. */
bool schema_check_number(struct sky_field_errors *errors, const struct sky_field_desc *field,
                         double value, const char *pointer);
bool schema_check_integer(struct sky_field_errors *errors, const struct sky_field_desc *field,
                          double value, const char *pointer);
bool schema_check_time(struct sky_field_errors *errors, const struct sky_field_desc *field,
                       double seconds, const char *pointer);
/* `pointer` with "/index" appended. */
void schema_element_pointer(const char *pointer, int index, char *out, size_t capacity);
struct cJSON *schema_new_json_number(double value);

#endif
