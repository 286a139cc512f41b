/* The world state's JSON Schema (protocol/schema_json_schema.c) against the field table it is
 * generated from and against the schema engine that validates every `set`: every field is
 * there with its type, range, unit, default and description, nothing else is; the default
 * state conforms to it (checked by schema_validator.c, written independently of the
 * generator); and out-of-range values, unknown members and bad enum names that the engine
 * refuses, the schema refuses too. The client messages' schema: test_message_schema.c. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cjson/cJSON.h>

#include "check.h"
#include "config.h"
#include "field_errors.h"
#include "field_schema.h"
#include "schema_validator.h"
#include "test_message_schema.h"
#include "world_state.h"

static bool conforms(const cJSON *schema, const cJSON *value)
{
    return schema_conforms(schema, schema, value);
}

/* ---- the schema against the table ---- */

static const cJSON *leaf_schema(const cJSON *schema, const char *dotted_path)
{
    const cJSON *node = schema;
    const char *segment = dotted_path;
    for (;;) {
        const char *dot = strchr(segment, '.');
        char name[128];
        snprintf(name, sizeof name, "%.*s", dot ? (int)(dot - segment) : (int)strlen(segment),
                 segment);
        node = cJSON_GetObjectItemCaseSensitive(
            cJSON_GetObjectItemCaseSensitive(node, "properties"), name);
        if (!node || !dot)
            return node;
        segment = dot + 1;
    }
}

static int count_leaves(const cJSON *schema)
{
    const cJSON *properties = cJSON_GetObjectItemCaseSensitive(schema, "properties");
    if (!properties)
        return 1;
    int n = 0;
    const cJSON *member;
    cJSON_ArrayForEach(member, properties) n += count_leaves(member);
    return n;
}

static const char *expected_type(enum proto_field_type type)
{
    switch (type) {
    case PROTO_FIELD_TYPE_NUMBER:
        return "number";
    case PROTO_FIELD_TYPE_INT:
    case PROTO_FIELD_TYPE_INT64:
        return "integer";
    case PROTO_FIELD_TYPE_INT_PAIR:
    case PROTO_FIELD_TYPE_INT_TRIPLE:
        return "array";
    case PROTO_FIELD_TYPE_ENUM:
    case PROTO_FIELD_TYPE_TIME:
        return "string";
    case PROTO_FIELD_TYPE_RGB:
        return NULL; /* oneOf a number and three */
    case PROTO_FIELD_TYPE_STRING:
        return "string";
    case PROTO_FIELD_TYPE_BOOL:
        return "boolean";
    }
    return NULL;
}

static void test_every_field(const cJSON *schema)
{
    size_t count = 0;
    const struct proto_field_desc *fields = proto_world_state_fields(&count);
    CHECK(count > 50);
    /* The table's leaves and "revision", nothing else. */
    CHECK_INT(count_leaves(schema), (long long)count + 1);
    for (size_t i = 0; i < count; i++) {
        const struct proto_field_desc *f = &fields[i];
        check_case_name = f->path;
        const cJSON *leaf = leaf_schema(schema, f->path);
        CHECK(leaf != NULL);
        if (!leaf)
            continue;
        const cJSON *type = cJSON_GetObjectItemCaseSensitive(leaf, "type");
        const char *want = expected_type(f->type);
        if (want)
            CHECK_STR(type ? type->valuestring : NULL, want);
        else
            CHECK(cJSON_GetArraySize(cJSON_GetObjectItemCaseSensitive(leaf, "oneOf")) == 2);
        const cJSON *description = cJSON_GetObjectItemCaseSensitive(leaf, "description");
        CHECK_STR(description ? description->valuestring : NULL, f->description);
        CHECK(cJSON_IsTrue(cJSON_GetObjectItemCaseSensitive(leaf, "readOnly")) == f->read_only);
        CHECK(cJSON_GetObjectItemCaseSensitive(leaf, "default") != NULL);
        const cJSON *unit = cJSON_GetObjectItemCaseSensitive(leaf, "x-unit");
        const char *want_unit = proto_field_unit(f);
        CHECK((unit == NULL) == (want_unit == NULL));
        if (unit && want_unit)
            CHECK_STR(unit->valuestring, want_unit);
        if (f->type == PROTO_FIELD_TYPE_NUMBER || f->type == PROTO_FIELD_TYPE_INT) {
            const cJSON *lo = cJSON_GetObjectItemCaseSensitive(leaf, "minimum");
            const cJSON *hi = cJSON_GetObjectItemCaseSensitive(leaf, "maximum");
            CHECK(lo && lo->valuedouble == f->min);
            CHECK(hi && hi->valuedouble == f->max);
        }
        if (f->type == PROTO_FIELD_TYPE_ENUM)
            CHECK_INT(cJSON_GetArraySize(cJSON_GetObjectItemCaseSensitive(leaf, "enum")),
                      f->enum_count);
    }
    check_case_name = "";
}

