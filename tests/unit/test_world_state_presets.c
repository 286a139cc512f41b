/* test_world_state's presets: the repository's (config/atmosphere) and broken ones written to a
 * temporary directory (test_world_state.h). */
#include "test_world_state.h"

/* ---- presets ---------------------------------------------------------------------------- */

void test_real_presets(const char *config_dir)
{
    check_case_name = "preset list";
    char names[8][WORLD_PRESET_NAME_MAX + 1];
    int count = world_preset_list(config_dir, "atmosphere", names, 8);
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
    struct proto_world_state state, defaults;
    struct proto_field_errors errors;
    char msg[512];
    starting_state(&state);
    starting_state(&defaults);
    CHECK(world_preset_apply(config_dir, "atmosphere", "mars", &state, &errors, msg, sizeof msg));
    CHECK_CONTAINS(msg, "applied atmosphere preset \"mars\"");
    CHECK_DOUBLE(state.atmosphere.bottom_radius_km, 3389.5);
    CHECK_DOUBLE(state.atmosphere.top_radius_km, 3389.5 + 80);
    CHECK_DOUBLE(state.atmosphere.mie_g[2], 0.78);
    CHECK_DOUBLE(state.atmosphere.mie_absorption_per_km[2], 0.0130);
    CHECK_DOUBLE(state.atmosphere.ground_albedo[1], 0.18);
    CHECK_DOUBLE(state.atmosphere.ozone_absorption_per_km[0], 0);
    struct proto_world_state only_atmosphere_changed = defaults;
    only_atmosphere_changed.atmosphere = state.atmosphere;
    CHECK(states_equal(&state, &only_atmosphere_changed));
    CHECK_INT(state.revision, STARTING_REVISION);

    check_case_name = "earth preset restores the default atmosphere";
    CHECK(world_preset_apply(config_dir, "atmosphere", "earth", &state, &errors, msg, sizeof msg));
    CHECK(states_equal(&state, &defaults));

    check_case_name = "missing preset lists the available ones";
    struct proto_world_state before;
    memcpy(&before, &state, sizeof before);
    CHECK(!world_preset_apply(config_dir, "atmosphere", "venus", &state, &errors, msg, sizeof msg));
    CHECK_CONTAINS(msg, "no atmosphere preset named \"venus\"");
    CHECK_CONTAINS(msg, "available: ");
    CHECK_CONTAINS(msg, "earth");
    CHECK_CONTAINS(msg, "mars");
    CHECK(memcmp(&state, &before, sizeof state) == 0);

    static const char *const invalid_names[] = {
        "",      "../earth",
        "Earth", "earth.json",
        "a b",   "earth/",
        "é",     "a12345678901234567890123456789012345678901234567890123456789012345", /* 65 */
    };
    for (size_t i = 0; i < sizeof invalid_names / sizeof invalid_names[0]; i++) {
        check_case_name = invalid_names[i];
        CHECK(!world_preset_apply(config_dir, "atmosphere", invalid_names[i], &state, &errors, msg,
                                  sizeof msg));
        CHECK_CONTAINS(msg, "invalid preset name");
        CHECK(memcmp(&state, &before, sizeof state) == 0);
    }
    check_case_name = "longest valid name";
    CHECK(world_preset_name_is_valid(
        "a1234567890123456789012345678901234567890123456789012345678901-_"));
    check_case_name = "invalid kind";
    CHECK(!world_preset_apply(config_dir, "../config", "earth", &state, &errors, msg, sizeof msg));
    CHECK_CONTAINS(msg, "invalid preset kind");
    CHECK(!world_preset_apply(config_dir, "atmosphere", NULL, &state, &errors, msg, sizeof msg));
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
    struct proto_world_state state, before;
    struct proto_field_errors errors;
    char msg[512];
    starting_state(&state);
    memcpy(&before, &state, sizeof before);
    CHECK(!world_preset_apply(dir, "atmosphere", name, &state, &errors, msg, sizeof msg));
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

    size_t huge_length = WORLD_PRESET_MAX_FILE_BYTES + 1;
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

void test_temp_presets(void)
{
    struct temp_tree tree = { .root = "/tmp/skyd-presets-XXXXXX", .count = 0 };
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
    expect_preset_failure(dir, "badfield",
                          "preset rejected, 2 invalid fields; first: "
                          "/atmosphere/mie/g: must be in",
                          2);
    expect_preset_failure(dir, "baddesc", "/description: expected a string", 1);
    expect_preset_failure(dir, "notobject", "(root): expected a JSON object", 1);
    expect_preset_failure(dir, "folder", "not a regular file", 0);
    expect_preset_failure(dir, "huge", "larger than the limit of 1048576 bytes", 0);
    expect_preset_failure(dir, "nothing", "available: baddesc, badfield, broken, described", 0);

    check_case_name = "description is stripped";
    struct proto_world_state state;
    struct proto_field_errors errors;
    char msg[512];
    starting_state(&state);
    CHECK(world_preset_apply(dir, "atmosphere", "described", &state, &errors, msg, sizeof msg));
    CHECK_DOUBLE(state.sun.elevation_deg, 10);
    CHECK(world_preset_apply(dir, "atmosphere", "described", &state, NULL, NULL, 0));

    check_case_name = "missing kind directory";
    CHECK(!world_preset_apply(dir, "scene", "x", &state, &errors, msg, sizeof msg));
    CHECK_CONTAINS(msg, "available: none");

    check_case_name = "listing is sorted and filtered";
    char names[4][WORLD_PRESET_NAME_MAX + 1];
    CHECK_INT(world_preset_list(dir, "listing", names, 4), 2);
    CHECK_STR(names[0], "a");
    CHECK_STR(names[1], "b");
    CHECK_INT(world_preset_list(dir, "listing", names, 1), 1);
    CHECK_STR(names[0], "a");
    CHECK_INT(world_preset_list(dir, "listing", names, 0), 0);
    CHECK_INT(world_preset_list(dir, "scene", names, 4), -1);
    CHECK_INT(world_preset_list(dir, "../listing", names, 4), -1);

    remove_temp_tree(&tree);
    check_case_name = "temporary directory removed";
    struct stat info;
    CHECK(stat(tree.root, &info) != 0);
}
