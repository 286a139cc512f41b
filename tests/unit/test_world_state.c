/* Unit tests for the world state schema (protocol/world_state.c) and presets (server/world/presets.c).
 *
 * Usage: test_world_state [CONFIG_DIR]
 * CONFIG_DIR is the repository's config directory; without it, SKYD_SOURCE_DIR "/config" when
 * that is defined at compile time, else "config".
 */
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

#ifdef SKYD_SOURCE_DIR
#define DEFAULT_CONFIG_DIR SKYD_SOURCE_DIR "/config"
#else
#define DEFAULT_CONFIG_DIR "config"
#endif

#include "check.h"

/* ---- helpers ---------------------------------------------------------------------------- */

#define STARTING_REVISION 7

static void starting_state(struct sky_world_state *state)
{
    memset(state, 0, sizeof *state);
    sky_world_state_defaults(state);
    state->revision = STARTING_REVISION;
}

static int field_elements(const struct sky_field_desc *field)
{
    switch (field->type) {
    case SKY_FIELD_TYPE_RGB:
    case SKY_FIELD_TYPE_INT_TRIPLE:
        return 3;
    case SKY_FIELD_TYPE_INT_PAIR:
        return 2;
    case SKY_FIELD_TYPE_NUMBER:
    case SKY_FIELD_TYPE_ENUM:
    case SKY_FIELD_TYPE_INT:
    case SKY_FIELD_TYPE_TIME:
        break;
    }
    return 1;
}

/* Reads element `index` of a leaf through the public descriptor table. */
static double read_element(const struct sky_world_state *state, const char *path, int index)
{
    const struct sky_field_desc *field = sky_world_state_find_field(path);
    if (!field)
        return NAN;
    const char *base = (const char *)state + field->offset;
    switch (field->type) {
    case SKY_FIELD_TYPE_NUMBER:
    case SKY_FIELD_TYPE_RGB:
    case SKY_FIELD_TYPE_TIME:
        return ((const double *)base)[index];
    case SKY_FIELD_TYPE_INT_PAIR:
    case SKY_FIELD_TYPE_INT_TRIPLE:
    case SKY_FIELD_TYPE_ENUM:
    case SKY_FIELD_TYPE_INT:
        return ((const int *)base)[index];
    }
    return NAN;
}

/* Exact equality of every field and the revision; unlike memcmp, blind to padding bytes. */
static bool states_equal(const struct sky_world_state *a, const struct sky_world_state *b)
{
    if (a->revision != b->revision)
        return false;
    size_t count = 0;
    const struct sky_field_desc *fields = sky_world_state_fields(&count);
    for (size_t i = 0; i < count; i++) {
        for (int e = 0; e < field_elements(&fields[i]); e++) {
            if (read_element(a, fields[i].path, e) != read_element(b, fields[i].path, e))
                return false;
        }
    }
    return true;
}

static bool apply_patch_text(struct sky_world_state *state, const char *text,
                             struct sky_field_errors *errors)
{
    cJSON *patch = cJSON_Parse(text);
    if (!patch) {
        check_record(false, __FILE__, __LINE__);
        printf("test patch is not valid JSON: %s\n", text);
        return false;
    }
    bool applied = sky_world_state_apply_json(state, patch, errors);
    cJSON_Delete(patch);
    return applied;
}

/* ---- table-driven patch and assignment cases -------------------------------------------- */

struct expected_error {
    int code; /* 0 ends the list */
    const char *pointer;
    const char *reason_part; /* NULL: not checked */
};

struct value_check {
    const char *path; /* NULL: no check */
    double values[3];
};

struct state_case {
    const char *input; /* a JSON patch or a "path=value" assignment */
    bool applied;
    int total;
    struct expected_error errors[6];
    struct value_check check;
};

#define ERR(code_, pointer_, reason_) {.code = (code_), .pointer = (pointer_), .reason_part = (reason_)}
#define APPLIES(input_, path_, ...) \
    {.input = (input_), .applied = true, .check = {.path = (path_), .values = {__VA_ARGS__}}}
#define REJECTS(input_, total_, ...) \
    {.input = (input_), .applied = false, .total = (total_), .errors = {__VA_ARGS__}}

