/* The schema engine: a table of rows, one per leaf field of a C struct (path, type, offset,
 * range), drives looking fields up, checking and applying JSON to the struct, writing it as
 * JSON and describing it as a JSON Schema. The world state (world_state.h), the service
 * configuration (server/host/config.c) and the client messages each describe their struct
 * with such a table; failures are reported as field errors (field_errors.h). */
#ifndef SKYD_FIELD_SCHEMA_H
#define SKYD_FIELD_SCHEMA_H

#include <stdbool.h>
#include <stddef.h>

struct cJSON;
struct proto_field_errors;

enum proto_field_type {
    PROTO_FIELD_TYPE_NUMBER,     /* double */
    PROTO_FIELD_TYPE_RGB,        /* double[3]; a single number in a patch sets all three */
    PROTO_FIELD_TYPE_INT_PAIR,   /* int[2] */
    PROTO_FIELD_TYPE_INT_TRIPLE, /* int[3] */
    PROTO_FIELD_TYPE_ENUM,       /* int-sized enum, written as enum_names[value] */
    PROTO_FIELD_TYPE_INT,        /* int */
    PROTO_FIELD_TYPE_TIME,       /* double seconds since 1970 UTC, ISO 8601 text in JSON;
                                  min and max bound the seconds */
    PROTO_FIELD_TYPE_STRING,     /* char[capacity], NUL-terminated (the service configuration) */
    PROTO_FIELD_TYPE_BOOL,       /* bool (the service configuration) */
    PROTO_FIELD_TYPE_INT64,      /* int64_t, within +-(2^53 - 1) (ids and counts in messages) */
};

struct proto_field_desc {
    const char *path; /* dotted, "atmosphere.mie.g" */
    enum proto_field_type type;
    size_t offset;                 /* into the struct the table describes */
    double min, max;               /* inclusive; for a number and for each array element;
                                      STRING: min is the shortest length in bytes */
    const char *const *enum_names; /* ENUM only: names indexed by value; a NULL name is no
                                      value (a value 0 that means "none") */
    int enum_count;
    const char *description; /* short, with the unit */
    bool read_only;          /* kept by the simulation: a client `set` is refused; a saved
                                      state restores it */
    size_t capacity;         /* STRING only: the buffer's bytes */
    bool required;           /* an absent member is PROTO_FIELD_MISSING */
    bool exclusive_min;      /* min itself is out of range: the value must exceed it */
};

/* A table of field rows over one struct: the world state's (proto_world_schema), the service
 * configuration's (server/host/config.c). */
struct proto_schema {
    const struct proto_field_desc *fields;
    size_t count;
    const char *read_only_member; /* a top-level member a patch may not name ("revision") */
    /* Top-level members the caller applies itself (no rows): skipped by the engine, listed
     * among the expected names when a member is unknown. */
    const char *const *caller_members;
    size_t caller_member_count;
    bool unique_members; /* a member given twice is PROTO_FIELD_BAD_VALUE (messages) */
};

/* The most rows a table may have. */
#define PROTO_SCHEMA_MAX_ROWS 256

/* The row of a leaf field by dotted path ("atmosphere.mie.g"), or NULL (also for a group
 * path like "atmosphere"). */
const struct proto_field_desc *proto_schema_find(const struct proto_schema *schema,
                                                 const char *dotted_path);

/* Checks the values stored in `base` (the struct the rows' offsets point into) against their
 * rows: numbers finite and in range, enum values named, strings terminated. Each failure is
 * added to `errors` (not cleared first) under the field's JSON Pointer. Returns whether this
 * call added no error. */
bool proto_schema_check(const struct proto_schema *schema, const void *base,
                        struct proto_field_errors *errors);

/* The schema engine: applies a JSON object to `target` (the struct the rows' offsets point
 * into) member by member. Unknown members, wrong types, values out of range and absent
 * required members are added to `errors` (not cleared first), each under its JSON Pointer
 * after `pointer_prefix`; nothing is checked across fields. Members are written as they pass:
 * apply to a scratch copy and keep it only when no error was added. `named` (NULL, or one
 * flag per row, cleared here) receives the rows the object names, valid or not. Returns
 * whether this call added no error. */
bool proto_schema_apply_json(const struct proto_schema *schema, void *target,
                             const struct cJSON *object, const char *pointer_prefix,
                             struct proto_field_errors *errors, bool *named);

/* The JSON patch that sets the leaf at `path` to `value_text` as a command line writes it (a
 * number, a JSON array "[1,2,3]", a bare number for an RGB field meaning all three channels,
 * an enum name, an ISO 8601 time): {"a": {"b": value}} for "a.b", to be applied with
 * proto_schema_apply_json. NULL, with the failure added to `errors`, for a group's path, value
 * text that reads as no JSON value, or no memory. An unknown path gives a patch whose
 * application reports it. The caller deletes the patch. */
struct cJSON *proto_schema_assignment(const struct proto_schema *schema, const char *path,
                                      const char *value_text, struct proto_field_errors *errors);

/* A field's value read from `base` (the struct its table describes) as JSON, the same as
 * proto_world_state_to_json and proto_schema_to_json write it; NULL when memory is out. */
struct cJSON *proto_field_to_json(const struct proto_field_desc *field, const void *base);

/* The field's JSON Pointer ("/atmosphere/mie/g" for "atmosphere.mie.g"), truncated to
 * capacity. */
void proto_field_pointer(const struct proto_field_desc *field, char *pointer, size_t capacity);

/* The bytes a field takes in its struct. */
size_t proto_field_size(const struct proto_field_desc *field);

/* The unit of a field ("km", "deg", "1/km", "lx", "cd/m2", "EV", "UTC", ...), read from its
 * name's suffix; NULL for a dimensionless one. */
const char *proto_field_unit(const struct proto_field_desc *field);

/* The rows of `schema` read from `base` as nested JSON ({"listen": {"port": 8080}}). */
struct cJSON *proto_schema_to_json(const struct proto_schema *schema, const void *base);
/* The same added to `root`, after the members it has; false when memory is out. */
bool proto_schema_add_to_json(const struct proto_schema *schema, const void *base,
                              struct cJSON *root);

/* The JSON Schema of any table: `defaults` (from proto_schema_to_json) gives the defaults, NULL
 * none. The caller adds what has no row (properties of its own) and deletes it. */
struct cJSON *proto_schema_json_schema(const struct proto_schema *schema,
                                       const struct cJSON *defaults, const char *title);

#endif
