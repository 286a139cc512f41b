/* test_world_state's table-driven cases: JSON patches and "path=value" assignments, each
 * applied to the starting state, with the errors or values expected (test_world_state.h). */
#include "test_world_state.h"

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

/* clang-format off */
#define ERR(code_, pointer_, reason_) {.code = (code_), .pointer = (pointer_), .reason_part = (reason_)}
#define APPLIES(input_, path_, ...) \
    {.input = (input_), .applied = true, .check = {.path = (path_), .values = {__VA_ARGS__}}}
#define REJECTS(input_, total_, ...) \
    {.input = (input_), .applied = false, .total = (total_), .errors = {__VA_ARGS__}}
/* clang-format on */

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
            PROTO_LIMB_DARKENING_NECKEL96),
    APPLIES("{\"sun\":{\"limb_darkening\":\"none\",\"elevation_deg\":-90}}", "sun.elevation_deg",
            -90),
    APPLIES("{\"exposure\":{\"mode\":\"manual\",\"ev100\":12.5,\"tonemap\":\"clamp\"}}",
            "exposure.tonemap", PROTO_TONEMAP_CLAMP),
    APPLIES("{\"render\":{\"skyview_lut\":[200,100],\"aerial_perspective_lut\":[16,16,64]}}",
            "render.aerial_perspective_lut", 16, 16, 64),
    APPLIES("{\"render\":{\"transmittance_lut\":[4096,8]}}", "render.transmittance_lut", 4096, 8),
    APPLIES("{\"atmosphere\":{\"bottom_radius_km\":6000,\"top_radius_km\":7000}}",
            "atmosphere.top_radius_km", 7000),
    /* the middle layer, its base anywhere in the middle etage */
    APPLIES("{\"clouds\":{\"mid\":{\"coverage\":0.8,\"type\":1}}}", "clouds.mid.coverage", 0.8),
    APPLIES("{\"clouds\":{\"mid\":{\"bottom_km\":2}}}", "clouds.mid.bottom_km", 2),
    APPLIES("{\"clouds\":{\"mid\":{\"bottom_km\":8,\"thickness_km\":4}}}",
            "clouds.mid.thickness_km", 4),

    /* unknown fields at each depth, and odd member names */
    REJECTS("{\"bogus\":1}", 1,
            ERR(PROTO_FIELD_UNKNOWN, "/bogus",
                "clock, location, atmosphere, sun, moon, night, clouds, weather, camera, exposure, "
                "render")),
    REJECTS("{\"atmosphere\":{\"bogus\":{}}}", 1,
            ERR(PROTO_FIELD_UNKNOWN, "/atmosphere/bogus", "rayleigh, mie, ozone")),
    REJECTS("{\"atmosphere\":{\"mie\":{\"bogus\":1}}}", 1,
            ERR(PROTO_FIELD_UNKNOWN, "/atmosphere/mie/bogus",
                "scattering_per_km, absorption_per_km, scale_height_km, g")),
    REJECTS("{\"a/b~c\":1}", 1, ERR(PROTO_FIELD_UNKNOWN, "/a~1b~0c", NULL)),
    REJECTS("{\"atmosphere.mie\":{\"g\":0.5}}", 1,
            ERR(PROTO_FIELD_UNKNOWN, "/atmosphere.mie", NULL)),
    REJECTS("{\"\":1}", 1, ERR(PROTO_FIELD_UNKNOWN, "/", NULL)),
    REJECTS("{\"revision\":8}", 1, ERR(PROTO_FIELD_BAD_VALUE, "/revision", "read-only")),
    REJECTS("{\"camera\":{\"revision\":8}}", 1, ERR(PROTO_FIELD_UNKNOWN, "/camera/revision", NULL)),

    /* wrong JSON types */
    REJECTS("{\"camera\":{\"fov_deg\":\"70\"}}", 1,
            ERR(PROTO_FIELD_WRONG_TYPE, "/camera/fov_deg", "expected a number, got a string")),
    REJECTS("{\"sun\":{\"elevation_deg\":true}}", 1,
            ERR(PROTO_FIELD_WRONG_TYPE, "/sun/elevation_deg", "got a boolean")),
    REJECTS("{\"sun\":{\"elevation_deg\":null}}", 1,
            ERR(PROTO_FIELD_WRONG_TYPE, "/sun/elevation_deg", "got null")),
    REJECTS("{\"atmosphere\":{\"mie\":{\"g\":{\"r\":0.5}}}}", 1,
            ERR(PROTO_FIELD_WRONG_TYPE, "/atmosphere/mie/g",
                "expected a number or an array of 3 numbers, got an object")),
    REJECTS("{\"atmosphere\":{\"mie\":5}}", 1,
            ERR(PROTO_FIELD_WRONG_TYPE, "/atmosphere/mie", "expected an object")),
    REJECTS("{\"sun\":[]}", 1,
            ERR(PROTO_FIELD_WRONG_TYPE, "/sun", "expected an object, got an array")),
    REJECTS("{\"atmosphere\":{\"mie\":{\"g\":[0.1,0.2]}}}", 1,
            ERR(PROTO_FIELD_BAD_VALUE, "/atmosphere/mie/g",
                "expected an array of 3 numbers, got 2 elements")),
    REJECTS("{\"atmosphere\":{\"mie\":{\"g\":[0.1,0.2,0.3,0.4]}}}", 1,
            ERR(PROTO_FIELD_BAD_VALUE, "/atmosphere/mie/g", "got 4 elements")),
    REJECTS("{\"atmosphere\":{\"mie\":{\"g\":[0.1,\"x\",0.3]}}}", 1,
            ERR(PROTO_FIELD_WRONG_TYPE, "/atmosphere/mie/g/1", "expected a number")),
    REJECTS("{\"render\":{\"skyview_lut\":256}}", 1,
            ERR(PROTO_FIELD_WRONG_TYPE, "/render/skyview_lut", "expected an array of 2 integers")),
    REJECTS("{\"render\":{\"skyview_lut\":[192.5,108]}}", 1,
            ERR(PROTO_FIELD_BAD_VALUE, "/render/skyview_lut/0", "must be an integer, got 192.5")),
    REJECTS("{\"sun\":{\"limb_darkening\":2}}", 1,
            ERR(PROTO_FIELD_WRONG_TYPE, "/sun/limb_darkening",
                "expected one of: none, neckel96, hm98")),
    REJECTS("{\"sun\":{\"limb_darkening\":\"HM98\"}}", 1,
            ERR(PROTO_FIELD_BAD_VALUE, "/sun/limb_darkening", "got \"HM98\"")),
    REJECTS("[1,2,3]", 1, ERR(PROTO_FIELD_WRONG_TYPE, "", "expected a JSON object")),
    REJECTS("\"sun\"", 1, ERR(PROTO_FIELD_WRONG_TYPE, "", "expected a JSON object")),

    /* out of range */
    REJECTS(
        "{\"atmosphere\":{\"mie\":{\"g\":1.5}}}", 1,
        ERR(PROTO_FIELD_OUT_OF_RANGE, "/atmosphere/mie/g", "must be in [-0.99, 0.99], got 1.5")),
    REJECTS("{\"atmosphere\":{\"mie\":{\"g\":[0.5,1.5,-2]}}}", 2,
            ERR(PROTO_FIELD_OUT_OF_RANGE, "/atmosphere/mie/g/1", "got 1.5"),
            ERR(PROTO_FIELD_OUT_OF_RANGE, "/atmosphere/mie/g/2", "got -2")),
    REJECTS("{\"camera\":{\"fov_deg\":1e400}}", 1,
            ERR(PROTO_FIELD_OUT_OF_RANGE, "/camera/fov_deg", "must be a finite number, got inf")),
    REJECTS("{\"camera\":{\"fov_deg\":0.999}}", 1,
            ERR(PROTO_FIELD_OUT_OF_RANGE, "/camera/fov_deg", "must be in [1, 170], got 0.999")),
    REJECTS("{\"sun\":{\"illuminance_lux\":-1}}", 1,
            ERR(PROTO_FIELD_OUT_OF_RANGE, "/sun/illuminance_lux", "[0, 1000000], got -1")),
    REJECTS("{\"render\":{\"aerial_perspective_lut\":[4,4,513]}}", 1,
            ERR(PROTO_FIELD_OUT_OF_RANGE, "/render/aerial_perspective_lut/2", "[4, 512], got 513")),

    /* the middle layer's base outside the middle etage, and the other fields' ranges */
    REJECTS("{\"clouds\":{\"mid\":{\"bottom_km\":1.5}}}", 1,
            ERR(PROTO_FIELD_OUT_OF_RANGE, "/clouds/mid/bottom_km", "must be in [2, 8], got 1.5")),
    REJECTS("{\"clouds\":{\"mid\":{\"bottom_km\":9}}}", 1,
            ERR(PROTO_FIELD_OUT_OF_RANGE, "/clouds/mid/bottom_km", "got 9")),
    REJECTS("{\"clouds\":{\"mid\":{\"coverage\":1.2,\"type\":-0.1,\"thickness_km\":5}}}", 3,
            ERR(PROTO_FIELD_OUT_OF_RANGE, "/clouds/mid/coverage", "must be in [0, 1], got 1.2"),
            ERR(PROTO_FIELD_OUT_OF_RANGE, "/clouds/mid/type", "got -0.1"),
            ERR(PROTO_FIELD_OUT_OF_RANGE, "/clouds/mid/thickness_km", "[0.05, 4], got 5")),
    REJECTS("{\"clouds\":{\"mid\":{\"density\":\"thick\"}}}", 1,
            ERR(PROTO_FIELD_WRONG_TYPE, "/clouds/mid/density", "expected a number")),
    REJECTS("{\"clouds\":{\"mid\":{\"bogus\":1}}}", 1,
            ERR(PROTO_FIELD_UNKNOWN, "/clouds/mid/bogus", "coverage, type, density")),

    /* inconsistent radii; not reported on top of field errors */
    REJECTS("{\"atmosphere\":{\"top_radius_km\":6300}}", 1,
            ERR(PROTO_FIELD_INCONSISTENT, "/atmosphere/top_radius_km",
                "must be greater than bottom_radius_km (6360), got 6300")),
    REJECTS("{\"atmosphere\":{\"top_radius_km\":6360}}", 1,
            ERR(PROTO_FIELD_INCONSISTENT, "/atmosphere/top_radius_km", NULL)),
    REJECTS("{\"atmosphere\":{\"bottom_radius_km\":7000}}", 1,
            ERR(PROTO_FIELD_INCONSISTENT, "/atmosphere/top_radius_km", "(7000), got 6460")),
    REJECTS("{\"atmosphere\":{\"top_radius_km\":7400.5}}", 1,
            ERR(PROTO_FIELD_INCONSISTENT, "/atmosphere/top_radius_km",
                "at most 1000 km above bottom_radius_km (6360), got 1040.5 km above")),
    REJECTS("{\"atmosphere\":{\"top_radius_km\":6300},\"camera\":{\"fov_deg\":0}}", 1,
            ERR(PROTO_FIELD_OUT_OF_RANGE, "/camera/fov_deg", NULL)),

    /* several errors at once, in patch order */
    REJECTS("{\"bogus\":1,\"camera\":{\"fov_deg\":500,\"yaw_deg\":\"x\"},"
            "\"sun\":{\"limb_darkening\":\"no\"},\"revision\":1}",
            5, ERR(PROTO_FIELD_UNKNOWN, "/bogus", NULL),
            ERR(PROTO_FIELD_OUT_OF_RANGE, "/camera/fov_deg", NULL),
            ERR(PROTO_FIELD_WRONG_TYPE, "/camera/yaw_deg", NULL),
            ERR(PROTO_FIELD_BAD_VALUE, "/sun/limb_darkening", NULL),
            ERR(PROTO_FIELD_BAD_VALUE, "/revision", NULL)),
};

