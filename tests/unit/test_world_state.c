/* Unit tests for the world state schema (protocol/world_state.c) and presets (server/world/presets.c).
 *
 * Usage: test_world_state [CONFIG_DIR]
 * CONFIG_DIR is the repository's config directory; without it, SKYD_SOURCE_DIR "/config" when
 * that is defined at compile time, else "config".
 */
#include "test_world_state.h"

#ifdef SKYD_SOURCE_DIR
#define DEFAULT_CONFIG_DIR SKYD_SOURCE_DIR "/config"
#else
#define DEFAULT_CONFIG_DIR "config"
#endif

/* ---- other behaviour -------------------------------------------------------------------- */

static void test_schema_table(void)
{
    check_case_name = "schema table";
    size_t count = 0;
    const struct proto_field_desc *fields = proto_world_state_fields(&count);
    CHECK_INT(count, 133);
    for (size_t i = 0; i < count; i++) {
        check_case_name = fields[i].path;
        CHECK(proto_world_state_find_field(fields[i].path) == &fields[i]);
        CHECK(fields[i].min <= fields[i].max);
        CHECK(fields[i].description && fields[i].description[0]);
        CHECK(fields[i].offset < sizeof(struct proto_world_state));
        if (fields[i].type == PROTO_FIELD_TYPE_ENUM)
            CHECK(fields[i].enum_names && fields[i].enum_count > 0);
    }
    check_case_name = "schema lookups";
    CHECK(proto_world_state_find_field("atmosphere.mie") == NULL);
    CHECK(proto_world_state_find_field("revision") == NULL);
    CHECK(proto_world_state_find_field(NULL) == NULL);
}

static void test_defaults(void)
{
    check_case_name = "defaults";
    struct proto_world_state state;
    struct proto_field_errors errors;
    memset(&state, 0x5A, sizeof state);
    proto_world_state_defaults(&state);
    CHECK(proto_world_state_validate(&state, &errors));
    CHECK_INT(errors.total, 0);
    CHECK_INT(state.revision, 0);
    CHECK_DOUBLE(state.atmosphere.bottom_radius_km, 6360);
    CHECK_DOUBLE(state.atmosphere.top_radius_km, 6460);
    CHECK_DOUBLE(state.atmosphere.rayleigh_scattering_per_km[2], 33.1e-3);
    CHECK_DOUBLE(state.atmosphere.ozone_absorption_per_km[1], 1.881e-3);
    CHECK_DOUBLE(state.sun.angular_diameter_deg, 0.545);
    CHECK_INT(state.sun.limb_darkening, PROTO_LIMB_DARKENING_HM98);
    CHECK_INT(state.exposure.tonemap, PROTO_TONEMAP_ACES);
    CHECK_INT(state.render.skyview_lut[0], 192);
    CHECK_INT(state.render.aerial_perspective_lut[2], 32);
}

static void test_validate_corrupt_state(void)
{
    check_case_name = "validate a corrupt state";
    struct proto_world_state state, before;
    struct proto_field_errors errors;
    starting_state(&state);
    state.camera.fov_deg = NAN;
    state.sun.limb_darkening = (enum proto_limb_darkening)7;
    state.render.transmittance_lut[1] = 3;
    state.atmosphere.top_radius_km = state.atmosphere.bottom_radius_km;
    CHECK(!proto_world_state_validate(&state, &errors));
    CHECK_INT(errors.total, 4);
    CHECK_STR(errors.items[0].pointer, "/sun/limb_darkening");
    CHECK_INT(errors.items[0].code, PROTO_FIELD_OUT_OF_RANGE);
    CHECK_STR(errors.items[1].pointer, "/camera/fov_deg");
    CHECK_STR(errors.items[2].pointer, "/render/transmittance_lut/1");
    CHECK_STR(errors.items[3].pointer, "/atmosphere/top_radius_km");
    CHECK_INT(errors.items[3].code, PROTO_FIELD_INCONSISTENT);

    check_case_name = "a valid patch cannot apply to a corrupt state";
    memcpy(&before, &state, sizeof before);
    CHECK(!apply_patch_text(&state, "{\"sun\":{\"elevation_deg\":10}}", &errors));
    CHECK_INT(errors.total, 4);
    CHECK(memcmp(&state, &before, sizeof state) == 0);
}

