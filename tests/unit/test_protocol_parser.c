/* test_protocol's parser details (offsets, limits) and the values parsed from the documented
 * examples (test_protocol.h). */
#include "test_protocol.h"

/* ---- parser details --------------------------------------------------------------------- */

void test_offsets_and_limits(void)
{
    struct proto_msg_limits limits = test_limits();
    struct proto_client_msg msg;
    struct proto_msg_parse_error error;

    check_case_name = "trailing garbage offset";
    CHECK_INT(parse("{\"type\":\"stats\"}  x", &msg, &error), PROTO_MSG_ERR_MALFORMED_JSON);
    CHECK_INT(error.offset, 18);

    check_case_name = "syntax error offset";
    CHECK_INT(parse("{\"type\" \"stats\"}", &msg, &error), PROTO_MSG_ERR_MALFORMED_JSON);
    CHECK_INT(error.offset, 8);

    check_case_name = "raw NUL byte";
    static const char with_nul[] = "{\"type\":\"auth\",\"token\":\"ab\0cd\"}";
    CHECK_INT(parse_with(with_nul, sizeof with_nul - 1, &limits, &msg, &error),
              PROTO_MSG_ERR_MALFORMED_JSON);
    CHECK_INT(error.offset, 26);
    check_case_name = "NUL after the object";
    static const char nul_after[] = "{\"type\":\"stats\"}\0";
    CHECK_INT(parse_with(nul_after, sizeof nul_after - 1, &limits, &msg, &error),
              PROTO_MSG_ERR_MALFORMED_JSON);
    CHECK_INT(error.offset, 16);

    check_case_name = "length bounds the text";
    static const char longer[] = "{\"type\":\"stats\"}{garbage";
    CHECK_INT(parse_with(longer, 16, &limits, &msg, &error), PROTO_MSG_OK);
    CHECK_INT(msg.type, PROTO_MSG_STATS);

    check_case_name = "invalid utf-8 offset";
    CHECK_INT(parse("{\"type\":\"hello\",\"client\":\"ab\x80\"}", &msg, &error),
              PROTO_MSG_ERR_INVALID_ENCODING);
    CHECK_INT(error.offset, 28);

    check_case_name = "message at the size limit";
    char *text = repeat(' ', limits.max_message_bytes);
    memcpy(text, "{\"type\":\"stats\"}", 16);
    CHECK_INT(parse_with(text, limits.max_message_bytes, &limits, &msg, &error), PROTO_MSG_OK);
    check_case_name = "message over the size limit";
    struct proto_msg_limits no_uploads = limits;
    no_uploads.max_upload_bytes = 0; /* else a set_weather_map may be larger (test_weather_map) */
    text[0] = '\x01';                /* never looked at: the size check comes first */
    CHECK_INT(parse_with(text, limits.max_message_bytes + 1, &no_uploads, &msg, &error),
              PROTO_MSG_ERR_MESSAGE_TOO_LARGE);
    CHECK_STR(first_pointer(&error), "");
    free(text);

    check_case_name = "token at and over its limit";
    char token_message[600];
    char *token = repeat('t', PROTO_MSG_TOKEN_MAX + 1);
    snprintf(token_message, sizeof token_message, "{\"type\":\"auth\",\"token\":\"%s\"}", token);
    CHECK_INT(parse(token_message, &msg, &error), PROTO_MSG_ERR_OUT_OF_RANGE);
    token[PROTO_MSG_TOKEN_MAX] = '\0';
    snprintf(token_message, sizeof token_message, "{\"type\":\"auth\",\"token\":\"%s\"}", token);
    CHECK_INT(parse(token_message, &msg, &error), PROTO_MSG_OK);
    CHECK_INT(strlen(msg.auth.token), PROTO_MSG_TOKEN_MAX);
    free(token);

    check_case_name = "deep nesting";
    struct proto_msg_limits large = limits;
    large.max_message_bytes = 1 << 20;
    char *deep = repeat('[', 100000);
    CHECK_INT(parse_with(deep, 100000, &large, &msg, &error), PROTO_MSG_ERR_MALFORMED_JSON);
    free(deep);

    check_case_name = "many unknown fields";
    size_t used = 0;
    char *many = malloc(large.max_message_bytes);
    used += (size_t)sprintf(many, "{\"type\":\"stats\"");
    for (int i = 0; i < 5000; i++)
        used += (size_t)sprintf(many + used, ",\"f%d\":%d", i, i);
    used += (size_t)sprintf(many + used, "}");
    CHECK_INT(parse_with(many, used, &large, &msg, &error), PROTO_MSG_ERR_UNKNOWN_FIELD);
    CHECK_INT(error.fields.total, 5000);
    CHECK_INT(error.fields.count, PROTO_MAX_FIELD_ERRORS);
    char *reply = proto_msg_build_parse_error(&msg, &error);
    cJSON *json = parse_built(reply, "error");
    CHECK_DOUBLE(number_at(json, "fields_omitted"), 5000 - PROTO_MAX_FIELD_ERRORS);
    CHECK_INT(cJSON_GetArraySize(get(json, "fields")), PROTO_MAX_FIELD_ERRORS);
    cJSON_Delete(json);
    free(many);

    check_case_name = "every failure is listed";
    CHECK_INT(parse("{\"type\":\"subscribe\",\"id\":\"v\",\"view\":{\"width\":0,\"height\":0,"
                    "\"fps\":100}}",
                    &msg, &error),
              PROTO_MSG_ERR_OUT_OF_RANGE);
    CHECK_INT(error.fields.total, 3);
    CHECK_STR(error.fields.items[1].pointer, "/view/height");
    CHECK_STR(error.fields.items[2].pointer, "/view/fps");
    CHECK_INT(error.fields.items[2].code, PROTO_MSG_ERR_OUT_OF_RANGE);

    check_case_name = "no limits";
    CHECK_INT(proto_msg_parse("{}", 2, NULL, &msg, &error), PROTO_MSG_ERR_INTERNAL);
    check_case_name = "";
}

