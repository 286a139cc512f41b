/* Unit tests for the WebSocket protocol messages (protocol/messages.c) and the binary frame
 * header (protocol/frame_header.c). No sockets.
 *
 * Usage: test_protocol [PROTOCOL_MD]
 * PROTOCOL_MD defaults to protocol/PROTOCOL.md next to this file's directory; every JSON
 * example in it is checked against the tables below, so the document cannot drift.
 */
#include "test_protocol.h"
#include "text_file.h"
#include "metar.h"
#include "weather_observation.h"

#include <cjson/cJSON.h>
#include <string.h>

/* ---- the documented examples (also in protocol/PROTOCOL.md, in this order) -------------- */

const struct protocol_client_example protocol_client_examples[] = {
    { "{\"type\":\"hello\",\"id\":1,\"client\":\"sky-web 0.1\",\"protocol\":1}", PROTO_MSG_HELLO },
    { "{\"type\":\"hello\",\"id\":2,\"client\":\"sky-web 0.1\",\"protocol\":1,"
      "\"simulation_events\":true}",
      PROTO_MSG_HELLO },
    { "{\"type\":\"auth\",\"id\":2,\"token\":\"s3cret-token\"}", PROTO_MSG_AUTH },
    { "{\"type\":\"get_state\",\"id\":3}", PROTO_MSG_GET_STATE },
    { "{\"type\":\"set\",\"id\":4,\"patch\":{\"sun\":{\"elevation_deg\":2,\"azimuth_deg\":250},"
      "\"atmosphere\":{\"mie\":{\"g\":0.76}}}}",
      PROTO_MSG_SET },
    { "{\"type\":\"subscribe\",\"id\":\"main-view\",\"view\":{\"camera\":{\"yaw_deg\":200,"
      "\"fov_deg\":60},\"width\":1280,\"height\":720,\"fps\":30,\"exposure\":{\"mode\":"
      "\"manual\",\"ev100\":12},\"format\":\"png\"}}",
      PROTO_MSG_SUBSCRIBE },
    { "{\"type\":\"unsubscribe\",\"id\":6,\"subscription\":1}", PROTO_MSG_UNSUBSCRIBE },
    { "{\"type\":\"snapshot\",\"id\":7,\"view\":{\"width\":640,\"height\":360}}",
      PROTO_MSG_SNAPSHOT },
    { "{\"type\":\"probe\",\"id\":8,\"quantity\":\"transmittance\",\"altitude_km\":0,\"mu\":0.5}",
      PROTO_MSG_PROBE },
    { "{\"type\":\"probe\",\"id\":9,\"quantity\":\"luminance\",\"altitude_km\":0,"
      "\"view_zenith_deg\":45,\"view_azimuth_deg\":90,\"sun_zenith_deg\":30}",
      PROTO_MSG_PROBE },
    { "{\"type\":\"probe\",\"id\":10,\"quantity\":\"illuminance\",\"sun_zenith_deg\":0}",
      PROTO_MSG_PROBE },
    { "{\"type\":\"list_presets\",\"id\":11,\"kind\":\"atmosphere\"}", PROTO_MSG_LIST_PRESETS },
    { "{\"type\":\"apply_preset\",\"id\":12,\"kind\":\"atmosphere\",\"name\":\"mars\"}",
      PROTO_MSG_APPLY_PRESET },
    { "{\"type\":\"list_presets\",\"id\":14,\"kind\":\"weather\"}", PROTO_MSG_LIST_PRESETS },
    { "{\"type\":\"apply_preset\",\"id\":15,\"kind\":\"weather\",\"name\":\"storm\","
      "\"transition_s\":1200}",
      PROTO_MSG_APPLY_PRESET },
    { "{\"type\":\"stats\",\"id\":13}", PROTO_MSG_STATS },
    { "{\"type\":\"set_weather_map\",\"id\":16,\"format\":\"rgba8\",\"width\":2,\"height\":1,"
      "\"data\":\"/wCgAIBAoCg=\"}",
      PROTO_MSG_SET_WEATHER_MAP },
    { "{\"type\":\"apply_observation\",\"id\":19,\"metar\":\"METAR LFLY 211200Z 18008KT 9999 "
      "FEW040 22/10 Q1018\"}",
      PROTO_MSG_APPLY_OBSERVATION },
    { "{\"type\":\"describe\",\"id\":18}", PROTO_MSG_DESCRIBE },
    { "{\"type\":\"snapshot\",\"id\":17,\"view\":{\"width\":1024,\"height\":512,"
      "\"projection\":\"equirectangular\",\"format\":\"png16\"}}",
      PROTO_MSG_SNAPSHOT },
    { "{\"type\":\"subscribe\",\"id\":\"phone\",\"view\":{\"width\":1280,\"height\":720,"
      "\"fps\":30,\"format\":\"jpeg\",\"quality\":80,\"max_kbps\":2000}}",
      PROTO_MSG_SUBSCRIBE },
};
const size_t protocol_client_example_count = COUNT_OF(protocol_client_examples);

