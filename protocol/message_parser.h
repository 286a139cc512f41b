/* The message parser's shared parts, internal to protocol/: its state, the readers that check
 * one member each and record failures by JSON Pointer (message_reader.c), and the parsers of
 * the nested objects (message_view.c). messages.c parses the envelope and each type's fields
 * with them. */
#ifndef SKYD_MESSAGE_PARSER_H
#define SKYD_MESSAGE_PARSER_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include <cjson/cJSON.h>

#include "messages.h"

#if defined(__GNUC__)
#define PRINTF_LIKE(format_index, first_arg) __attribute__((format(printf, format_index, first_arg)))
#else
#define PRINTF_LIKE(format_index, first_arg)
#endif

#define COUNT_OF(array) (sizeof(array) / sizeof((array)[0]))
#define REASON_MAX sizeof(((struct sky_field_error *)NULL)->reason)
#define MAX_MEMBERS 8

struct parser {
    const struct sky_msg_limits *limits;
    struct sky_msg_parse_error *error;
    cJSON *root;
    size_t length; /* of the message text */
};

int msg_find_name(const char *const *names, size_t count, const char *name);

void msg_join_names(const char *const *names, size_t count, char *out, size_t capacity);

void msg_child_pointer(char *out, const char *parent, const char *name);

PRINTF_LIKE(4, 5)
void parser_fail(struct parser *p, enum sky_msg_error_code code, const char *pointer,
                 const char *format, ...);

void parser_collect(struct parser *p, const cJSON *object, const char *pointer,
                    const char *const *names, size_t count, const cJSON **found);

bool parser_require(struct parser *p, const cJSON *item, const char *pointer);

bool parser_read_number(struct parser *p, const cJSON *item, const char *pointer, double min,
                        double max, double *out);

bool parser_read_integer(struct parser *p, const cJSON *item, const char *pointer, int64_t min,
                         int64_t max, int64_t *out);

bool parser_read_string(struct parser *p, const cJSON *item, const char *pointer, size_t min,
                        size_t max, char *out);

int parser_read_enum(struct parser *p, const cJSON *item, const char *pointer,
                     const char *const *names, size_t count);

void parser_read_schema_number(struct parser *p, const cJSON *item, const char *pointer,
                               const char *schema_path, bool *has, double *out);

void msg_parse_view(struct parser *p, const cJSON *object, const char *pointer,
                    struct sky_msg_view *view);

void msg_parse_weather_map(struct parser *p, const cJSON **found, struct sky_weather_map *map);

#endif