static void test_error_overflow(void)
{
    check_case_name = "more errors than fit";
    cJSON *patch = cJSON_CreateObject();
    for (int i = 0; i < 40; i++) {
        char name[16];
        snprintf(name, sizeof name, "x%d", i);
        cJSON_AddNumberToObject(patch, name, i);
    }
    struct proto_world_state state, before;
    struct proto_field_errors errors;
    starting_state(&state);
    memcpy(&before, &state, sizeof before);
    CHECK(!proto_world_state_apply_json(&state, patch, &errors));
    cJSON_Delete(patch);
    CHECK_INT(errors.count, PROTO_MAX_FIELD_ERRORS);
    CHECK_INT(errors.total, 40);
    CHECK_STR(errors.items[31].pointer, "/x31");
    CHECK(memcmp(&state, &before, sizeof state) == 0);

    char text[16384];
    proto_field_errors_format(&errors, text, sizeof text);
    CHECK(strncmp(text, "/x0: unknown field", 18) == 0);
    CHECK_CONTAINS(text, "\n/x31: unknown field");
    CHECK_CONTAINS(text, "\n(and 8 more)");
}

static void test_format(void)
{
    check_case_name = "format";
    struct proto_field_errors errors;
    proto_field_errors_clear(&errors);
    proto_field_errors_add(&errors, PROTO_FIELD_UNKNOWN, "/a", "first");
    proto_field_errors_add(&errors, PROTO_FIELD_WRONG_TYPE, "", "second");
    char text[256];
    proto_field_errors_format(&errors, text, sizeof text);
    CHECK_STR(text, "/a: first\n(root): second");

    check_case_name = "format truncates";
    char small[12];
    memset(small, 'Z', sizeof small);
    proto_field_errors_format(&errors, small, sizeof small);
    CHECK_INT(strlen(small), sizeof small - 1);
    CHECK_STR(small, "/a: firs...");
    char tiny[6];
    proto_field_errors_format(&errors, tiny, sizeof tiny);
    CHECK_STR(tiny, "/a...");
    char one[1] = { 'Z' };
    proto_field_errors_format(&errors, one, sizeof one);
    CHECK_INT(one[0], '\0');

    check_case_name = "format of no errors";
    proto_field_errors_clear(&errors);
    proto_field_errors_format(&errors, text, sizeof text);
    CHECK_STR(text, "");

    check_case_name = "long texts are truncated when added";
    char long_text[600];
    memset(long_text, 'q', sizeof long_text - 1);
    long_text[sizeof long_text - 1] = '\0';
    proto_field_errors_add(&errors, PROTO_FIELD_UNKNOWN, long_text, long_text);
    CHECK_INT(strlen(errors.items[0].pointer), sizeof errors.items[0].pointer - 1);
    CHECK_INT(strlen(errors.items[0].reason), sizeof errors.items[0].reason - 1);
}

static void odd_valued_state(struct proto_world_state *state)
{
    starting_state(state);
    state->revision = 42;
    state->atmosphere.mie_g[0] = 0.1 + 0.2;
    state->atmosphere.mie_g[1] = 1.0 / 3.0;
    state->atmosphere.mie_g[2] = -0.5;
    state->atmosphere.rayleigh_scattering_per_km[1] = 1e-7 / 3.0;
    state->sun.azimuth_deg = -123.456789012345678;
    state->sun.limb_darkening = PROTO_LIMB_DARKENING_NONE;
    state->exposure.mode = PROTO_EXPOSURE_MANUAL;
    state->exposure.tonemap = PROTO_TONEMAP_REINHARD;
    state->render.aerial_perspective_lut[0] = 5;
    state->render.aerial_perspective_lut[1] = 6;
    state->render.aerial_perspective_lut[2] = 7;
}

/* to_json without "revision", which patches may not carry; optionally printed and reparsed. */
static cJSON *state_patch(const struct proto_world_state *state, bool through_text)
{
    cJSON *json = proto_world_state_to_json(state);
    if (json && through_text) {
        char *text = cJSON_PrintUnformatted(json);
        cJSON_Delete(json);
        json = text ? cJSON_Parse(text) : NULL;
        free(text);
    }
    if (json)
        cJSON_DeleteItemFromObjectCaseSensitive(json, "revision");
    return json;
}

/* Applies state's JSON to a fresh state with the same revision. */
static bool round_trip(const struct proto_world_state *state, bool through_text,
                       struct proto_world_state *restored)
{
    starting_state(restored);
    restored->revision = state->revision;
    cJSON *patch = state_patch(state, through_text);
    CHECK(patch != NULL);
    struct proto_field_errors errors;
    bool applied = patch && proto_world_state_apply_json(restored, patch, &errors);
    cJSON_Delete(patch);
    return applied;
}