/* apply_observation's reply to its example (revision 7): the report decoded and mapped. */
static char *build_observation_example(void)
{
    const char *text = "METAR LFLY 211200Z 18008KT 9999 FEW040 22/10 Q1018";
    struct proto_metar_report report;
    cJSON *patch = NULL, *unmapped = NULL;
    char why[160];
    if (!proto_metar_decode(text, strlen(text), &report, NULL) ||
        !proto_obs_metar_patch(&report, &patch, &unmapped, why, sizeof why))
        return NULL;
    cJSON *decoded = proto_metar_to_json(&report);
    struct proto_msg_id id = int_id(19);
    char *built = proto_msg_build_observation(&id, 7, decoded, patch, unmapped);
    cJSON_Delete(decoded);
    cJSON_Delete(patch);
    cJSON_Delete(unmapped);
    return built;
}

/* The server examples of PROTOCOL.md, in its order, produced by the builders. */
static size_t build_server_examples(char **out, size_t max)
{
    size_t n = 0;
    struct proto_msg_limits limits;
    proto_msg_limits_default(&limits);
    size_t capability_count;
    const char *const *caps = proto_msg_default_capabilities(&capability_count);
    struct proto_world_state state;
    proto_world_state_defaults(&state);
    state.revision = 5;
    struct proto_msg_id id2 = int_id(2), id3 = int_id(3), id4 = int_id(4), id7 = int_id(7);
    struct proto_msg_id id8 = int_id(8), id9 = int_id(9), id10 = int_id(10), id11 = int_id(11);
    struct proto_msg_id id13 = int_id(13);

#define ADD(expression)                                                                            \
    do {                                                                                           \
        if (n < max)                                                                               \
            out[n] = expression;                                                                   \
        n++;                                                                                       \
    } while (0)

    ADD(proto_msg_build_hello("0.1.0", PROTO_ROLE_VIEWER, caps, capability_count, &limits));
    ADD(proto_msg_build_state(&id3, &state));
    ADD(proto_msg_build_ack(&id4, 6, PROTO_ROLE_NONE));
    ADD(proto_msg_build_ack(&id2, 5, PROTO_ROLE_CONTROLLER));
    ADD(build_observation_example());

    struct proto_client_msg msg;
    struct proto_msg_parse_error error;
    parse("{\"type\":\"set\",\"id\":4,\"patch\":{\"atmosphere\":{\"bogus\":1}}}", &msg, &error);
    ADD(proto_msg_build_parse_error(&msg, &error));
    proto_client_msg_free(&msg);
    ADD(proto_msg_build_error(&id4, PROTO_MSG_ERR_FORBIDDEN, "set needs the controller role",
                              NULL));

    parse(protocol_client_examples[5].text, &msg, &error);
    ADD(proto_msg_build_subscribed(&msg.id, 1, &msg.view));
    proto_client_msg_free(&msg);
    ADD(proto_msg_build_frame(NULL, 1, 42));
    ADD(proto_msg_build_frame(&id7, 0, 43));

    struct proto_world_state after = state;
    parse(protocol_client_examples[4].text, &msg, &error);
    proto_world_state_apply_patch(&after, msg.set.patch, NULL);
    proto_client_msg_free(&msg);
    after.revision = 6;
    char changed[8][PROTO_MSG_POINTER_MAX];
    size_t changed_count = proto_msg_state_diff(&state, &after, changed, 8);
    const char *pointers[8];
    for (size_t i = 0; i < changed_count && i < 8; i++)
        pointers[i] = changed[i];
    ADD(proto_msg_build_state_changed(after.revision, pointers, changed_count, &after,
                                      "sky-web 0.1"));
    struct proto_world_state moved = after;
    moved.clock.utc_unix_s = 1782066600.25;
    moved.sun.elevation_deg = 11.42;
    moved.sun.azimuth_deg = 295.1;
    changed_count = proto_msg_state_diff(&after, &moved, changed, 8);
    for (size_t i = 0; i < changed_count && i < 8; i++)
        pointers[i] = changed[i];
    ADD(proto_msg_build_simulation_event(moved.revision, pointers, changed_count, &moved));

    const char *presets[] = { "earth", "mars" };
    ADD(proto_msg_build_presets(&id11, PROTO_PRESET_ATMOSPHERE, presets, 2));
    struct proto_msg_probe_result t = {
        PROTO_PROBE_TRANSMITTANCE, { 0.8, 0.67, 0.46 }, 0, 0, NULL
    };
    struct proto_msg_probe_result l = {
        PROTO_PROBE_LUMINANCE, { 3200, 4100, 6900 }, 0, 0, "converged"
    };
    struct proto_msg_probe_result e = { PROTO_PROBE_ILLUMINANCE, { 0, 0, 0 }, 120014, 18700, NULL };
    ADD(proto_msg_build_probe_result(&id8, &t));
    ADD(proto_msg_build_probe_result(&id9, &l));
    ADD(proto_msg_build_probe_result(&id10, &e));
    const struct proto_msg_pass_time passes[] = { { "skyview", 0.42 },
                                                  { "aerial_perspective", 0.31 },
                                                  { "composite", 1.9 },
                                                  { "sun_disk", 0.05 } };
    const struct proto_msg_subscription_stats subscriptions[] = { { 1, 5242880, 12.5, 70, 2000 } };
    const struct proto_msg_multiple_scattering ms = { 0.4, 1, 0 };
    const enum proto_cloud_resolution traced = PROTO_CLOUD_RESOLUTION_SIXTYFOURTH;
    struct proto_msg_stats stats = {
        .fps = 29.8,
        .clients = 3,
        .passes = passes,
        .pass_count = COUNT_OF(passes),
        .lut_rebuild_progress = 1,
        .simulation_time_s = 1782043200,
        .subscriptions = subscriptions,
        .subscription_count = COUNT_OF(subscriptions),
        .multiple_scattering = &ms,
        .cloud_resolution = &traced,
        .cloud_primary_steps = 64,
    };
    ADD(proto_msg_build_stats(&id13, &stats));
#undef ADD
    return n;
}

