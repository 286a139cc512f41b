/* The message parser's shared parts, internal to protocol/: its state, the readers of the
 * envelope's members that record failures by JSON Pointer (message_reader.c), each message
 * type's rows on the schema engine (message_fields.c), and the parsers of the nested objects
 * (message_view.c). messages.c parses the envelope and runs each type's rows with them. */
#ifndef SKYD_MESSAGE_PARSER_H
#define SKYD_MESSAGE_PARSER_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include <cjson/cJSON.h>

#include "field_schema.h"
#include "messages.h"

#if defined(__GNUC__)
#define PRINTF_LIKE(format_index, first_arg)                                                       \
    __attribute__((format(printf, format_index, first_arg)))
#else
#define PRINTF_LIKE(format_index, first_arg)
#endif

#define COUNT_OF(array) (sizeof(array) / sizeof((array)[0]))
#define REASON_MAX sizeof(((struct proto_field_error *)NULL)->reason)

struct parser {
    const struct proto_msg_limits *limits;
    struct proto_msg_parse_error *error;
    cJSON *root;
    size_t length; /* of the message text */
};

int msg_find_name(const char *const *names, size_t count, const char *name);

void msg_join_names(const char *const *names, size_t count, char *out, size_t capacity);

void msg_child_pointer(char *out, const char *parent, const char *name);

PRINTF_LIKE(4, 5)
void parser_fail(struct parser *p, enum proto_msg_error_code code, const char *pointer,
                 const char *format, ...);

bool parser_require(struct parser *p, const cJSON *item, const char *pointer);

bool parser_read_integer(struct parser *p, const cJSON *item, const char *pointer, int64_t min,
                         int64_t max, int64_t *out);

bool parser_read_string(struct parser *p, const cJSON *item, const char *pointer, size_t min,
                        size_t max, char *out);

/* One client message type's rows (message_fields.c): its members over struct proto_client_msg
 * with "type", "id" and what messages.c reads itself as caller members. A discriminator (an
 * enum member: probe's "quantity", set_weather_map's "format") picks a variant table when its
 * value is one of its names: the members that value needs are required there, and those it
 * does not take unknown. */
struct msg_schema {
    const struct proto_schema *schema;   /* any discriminator value */
    const char *discriminator;           /* NULL: none */
    const struct proto_schema *variants; /* indexed by the discriminator's value */
    size_t variant_count;
    /* The reply is told from other messages by the request's id (a snapshot's frame from a
     * subscription's), so the request must give one. */
    bool id_required;
};

/* NULL for PROTO_MSG_NONE and values out of range. */
const struct msg_schema *msg_schema_of(enum proto_msg_type type);
/* The table for this message: the variant its discriminator names, else the general one. */
const struct proto_schema *msg_schema_variant(const struct msg_schema *kind, const cJSON *message);

/* The view object's rows, in order. */
enum msg_view_row {
    MSG_VIEW_ALTITUDE,
    MSG_VIEW_YAW,
    MSG_VIEW_PITCH,
    MSG_VIEW_FOV,
    MSG_VIEW_WIDTH,
    MSG_VIEW_HEIGHT,
    MSG_VIEW_FPS,
    MSG_VIEW_EXPOSURE_MODE,
    MSG_VIEW_EV100,
    MSG_VIEW_COMPENSATION,
    MSG_VIEW_FORMAT,
    MSG_VIEW_QUALITY,
    MSG_VIEW_MAX_KBPS,
    MSG_VIEW_PROJECTION,
    MSG_VIEW_ROWS
};

struct msg_view_schema {
    struct proto_field_desc rows[MSG_VIEW_ROWS];
    struct proto_schema schema;
};

/* The view object's schema over struct proto_msg_view: sizes and frame rate up to the limits,
 * camera and exposure members with the world state's ranges, names and descriptions. */
void msg_view_schema(const struct proto_msg_limits *limits, struct msg_view_schema *out);

/* The view object at `pointer` (present), defaults filled in. */
void msg_parse_view(struct parser *p, const cJSON *object, const char *pointer,
                    struct proto_msg_view *view);

/* After the rows of set_weather_map: "data" (base64) decoded into msg->weather_map. */
void msg_parse_weather_map(struct parser *p, struct proto_client_msg *msg);

#endif