static void test_units(void)
{
    static const struct {
        const char *path, *unit;
    } cases[] = {
        { "sun.elevation_deg", "deg" },
        { "atmosphere.rayleigh.scattering_per_km", "1/km" },
        { "atmosphere.bottom_radius_km", "km" },
        { "weather.wind.speed_m_s", "m/s" },
        { "location.altitude_m", "m" },
        { "sun.illuminance_lux", "lx" },
        { "night.airglow_luminance_cd_m2", "cd/m2" },
        { "exposure.ev100", "EV" },
        { "weather.transition.duration_s", "s" },
        { "clock.utc", "UTC" },
        { "clouds.albedo", NULL },
        { "clouds.low.coverage", NULL },
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        check_case_name = cases[i].path;
        const struct proto_field_desc *f = proto_world_state_find_field(cases[i].path);
        CHECK(f != NULL);
        const char *unit = f ? proto_field_unit(f) : NULL;
        if (cases[i].unit)
            CHECK_STR(unit, cases[i].unit);
        else
            CHECK(unit == NULL);
    }
    check_case_name = "";
}

/* ---- the schema against the engine ---- */

static void test_defaults_conform(const cJSON *schema)
{
    struct proto_world_state state;
    proto_world_state_defaults(&state);
    cJSON *json = proto_world_state_to_json(&state);
    CHECK(json && conforms(schema, json));
    /* The defaults in the schema are the default state's. */
    size_t count = 0;
    const struct proto_field_desc *fields = proto_world_state_fields(&count);
    for (size_t i = 0; i < count && json; i++) {
        check_case_name = fields[i].path;
        const cJSON *value = json;
        char path[128];
        snprintf(path, sizeof path, "%s", fields[i].path);
        for (char *segment = strtok(path, "."); segment && value; segment = strtok(NULL, "."))
            value = cJSON_GetObjectItemCaseSensitive(value, segment);
        const cJSON *leaf = leaf_schema(schema, fields[i].path);
        CHECK(value && leaf &&
              cJSON_Compare(cJSON_GetObjectItemCaseSensitive(leaf, "default"), value, true));
    }
    check_case_name = "";
    /* Another state the engine accepted conforms too. */
    struct proto_field_errors errors;
    cJSON *patch = cJSON_Parse("{\"sun\":{\"elevation_deg\":-12},\"clouds\":{\"low\":"
                               "{\"coverage\":0.6}},\"exposure\":{\"tonemap\":\"clamp\"}}");
    CHECK(patch && proto_world_state_apply_json(&state, patch, &errors));
    cJSON_Delete(patch);
    cJSON *changed = proto_world_state_to_json(&state);
    CHECK(changed && conforms(schema, changed));
    cJSON_Delete(changed);
    cJSON_Delete(json);
}

/* A patch the engine refuses, and the default state with the same change, which the schema
 * must refuse. */
static void check_both_refuse(const cJSON *schema, const char *patch_text)
{
    check_case_name = patch_text;
    struct proto_world_state state;
    proto_world_state_defaults(&state);
    struct proto_field_errors errors;
    cJSON *patch = cJSON_Parse(patch_text);
    CHECK(patch != NULL);
    CHECK(!proto_world_state_apply_json(&state, patch, &errors));
    proto_world_state_defaults(&state);
    cJSON *json = proto_world_state_to_json(&state);
    /* Merge the patch into the state's JSON, replacing leaves. */
    const cJSON *group;
    cJSON_ArrayForEach(group, patch)
    {
        cJSON *target = cJSON_GetObjectItemCaseSensitive(json, group->string);
        if (!cJSON_IsObject(group) || !target) {
            cJSON_DeleteItemFromObjectCaseSensitive(json, group->string);
            cJSON_AddItemToObject(json, group->string, cJSON_Duplicate(group, true));
            continue;
        }
        const cJSON *leaf;
        cJSON_ArrayForEach(leaf, group)
        {
            cJSON_DeleteItemFromObjectCaseSensitive(target, leaf->string);
            cJSON_AddItemToObject(target, leaf->string, cJSON_Duplicate(leaf, true));
        }
    }
    CHECK(json && !conforms(schema, json));
    cJSON_Delete(json);
    cJSON_Delete(patch);
    check_case_name = "";
}

