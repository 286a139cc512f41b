/* World state patching and validation on the schema engine (field_schema.h) with the world's
 * table (world_fields.c); what the rows cannot say, the checks across fields, is here. */
#include "world_state.h"
#include "field_errors.h"
#include "field_schema.h"
#include "world_fields.h"

#include <cjson/cJSON.h>

#include <math.h>
#include <string.h>

static const double MAX_ATMOSPHERE_THICKNESS_KM = 1000.0;

static void check_consistency(const struct proto_world_state *state,
                              struct proto_field_errors *errors)
{
    double bottom = state->atmosphere.bottom_radius_km;
    double top = state->atmosphere.top_radius_km;
    if (!isfinite(bottom) || !isfinite(top))
        return;
    char bottom_text[PROTO_FIELD_NUMBER_TEXT_MAX], top_text[PROTO_FIELD_NUMBER_TEXT_MAX];
    char limit_text[PROTO_FIELD_NUMBER_TEXT_MAX], thickness_text[PROTO_FIELD_NUMBER_TEXT_MAX];
    proto_field_format_number(bottom, bottom_text, sizeof bottom_text);
    proto_field_format_number(top, top_text, sizeof top_text);
    if (top <= bottom) {
        proto_field_errors_addf(errors, PROTO_FIELD_INCONSISTENT, "/atmosphere/top_radius_km",
                                "must be greater than bottom_radius_km (%s), got %s", bottom_text,
                                top_text);
    } else if (top - bottom > MAX_ATMOSPHERE_THICKNESS_KM) {
        proto_field_format_number(MAX_ATMOSPHERE_THICKNESS_KM, limit_text, sizeof limit_text);
        proto_field_format_number(top - bottom, thickness_text, sizeof thickness_text);
        proto_field_errors_addf(
            errors, PROTO_FIELD_INCONSISTENT, "/atmosphere/top_radius_km",
            "must be at most %s km above bottom_radius_km (%s), got %s km above", limit_text,
            bottom_text, thickness_text);
    }
}

/* Every stored value against its row, then the checks across fields. */
static void validate_into(const struct proto_world_state *state, struct proto_field_errors *errors)
{
    proto_schema_check(proto_world_schema(), state, errors);
    check_consistency(state, errors);
}

bool proto_world_state_validate(const struct proto_world_state *state,
                                struct proto_field_errors *errors)
{
    struct proto_field_errors scratch;
    if (!errors)
        errors = &scratch;
    proto_field_errors_clear(errors);
    if (!state) {
        proto_field_errors_addf(errors, PROTO_FIELD_BAD_VALUE, "", "no state");
        return false;
    }
    validate_into(state, errors);
    return errors->total == 0;
}

bool proto_world_state_apply_json(struct proto_world_state *state, const struct cJSON *patch,
                                  struct proto_field_errors *errors)
{
    struct proto_field_errors scratch;
    if (!errors)
        errors = &scratch;
    proto_field_errors_clear(errors);
    if (!state) {
        proto_field_errors_addf(errors, PROTO_FIELD_BAD_VALUE, "", "no state");
        return false;
    }
    /* memcpy rather than assignment keeps padding bytes identical, so callers can memcmp. */
    struct proto_world_state candidate;
    memcpy(&candidate, state, sizeof candidate);
    if (proto_schema_apply_json(proto_world_schema(), &candidate, patch, "", errors, NULL))
        validate_into(&candidate, errors);
    if (errors->total != 0)
        return false;
    memcpy(state, &candidate, sizeof *state);
    return true;
}

bool proto_world_patch_compile(const struct cJSON *json, const char *pointer_prefix,
                               struct proto_world_patch *out, struct proto_field_errors *errors)
{
    const struct proto_schema *schema = proto_world_schema();
    out->count = 0;
    proto_world_state_defaults(&out->values);
    bool named[PROTO_SCHEMA_MAX_ROWS];
    bool ok = proto_schema_apply_json(schema, &out->values, json, pointer_prefix, errors, named);
    for (size_t i = 0; i < schema->count; i++)
        if (named[i])
            out->fields[out->count++] = (unsigned short)i;
    return ok;
}

bool proto_world_patch_names(const struct proto_world_patch *patch,
                             const struct proto_field_desc *field)
{
    for (size_t i = 0; i < patch->count; i++)
        if (&proto_world_field_table[patch->fields[i]] == field)
            return true;
    return false;
}

bool proto_world_state_apply_patch(struct proto_world_state *state,
                                   const struct proto_world_patch *patch,
                                   struct proto_field_errors *errors)
{
    struct proto_field_errors scratch;
    if (!errors)
        errors = &scratch;
    proto_field_errors_clear(errors);
    struct proto_world_state candidate;
    memcpy(&candidate, state, sizeof candidate);
    for (size_t i = 0; i < patch->count; i++) {
        const struct proto_field_desc *field = &proto_world_field_table[patch->fields[i]];
        memcpy((char *)&candidate + field->offset, (const char *)&patch->values + field->offset,
               proto_field_size(field));
    }
    validate_into(&candidate, errors);
    if (errors->total != 0)
        return false;
    memcpy(state, &candidate, sizeof *state);
    return true;
}