/* ---- PROTOCOL.md ------------------------------------------------------------------------ */

/* cJSON_Compare, except that the human-readable "message" and "reason" texts may differ. */
static bool same_json(const cJSON *a, const cJSON *b)
{
    if (cJSON_IsObject(a) && cJSON_IsObject(b)) {
        if (cJSON_GetArraySize(a) != cJSON_GetArraySize(b))
            return false;
        for (const cJSON *member = a->child; member; member = member->next) {
            const cJSON *other = get(b, member->string);
            bool text = strcmp(member->string, "message") == 0 ||
                        strcmp(member->string, "reason") == 0;
            if (!other || (text ? !cJSON_IsString(other) : !same_json(member, other)))
                return false;
        }
        return true;
    }
    if (cJSON_IsArray(a) && cJSON_IsArray(b)) {
        if (cJSON_GetArraySize(a) != cJSON_GetArraySize(b))
            return false;
        for (const cJSON *x = a->child, *y = b->child; x && y; x = x->next, y = y->next) {
            if (!same_json(x, y))
                return false;
        }
        return true;
    }
    return cJSON_Compare(a, b, true);
}

/* Finds the blocks fenced by "```json <role>" lines; returns how many, storing up to max. */
static size_t doc_blocks(const char *doc, const char *role, char **out, size_t max)
{
    char fence[32];
    snprintf(fence, sizeof fence, "```json %s\n", role);
    size_t n = 0;
    for (const char *at = strstr(doc, fence); at; at = strstr(at, fence)) {
        at += strlen(fence);
        const char *end = strstr(at, "```");
        if (!end)
            break;
        if (n < max) {
            out[n] = malloc((size_t)(end - at) + 1);
            memcpy(out[n], at, (size_t)(end - at));
            out[n][end - at] = '\0';
        }
        n++;
        at = end + 3;
    }
    return n;
}