static const struct state_case patch_cases[] = {
    /* valid partial patches */
    APPLIES("{}", NULL, 0),
    APPLIES("{\"camera\":{\"fov_deg\":90}}", "camera.fov_deg", 90),
    APPLIES("{\"atmosphere\":{\"mie\":{\"g\":0.7}}}", "atmosphere.mie.g", 0.7, 0.7, 0.7),
    APPLIES("{\"atmosphere\":{\"rayleigh\":{\"scattering_per_km\":[1e-3,2e-3,3e-3]}}}",
            "atmosphere.rayleigh.scattering_per_km", 1e-3, 2e-3, 3e-3),
    APPLIES("{\"atmosphere\":{\"mie\":{\"g\":[-0.99,0,0.99]}}}", "atmosphere.mie.g", -0.99, 0,
            0.99),
    APPLIES("{\"atmosphere\":{\"ground_albedo\":1}}", "atmosphere.ground_albedo", 1, 1, 1),
    APPLIES("{\"sun\":{\"limb_darkening\":\"neckel96\"}}", "sun.limb_darkening",
            SKY_LIMB_DARKENING_NECKEL96),
    APPLIES("{\"sun\":{\"limb_darkening\":\"none\",\"elevation_deg\":-90}}", "sun.elevation_deg",
            -90),
    APPLIES("{\"exposure\":{\"mode\":\"manual\",\"ev100\":12.5,\"tonemap\":\"clamp\"}}",
            "exposure.tonemap", SKY_TONEMAP_CLAMP),
    APPLIES("{\"render\":{\"skyview_lut\":[200,100],\"aerial_perspective_lut\":[16,16,64]}}",
            "render.aerial_perspective_lut", 16, 16, 64),
    APPLIES("{\"render\":{\"transmittance_lut\":[4096,8]}}", "render.transmittance_lut", 4096, 8),
    APPLIES("{\"atmosphere\":{\"bottom_radius_km\":6000,\"top_radius_km\":7000}}",
            "atmosphere.top_radius_km", 7000),

    /* unknown fields at each depth, and odd member names */
    REJECTS("{\"bogus\":1}", 1,
            ERR(SKY_FIELD_UNKNOWN, "/bogus", "clock, location, atmosphere, sun, moon, night, clouds, weather, camera, exposure, render")),
    REJECTS("{\"atmosphere\":{\"bogus\":{}}}", 1,
            ERR(SKY_FIELD_UNKNOWN, "/atmosphere/bogus", "rayleigh, mie, ozone")),
    REJECTS("{\"atmosphere\":{\"mie\":{\"bogus\":1}}}", 1,
            ERR(SKY_FIELD_UNKNOWN, "/atmosphere/mie/bogus",
                "scattering_per_km, absorption_per_km, scale_height_km, g")),
    REJECTS("{\"a/b~c\":1}", 1, ERR(SKY_FIELD_UNKNOWN, "/a~1b~0c", NULL)),
    REJECTS("{\"atmosphere.mie\":{\"g\":0.5}}", 1, ERR(SKY_FIELD_UNKNOWN, "/atmosphere.mie", NULL)),
    REJECTS("{\"\":1}", 1, ERR(SKY_FIELD_UNKNOWN, "/", NULL)),
    REJECTS("{\"revision\":8}", 1, ERR(SKY_FIELD_BAD_VALUE, "/revision", "read-only")),
    REJECTS("{\"camera\":{\"revision\":8}}", 1, ERR(SKY_FIELD_UNKNOWN, "/camera/revision", NULL)),

    /* wrong JSON types */
    REJECTS("{\"camera\":{\"fov_deg\":\"70\"}}", 1,
            ERR(SKY_FIELD_WRONG_TYPE, "/camera/fov_deg", "expected a number, got a string")),
    REJECTS("{\"sun\":{\"elevation_deg\":true}}", 1,
            ERR(SKY_FIELD_WRONG_TYPE, "/sun/elevation_deg", "got a boolean")),
    REJECTS("{\"sun\":{\"elevation_deg\":null}}", 1,
            ERR(SKY_FIELD_WRONG_TYPE, "/sun/elevation_deg", "got null")),
    REJECTS("{\"atmosphere\":{\"mie\":{\"g\":{\"r\":0.5}}}}", 1,
            ERR(SKY_FIELD_WRONG_TYPE, "/atmosphere/mie/g",
                "expected a number or an array of 3 numbers, got an object")),
    REJECTS("{\"atmosphere\":{\"mie\":5}}", 1,
            ERR(SKY_FIELD_WRONG_TYPE, "/atmosphere/mie", "expected an object")),
    REJECTS("{\"sun\":[]}", 1, ERR(SKY_FIELD_WRONG_TYPE, "/sun", "expected an object, got an array")),
    REJECTS("{\"atmosphere\":{\"mie\":{\"g\":[0.1,0.2]}}}", 1,
            ERR(SKY_FIELD_BAD_VALUE, "/atmosphere/mie/g",
                "expected an array of 3 numbers, got 2 elements")),
    REJECTS("{\"atmosphere\":{\"mie\":{\"g\":[0.1,0.2,0.3,0.4]}}}", 1,
            ERR(SKY_FIELD_BAD_VALUE, "/atmosphere/mie/g", "got 4 elements")),
    REJECTS("{\"atmosphere\":{\"mie\":{\"g\":[0.1,\"x\",0.3]}}}", 1,
            ERR(SKY_FIELD_WRONG_TYPE, "/atmosphere/mie/g/1", "expected a number")),
    REJECTS("{\"render\":{\"skyview_lut\":256}}", 1,
            ERR(SKY_FIELD_WRONG_TYPE, "/render/skyview_lut", "expected an array of 2 integers")),
    REJECTS("{\"render\":{\"skyview_lut\":[192.5,108]}}", 1,
            ERR(SKY_FIELD_BAD_VALUE, "/render/skyview_lut/0", "must be an integer, got 192.5")),
    REJECTS("{\"sun\":{\"limb_darkening\":2}}", 1,
            ERR(SKY_FIELD_WRONG_TYPE, "/sun/limb_darkening", "expected one of: none, neckel96, hm98")),
    REJECTS("{\"sun\":{\"limb_darkening\":\"HM98\"}}", 1,
            ERR(SKY_FIELD_BAD_VALUE, "/sun/limb_darkening", "got \"HM98\"")),
    REJECTS("[1,2,3]", 1, ERR(SKY_FIELD_WRONG_TYPE, "", "expected a JSON object")),
    REJECTS("\"sun\"", 1, ERR(SKY_FIELD_WRONG_TYPE, "", "expected a JSON object")),

    /* out of range */
    REJECTS("{\"atmosphere\":{\"mie\":{\"g\":1.5}}}", 1,
            ERR(SKY_FIELD_OUT_OF_RANGE, "/atmosphere/mie/g", "must be in [-0.99, 0.99], got 1.5")),
    REJECTS("{\"atmosphere\":{\"mie\":{\"g\":[0.5,1.5,-2]}}}", 2,
            ERR(SKY_FIELD_OUT_OF_RANGE, "/atmosphere/mie/g/1", "got 1.5"),
            ERR(SKY_FIELD_OUT_OF_RANGE, "/atmosphere/mie/g/2", "got -2")),
    REJECTS("{\"camera\":{\"fov_deg\":1e400}}", 1,
            ERR(SKY_FIELD_OUT_OF_RANGE, "/camera/fov_deg", "must be a finite number, got inf")),
    REJECTS("{\"camera\":{\"fov_deg\":0.999}}", 1,
            ERR(SKY_FIELD_OUT_OF_RANGE, "/camera/fov_deg", "must be in [1, 170], got 0.999")),
    REJECTS("{\"sun\":{\"illuminance_lux\":-1}}", 1,
            ERR(SKY_FIELD_OUT_OF_RANGE, "/sun/illuminance_lux", "[0, 1000000], got -1")),
    REJECTS("{\"render\":{\"aerial_perspective_lut\":[4,4,513]}}", 1,
            ERR(SKY_FIELD_OUT_OF_RANGE, "/render/aerial_perspective_lut/2", "[4, 512], got 513")),

    /* inconsistent radii; not reported on top of field errors */
    REJECTS("{\"atmosphere\":{\"top_radius_km\":6300}}", 1,
            ERR(SKY_FIELD_INCONSISTENT, "/atmosphere/top_radius_km",
                "must be greater than bottom_radius_km (6360), got 6300")),
    REJECTS("{\"atmosphere\":{\"top_radius_km\":6360}}", 1,
            ERR(SKY_FIELD_INCONSISTENT, "/atmosphere/top_radius_km", NULL)),
    REJECTS("{\"atmosphere\":{\"bottom_radius_km\":7000}}", 1,
            ERR(SKY_FIELD_INCONSISTENT, "/atmosphere/top_radius_km", "(7000), got 6460")),
    REJECTS("{\"atmosphere\":{\"top_radius_km\":7400.5}}", 1,
            ERR(SKY_FIELD_INCONSISTENT, "/atmosphere/top_radius_km",
                "at most 1000 km above bottom_radius_km (6360), got 1040.5 km above")),
    REJECTS("{\"atmosphere\":{\"top_radius_km\":6300},\"camera\":{\"fov_deg\":0}}", 1,
            ERR(SKY_FIELD_OUT_OF_RANGE, "/camera/fov_deg", NULL)),

    /* several errors at once, in patch order */
    REJECTS("{\"bogus\":1,\"camera\":{\"fov_deg\":500,\"yaw_deg\":\"x\"},"
            "\"sun\":{\"limb_darkening\":\"no\"},\"revision\":1}",
            5, ERR(SKY_FIELD_UNKNOWN, "/bogus", NULL),
            ERR(SKY_FIELD_OUT_OF_RANGE, "/camera/fov_deg", NULL),
            ERR(SKY_FIELD_WRONG_TYPE, "/camera/yaw_deg", NULL),
            ERR(SKY_FIELD_BAD_VALUE, "/sun/limb_darkening", NULL),
            ERR(SKY_FIELD_BAD_VALUE, "/revision", NULL)),
};

