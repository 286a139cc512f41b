/* Field errors: what a check of JSON against a table of field rows (field_schema.h) reports,
 * one entry per failure, each under the JSON Pointer of the field ("/atmosphere/mie/g") with a
 * stable code and a reason. The world state, the service configuration and the client
 * messages report through them. */
#ifndef SKYD_FIELD_ERRORS_H
#define SKYD_FIELD_ERRORS_H

#include <stdarg.h>
#include <stddef.h>

struct cJSON;

/* One validation failure: a JSON Pointer to the field ("/atmosphere/mie/g") and a reason. */
struct proto_field_error {
    char pointer[128];
    char reason[160];
    int code; /* stable id, one of enum proto_field_error_code */
};

enum proto_field_error_code {
    PROTO_FIELD_UNKNOWN = 1,      /* no such field */
    PROTO_FIELD_WRONG_TYPE = 2,   /* e.g. a string where a number is expected */
    PROTO_FIELD_OUT_OF_RANGE = 3, /* number outside [min, max] or not finite */
    PROTO_FIELD_BAD_VALUE = 4,    /* unparsable value text, unknown enum name, wrong array length */
    PROTO_FIELD_INCONSISTENT = 5, /* fields valid alone but not together (top radius <= bottom) */
    PROTO_FIELD_MISSING = 6,      /* a required member is absent */
};

#define PROTO_MAX_FIELD_ERRORS 32

struct proto_field_errors {
    int count; /* number of entries filled (at most PROTO_MAX_FIELD_ERRORS) */
    int total; /* number of failures found, may exceed count */
    struct proto_field_error items[PROTO_MAX_FIELD_ERRORS];
};

/* Empties errors (count and total 0). */
void proto_field_errors_clear(struct proto_field_errors *errors);

/* Records one failure: counts it in total, stores it while there is room. Long texts are
 * truncated. */
void proto_field_errors_add(struct proto_field_errors *errors, int code, const char *pointer,
                            const char *reason);

/* The same with a printf-style reason; the va_list form is for wrappers. */
#if defined(__GNUC__)
__attribute__((format(printf, 4, 5)))
#endif
void proto_field_errors_addf(struct proto_field_errors *errors, int code, const char *pointer,
                           const char *format, ...);
void proto_field_errors_vaddf(struct proto_field_errors *errors, int code, const char *pointer,
                              const char *format, va_list args);

/* Formats errors as one line per failure, "pointer: reason", into buf. */
void proto_field_errors_format(const struct proto_field_errors *errors, char *buf, size_t buflen);

/* How reasons write a number: the shortest text that reads back as the same double, at most
 * PROTO_FIELD_NUMBER_TEXT_MAX bytes with its NUL. */
#define PROTO_FIELD_NUMBER_TEXT_MAX 32
void proto_field_format_number(double value, char *text, size_t capacity);

/* "a number", "a string", "a boolean", "null", "an array" or "an object": how error reasons
 * name the JSON value they got. */
const char *proto_json_type_name(const struct cJSON *value);

#endif