static bool json_has_path(const cJSON *root, const char *dotted_path)
{
    char path[128];
    snprintf(path, sizeof path, "%s", dotted_path);
    const cJSON *node = root;
    for (char *name = strtok(path, "."); name && node; name = strtok(NULL, "."))
        node = cJSON_GetObjectItemCaseSensitive(node, name);
    return node != NULL;
}

static void test_to_json(void)
{
    check_case_name = "to_json content";
    struct proto_world_state state;
    struct proto_field_errors errors;
    odd_valued_state(&state);
    CHECK(proto_world_state_validate(&state, &errors));
    cJSON *json = proto_world_state_to_json(&state);
    CHECK(json != NULL);
    if (!json)
        return;
    CHECK_DOUBLE(cJSON_GetNumberValue(cJSON_GetObjectItemCaseSensitive(json, "revision")), 42);
    size_t count = 0;
    const struct proto_field_desc *fields = proto_world_state_fields(&count);
    for (size_t i = 0; i < count; i++)
        CHECK(json_has_path(json, fields[i].path));
    const cJSON *sun = cJSON_GetObjectItemCaseSensitive(json, "sun");
    CHECK_STR(cJSON_GetStringValue(cJSON_GetObjectItemCaseSensitive(sun, "limb_darkening")),
              "none");
    const cJSON *render = cJSON_GetObjectItemCaseSensitive(json, "render");
    CHECK_INT(cJSON_GetArraySize(cJSON_GetObjectItemCaseSensitive(render, "skyview_lut")), 2);

    check_case_name = "to_json output is rejected while it carries revision";
    struct proto_world_state other;
    starting_state(&other);
    CHECK(!proto_world_state_apply_json(&other, json, &errors));
    CHECK_INT(errors.total, 1);
    CHECK_STR(errors.items[0].pointer, "/revision");
    cJSON_Delete(json);
}

static bool nearly_equal(double a, double b)
{
    double difference = a > b ? a - b : b - a;
    double magnitude = b < 0 ? -b : b;
    return difference <= magnitude * 2 * DBL_EPSILON;
}

static void test_round_trip(void)
{
    struct proto_world_state state, restored;

    check_case_name = "round trip through the cJSON tree is exact";
    odd_valued_state(&state);
    CHECK(round_trip(&state, false, &restored));
    CHECK(states_equal(&restored, &state));

    check_case_name = "round trip of the defaults through text is exact";
    starting_state(&state);
    CHECK(round_trip(&state, true, &restored));
    CHECK(states_equal(&restored, &state));

    /* cJSON 1.7 prints "%.15g" whenever that reads back within a relative DBL_EPSILON, so
     * through text a double may come back one unit in the last place off. */
    check_case_name = "round trip through text is within an ulp";
    odd_valued_state(&state);
    CHECK(round_trip(&state, true, &restored));
    size_t count = 0;
    const struct proto_field_desc *fields = proto_world_state_fields(&count);
    for (size_t i = 0; i < count; i++) {
        check_case_name = fields[i].path;
        for (int e = 0; e < field_elements(&fields[i]); e++) {
            double expected = read_element(&state, fields[i].path, e);
            double actual = read_element(&restored, fields[i].path, e);
            if (!check_record(nearly_equal(actual, expected), __FILE__, __LINE__))
                printf("nearly_equal(%.17g, %.17g) failed at element %d\n", actual, expected, e);
        }
    }
}

static void test_null_arguments(void)
{
    check_case_name = "null arguments";
    struct proto_world_state state;
    struct proto_field_errors errors;
    starting_state(&state);
    CHECK(!proto_world_state_apply_json(&state, NULL, &errors));
    CHECK_INT(errors.items[0].code, PROTO_FIELD_WRONG_TYPE);
    CHECK(!proto_world_state_set_path(&state, NULL, "1", &errors));
    CHECK(!proto_world_state_set_assignment(&state, NULL, &errors));
    CHECK(proto_world_state_set_path(&state, "camera.fov_deg", "60", NULL));
    CHECK_DOUBLE(state.camera.fov_deg, 60);
    CHECK(proto_world_state_to_json(NULL) == NULL);
}

int main(int argc, char **argv)
{
    const char *config_dir = argc > 1 ? argv[1] : DEFAULT_CONFIG_DIR;

    test_schema_table();
    test_defaults();
    test_state_cases();
    test_validate_corrupt_state();
    test_error_overflow();
    test_format();
    test_to_json();
    test_round_trip();
    test_null_arguments();
    test_real_presets(config_dir);
    test_temp_presets();
    return check_summary();
}