static const struct state_case assignment_cases[] = {
    APPLIES("atmosphere.mie.g=0.7", "atmosphere.mie.g", 0.7, 0.7, 0.7),
    APPLIES("sun.limb_darkening=none", "sun.limb_darkening", SKY_LIMB_DARKENING_NONE),
    APPLIES("atmosphere.rayleigh.scattering_per_km=[1e-3,2e-3,3e-3]",
            "atmosphere.rayleigh.scattering_per_km", 1e-3, 2e-3, 3e-3),
    APPLIES(" camera.fov_deg = 85 ", "camera.fov_deg", 85),
    APPLIES("render.skyview_lut=[256, 128]", "render.skyview_lut", 256, 128),
    APPLIES("sun.limb_darkening=\"neckel96\"", "sun.limb_darkening", SKY_LIMB_DARKENING_NECKEL96),
    APPLIES("exposure.ev100=-2.5", "exposure.ev100", -2.5),
    APPLIES("exposure.mode=manual", "exposure.mode", SKY_EXPOSURE_MANUAL),

    REJECTS("bogus.path=1", 1, ERR(SKY_FIELD_UNKNOWN, "/bogus", NULL)),
    REJECTS("atmosphere.nothing=1", 1, ERR(SKY_FIELD_UNKNOWN, "/atmosphere/nothing", NULL)),
    REJECTS("atmosphere.mie=1", 1,
            ERR(SKY_FIELD_UNKNOWN, "/atmosphere/mie",
                "atmosphere.mie is a group, not a field; set one of: scattering_per_km")),
    REJECTS("atmosphere=1", 1, ERR(SKY_FIELD_UNKNOWN, "/atmosphere", "is a group")),
    REJECTS("=1", 1, ERR(SKY_FIELD_UNKNOWN, "/", NULL)),
    REJECTS("camera..fov_deg=1", 1, ERR(SKY_FIELD_UNKNOWN, "/camera/", NULL)),
    REJECTS("camera.fov_deg", 1, ERR(SKY_FIELD_BAD_VALUE, "", "expected dotted.path=value")),
    REJECTS("camera.fov_deg=abc", 1,
            ERR(SKY_FIELD_BAD_VALUE, "/camera/fov_deg", "expected a number, got \"abc\"")),
    REJECTS("camera.fov_deg=70abc", 1, ERR(SKY_FIELD_BAD_VALUE, "/camera/fov_deg", NULL)),
    REJECTS("camera.fov_deg=", 1, ERR(SKY_FIELD_BAD_VALUE, "/camera/fov_deg", "empty value")),
    REJECTS("camera.fov_deg=nan", 1,
            ERR(SKY_FIELD_OUT_OF_RANGE, "/camera/fov_deg", "must be a finite number, got nan")),
    REJECTS("camera.fov_deg=1e400", 1,
            ERR(SKY_FIELD_OUT_OF_RANGE, "/camera/fov_deg", "must be a finite number, got inf")),
    REJECTS("camera.fov_deg=-inf", 1,
            ERR(SKY_FIELD_OUT_OF_RANGE, "/camera/fov_deg", "got -inf")),
    REJECTS("camera.fov_deg=[70]", 1, ERR(SKY_FIELD_WRONG_TYPE, "/camera/fov_deg", "got an array")),
    REJECTS("atmosphere.mie.g=[0.1,0.2", 1,
            ERR(SKY_FIELD_BAD_VALUE, "/atmosphere/mie/g", "invalid JSON")),
    REJECTS("atmosphere.mie.g=2", 1,
            ERR(SKY_FIELD_OUT_OF_RANGE, "/atmosphere/mie/g", "must be in [-0.99, 0.99], got 2")),
    REJECTS("sun.limb_darkening=bogus", 1,
            ERR(SKY_FIELD_BAD_VALUE, "/sun/limb_darkening", "got \"bogus\"")),
    REJECTS("sun.limb_darkening=1", 1, ERR(SKY_FIELD_WRONG_TYPE, "/sun/limb_darkening", NULL)),
    REJECTS("render.skyview_lut=256", 1,
            ERR(SKY_FIELD_WRONG_TYPE, "/render/skyview_lut", "expected an array of 2 integers")),
    REJECTS("render.skyview_lut=big", 1,
            ERR(SKY_FIELD_BAD_VALUE, "/render/skyview_lut", "a JSON array like [256,64]")),
    REJECTS("revision=3", 1, ERR(SKY_FIELD_BAD_VALUE, "/revision", "read-only")),
    REJECTS("atmosphere.top_radius_km=6000", 1,
            ERR(SKY_FIELD_INCONSISTENT, "/atmosphere/top_radius_km", NULL)),
};