static const struct state_case assignment_cases[] = {
    APPLIES("atmosphere.mie.g=0.7", "atmosphere.mie.g", 0.7, 0.7, 0.7),
    APPLIES("sun.limb_darkening=none", "sun.limb_darkening", PROTO_LIMB_DARKENING_NONE),
    APPLIES("atmosphere.rayleigh.scattering_per_km=[1e-3,2e-3,3e-3]",
            "atmosphere.rayleigh.scattering_per_km", 1e-3, 2e-3, 3e-3),
    APPLIES(" camera.fov_deg = 85 ", "camera.fov_deg", 85),
    APPLIES("render.skyview_lut=[256, 128]", "render.skyview_lut", 256, 128),
    APPLIES("sun.limb_darkening=\"neckel96\"", "sun.limb_darkening", PROTO_LIMB_DARKENING_NECKEL96),
    APPLIES("exposure.ev100=-2.5", "exposure.ev100", -2.5),
    APPLIES("exposure.mode=manual", "exposure.mode", PROTO_EXPOSURE_MANUAL),

    REJECTS("bogus.path=1", 1, ERR(PROTO_FIELD_UNKNOWN, "/bogus", NULL)),
    REJECTS("atmosphere.nothing=1", 1, ERR(PROTO_FIELD_UNKNOWN, "/atmosphere/nothing", NULL)),
    REJECTS("atmosphere.mie=1", 1,
            ERR(PROTO_FIELD_UNKNOWN, "/atmosphere/mie",
                "atmosphere.mie is a group, not a field; set one of: scattering_per_km")),
    REJECTS("atmosphere=1", 1, ERR(PROTO_FIELD_UNKNOWN, "/atmosphere", "is a group")),
    REJECTS("=1", 1, ERR(PROTO_FIELD_UNKNOWN, "/", NULL)),
    REJECTS("camera..fov_deg=1", 1, ERR(PROTO_FIELD_UNKNOWN, "/camera/", NULL)),
    REJECTS("camera.fov_deg", 1, ERR(PROTO_FIELD_BAD_VALUE, "", "expected dotted.path=value")),
    REJECTS("camera.fov_deg=abc", 1,
            ERR(PROTO_FIELD_BAD_VALUE, "/camera/fov_deg", "expected a number, got \"abc\"")),
    REJECTS("camera.fov_deg=70abc", 1, ERR(PROTO_FIELD_BAD_VALUE, "/camera/fov_deg", NULL)),
    REJECTS("camera.fov_deg=", 1, ERR(PROTO_FIELD_BAD_VALUE, "/camera/fov_deg", "empty value")),
    REJECTS("camera.fov_deg=nan", 1,
            ERR(PROTO_FIELD_OUT_OF_RANGE, "/camera/fov_deg", "must be a finite number, got nan")),
    REJECTS("camera.fov_deg=1e400", 1,
            ERR(PROTO_FIELD_OUT_OF_RANGE, "/camera/fov_deg", "must be a finite number, got inf")),
    REJECTS("camera.fov_deg=-inf", 1, ERR(PROTO_FIELD_OUT_OF_RANGE, "/camera/fov_deg", "got -inf")),
    REJECTS("camera.fov_deg=[70]", 1,
            ERR(PROTO_FIELD_WRONG_TYPE, "/camera/fov_deg", "got an array")),
    REJECTS("atmosphere.mie.g=[0.1,0.2", 1,
            ERR(PROTO_FIELD_BAD_VALUE, "/atmosphere/mie/g", "invalid JSON")),
    REJECTS("atmosphere.mie.g=2", 1,
            ERR(PROTO_FIELD_OUT_OF_RANGE, "/atmosphere/mie/g", "must be in [-0.99, 0.99], got 2")),
    REJECTS("sun.limb_darkening=bogus", 1,
            ERR(PROTO_FIELD_BAD_VALUE, "/sun/limb_darkening", "got \"bogus\"")),
    REJECTS("sun.limb_darkening=1", 1, ERR(PROTO_FIELD_WRONG_TYPE, "/sun/limb_darkening", NULL)),
    REJECTS("render.skyview_lut=256", 1,
            ERR(PROTO_FIELD_WRONG_TYPE, "/render/skyview_lut", "expected an array of 2 integers")),
    REJECTS("render.skyview_lut=big", 1,
            ERR(PROTO_FIELD_BAD_VALUE, "/render/skyview_lut", "a JSON array like [256,64]")),
    REJECTS("revision=3", 1, ERR(PROTO_FIELD_BAD_VALUE, "/revision", "read-only")),
    REJECTS("atmosphere.top_radius_km=6000", 1,
            ERR(PROTO_FIELD_INCONSISTENT, "/atmosphere/top_radius_km", NULL)),
};

