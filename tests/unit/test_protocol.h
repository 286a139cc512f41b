/* What the files of test_protocol share: the parse and JSON helpers, the documented client
 * examples (defined in test_protocol.c) and the tests of each file, run by test_protocol.c's
 * main in this order:
 *   test_protocol_parse.c     the parse table
 *   test_protocol_parser.c    parser details and parsed values
 *   test_protocol_builders.c  the builders and the binary frame header
 *   test_protocol.c           PROTOCOL.md's examples, main
 * The helpers are static inline so that their checks name the caller's file and line. */
#ifndef SKYD_TEST_PROTOCOL_H
#define SKYD_TEST_PROTOCOL_H

#include "field_errors.h"
#include "frame_header.h"
#include "messages.h"
#include "world_state.h"

#include <cjson/cJSON.h>

#include <math.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"

#define COUNT_OF(array) (sizeof(array) / sizeof((array)[0]))

/* ---- helpers ---------------------------------------------------------------------------- */

static inline struct proto_msg_limits test_limits(void)
{
    struct proto_msg_limits limits;
    proto_msg_limits_default(&limits);
    limits.max_message_bytes = 1024;
    return limits;
}

static inline enum proto_msg_error_code parse_with(const char *text, size_t length,
                                                   const struct proto_msg_limits *limits,
                                                   struct proto_client_msg *msg,
                                                   struct proto_msg_parse_error *error)
{
    return proto_msg_parse(text, length, limits, msg, error);
}

static inline enum proto_msg_error_code parse(const char *text, struct proto_client_msg *msg,
                                              struct proto_msg_parse_error *error)
{
    struct proto_msg_limits limits = test_limits();
    return parse_with(text, strlen(text), &limits, msg, error);
}

static inline const char *first_pointer(const struct proto_msg_parse_error *error)
{
    return error->fields.count > 0 ? error->fields.items[0].pointer : "(none)";
}

/* Parses a builder's output, which must be a JSON object of the given type; frees `text`. */
static inline cJSON *parse_built(char *text, const char *type)
{
    CHECK(text != NULL);
    if (!text)
        return NULL;
    cJSON *json = cJSON_Parse(text);
    free(text);
    CHECK(cJSON_IsObject(json));
    const cJSON *member = cJSON_GetObjectItemCaseSensitive(json, "type");
    CHECK_STR(cJSON_IsString(member) ? member->valuestring : NULL, type);
    return json;
}

static inline const cJSON *get(const cJSON *object, const char *name)
{
    return cJSON_GetObjectItemCaseSensitive(object, name);
}

static inline double number_at(const cJSON *object, const char *name)
{
    const cJSON *member = get(object, name);
    return cJSON_IsNumber(member) ? member->valuedouble : NAN;
}

static inline const char *string_at(const cJSON *object, const char *name)
{
    const cJSON *member = get(object, name);
    return cJSON_IsString(member) ? member->valuestring : NULL;
}

static inline char *repeat(char c, size_t count)
{
    char *text = malloc(count + 1);
    memset(text, c, count);
    text[count] = '\0';
    return text;
}

static inline struct proto_msg_id int_id(int64_t number)
{
    struct proto_msg_id id = { .kind = PROTO_MSG_ID_INTEGER, .number = number };
    return id;
}

static inline struct proto_msg_id string_id(const char *text)
{
    struct proto_msg_id id = { .kind = PROTO_MSG_ID_STRING };
    snprintf(id.text, sizeof id.text, "%s", text);
    return id;
}

/* ---- the documented examples (also in protocol/PROTOCOL.md, in this order) -------------- */

struct protocol_client_example {
    const char *text;
    enum proto_msg_type type;
};

extern const struct protocol_client_example protocol_client_examples[];
extern const size_t protocol_client_example_count;

/* ---- the tests of each file ---------------------------------------------------------------- */

void test_parse_table(void);

void test_offsets_and_limits(void);
void test_parsed_values(void);

void test_builders(void);
void test_frame_header(void);

#endif