static int expected_error_count(const struct state_case *test)
{
    int count = 0;
    while (count < (int)(sizeof test->errors / sizeof test->errors[0]) && test->errors[count].code)
        count++;
    return count;
}

static void check_errors(const struct sky_field_errors *errors, const struct state_case *test)
{
    CHECK_INT(errors->total, test->total);
    CHECK_INT(errors->count, test->total < SKY_MAX_FIELD_ERRORS ? test->total : SKY_MAX_FIELD_ERRORS);
    int expected = expected_error_count(test);
    for (int i = 0; i < expected && i < errors->count; i++) {
        const struct sky_field_error *item = &errors->items[i];
        CHECK_INT(item->code, test->errors[i].code);
        CHECK_STR(item->pointer, test->errors[i].pointer);
        if (test->errors[i].reason_part)
            CHECK_CONTAINS(item->reason, test->errors[i].reason_part);
    }
}

static void check_values(const struct sky_world_state *state, const struct value_check *check)
{
    const struct sky_field_desc *field = sky_world_state_find_field(check->path);
    CHECK(field != NULL);
    if (!field)
        return;
    for (int i = 0; i < field_elements(field); i++)
        CHECK_DOUBLE(read_element(state, check->path, i), check->values[i]);
}

typedef bool (*apply_text_fn)(struct sky_world_state *state, const char *text,
                              struct sky_field_errors *errors);

static void run_state_case(const struct state_case *test, apply_text_fn apply)
{
    check_case_name = test->input;
    struct sky_world_state state, before;
    starting_state(&state);
    memcpy(&before, &state, sizeof before);
    struct sky_field_errors errors;
    memset(&errors, 0xAB, sizeof errors); /* must be reset by the call */

    bool applied = apply(&state, test->input, &errors);
    CHECK_INT(applied, test->applied);
    check_errors(&errors, test);
    if (!test->applied)
        CHECK(memcmp(&state, &before, sizeof state) == 0);
    CHECK_INT(state.revision, STARTING_REVISION);
    if (test->applied && test->check.path)
        check_values(&state, &test->check);
}

