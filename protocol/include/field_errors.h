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
struct sky_field_error {
    char pointer[128];
    char reason[160];
    int code; /* stable id, one of enum sky_field_error_code */
};

enum sky_field_error_code {
    SKY_FIELD_UNKNOWN = 1,      /* no such field */
    SKY_FIELD_WRONG_TYPE = 2,   /* e.g. a string where a number is expected */
    SKY_FIELD_OUT_OF_RANGE = 3, /* number outside [min, max] or not finite */
    SKY_FIELD_BAD_VALUE = 4,    /* unparsable value text, unknown enum name, wrong array length */
    SKY_FIELD_INCONSISTENT = 5, /* fields valid alone but not together (top radius <= bottom) */
    SKY_FIELD_MISSING = 6,      /* a required member is absent */
};

#define SKY_MAX_FIELD_ERRORS 32

struct sky_field_errors {
    int count; /* number of entries filled (at most SKY_MAX_FIELD_ERRORS) */
    int total; /* number of failures found, may exceed count */
    struct sky_field_error items[SKY_MAX_FIELD_ERRORS];
};

/* Empties errors (count and total 0). */
void sky_field_errors_clear(struct sky_field_errors *errors);

/* Records one failure: counts it in total, stores it while there is room. Long texts are
 * truncated. */
void sky_field_errors_add(struct sky_field_errors *errors, int code, const char *pointer,
                          const char *reason);

/* The same with a printf-style reason; the va_list form is for wrappers. */
#if defined(__GNUC__)
__attribute__((format(printf, 4, 5)))
#endif
void sky_field_errors_addf(struct sky_field_errors *errors, int code, const char *pointer,
                           const char *format, ...);
void sky_field_errors_vaddf(struct sky_field_errors *errors, int code, const char *pointer,
                            const char *format, va_list args);

/* Formats errors as one line per failure, "pointer: reason", into buf. */
void sky_field_errors_format(const struct sky_field_errors *errors, char *buf, size_t buflen);

/* How reasons write a number: the shortest text that reads back as the same double, at most
 * SKY_FIELD_NUMBER_TEXT_MAX bytes with its NUL. */
#define SKY_FIELD_NUMBER_TEXT_MAX 32
void sky_field_format_number(double value, char *text, size_t capacity);

/* "a number", "a string", "a boolean", "null", "an array" or "an object": how error reasons
 * name the JSON value they got. */
const char *sky_json_type_name(const struct cJSON *value);

#endif