static void test_documented_examples(const char *doc_path)
{
    check_case_name = "client examples parse";
    for (size_t i = 0; i < protocol_client_example_count; i++) {
        struct proto_client_msg msg;
        struct proto_msg_parse_error error;
        CHECK_INT(parse(protocol_client_examples[i].text, &msg, &error), PROTO_MSG_OK);
        if (error.code != PROTO_MSG_OK)
            printf("    %s: %s\n", protocol_client_examples[i].text, error.message);
        CHECK_STR(proto_msg_type_name(msg.type),
                  proto_msg_type_name(protocol_client_examples[i].type));
        proto_client_msg_free(&msg);
    }

    char *doc = text_file_read(doc_path, 1 << 22, &(size_t){ 0 });
    check_case_name = doc_path;
    CHECK(doc != NULL);
    if (!doc)
        return;
    char *blocks[64];
    check_case_name = "PROTOCOL.md client examples";
    size_t count = doc_blocks(doc, "client", blocks, 64);
    CHECK_INT(count, protocol_client_example_count);
    for (size_t i = 0; i < count && i < 64; i++) {
        cJSON *documented = cJSON_Parse(blocks[i]);
        cJSON *tabled = i < protocol_client_example_count
                            ? cJSON_Parse(protocol_client_examples[i].text)
                            : NULL;
        CHECK(documented != NULL && cJSON_Compare(documented, tabled, true));
        if (!documented || !cJSON_Compare(documented, tabled, true))
            printf("    example %zu differs: %s", i + 1, blocks[i]);
        cJSON_Delete(documented);
        cJSON_Delete(tabled);
        free(blocks[i]);
    }

    check_case_name = "PROTOCOL.md server examples";
    char *built[64];
    size_t built_count = build_server_examples(built, 64);
    count = doc_blocks(doc, "server", blocks, 64);
    CHECK_INT(count, built_count);
    for (size_t i = 0; i < count && i < 64; i++) {
        cJSON *documented = cJSON_Parse(blocks[i]);
        cJSON *expected = i < built_count && built[i] ? cJSON_Parse(built[i]) : NULL;
        bool same = documented && expected && same_json(documented, expected);
        CHECK(same);
        if (!same)
            printf("    example %zu: documented %s    built %s\n", i + 1, blocks[i],
                   i < built_count && built[i] ? built[i] : "(nothing)");
        cJSON_Delete(documented);
        cJSON_Delete(expected);
        free(blocks[i]);
    }
    for (size_t i = 0; i < built_count && i < 64; i++)
        free(built[i]);
    free(doc);
    check_case_name = "";
}

static char *default_doc_path(void)
{
    const char *file = __FILE__;
    const char *suffix = "tests/unit/test_protocol.c";
    size_t length = strlen(file), suffix_length = strlen(suffix);
    size_t prefix = length >= suffix_length && strcmp(file + length - suffix_length, suffix) == 0
                        ? length - suffix_length
                        : 0;
    char *path = malloc(prefix + sizeof "protocol/PROTOCOL.md");
    memcpy(path, file, prefix);
    strcpy(path + prefix, "protocol/PROTOCOL.md");
    return path;
}

int main(int argc, char **argv)
{
    test_parse_table();
    test_offsets_and_limits();
    test_parsed_values();
    test_builders();
    test_frame_header();
    char *doc_path = argc > 1 ? NULL : default_doc_path();
    test_documented_examples(argc > 1 ? argv[1] : doc_path);
    free(doc_path);
    return check_summary();
}