static void test_state_cases(void)
{
    for (size_t i = 0; i < sizeof patch_cases / sizeof patch_cases[0]; i++)
        run_state_case(&patch_cases[i], apply_patch_text);
    for (size_t i = 0; i < sizeof assignment_cases / sizeof assignment_cases[0]; i++)
        run_state_case(&assignment_cases[i], sky_world_state_set_assignment);
}

/* ---- other behaviour -------------------------------------------------------------------- */

static void test_schema_table(void)
{
    check_case_name = "schema table";
    size_t count = 0;
    const struct sky_field_desc *fields = sky_world_state_fields(&count);
    CHECK_INT(count, 111);
    for (size_t i = 0; i < count; i++) {
        check_case_name = fields[i].path;
        CHECK(sky_world_state_find_field(fields[i].path) == &fields[i]);
        CHECK(fields[i].min <= fields[i].max);
        CHECK(fields[i].description && fields[i].description[0]);
        CHECK(fields[i].offset < sizeof(struct sky_world_state));
        if (fields[i].type == SKY_FIELD_TYPE_ENUM)
            CHECK(fields[i].enum_names && fields[i].enum_count > 0);
    }
    check_case_name = "schema lookups";
    CHECK(sky_world_state_find_field("atmosphere.mie") == NULL);
    CHECK(sky_world_state_find_field("revision") == NULL);
    CHECK(sky_world_state_find_field(NULL) == NULL);
}

static void test_defaults(void)
{
    check_case_name = "defaults";
    struct sky_world_state state;
    struct sky_field_errors errors;
    memset(&state, 0x5A, sizeof state);
    sky_world_state_defaults(&state);
    CHECK(sky_world_state_validate(&state, &errors));
    CHECK_INT(errors.total, 0);
    CHECK_INT(state.revision, 0);
    CHECK_DOUBLE(state.atmosphere.bottom_radius_km, 6360);
    CHECK_DOUBLE(state.atmosphere.top_radius_km, 6460);
    CHECK_DOUBLE(state.atmosphere.rayleigh_scattering_per_km[2], 33.1e-3);
    CHECK_DOUBLE(state.atmosphere.ozone_absorption_per_km[1], 1.881e-3);
    CHECK_DOUBLE(state.sun.angular_diameter_deg, 0.545);
    CHECK_INT(state.sun.limb_darkening, SKY_LIMB_DARKENING_HM98);
    CHECK_INT(state.exposure.tonemap, SKY_TONEMAP_ACES);
    CHECK_INT(state.render.skyview_lut[0], 192);
    CHECK_INT(state.render.aerial_perspective_lut[2], 32);
}

static void test_validate_corrupt_state(void)
{
    check_case_name = "validate a corrupt state";
    struct sky_world_state state, before;
    struct sky_field_errors errors;
    starting_state(&state);
    state.camera.fov_deg = NAN;
    state.sun.limb_darkening = (enum sky_limb_darkening)7;
    state.render.transmittance_lut[1] = 3;
    state.atmosphere.top_radius_km = state.atmosphere.bottom_radius_km;
    CHECK(!sky_world_state_validate(&state, &errors));
    CHECK_INT(errors.total, 4);
    CHECK_STR(errors.items[0].pointer, "/sun/limb_darkening");
    CHECK_INT(errors.items[0].code, SKY_FIELD_OUT_OF_RANGE);
    CHECK_STR(errors.items[1].pointer, "/camera/fov_deg");
    CHECK_STR(errors.items[2].pointer, "/render/transmittance_lut/1");
    CHECK_STR(errors.items[3].pointer, "/atmosphere/top_radius_km");
    CHECK_INT(errors.items[3].code, SKY_FIELD_INCONSISTENT);

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
    struct sky_world_state state, before;
    struct sky_field_errors errors;
    starting_state(&state);
    memcpy(&before, &state, sizeof before);
    CHECK(!sky_world_state_apply_json(&state, patch, &errors));
    cJSON_Delete(patch);
    CHECK_INT(errors.count, SKY_MAX_FIELD_ERRORS);
    CHECK_INT(errors.total, 40);
    CHECK_STR(errors.items[31].pointer, "/x31");
    CHECK(memcmp(&state, &before, sizeof state) == 0);

    char text[16384];
    sky_field_errors_format(&errors, text, sizeof text);
    CHECK(strncmp(text, "/x0: unknown field", 18) == 0);
    CHECK_CONTAINS(text, "\n/x31: unknown field");
    CHECK_CONTAINS(text, "\n(and 8 more)");
}

