/* World states as JSON and as a JSON Schema, and dotted-path assignments ("sun.elevation_deg=12",
 * the command line's --set) applied like a client's patch; the schema engine (field_schema.h)
 * does the work with the world's table. */
#include "world_state.h"
#include "field_errors.h"
#include "field_schema.h"

#include <cjson/cJSON.h>

#include <stdlib.h>
#include <string.h>

bool proto_world_state_set_path(struct proto_world_state *state, const char *path,
                                const char *value_text, struct proto_field_errors *errors)
{
    struct proto_field_errors scratch;
    if (!errors)
        errors = &scratch;
    proto_field_errors_clear(errors);
    if (!path || !value_text) {
        proto_field_errors_addf(errors, PROTO_FIELD_BAD_VALUE, "", "missing path or value");
        return false;
    }
    cJSON *patch = proto_schema_assignment(proto_world_schema(), path, value_text, errors);
    if (!patch)
        return false;
    bool applied = proto_world_state_apply_json(state, patch, errors);
    cJSON_Delete(patch);
    return applied;
}

bool proto_world_state_set_assignment(struct proto_world_state *state, const char *assignment,
                                      struct proto_field_errors *errors)
{
    const char *equals = assignment ? strchr(assignment, '=') : NULL;
    if (!equals) {
        proto_field_errors_clear(errors);
        proto_field_errors_addf(errors, PROTO_FIELD_BAD_VALUE, "",
                                "expected dotted.path=value, got \"%s\"",
                                assignment ? assignment : "");
        return false;
    }
    const char *blanks = " \t\r\n\v\f";
    const char *start = assignment + strspn(assignment, blanks);
    const char *end = equals;
    while (end > start && strchr(blanks, end[-1]))
        end--;
    size_t length = (size_t)(end - start);
    char *path = malloc(length + 1);
    if (!path) {
        proto_field_errors_clear(errors);
        proto_field_errors_addf(errors, PROTO_FIELD_BAD_VALUE, "", "out of memory");
        return false;
    }
    memcpy(path, start, length);
    path[length] = '\0';
    bool applied = proto_world_state_set_path(state, path, equals + 1, errors);
    free(path);
    return applied;
}

cJSON *proto_world_state_to_json(const struct proto_world_state *state)
{
    if (!state)
        return NULL;
    cJSON *root = cJSON_CreateObject();
    cJSON *revision = cJSON_CreateNumber((double)state->revision);
    if (!root || !revision || !cJSON_AddItemToObject(root, "revision", revision)) {
        cJSON_Delete(revision);
        cJSON_Delete(root);
        return NULL;
    }
    if (!proto_schema_add_to_json(proto_world_schema(), state, root)) {
        cJSON_Delete(root);
        return NULL;
    }
    return root;
}

char *proto_world_state_to_text(const struct proto_world_state *state)
{
    cJSON *json = proto_world_state_to_json(state);
    char *text = json ? cJSON_PrintUnformatted(json) : NULL;
    cJSON_Delete(json);
    return text;
}

cJSON *proto_world_state_json_schema(void)
{
    struct proto_world_state state;
    proto_world_state_defaults(&state);
    cJSON *defaults = proto_world_state_to_json(&state);
    cJSON *root = defaults
                      ? proto_schema_json_schema(proto_world_schema(), defaults, "skyd world state")
                      : NULL;
    cJSON_Delete(defaults);
    cJSON *properties = cJSON_GetObjectItemCaseSensitive(root, "properties");
    cJSON *revision = properties ? cJSON_CreateObject() : NULL;
    bool ok = revision && cJSON_AddStringToObject(revision, "type", "integer") &&
              cJSON_AddNumberToObject(revision, "minimum", 0) &&
              cJSON_AddStringToObject(revision, "description",
                                      "accepted changes so far; set by the daemon") &&
              cJSON_AddTrueToObject(revision, "readOnly");
    if (!ok || !cJSON_AddItemToObject(properties, "revision", revision)) {
        cJSON_Delete(revision);
        cJSON_Delete(root);
        return NULL;
    }
    return root;
}