static void test_refusals_agree(const cJSON *schema)
{
    check_both_refuse(schema, "{\"sun\":{\"elevation_deg\":91}}");
    check_both_refuse(schema, "{\"location\":{\"latitude_deg\":-90.5}}");
    check_both_refuse(schema, "{\"exposure\":{\"tonemap\":\"filmic\"}}");
    check_both_refuse(schema, "{\"clouds\":{\"low\":{\"coverage\":1.5}}}");
    check_both_refuse(schema, "{\"clouds\":{\"quality\":{\"primary_steps\":\"many\"}}}");
    check_both_refuse(schema, "{\"sun\":{\"brightness\":2}}");
    check_both_refuse(schema, "{\"weather\":{\"cloudiness\":0.5}}");
    check_both_refuse(schema, "{\"clock\":{\"utc\":\"yesterday\"}}");
    check_both_refuse(schema, "{\"render\":{\"skyview_lut\":[192,108,3]}}");
}

/* The configuration's schema, from config.c's rows: the shipped file conforms; files that
 * skyd_config_parse refuses, it refuses too. */
static void test_config_schema(const char *shipped_path)
{
    cJSON *schema = skyd_config_json_schema();
    CHECK(schema != NULL);
    if (!schema)
        return;
    const cJSON *port = leaf_schema(schema, "listen.port");
    CHECK(port && cJSON_GetObjectItemCaseSensitive(port, "maximum")->valuedouble == 65535);
    const cJSON *delay = leaf_schema(schema, "state_save_delay_s");
    CHECK(delay &&
          strcmp(cJSON_GetObjectItemCaseSensitive(delay, "x-unit")->valuestring, "s") == 0);
    CHECK(leaf_schema(schema, "allowed_origins") && leaf_schema(schema, "initial_state"));

    FILE *f = fopen(shipped_path, "rb");
    char text[1 << 16];
    size_t n = f ? fread(text, 1, sizeof text - 1, f) : 0;
    if (f)
        fclose(f);
    text[n] = '\0';
    cJSON *shipped = cJSON_Parse(text);
    CHECK(shipped && conforms(schema, shipped));
    cJSON_Delete(shipped);

    static const char *const refused[] = {
        "{\"listen\":{\"port\":70000}}",
        "{\"listen\":{\"portt\":1}}",
        "{\"render\":{\"validation\":\"yes\"}}",
        "{\"limits\":{\"max_fps\":0}}",
        "{\"allowed_origins\":\"*\"}",
        "{\"allowed_origins\":[1]}",
        "{\"bogus\":1}",
        "{\"listen\":7}",
    };
    for (size_t i = 0; i < sizeof refused / sizeof refused[0]; i++) {
        check_case_name = refused[i];
        struct skyd_config config;
        struct proto_field_errors errors;
        char msg[256];
        CHECK(!skyd_config_parse(refused[i], strlen(refused[i]), "test", &config, &errors, msg,
                                 sizeof msg));
        cJSON *json = cJSON_Parse(refused[i]);
        CHECK(json && !conforms(schema, json));
        cJSON_Delete(json);
    }
    check_case_name = "";
    cJSON_Delete(schema);
}

int main(int argc, char **argv)
{
    if (argc != 3) {
        fprintf(stderr, "usage: test_world_schema CONFIG_JSON PROTOCOL_MD\n");
        return 2;
    }
    test_config_schema(argv[1]);
    test_message_schema(argv[2]);
    cJSON *schema = proto_world_state_json_schema();
    CHECK(schema != NULL);
    if (schema) {
        const cJSON *dialect = cJSON_GetObjectItemCaseSensitive(schema, "$schema");
        CHECK_STR(dialect ? dialect->valuestring : NULL,
                  "https://json-schema.org/draft/2020-12/schema");
        test_every_field(schema);
        test_units();
        test_defaults_conform(schema);
        test_refusals_agree(schema);
    }
    cJSON_Delete(schema);
    return check_summary();
}