static int expected_error_count(const struct state_case *test)
{
    int count = 0;
    while (count < (int)(sizeof test->errors / sizeof test->errors[0]) && test->errors[count].code)
        count++;
    return count;
}

static void check_errors(const struct proto_field_errors *errors, const struct state_case *test)
{
    CHECK_INT(errors->total, test->total);
    CHECK_INT(errors->count,
              test->total < PROTO_MAX_FIELD_ERRORS ? test->total : PROTO_MAX_FIELD_ERRORS);
    int expected = expected_error_count(test);
    for (int i = 0; i < expected && i < errors->count; i++) {
        const struct proto_field_error *item = &errors->items[i];
        CHECK_INT(item->code, test->errors[i].code);
        CHECK_STR(item->pointer, test->errors[i].pointer);
        if (test->errors[i].reason_part)
            CHECK_CONTAINS(item->reason, test->errors[i].reason_part);
    }
}

static void check_values(const struct proto_world_state *state, const struct value_check *check)
{
    const struct proto_field_desc *field = proto_world_state_find_field(check->path);
    CHECK(field != NULL);
    if (!field)
        return;
    for (int i = 0; i < field_elements(field); i++)
        CHECK_DOUBLE(read_element(state, check->path, i), check->values[i]);
}

typedef bool (*apply_text_fn)(struct proto_world_state *state, const char *text,
                              struct proto_field_errors *errors);

static void run_state_case(const struct state_case *test, apply_text_fn apply)
{
    check_case_name = test->input;
    struct proto_world_state state, before;
    starting_state(&state);
    memcpy(&before, &state, sizeof before);
    struct proto_field_errors errors;
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

void test_state_cases(void)
{
    for (size_t i = 0; i < sizeof patch_cases / sizeof patch_cases[0]; i++)
        run_state_case(&patch_cases[i], apply_patch_text);
    for (size_t i = 0; i < sizeof assignment_cases / sizeof assignment_cases[0]; i++)
        run_state_case(&assignment_cases[i], proto_world_state_set_assignment);
}
