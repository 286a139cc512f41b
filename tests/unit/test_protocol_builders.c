/* test_protocol's builders of server messages and the binary frame header
 * (test_protocol.h). */
#include "test_protocol.h"

/* ---- builders --------------------------------------------------------------------------- */

void test_builders(void)
{
    struct proto_msg_limits limits;
    proto_msg_limits_default(&limits);
    size_t capability_count;
    const char *const *caps = proto_msg_default_capabilities(&capability_count);
    struct proto_msg_id id = string_id("abc"), id5 = int_id(5);

    check_case_name = "hello";
    cJSON *json = parse_built(
        proto_msg_build_hello("1.2.3", PROTO_ROLE_CONTROLLER, caps, capability_count, &limits),
        "hello");
    CHECK_DOUBLE(number_at(json, "protocol"), PROTO_PROTOCOL_VERSION);
    CHECK_STR(string_at(json, "server"), "skyd 1.2.3");
    CHECK_STR(string_at(json, "role"), "controller");
    CHECK_INT(cJSON_GetArraySize(get(json, "capabilities")), capability_count);
    const cJSON *json_limits = get(json, "limits");
    CHECK_DOUBLE(number_at(json_limits, "max_message_bytes"), 65536);
    CHECK_DOUBLE(number_at(json_limits, "max_clients"), 64);
    CHECK_DOUBLE(number_at(json_limits, "max_width"), 3840);
    CHECK_DOUBLE(number_at(json_limits, "max_height"), 2160);
    CHECK_DOUBLE(number_at(json_limits, "max_fps"), 60);
    CHECK_DOUBLE(number_at(json_limits, "control_messages_per_second"), 20);
    cJSON_Delete(json);
    CHECK(proto_msg_build_hello("1", PROTO_ROLE_NONE, caps, capability_count, &limits) == NULL);
    CHECK(proto_msg_build_hello(NULL, PROTO_ROLE_VIEWER, caps, capability_count, &limits) == NULL);
    CHECK(proto_msg_build_hello("1", PROTO_ROLE_VIEWER, caps, capability_count, NULL) == NULL);
    struct proto_msg_limits bad = limits;
    bad.max_fps = NAN;
    CHECK(proto_msg_build_hello("1", PROTO_ROLE_VIEWER, caps, capability_count, &bad) == NULL);
    bad = limits;
    bad.max_clients = -1;
    CHECK(proto_msg_build_hello("1", PROTO_ROLE_VIEWER, caps, capability_count, &bad) == NULL);

    check_case_name = "state";
    struct proto_world_state state;
    proto_world_state_defaults(&state);
    state.revision = 41;
    json = parse_built(proto_msg_build_state(&id, &state), "state");
    CHECK_STR(string_at(json, "id"), "abc");
    CHECK_DOUBLE(number_at(json, "revision"), 41);
    const cJSON *state_json = get(json, "state");
    CHECK(get(state_json, "revision") == NULL);
    CHECK_DOUBLE(number_at(get(state_json, "sun"), "elevation_deg"), 45);
    struct proto_world_state copy;
    proto_world_state_defaults(&copy);
    copy.sun.elevation_deg = 3;
    CHECK(proto_world_state_apply_json(&copy, state_json, NULL));
    CHECK_DOUBLE(copy.sun.elevation_deg, 45);
    struct proto_field_errors patch_errors;
    proto_field_errors_clear(&patch_errors);
    struct proto_world_patch *patch = malloc(sizeof *patch);
    CHECK(patch && proto_world_patch_compile(state_json, "/patch", patch, &patch_errors));
    free(patch);
    cJSON_Delete(json);
    state.sun.elevation_deg = NAN;
    CHECK(proto_msg_build_state(&id, &state) == NULL);
    state.sun.elevation_deg = INFINITY;
    CHECK(proto_msg_build_state(&id, &state) == NULL);
    CHECK(proto_msg_build_state(&id, NULL) == NULL);

    check_case_name = "ack";
    json = parse_built(proto_msg_build_ack(&id5, 9007199254740991ULL, PROTO_ROLE_NONE), "ack");
    CHECK_DOUBLE(number_at(json, "id"), 5);
    CHECK_DOUBLE(number_at(json, "revision"), 9007199254740991.0);
    CHECK(get(json, "role") == NULL);
    cJSON_Delete(json);
    json = parse_built(proto_msg_build_ack(NULL, 0, PROTO_ROLE_CONTROLLER), "ack");
    CHECK(get(json, "id") == NULL);
    CHECK_STR(string_at(json, "role"), "controller");
    cJSON_Delete(json);
    CHECK(proto_msg_build_ack(&id5, 9007199254740992ULL, PROTO_ROLE_NONE) == NULL);
    struct proto_msg_id bad_id = int_id(9007199254740992LL);
    CHECK(proto_msg_build_ack(&bad_id, 1, PROTO_ROLE_NONE) == NULL);
    bad_id = string_id("");
    CHECK(proto_msg_build_ack(&bad_id, 1, PROTO_ROLE_NONE) == NULL);
    bad_id.kind = (enum proto_msg_id_kind)7;
    CHECK(proto_msg_build_ack(&bad_id, 1, PROTO_ROLE_NONE) == NULL);
    CHECK(proto_msg_build_ack(NULL, 1, (enum proto_msg_role)9) == NULL);

    check_case_name = "error";
    struct proto_field_errors fields;
    proto_field_errors_clear(&fields);
    proto_field_errors_add(&fields, PROTO_MSG_ERR_OUT_OF_RANGE, "/view/fps", "too fast");
    proto_field_errors_add(&fields, PROTO_MSG_ERR_MISSING_FIELD, "/view/width", "required");
    json = parse_built(proto_msg_build_error(&id5, PROTO_MSG_ERR_OUT_OF_RANGE, "bad view", &fields),
                       "error");
    CHECK_DOUBLE(number_at(json, "id"), 5);
    CHECK_STR(string_at(json, "code"), "out_of_range");
    CHECK_STR(string_at(json, "message"), "bad view");
    CHECK_INT(cJSON_GetArraySize(get(json, "fields")), 2);
    const cJSON *second = cJSON_GetArrayItem(get(json, "fields"), 1);
    CHECK_STR(string_at(second, "pointer"), "/view/width");
    CHECK_STR(string_at(second, "reason"), "required");
    CHECK_STR(string_at(second, "code"), "missing_field");
    CHECK(get(json, "fields_omitted") == NULL);
    cJSON_Delete(json);
    json = parse_built(proto_msg_build_error(NULL, PROTO_MSG_ERR_RATE_LIMITED, NULL, NULL),
                       "error");
    CHECK_INT(cJSON_GetArraySize(get(json, "fields")), 0);
    CHECK_STR(string_at(json, "message"), "");
    cJSON_Delete(json);
    CHECK(proto_msg_build_error(NULL, PROTO_MSG_OK, "x", NULL) == NULL);
    CHECK(proto_msg_build_error(NULL, (enum proto_msg_error_code)99, "x", NULL) == NULL);
    proto_field_errors_add(&fields, 99, "/x", "unknown code");
    CHECK(proto_msg_build_error(NULL, PROTO_MSG_ERR_BAD_VALUE, "x", &fields) == NULL);

    check_case_name = "error text is made UTF-8";
    char *text = proto_msg_build_error(NULL, PROTO_MSG_ERR_BAD_VALUE, "cut \xe2\x98", NULL);
    CHECK(text != NULL);
    json = parse_built(text, "error");
    CHECK_STR(string_at(json, "message"), "cut ??");
    cJSON_Delete(json);

    check_case_name = "subscribed round trip";
    struct proto_client_msg msg, again;
    struct proto_msg_parse_error error;
    CHECK_INT(parse(protocol_client_examples[5].text, &msg, &error), PROTO_MSG_OK);
    json = parse_built(proto_msg_build_subscribed(&msg.id, 3, &msg.view), "subscribed");
    CHECK_STR(string_at(json, "id"), "main-view");
    CHECK_DOUBLE(number_at(json, "subscription"), 3);
    cJSON *request = cJSON_CreateObject();
    cJSON_AddStringToObject(request, "type", "subscribe");
    cJSON_AddItemToObject(request, "view", cJSON_DetachItemFromObject(json, "view"));
    char *request_text = cJSON_PrintUnformatted(request);
    CHECK_INT(parse(request_text, &again, &error), PROTO_MSG_OK);
    CHECK(memcmp(&again.view, &msg.view, sizeof msg.view) == 0);
    free(request_text);
    cJSON_Delete(request);
    cJSON_Delete(json);
    check_case_name = "subscribed round trip jpeg";
    CHECK_INT(parse("{\"type\":\"subscribe\",\"view\":{\"width\":2,\"height\":2,"
                    "\"format\":\"jpeg\",\"max_kbps\":250}}",
                    &msg, &error),
              PROTO_MSG_OK);
    CHECK_INT(msg.view.format, PROTO_FRAME_FORMAT_JPEG);
    CHECK_INT(msg.view.quality, PROTO_MSG_JPEG_QUALITY_DEFAULT);
    CHECK_DOUBLE(msg.view.max_kbps, 250);
    json = parse_built(proto_msg_build_subscribed(&msg.id, 4, &msg.view), "subscribed");
    const cJSON *jpeg_view = get(json, "view");
    CHECK_STR(string_at(jpeg_view, "format"), "jpeg");
    CHECK_DOUBLE(number_at(jpeg_view, "quality"), PROTO_MSG_JPEG_QUALITY_DEFAULT);
    CHECK_DOUBLE(number_at(jpeg_view, "max_kbps"), 250);
    cJSON_Delete(json);
    CHECK_INT(
        parse("{\"type\":\"snapshot\",\"id\":1,\"view\":{\"width\":2,\"height\":2}}", &msg, &error),
        PROTO_MSG_OK);
    CHECK_INT(msg.view.quality, 0);
    CHECK_DOUBLE(msg.view.max_kbps, 0);
    json = parse_built(proto_msg_build_subscribed(&msg.id, 4, &msg.view), "subscribed");
    CHECK(get(get(json, "view"), "quality") == NULL);
    CHECK(get(get(json, "view"), "max_kbps") == NULL);
    cJSON_Delete(json);
    CHECK_INT(parse(protocol_client_examples[5].text, &msg, &error), PROTO_MSG_OK);

    CHECK(proto_msg_build_subscribed(&msg.id, 0, &msg.view) == NULL);
    msg.view.fov_deg = NAN;
    CHECK(proto_msg_build_subscribed(&msg.id, 1, &msg.view) == NULL);
    CHECK(proto_msg_build_subscribed(&msg.id, 1, NULL) == NULL);

    check_case_name = "frame";
    json = parse_built(proto_msg_build_frame(NULL, 2, 100), "frame");
    CHECK_DOUBLE(number_at(json, "subscription"), 2);
    CHECK_DOUBLE(number_at(json, "frame_number"), 100);
    CHECK(get(json, "id") == NULL);
    cJSON_Delete(json);
    json = parse_built(proto_msg_build_frame(&id, 0, 101), "frame");
    CHECK_STR(string_at(json, "id"), "abc");
    CHECK(get(json, "subscription") == NULL);
    cJSON_Delete(json);
    CHECK(proto_msg_build_frame(&id, 2, 1) == NULL);
    CHECK(proto_msg_build_frame(NULL, 0, 1) == NULL);

    check_case_name = "state_changed";
    struct proto_world_state before, after;
    proto_world_state_defaults(&before);
    after = before;
    after.camera.fov_deg = 30;
    after.sun.elevation_deg = 10;
    after.render.skyview_lut[1] = 200;
    char changed[2][PROTO_MSG_POINTER_MAX];
    CHECK_INT(proto_msg_state_diff(&before, &after, changed, 2), 3);
    CHECK_STR(changed[0], "/sun/elevation_deg");
    CHECK_STR(changed[1], "/camera/fov_deg");
    CHECK_INT(proto_msg_state_diff(&before, &before, changed, 2), 0);
    const char *pointers[] = { changed[0],     changed[1],   "/render/skyview_lut",
                               "/weather/map", "/clock/utc", "/exposure/mode" };
    after.exposure.mode = PROTO_EXPOSURE_MANUAL;
    json = parse_built(proto_msg_build_state_changed(8, pointers, 6, &after, "app 2"), "event");
    CHECK_STR(string_at(json, "event"), "state_changed");
    CHECK_DOUBLE(number_at(json, "revision"), 8);
    CHECK_STR(string_at(json, "by"), "app 2");
    CHECK_STR(cJSON_GetArrayItem(get(json, "changed"), 1)->valuestring, "/camera/fov_deg");
    CHECK_INT(cJSON_GetArraySize(get(json, "changed")), 6);
    /* Each value as get_state writes it; the map has none. */
    const cJSON *values = get(json, "values");
    CHECK_INT(cJSON_GetArraySize(values), 5);
    CHECK_DOUBLE(number_at(values, "/sun/elevation_deg"), 10);
    CHECK_DOUBLE(number_at(values, "/camera/fov_deg"), 30);
    CHECK_DOUBLE(cJSON_GetArrayItem(get(values, "/render/skyview_lut"), 1)->valuedouble, 200);
    CHECK(get(values, "/weather/map") == NULL);
    CHECK_STR(string_at(values, "/exposure/mode"), "manual");
    cJSON *whole = proto_world_state_to_json(&after);
    CHECK(cJSON_Compare(get(values, "/clock/utc"), get(get(whole, "clock"), "utc"), true));
    cJSON_Delete(whole);
    cJSON_Delete(json);
    const char *not_pointers[] = { "sun.elevation_deg" };
    CHECK(proto_msg_build_state_changed(8, not_pointers, 1, &after, "x") == NULL);
    CHECK(proto_msg_build_state_changed(8, NULL, 1, &after, "x") == NULL);
    CHECK(proto_msg_build_state_changed(8, pointers, 2, NULL, "x") == NULL);
    CHECK(proto_msg_build_state_changed(8, pointers, 2, &after, "") == NULL);

    check_case_name = "schema";
    struct proto_msg_limits narrow;
    proto_msg_limits_default(&narrow);
    narrow.max_width = 800;
    char *schema = proto_msg_build_schema(&id, &narrow);
    CHECK(schema && strstr(schema, "9007199254740991") != NULL); /* printed exactly */
    json = parse_built(schema, "schema");
    CHECK_STR(string_at(json, "id"), "abc");
    CHECK_STR(string_at(get(json, "state"), "title"), "skyd world state");
    CHECK_STR(string_at(get(json, "messages"), "title"), "skyd client messages");
    const cJSON *width = get(get(get(get(get(json, "messages"), "$defs"), "view"), "properties"),
                             "width");
    CHECK_DOUBLE(number_at(width, "maximum"), 800);
    cJSON_Delete(json);
    CHECK(proto_msg_build_schema(&id, NULL) == NULL);

    check_case_name = "presets";
    const char *names[] = { "earth", "mars" };
    json = parse_built(proto_msg_build_presets(&id, PROTO_PRESET_ATMOSPHERE, names, 2), "presets");
    CHECK_STR(string_at(json, "kind"), "atmosphere");
    CHECK_STR(cJSON_GetArrayItem(get(json, "names"), 1)->valuestring, "mars");
    cJSON_Delete(json);
    json = parse_built(proto_msg_build_presets(NULL, PROTO_PRESET_ATMOSPHERE, NULL, 0), "presets");
    CHECK_INT(cJSON_GetArraySize(get(json, "names")), 0);
    cJSON_Delete(json);
    const char *bad_names[] = { "earth", "Bad Name" };
    CHECK(proto_msg_build_presets(NULL, PROTO_PRESET_ATMOSPHERE, bad_names, 2) == NULL);
    CHECK(proto_msg_build_presets(NULL, (enum proto_preset_kind)3, names, 2) == NULL);

    check_case_name = "probe_result";
    struct proto_msg_probe_result result = {
        PROTO_PROBE_TRANSMITTANCE, { 0.5, 0.25, 0.125 }, 0, 0, "fast"
    };
    json = parse_built(proto_msg_build_probe_result(&id5, &result), "probe_result");
    CHECK_STR(string_at(json, "quantity"), "transmittance");
    CHECK_DOUBLE(cJSON_GetArrayItem(get(json, "transmittance"), 2)->valuedouble, 0.125);
    CHECK(get(json, "luminance") == NULL);
    CHECK(get(json, "multiple_scattering") == NULL); /* transmittance has none */
    cJSON_Delete(json);
    result.quantity = PROTO_PROBE_LUMINANCE;
    json = parse_built(proto_msg_build_probe_result(NULL, &result), "probe_result");
    CHECK_INT(cJSON_GetArraySize(get(json, "luminance")), 3);
    CHECK_STR(string_at(json, "multiple_scattering"), "fast");
    cJSON_Delete(json);
    result.quantity = PROTO_PROBE_ILLUMINANCE;
    result.sun_lux = 120014;
    result.sky_lux = 15000.5;
    json = parse_built(proto_msg_build_probe_result(NULL, &result), "probe_result");
    CHECK_DOUBLE(number_at(json, "sun_lux"), 120014);
    CHECK_DOUBLE(number_at(json, "sky_lux"), 15000.5);
    cJSON_Delete(json);
    result.sky_lux = INFINITY;
    CHECK(proto_msg_build_probe_result(NULL, &result) == NULL);
    result.quantity = PROTO_PROBE_LUMINANCE;
    result.rgb[1] = NAN;
    CHECK(proto_msg_build_probe_result(NULL, &result) == NULL);
    result.quantity = (enum proto_probe_quantity)5;
    CHECK(proto_msg_build_probe_result(NULL, &result) == NULL);

    check_case_name = "stats";
    struct proto_msg_pass_time passes[] = { { "skyview", 0.5 }, { "composite", 1.25 } };
    struct proto_msg_subscription_stats subs[] = { { 2, 1000, 10, 0, 0 },
                                                   { 3, 4096, 2.5, 55, 80 } };
    struct proto_msg_multiple_scattering ms = { 0.25, 0.5, 3 };
    enum proto_cloud_resolution traced = PROTO_CLOUD_RESOLUTION_QUARTER;
    struct proto_msg_stats stats = {
        .fps = 30,
        .clients = 2,
        .passes = passes,
        .pass_count = 2,
        .lut_rebuild_progress = 0.5,
        .simulation_time_s = 1782043200.25,
        .subscriptions = subs,
        .subscription_count = 2,
        .multiple_scattering = &ms,
        .cloud_resolution = &traced,
        .cloud_primary_steps = 128,
    };
    json = parse_built(proto_msg_build_stats(NULL, &stats), "stats");
    const cJSON *sub_items = get(json, "subscriptions");
    CHECK_INT(cJSON_GetArraySize(sub_items), 2);
    const cJSON *png_sub = cJSON_GetArrayItem(sub_items, 0);
    const cJSON *jpeg_sub = cJSON_GetArrayItem(sub_items, 1);
    CHECK_DOUBLE(number_at(png_sub, "bytes_sent"), 1000);
    CHECK(get(png_sub, "quality") == NULL && get(png_sub, "max_kbps") == NULL);
    CHECK_DOUBLE(number_at(jpeg_sub, "subscription"), 3);
    CHECK_DOUBLE(number_at(jpeg_sub, "fps"), 2.5);
    CHECK_DOUBLE(number_at(jpeg_sub, "quality"), 55);
    CHECK_DOUBLE(number_at(jpeg_sub, "max_kbps"), 80);
    CHECK_DOUBLE(number_at(json, "simulation_time_s"), 1782043200.25);
    CHECK_DOUBLE(number_at(json, "fps"), 30);
    CHECK_DOUBLE(number_at(json, "clients"), 2);
    CHECK_DOUBLE(number_at(get(json, "passes"), "composite"), 1.25);
    CHECK_DOUBLE(number_at(json, "lut_rebuild_progress"), 0.5);
    CHECK_DOUBLE(number_at(get(json, "multiple_scattering"), "weight"), 0.25);
    CHECK_DOUBLE(number_at(get(json, "multiple_scattering"), "progress"), 0.5);
    CHECK_DOUBLE(number_at(get(json, "multiple_scattering"), "order"), 3);
    CHECK(cJSON_IsString(get(json, "cloud_resolution")) &&
          strcmp(get(json, "cloud_resolution")->valuestring, "quarter") == 0);
    CHECK_DOUBLE(number_at(json, "cloud_primary_steps"), 128);
    cJSON_Delete(json);
    /* "auto" is asked for, never traced at: a frame's level is one of the four */
    traced = PROTO_CLOUD_RESOLUTION_AUTO;
    CHECK(proto_msg_build_stats(NULL, &stats) == NULL);
    stats.cloud_resolution = NULL;
    stats.cloud_primary_steps = 0;
    json = parse_built(proto_msg_build_stats(NULL, &stats), "stats");
    CHECK(get(json, "cloud_resolution") == NULL && get(json, "cloud_primary_steps") == NULL);
    cJSON_Delete(json);
    stats.cloud_resolution = &traced;
    traced = PROTO_CLOUD_RESOLUTION_FULL;
    ms.weight = 1.5;
    CHECK(proto_msg_build_stats(NULL, &stats) == NULL);
    ms.weight = 1;
    stats.lut_rebuild_progress = 1.5;
    CHECK(proto_msg_build_stats(NULL, &stats) == NULL);
    stats.lut_rebuild_progress = NAN;
    CHECK(proto_msg_build_stats(NULL, &stats) == NULL);
    stats.lut_rebuild_progress = 1;
    stats.simulation_time_s = INFINITY;
    CHECK(proto_msg_build_stats(NULL, &stats) == NULL);
    stats.simulation_time_s = 0;
    passes[1].name = "skyview";
    CHECK(proto_msg_build_stats(NULL, &stats) == NULL);
    passes[1].name = "composite";
    passes[1].ms = -1;
    CHECK(proto_msg_build_stats(NULL, &stats) == NULL);
    passes[1].ms = 1;
    subs[1].fps = 0;
    CHECK(proto_msg_build_stats(NULL, &stats) == NULL);
    subs[1].fps = 1;
    stats.fps = INFINITY;
    CHECK(proto_msg_build_stats(NULL, &stats) == NULL);
    check_case_name = "";
}