static void test_format(void)
{
    check_case_name = "format";
    struct sky_field_errors errors;
    sky_field_errors_clear(&errors);
    sky_field_errors_add(&errors, SKY_FIELD_UNKNOWN, "/a", "first");
    sky_field_errors_add(&errors, SKY_FIELD_WRONG_TYPE, "", "second");
    char text[256];
    sky_field_errors_format(&errors, text, sizeof text);
    CHECK_STR(text, "/a: first\n(root): second");

    check_case_name = "format truncates";
    char small[12];
    memset(small, 'Z', sizeof small);
    sky_field_errors_format(&errors, small, sizeof small);
    CHECK_INT(strlen(small), sizeof small - 1);
    CHECK_STR(small, "/a: firs...");
    char tiny[6];
    sky_field_errors_format(&errors, tiny, sizeof tiny);
    CHECK_STR(tiny, "/a...");
    char one[1] = {'Z'};
    sky_field_errors_format(&errors, one, sizeof one);
    CHECK_INT(one[0], '\0');

    check_case_name = "format of no errors";
    sky_field_errors_clear(&errors);
    sky_field_errors_format(&errors, text, sizeof text);
    CHECK_STR(text, "");

    check_case_name = "long texts are truncated when added";
    char long_text[600];
    memset(long_text, 'q', sizeof long_text - 1);
    long_text[sizeof long_text - 1] = '\0';
    sky_field_errors_add(&errors, SKY_FIELD_UNKNOWN, long_text, long_text);
    CHECK_INT(strlen(errors.items[0].pointer), sizeof errors.items[0].pointer - 1);
    CHECK_INT(strlen(errors.items[0].reason), sizeof errors.items[0].reason - 1);
}

static void odd_valued_state(struct sky_world_state *state)
{
    starting_state(state);
    state->revision = 42;
    state->atmosphere.mie_g[0] = 0.1 + 0.2;
    state->atmosphere.mie_g[1] = 1.0 / 3.0;
    state->atmosphere.mie_g[2] = -0.5;
    state->atmosphere.rayleigh_scattering_per_km[1] = 1e-7 / 3.0;
    state->sun.azimuth_deg = -123.456789012345678;
    state->sun.limb_darkening = SKY_LIMB_DARKENING_NONE;
    state->exposure.mode = SKY_EXPOSURE_MANUAL;
    state->exposure.tonemap = SKY_TONEMAP_REINHARD;
    state->render.aerial_perspective_lut[0] = 5;
    state->render.aerial_perspective_lut[1] = 6;
    state->render.aerial_perspective_lut[2] = 7;
}

