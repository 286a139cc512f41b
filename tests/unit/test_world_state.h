/* What the files of test_world_state share: the starting state, reading a field through the
 * descriptor table, comparing states, applying a patch given as text, and the tests of each
 * file, which test_world_state.c's main runs:
 *   test_world_state.c          the schema, validation, errors, JSON; main
 *   test_world_state_cases.c    the table-driven patch and assignment cases
 *   test_world_state_presets.c  the real presets and broken ones in a temporary directory
 * The helpers are static inline so that their checks name the caller's file and line. */
#ifndef SKYD_TEST_WORLD_STATE_H
#define SKYD_TEST_WORLD_STATE_H

#include "field_errors.h"
#include "field_schema.h"
#include "presets.h"
#include "world_state.h"

#include <cjson/cJSON.h>

#include <float.h>
#include <math.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "check.h"
#include "schema_text.h"

/* ---- helpers ---------------------------------------------------------------------------- */

#define STARTING_REVISION 7

static inline void starting_state(struct proto_world_state *state)
{
    memset(state, 0, sizeof *state);
    proto_world_state_defaults(state);
    state->revision = STARTING_REVISION;
}

static inline int field_elements(const struct proto_field_desc *field)
{
    return schema_element_count(field->type);
}

/* Reads element `index` of a leaf through the public descriptor table. */
static inline double read_element(const struct proto_world_state *state, const char *path,
                                  int index)
{
    const struct proto_field_desc *field = proto_world_state_find_field(path);
    if (!field)
        return NAN;
    const char *base = (const char *)state + field->offset;
    switch (field->type) {
    case PROTO_FIELD_TYPE_NUMBER:
    case PROTO_FIELD_TYPE_RGB:
    case PROTO_FIELD_TYPE_TIME:
        return ((const double *)base)[index];
    case PROTO_FIELD_TYPE_INT_PAIR:
    case PROTO_FIELD_TYPE_INT_TRIPLE:
    case PROTO_FIELD_TYPE_ENUM:
    case PROTO_FIELD_TYPE_INT:
        return ((const int *)base)[index];
    case PROTO_FIELD_TYPE_STRING:
    case PROTO_FIELD_TYPE_BOOL:
    case PROTO_FIELD_TYPE_INT64:
        break;
    }
    return NAN;
}

/* Exact equality of every field and the revision; unlike memcmp, blind to padding bytes. */
static inline bool states_equal(const struct proto_world_state *a,
                                const struct proto_world_state *b)
{
    if (a->revision != b->revision)
        return false;
    size_t count = 0;
    const struct proto_field_desc *fields = proto_world_state_fields(&count);
    for (size_t i = 0; i < count; i++) {
        for (int e = 0; e < field_elements(&fields[i]); e++) {
            if (read_element(a, fields[i].path, e) != read_element(b, fields[i].path, e))
                return false;
        }
    }
    return true;
}

static inline bool apply_patch_text(struct proto_world_state *state, const char *text,
                                    struct proto_field_errors *errors)
{
    cJSON *patch = cJSON_Parse(text);
    if (!patch) {
        check_record(false, __FILE__, __LINE__);
        printf("test patch is not valid JSON: %s\n", text);
        return false;
    }
    bool applied = proto_world_state_apply_json(state, patch, errors);
    cJSON_Delete(patch);
    return applied;
}

/* ---- the tests of each file ---------------------------------------------------------------- */

void test_state_cases(void);

void test_real_presets(const char *config_dir);
void test_temp_presets(void);

#endif