/* ---- frame header ----------------------------------------------------------------------- */

void test_frame_header(void)
{
    check_case_name = "frame header layout";
    struct proto_frame_header header = {
        .format = PROTO_FRAME_FORMAT_PNG,
        .frame_number = 0x0102030405060708ULL,
        .state_revision = 0x1112131415161718ULL,
        .simulation_time_s = 1.5, /* 0x3FF8000000000000 */
        .width = 640,
        .height = 360,
        .payload_length = 1000,
    };
    static const uint8_t expected[PROTO_FRAME_HEADER_SIZE] = {
        'S',  'K',  'Y',  'F',  0x01, 0x00, 0x01, 0x00, /* magic, version, format */
        0x08, 0x07, 0x06, 0x05, 0x04, 0x03, 0x02, 0x01, /* frame_number */
        0x18, 0x17, 0x16, 0x15, 0x14, 0x13, 0x12, 0x11, /* state_revision */
        0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0xF8, 0x3F, /* simulation_time_s */
        0x80, 0x02, 0x00, 0x00, 0x68, 0x01, 0x00, 0x00, /* width, height */
        0xE8, 0x03, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, /* payload_length, reserved */
    };
    uint8_t message[PROTO_FRAME_HEADER_SIZE + 1000];
    memset(message, 0xAB, sizeof message);
    CHECK_INT(proto_frame_header_pack(&header, message), PROTO_FRAME_HEADER_OK);
    for (int i = 0; i < PROTO_FRAME_HEADER_SIZE; i++) {
        if (message[i] != expected[i]) {
            CHECK_INT(i, -1);
            printf("    byte %d: 0x%02X, expected 0x%02X\n", i, message[i], expected[i]);
        }
    }
    CHECK_INT(message[PROTO_FRAME_HEADER_SIZE], 0xAB);

    check_case_name = "frame header round trip";
    struct proto_frame_header read;
    memset(&read, 0, sizeof read);
    CHECK_INT(proto_frame_header_unpack(message, sizeof message, &read), PROTO_FRAME_HEADER_OK);
    CHECK_INT(read.format, PROTO_FRAME_FORMAT_PNG);
    CHECK(read.frame_number == header.frame_number);
    CHECK(read.state_revision == header.state_revision);
    CHECK_DOUBLE(read.simulation_time_s, 1.5);
    CHECK_INT(read.width, 640);
    CHECK_INT(read.height, 360);
    CHECK_INT(read.payload_length, 1000);
    struct proto_frame_header extreme = {
        PROTO_FRAME_FORMAT_PNG, UINT64_MAX, UINT64_MAX - 1, -12345.678901234567, UINT32_MAX, 1, 0
    };
    uint8_t bare[PROTO_FRAME_HEADER_SIZE];
    CHECK_INT(proto_frame_header_pack(&extreme, bare), PROTO_FRAME_HEADER_OK);
    CHECK_INT(proto_frame_header_unpack(bare, sizeof bare, &read), PROTO_FRAME_HEADER_OK);
    CHECK(read.frame_number == UINT64_MAX && read.state_revision == UINT64_MAX - 1);
    CHECK_DOUBLE(read.simulation_time_s, -12345.678901234567);
    CHECK_INT(read.width, UINT32_MAX);
    CHECK_INT(read.payload_length, 0);

    static const struct {
        const char *name;
        int offset; /* byte to change, or -1 */
        uint8_t value;
        size_t length; /* message length given to unpack */
        enum proto_frame_header_status status;
    } rejections[] = {
        { "too short", -1, 0, PROTO_FRAME_HEADER_SIZE - 1, PROTO_FRAME_HEADER_TOO_SHORT },
        { "empty", -1, 0, 0, PROTO_FRAME_HEADER_TOO_SHORT },
        { "bad magic", 0, 's', sizeof message, PROTO_FRAME_HEADER_BAD_MAGIC },
        { "bad magic end", 3, 'G', sizeof message, PROTO_FRAME_HEADER_BAD_MAGIC },
        { "version 2", 4, 2, sizeof message, PROTO_FRAME_HEADER_BAD_VERSION },
        { "version 0x101", 5, 1, sizeof message, PROTO_FRAME_HEADER_BAD_VERSION },
        { "format 0", 6, 0, sizeof message, PROTO_FRAME_HEADER_BAD_FORMAT },
        { "format 4", 6, 4, sizeof message, PROTO_FRAME_HEADER_BAD_FORMAT },
        { "format 0x101", 7, 1, sizeof message, PROTO_FRAME_HEADER_BAD_FORMAT },
        { "payload short by one", -1, 0, sizeof message - 1, PROTO_FRAME_HEADER_BAD_LENGTH },
        { "payload long by one", 40, 0xE7, sizeof message, PROTO_FRAME_HEADER_BAD_LENGTH },
        { "payload length high byte", 43, 1, sizeof message, PROTO_FRAME_HEADER_BAD_LENGTH },
        { "header only", -1, 0, PROTO_FRAME_HEADER_SIZE, PROTO_FRAME_HEADER_BAD_LENGTH },
        { "reserved", 47, 1, sizeof message, PROTO_FRAME_HEADER_BAD_RESERVED },
        { "zero width", 32, 0, sizeof message, PROTO_FRAME_HEADER_BAD_VALUE },
        { "NaN time", 30, 0xFF, sizeof message, PROTO_FRAME_HEADER_BAD_VALUE },
    };
    for (size_t i = 0; i < COUNT_OF(rejections); i++) {
        check_case_name = rejections[i].name;
        uint8_t copy[sizeof message];
        memcpy(copy, message, sizeof copy);
        if (rejections[i].offset >= 0)
            copy[rejections[i].offset] = rejections[i].value;
        if (rejections[i].offset == 30) /* exponent all ones with a non-zero mantissa */
            copy[31] = 0x7F;
        if (rejections[i].offset == 32) /* 640 is 0x0280 */
            copy[33] = 0;
        struct proto_frame_header untouched = header;
        enum proto_frame_header_status status =
            proto_frame_header_unpack(copy, rejections[i].length, &untouched);
        CHECK_STR(proto_frame_header_status_name(status),
                  proto_frame_header_status_name(rejections[i].status));
        CHECK(memcmp(&untouched, &header, sizeof header) == 0);
    }
    check_case_name = "frame header format png16";
    uint8_t png16[sizeof message];
    memcpy(png16, message, sizeof png16);
    png16[6] = PROTO_FRAME_FORMAT_PNG16;
    struct proto_frame_header read16;
    CHECK_INT(proto_frame_header_unpack(png16, sizeof png16, &read16), PROTO_FRAME_HEADER_OK);
    CHECK_INT(read16.format, PROTO_FRAME_FORMAT_PNG16);
    check_case_name = "frame header format jpeg";
    png16[6] = PROTO_FRAME_FORMAT_JPEG;
    CHECK_INT(proto_frame_header_unpack(png16, sizeof png16, &read16), PROTO_FRAME_HEADER_OK);
    CHECK_INT(read16.format, PROTO_FRAME_FORMAT_JPEG);
    png16[6] = 4;
    CHECK_INT(proto_frame_header_unpack(png16, sizeof png16, &read16),
              PROTO_FRAME_HEADER_BAD_FORMAT);

    check_case_name = "frame header pack rejections";
    CHECK_INT(proto_frame_header_unpack(NULL, 100, NULL), PROTO_FRAME_HEADER_TOO_SHORT);
    struct proto_frame_header bad = header;
    bad.simulation_time_s = NAN;
    CHECK_INT(proto_frame_header_pack(&bad, bare), PROTO_FRAME_HEADER_BAD_VALUE);
    bad = header;
    bad.format = (enum proto_frame_format)7;
    CHECK_INT(proto_frame_header_pack(&bad, bare), PROTO_FRAME_HEADER_BAD_FORMAT);
    bad = header;
    bad.height = 0;
    CHECK_INT(proto_frame_header_pack(&bad, bare), PROTO_FRAME_HEADER_BAD_VALUE);
    CHECK_STR(proto_frame_header_status_name(PROTO_FRAME_HEADER_BAD_LENGTH), "bad_length");
    CHECK(proto_frame_header_status_name(8) == NULL);
    check_case_name = "";
}