/* to_json without "revision", which patches may not carry; optionally printed and reparsed. */
static cJSON *state_patch(const struct sky_world_state *state, bool through_text)
{
    cJSON *json = sky_world_state_to_json(state);
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
static bool round_trip(const struct sky_world_state *state, bool through_text,
                       struct sky_world_state *restored)
{
    starting_state(restored);
    restored->revision = state->revision;
    cJSON *patch = state_patch(state, through_text);
    CHECK(patch != NULL);
    struct sky_field_errors errors;
    bool applied = patch && sky_world_state_apply_json(restored, patch, &errors);
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
    struct sky_world_state state;
    struct sky_field_errors errors;
    odd_valued_state(&state);
    CHECK(sky_world_state_validate(&state, &errors));
    cJSON *json = sky_world_state_to_json(&state);
    CHECK(json != NULL);
    if (!json)
        return;
    CHECK_DOUBLE(cJSON_GetNumberValue(cJSON_GetObjectItemCaseSensitive(json, "revision")), 42);
    size_t count = 0;
    const struct sky_field_desc *fields = sky_world_state_fields(&count);
    for (size_t i = 0; i < count; i++)
        CHECK(json_has_path(json, fields[i].path));
    const cJSON *sun = cJSON_GetObjectItemCaseSensitive(json, "sun");
    CHECK_STR(cJSON_GetStringValue(cJSON_GetObjectItemCaseSensitive(sun, "limb_darkening")),
              "none");
    const cJSON *render = cJSON_GetObjectItemCaseSensitive(json, "render");
    CHECK_INT(cJSON_GetArraySize(cJSON_GetObjectItemCaseSensitive(render, "skyview_lut")), 2);

    check_case_name = "to_json output is rejected while it carries revision";
    struct sky_world_state other;
    starting_state(&other);
    CHECK(!sky_world_state_apply_json(&other, json, &errors));
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
    struct sky_world_state state, restored;

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
    const struct sky_field_desc *fields = sky_world_state_fields(&count);
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
    struct sky_world_state state;
    struct sky_field_errors errors;
    starting_state(&state);
    CHECK(!sky_world_state_apply_json(&state, NULL, &errors));
    CHECK_INT(errors.items[0].code, SKY_FIELD_WRONG_TYPE);
    CHECK(!sky_world_state_set_path(&state, NULL, "1", &errors));
    CHECK(!sky_world_state_set_assignment(&state, NULL, &errors));
    CHECK(sky_world_state_set_path(&state, "camera.fov_deg", "60", NULL));
    CHECK_DOUBLE(state.camera.fov_deg, 60);
    CHECK(sky_world_state_to_json(NULL) == NULL);
}

/* ---- presets ---------------------------------------------------------------------------- */

static void test_real_presets(const char *config_dir)
{
    check_case_name = "preset list";
    char names[8][SKY_PRESET_NAME_MAX + 1];
    int count = sky_preset_list(config_dir, "atmosphere", names, 8);
    CHECK(count >= 2);
    bool has_earth = false, has_mars = false;
    for (int i = 0; i < count; i++) {
        has_earth = has_earth || strcmp(names[i], "earth") == 0;
        has_mars = has_mars || strcmp(names[i], "mars") == 0;
        if (i > 0)
            CHECK(strcmp(names[i - 1], names[i]) < 0);
    }
    CHECK(has_earth);
    CHECK(has_mars);

    check_case_name = "mars preset";
    struct sky_world_state state, defaults;
    struct sky_field_errors errors;
    char msg[512];
    starting_state(&state);
    starting_state(&defaults);
    CHECK(sky_preset_apply(config_dir, "atmosphere", "mars", &state, &errors, msg, sizeof msg));
    CHECK_CONTAINS(msg, "applied atmosphere preset \"mars\"");
    CHECK_DOUBLE(state.atmosphere.bottom_radius_km, 3389.5);
    CHECK_DOUBLE(state.atmosphere.top_radius_km, 3389.5 + 80);
    CHECK_DOUBLE(state.atmosphere.mie_g[2], 0.78);
    CHECK_DOUBLE(state.atmosphere.mie_absorption_per_km[2], 0.0130);
    CHECK_DOUBLE(state.atmosphere.ground_albedo[1], 0.18);
    CHECK_DOUBLE(state.atmosphere.ozone_absorption_per_km[0], 0);
    struct sky_world_state only_atmosphere_changed = defaults;
    only_atmosphere_changed.atmosphere = state.atmosphere;
    CHECK(states_equal(&state, &only_atmosphere_changed));
    CHECK_INT(state.revision, STARTING_REVISION);

    check_case_name = "earth preset restores the default atmosphere";
    CHECK(sky_preset_apply(config_dir, "atmosphere", "earth", &state, &errors, msg, sizeof msg));
    CHECK(states_equal(&state, &defaults));

    check_case_name = "missing preset lists the available ones";
    struct sky_world_state before;
    memcpy(&before, &state, sizeof before);
    CHECK(!sky_preset_apply(config_dir, "atmosphere", "venus", &state, &errors, msg, sizeof msg));
    CHECK_CONTAINS(msg, "no atmosphere preset named \"venus\"");
    CHECK_CONTAINS(msg, "available: ");
    CHECK_CONTAINS(msg, "earth");
    CHECK_CONTAINS(msg, "mars");
    CHECK(memcmp(&state, &before, sizeof state) == 0);

    static const char *const invalid_names[] = {
        "", "../earth", "Earth", "earth.json", "a b", "earth/", "é",
        "a12345678901234567890123456789012345678901234567890123456789012345", /* 65 */
    };
    for (size_t i = 0; i < sizeof invalid_names / sizeof invalid_names[0]; i++) {
        check_case_name = invalid_names[i];
        CHECK(!sky_preset_apply(config_dir, "atmosphere", invalid_names[i], &state, &errors, msg,
                                sizeof msg));
        CHECK_CONTAINS(msg, "invalid preset name");
        CHECK(memcmp(&state, &before, sizeof state) == 0);
    }
    check_case_name = "longest valid name";
    CHECK(sky_preset_name_is_valid(
        "a1234567890123456789012345678901234567890123456789012345678901-_"));
    check_case_name = "invalid kind";
    CHECK(!sky_preset_apply(config_dir, "../config", "earth", &state, &errors, msg, sizeof msg));
    CHECK_CONTAINS(msg, "invalid preset kind");
    CHECK(!sky_preset_apply(config_dir, "atmosphere", NULL, &state, &errors, msg, sizeof msg));
    CHECK_CONTAINS(msg, "invalid preset name");
}

#define MAX_TEMP_PATHS 32

struct temp_tree {
    char root[64];
    char paths[MAX_TEMP_PATHS][256]; /* removed in reverse order */
    int count;
};

static const char *temp_path(struct temp_tree *tree, const char *relative)
{
    if (tree->count >= MAX_TEMP_PATHS)
        return NULL;
    char root[sizeof tree->root]; /* a separate copy keeps -Wrestrict quiet at -O2 */
    memcpy(root, tree->root, sizeof root);
    char *path = tree->paths[tree->count++];
    snprintf(path, sizeof tree->paths[0], "%s/%s", root, relative);
    return path;
}

static bool temp_dir(struct temp_tree *tree, const char *relative)
{
    const char *path = temp_path(tree, relative);
    return path && mkdir(path, 0700) == 0;
}

static bool temp_file(struct temp_tree *tree, const char *relative, const char *contents,
                      size_t length)
{
    const char *path = temp_path(tree, relative);
    FILE *file = path ? fopen(path, "wb") : NULL;
    if (!file)
        return false;
    bool ok = fwrite(contents, 1, length, file) == length;
    return fclose(file) == 0 && ok;
}

static void remove_temp_tree(struct temp_tree *tree)
{
    for (int i = tree->count - 1; i >= 0; i--)
        remove(tree->paths[i]);
    remove(tree->root);
}

#define TEXT_FILE(tree, name, text) temp_file((tree), (name), (text), strlen(text))

static void expect_preset_failure(const char *dir, const char *name, const char *msg_part,
                                  int error_total)
{
    check_case_name = name;
    struct sky_world_state state, before;
    struct sky_field_errors errors;
    char msg[512];
    starting_state(&state);
    memcpy(&before, &state, sizeof before);
    CHECK(!sky_preset_apply(dir, "atmosphere", name, &state, &errors, msg, sizeof msg));
    CHECK_CONTAINS(msg, msg_part);
    CHECK_INT(errors.total, error_total);
    CHECK(memcmp(&state, &before, sizeof state) == 0);
}

static void write_temp_presets(struct temp_tree *tree)
{
    bool ok = temp_dir(tree, "atmosphere") &&
              TEXT_FILE(tree, "atmosphere/broken.json",
                        "{\n  \"atmosphere\": {\n    \"mie\": { \"g\": 0.5, }\n  }\n}\n") &&
              TEXT_FILE(tree, "atmosphere/truncated.json", "{\"atmosphere\": {") &&
              TEXT_FILE(tree, "atmosphere/empty.json", "") &&
              temp_file(tree, "atmosphere/nul.json", "{}\0{}", 5) &&
              TEXT_FILE(tree, "atmosphere/badfield.json",
                        "{\"atmosphere\":{\"mie\":{\"g\":2}},\"camera\":{\"fov\":1}}") &&
              TEXT_FILE(tree, "atmosphere/baddesc.json", "{\"description\":5,\"atmosphere\":{}}") &&
              TEXT_FILE(tree, "atmosphere/notobject.json", "[1]") &&
              TEXT_FILE(tree, "atmosphere/described.json",
                        "{\"description\":\"low sun\",\"sun\":{\"elevation_deg\":10}}") &&
              temp_dir(tree, "atmosphere/folder.json") && temp_dir(tree, "listing") &&
              TEXT_FILE(tree, "listing/b.json", "{}") && TEXT_FILE(tree, "listing/a.json", "{}") &&
              TEXT_FILE(tree, "listing/Upper.json", "{}") &&
              TEXT_FILE(tree, "listing/c.txt", "{}") && TEXT_FILE(tree, "listing/.json", "{}") &&
              TEXT_FILE(tree, "listing/d.json.bak", "{}");
    check_case_name = "writing temporary presets";
    CHECK(ok);

    size_t huge_length = SKY_PRESET_MAX_FILE_BYTES + 1;
    char *huge = malloc(huge_length);
    CHECK(huge != NULL);
    if (huge) {
        memset(huge, ' ', huge_length);
        huge[0] = '{';
        huge[huge_length - 1] = '}';
        CHECK(temp_file(tree, "atmosphere/huge.json", huge, huge_length));
        free(huge);
    }
}

static void test_temp_presets(void)
{
    struct temp_tree tree = {.root = "/tmp/skyd-presets-XXXXXX", .count = 0};
    check_case_name = "temporary directory";
    CHECK(mkdtemp(tree.root) != NULL);
    write_temp_presets(&tree);
    const char *dir = tree.root;

    expect_preset_failure(dir, "broken", "broken.json:3:", 0);
    expect_preset_failure(dir, "broken", "invalid JSON near \"", 0);
    expect_preset_failure(dir, "broken", "0.5, }\"", 0);
    expect_preset_failure(dir, "truncated", "truncated.json:1:", 0);
    expect_preset_failure(dir, "empty", "empty.json:1:1: invalid JSON", 0);
    expect_preset_failure(dir, "nul", "nul.json:1:3: invalid JSON", 0);
    expect_preset_failure(dir, "badfield", "preset rejected, 2 invalid fields; first: "
                                           "/atmosphere/mie/g: must be in", 2);
    expect_preset_failure(dir, "baddesc", "/description: expected a string", 1);
    expect_preset_failure(dir, "notobject", "(root): expected a JSON object", 1);
    expect_preset_failure(dir, "folder", "not a regular file", 0);
    expect_preset_failure(dir, "huge", "larger than the limit of 1048576 bytes", 0);
    expect_preset_failure(dir, "nothing", "available: baddesc, badfield, broken, described", 0);

    check_case_name = "description is stripped";
    struct sky_world_state state;
    struct sky_field_errors errors;
    char msg[512];
    starting_state(&state);
    CHECK(sky_preset_apply(dir, "atmosphere", "described", &state, &errors, msg, sizeof msg));
    CHECK_DOUBLE(state.sun.elevation_deg, 10);
    CHECK(sky_preset_apply(dir, "atmosphere", "described", &state, NULL, NULL, 0));

    check_case_name = "missing kind directory";
    CHECK(!sky_preset_apply(dir, "scene", "x", &state, &errors, msg, sizeof msg));
    CHECK_CONTAINS(msg, "available: none");

    check_case_name = "listing is sorted and filtered";
    char names[4][SKY_PRESET_NAME_MAX + 1];
    CHECK_INT(sky_preset_list(dir, "listing", names, 4), 2);
    CHECK_STR(names[0], "a");
    CHECK_STR(names[1], "b");
    CHECK_INT(sky_preset_list(dir, "listing", names, 1), 1);
    CHECK_STR(names[0], "a");
    CHECK_INT(sky_preset_list(dir, "listing", names, 0), 0);
    CHECK_INT(sky_preset_list(dir, "scene", names, 4), -1);
    CHECK_INT(sky_preset_list(dir, "../listing", names, 4), -1);

    remove_temp_tree(&tree);
    check_case_name = "temporary directory removed";
    struct stat info;
    CHECK(stat(tree.root, &info) != 0);
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