void test_parsed_values(void)
{
    struct proto_client_msg msg;
    struct proto_msg_parse_error error;

    check_case_name = "hello values";
    CHECK_INT(parse(protocol_client_examples[0].text, &msg, &error), PROTO_MSG_OK);
    CHECK(msg.hello.has_client);
    CHECK_STR(msg.hello.client, "sky-web 0.1");
    CHECK_INT(msg.hello.protocol, 1);
    CHECK_INT(msg.id.kind, PROTO_MSG_ID_INTEGER);
    CHECK_INT(msg.id.number, 1);
    CHECK(!msg.hello.simulation_events);
    CHECK_INT(parse(protocol_client_examples[1].text, &msg, &error), PROTO_MSG_OK);
    CHECK(msg.hello.simulation_events);
    CHECK_INT(parse("{\"type\":\"hello\",\"simulation_events\":1}", &msg, &error),
              PROTO_MSG_ERR_WRONG_TYPE);
    CHECK_STR(error.fields.items[0].pointer, "/simulation_events");

    check_case_name = "auth values";
    CHECK_INT(parse(protocol_client_examples[2].text, &msg, &error), PROTO_MSG_OK);
    CHECK_STR(msg.auth.token, "s3cret-token");

    check_case_name = "id kinds";
    CHECK_INT(parse("{\"type\":\"stats\"}", &msg, &error), PROTO_MSG_OK);
    CHECK_INT(msg.id.kind, PROTO_MSG_ID_NONE);
    CHECK_INT(parse("{\"type\":\"stats\",\"id\":-9007199254740991}", &msg, &error), PROTO_MSG_OK);
    CHECK_INT(msg.id.number, -9007199254740991LL);
    CHECK_INT(parse("{\"id\":\"q\",\"type\":\"stats\"}", &msg, &error), PROTO_MSG_OK);
    CHECK_INT(msg.id.kind, PROTO_MSG_ID_STRING);
    CHECK_STR(msg.id.text, "q");

    check_case_name = "id kept when the rest fails";
    CHECK_INT(parse("{\"type\":\"bogus\",\"id\":\"keep-me\"}", &msg, &error),
              PROTO_MSG_ERR_UNKNOWN_TYPE);
    CHECK_STR(msg.id.text, "keep-me");
    cJSON *json = parse_built(proto_msg_build_parse_error(&msg, &error), "error");
    CHECK_STR(string_at(json, "id"), "keep-me");
    CHECK_STR(string_at(json, "code"), "unknown_type");
    cJSON_Delete(json);
    CHECK_INT(parse("{\"type\":\"set\",\"id\":77,\"patch\":{\"sun\":{\"bogus\":1}}}", &msg, &error),
              PROTO_MSG_ERR_UNKNOWN_FIELD);
    CHECK_INT(msg.type, PROTO_MSG_SET);
    CHECK(msg.set.patch == NULL);
    json = parse_built(proto_msg_build_parse_error(&msg, &error), "error");
    CHECK_DOUBLE(number_at(json, "id"), 77);
    const cJSON *field = cJSON_GetArrayItem(get(json, "fields"), 0);
    CHECK_STR(string_at(field, "pointer"), "/patch/sun/bogus");
    CHECK_STR(string_at(field, "code"), "unknown_field");
    CHECK(string_at(field, "reason") != NULL);
    cJSON_Delete(json);

    check_case_name = "invalid id not echoed";
    CHECK_INT(parse("{\"type\":\"stats\",\"id\":1.5}", &msg, &error), PROTO_MSG_ERR_BAD_VALUE);
    CHECK_INT(msg.id.kind, PROTO_MSG_ID_NONE);
    json = parse_built(proto_msg_build_parse_error(&msg, &error), "error");
    CHECK(get(json, "id") == NULL);
    cJSON_Delete(json);

    check_case_name = "patch is validated once and applies";
    CHECK_INT(parse(protocol_client_examples[4].text, &msg, &error), PROTO_MSG_OK);
    CHECK(msg.set.patch != NULL && msg.set.patch->count > 0);
    struct proto_world_state state;
    proto_world_state_defaults(&state);
    CHECK(proto_world_state_apply_patch(&state, msg.set.patch, NULL));
    CHECK_DOUBLE(state.sun.elevation_deg, 2);
    CHECK_DOUBLE(state.atmosphere.mie_g[2], 0.76);
    proto_client_msg_free(&msg);
    CHECK(msg.set.patch == NULL);
    proto_client_msg_free(&msg);

    check_case_name = "inconsistency is left to the apply";
    CHECK_INT(parse("{\"type\":\"set\",\"patch\":{\"atmosphere\":{\"bottom_radius_km\":7000}}}",
                    &msg, &error),
              PROTO_MSG_OK);
    struct proto_field_errors apply_errors;
    CHECK(!proto_world_state_apply_patch(&state, msg.set.patch, &apply_errors));
    CHECK_INT(apply_errors.items[0].code, PROTO_MSG_ERR_INCONSISTENT);
    json = parse_built(
        proto_msg_build_error(NULL, PROTO_MSG_ERR_INCONSISTENT, "rejected", &apply_errors),
        "error");
    CHECK_STR(string_at(json, "code"), "inconsistent");
    CHECK_STR(string_at(cJSON_GetArrayItem(get(json, "fields"), 0), "code"), "inconsistent");
    cJSON_Delete(json);
    proto_client_msg_free(&msg);

    check_case_name = "view defaults";
    CHECK_INT(parse(protocol_client_examples[7].text, &msg, &error), PROTO_MSG_OK);
    CHECK_INT(msg.view.width, 640);
    CHECK_INT(msg.view.height, 360);
    CHECK_DOUBLE(msg.view.fps, 10);
    CHECK_INT(msg.view.format, PROTO_FRAME_FORMAT_PNG);
    CHECK_INT(msg.view.projection, PROTO_VIEW_PROJECTION_PERSPECTIVE);
    CHECK(!msg.view.has_altitude_km && !msg.view.has_yaw_deg && !msg.view.has_pitch_deg &&
          !msg.view.has_fov_deg);
    CHECK(!msg.view.has_exposure_mode && !msg.view.has_ev100 && !msg.view.has_compensation_ev);
    struct proto_msg_limits slow = test_limits();
    slow.max_fps = 4;
    const char *snapshot = protocol_client_examples[7].text;
    CHECK_INT(parse_with(snapshot, strlen(snapshot), &slow, &msg, &error), PROTO_MSG_OK);
    CHECK_DOUBLE(msg.view.fps, 4);

    check_case_name = "view environment map";
    const char *environment_map = protocol_client_examples[protocol_client_example_count - 2].text;
    CHECK_INT(parse(environment_map, &msg, &error), PROTO_MSG_OK);
    CHECK_INT(msg.view.projection, PROTO_VIEW_PROJECTION_EQUIRECTANGULAR);
    CHECK_INT(msg.view.format, PROTO_FRAME_FORMAT_PNG16);
    CHECK_INT(msg.view.width, 2 * msg.view.height);

    check_case_name = "view given";
    CHECK_INT(parse(protocol_client_examples[5].text, &msg, &error), PROTO_MSG_OK);
    CHECK(msg.view.has_yaw_deg && msg.view.has_fov_deg && !msg.view.has_pitch_deg);
    CHECK_DOUBLE(msg.view.yaw_deg, 200);
    CHECK_DOUBLE(msg.view.fov_deg, 60);
    CHECK_DOUBLE(msg.view.fps, 30);
    CHECK(msg.view.has_exposure_mode && msg.view.has_ev100 && !msg.view.has_compensation_ev);
    CHECK_INT(msg.view.exposure_mode, PROTO_EXPOSURE_MANUAL);
    CHECK_DOUBLE(msg.view.ev100, 12);

    check_case_name = "view resolve";
    struct proto_camera_state camera;
    struct proto_exposure_state exposure;
    proto_world_state_defaults(&state);
    proto_msg_view_resolve(&msg.view, &state, &camera, &exposure);
    CHECK_DOUBLE(camera.yaw_deg, 200);
    CHECK_DOUBLE(camera.fov_deg, 60);
    CHECK_DOUBLE(camera.pitch_deg, state.camera.pitch_deg);
    CHECK_DOUBLE(camera.altitude_km, state.camera.altitude_km);
    CHECK_INT(exposure.mode, PROTO_EXPOSURE_MANUAL);
    CHECK_DOUBLE(exposure.ev100, 12);
    CHECK_DOUBLE(exposure.compensation_ev, state.exposure.compensation_ev);
    CHECK_INT(exposure.tonemap, state.exposure.tonemap);

    check_case_name = "probe values";
    CHECK_INT(parse(protocol_client_examples[9].text, &msg, &error), PROTO_MSG_OK);
    CHECK_INT(msg.probe.quantity, PROTO_PROBE_LUMINANCE);
    CHECK_DOUBLE(msg.probe.view_zenith_deg, 45);
    CHECK_DOUBLE(msg.probe.view_azimuth_deg, 90);
    CHECK_DOUBLE(msg.probe.sun_zenith_deg, 30);
    CHECK_INT(parse(protocol_client_examples[8].text, &msg, &error), PROTO_MSG_OK);
    CHECK_INT(msg.probe.quantity, PROTO_PROBE_TRANSMITTANCE);
    CHECK_DOUBLE(msg.probe.mu, 0.5);

    check_case_name = "preset values";
    CHECK_INT(parse(protocol_client_examples[12].text, &msg, &error), PROTO_MSG_OK);
    CHECK_INT(msg.preset.kind, PROTO_PRESET_ATMOSPHERE);
    CHECK_STR(msg.preset.name, "mars");
    CHECK(!msg.preset.has_transition);
    CHECK_INT(parse(protocol_client_examples[14].text, &msg, &error), PROTO_MSG_OK);
    CHECK_INT(msg.preset.kind, PROTO_PRESET_WEATHER);
    CHECK_STR(msg.preset.name, "storm");
    CHECK(msg.preset.has_transition);
    CHECK_DOUBLE(msg.preset.transition_s, 1200);
    CHECK_INT(parse(protocol_client_examples[6].text, &msg, &error), PROTO_MSG_OK);
    CHECK_INT(msg.unsubscribe.subscription, 1);

    check_case_name = "roles";
    for (int t = PROTO_MSG_HELLO; t <= PROTO_MSG_STATS; t++) {
        bool expected = t == PROTO_MSG_SET || t == PROTO_MSG_APPLY_PRESET;
        CHECK_INT(proto_msg_needs_controller((enum proto_msg_type)t), expected);
        CHECK(proto_msg_type_name((enum proto_msg_type)t) != NULL);
    }
    CHECK(proto_msg_type_name(PROTO_MSG_NONE) == NULL);

    check_case_name = "error names";
    /* clang-format off */
    static const struct {
        int code;
        const char *name;
    } names[] = {
        {PROTO_MSG_ERR_UNKNOWN_FIELD, "unknown_field"}, {PROTO_MSG_ERR_WRONG_TYPE, "wrong_type"},
        {PROTO_MSG_ERR_OUT_OF_RANGE, "out_of_range"}, {PROTO_MSG_ERR_BAD_VALUE, "bad_value"},
        {PROTO_MSG_ERR_INCONSISTENT, "inconsistent"}, {PROTO_MSG_ERR_MISSING_FIELD, "missing_field"},
        {PROTO_MSG_ERR_MALFORMED_JSON, "malformed_json"},
        {PROTO_MSG_ERR_MESSAGE_TOO_LARGE, "message_too_large"},
        {PROTO_MSG_ERR_NOT_AN_OBJECT, "not_an_object"}, {PROTO_MSG_ERR_UNKNOWN_TYPE, "unknown_type"},
        {PROTO_MSG_ERR_INVALID_ENCODING, "invalid_encoding"},
        {PROTO_MSG_ERR_UNSUPPORTED_PROTOCOL, "unsupported_protocol"},
        {PROTO_MSG_ERR_FORBIDDEN, "forbidden"}, {PROTO_MSG_ERR_AUTH_FAILED, "auth_failed"},
        {PROTO_MSG_ERR_RATE_LIMITED, "rate_limited"}, {PROTO_MSG_ERR_NOT_FOUND, "not_found"},
        {PROTO_MSG_ERR_LIMIT_REACHED, "limit_reached"}, {PROTO_MSG_ERR_INTERNAL, "internal"},
        {PROTO_MSG_ERR_UNAVAILABLE, "unavailable"},
        {PROTO_FIELD_UNKNOWN, "unknown_field"}, {PROTO_FIELD_INCONSISTENT, "inconsistent"},
    };
    /* clang-format on */
    for (size_t i = 0; i < COUNT_OF(names); i++) {
        CHECK_STR(proto_msg_error_name(names[i].code), names[i].name);
        CHECK_INT(proto_msg_error_code_named(names[i].name, strlen(names[i].name)), names[i].code);
    }
    CHECK_INT(proto_msg_error_code_named("auth_failedx", 11), PROTO_MSG_ERR_AUTH_FAILED);
    CHECK_INT(proto_msg_error_code_named("auth", 4), PROTO_MSG_OK);
    CHECK_INT(proto_msg_error_code_named("ok", 2), PROTO_MSG_OK);
    CHECK(proto_msg_error_name(13) == NULL);
    CHECK(proto_msg_error_name(-1) == NULL);
    CHECK(proto_msg_error_name(1000) == NULL);
    check_case_name = "";
}
