/* The client messages' JSON Schema (protocol/message_schema_json.c) against the parser it is
 * generated beside: every client example of PROTOCOL.md parses and conforms; messages the
 * parser refuses and the schema can express, it refuses too; the view's limits are the
 * server's. Part of test_world_schema (shares its validator, schema_validator.c). */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cjson/cJSON.h>

#include "check.h"
#include "field_schema.h"
#include "messages.h"
#include "schema_validator.h"
#include "test_message_schema.h"
#include "text_file.h"

static bool parses(const char *text)
{
    struct proto_msg_limits limits;
    proto_msg_limits_default(&limits);
    struct proto_client_msg msg;
    struct proto_msg_parse_error error;
    enum proto_msg_error_code code = proto_msg_parse(text, strlen(text), &limits, &msg, &error);
    proto_client_msg_free(&msg);
    return code == PROTO_MSG_OK;
}

static bool conforms_text(const cJSON *schema, const char *text)
{
    cJSON *json = cJSON_Parse(text);
    bool ok = json && schema_conforms(schema, schema, json);
    cJSON_Delete(json);
    return ok;
}

/* Every "```json client" block of PROTOCOL.md. */
static void test_documented_examples(const cJSON *schema, const char *protocol_md)
{
    char *doc = text_file_read(protocol_md, 1 << 22, &(size_t){ 0 });
    check_case_name = protocol_md;
    CHECK(doc != NULL);
    const char *fence = "```json client\n";
    int count = 0;
    for (const char *at = doc ? strstr(doc, fence) : NULL; at; at = strstr(at, fence)) {
        at += strlen(fence);
        const char *end = strstr(at, "```");
        if (!end)
            break;
        char *block = strndup(at, (size_t)(end - at));
        check_case_name = block;
        CHECK(parses(block));
        CHECK(conforms_text(schema, block));
        free(block);
        count++;
        at = end;
    }
    check_case_name = "PROTOCOL.md client examples";
    CHECK(count >= 17);
    free(doc);
}

/* Messages both accept, beyond the documented ones. */
static const char *const accepted[] = {
    "{\"type\":\"hello\",\"client\":\"\"}",
    "{\"type\":\"stats\",\"id\":9007199254740991}",
    "{\"type\":\"stats\",\"id\":\"x\"}",
    "{\"type\":\"snapshot\",\"id\":1,\"view\":{\"width\":3840,\"height\":2160,\"fps\":60,"
    "\"camera\":"
    "{\"altitude_km\":100000,\"yaw_deg\":-360,\"pitch_deg\":90,\"fov_deg\":170},\"exposure\":"
    "{\"mode\":\"auto\",\"ev100\":-10,\"compensation_ev\":10}}}",
    "{\"type\":\"probe\",\"quantity\":\"transmittance\",\"altitude_km\":0,\"mu\":-1}",
    /* A 1 x 1 RGBA PNG. */
    "{\"type\":\"set_weather_map\",\"format\":\"png\",\"data\":\"iVBORw0KGgoAAAANSUhEUgAAAAEAAAAB"
    "CAYAAAAfFcSJAAAADUlEQVR4nGMQUDBwAAABRQChUYYmTwAAAABJRU5ErkJggg==\"}",
    "{\"type\":\"apply_preset\",\"kind\":\"weather\",\"name\":\"storm\",\"transition_s\":0}",
    "{\"type\":\"set\",\"patch\":{\"atmosphere\":{\"ground_albedo\":0.2}}}",
    "{\"type\":\"subscribe\",\"view\":{\"width\":1,\"height\":1,\"format\":\"jpeg\","
    "\"quality\":100,\"max_kbps\":1000000}}",
    "{\"type\":\"snapshot\",\"id\":1,\"view\":{\"width\":1,\"height\":1,\"format\":\"jpeg\","
    "\"quality\":1,\"max_kbps\":0.5}}",
};

/* Messages both refuse: each breaks one rule that a row, or the schema's own members, says. */
static const char *const refused[] = {
    "{}",
    "{\"type\":\"bogus\"}",
    "{\"type\":\"stats\",\"extra\":1}",
    "{\"type\":\"stats\",\"id\":1.5}",
    "{\"type\":\"stats\",\"id\":9007199254740992}",
    "{\"type\":\"stats\",\"id\":\"\"}",
    "{\"type\":\"hello\",\"client\":1}",
    "{\"type\":\"hello\",\"protocol\":0}",
    "{\"type\":\"auth\"}",
    "{\"type\":\"auth\",\"token\":\"\"}",
    "{\"type\":\"set\"}",
    "{\"type\":\"set\",\"patch\":{\"sun\":{\"elevation_deg\":95}}}",
    "{\"type\":\"set\",\"patch\":{\"atmosphere\":{\"bogus\":1}}}",
    "{\"type\":\"set\",\"patch\":{\"revision\":3}}",
    "{\"type\":\"subscribe\"}",
    /* a snapshot's frame is told from a subscription's by the request's id */
    "{\"type\":\"snapshot\",\"view\":{\"width\":2,\"height\":2}}",
    "{\"type\":\"subscribe\",\"view\":{\"height\":10}}",
    "{\"type\":\"subscribe\",\"view\":{\"width\":3841,\"height\":10}}",
    "{\"type\":\"subscribe\",\"view\":{\"width\":1,\"height\":1,\"fps\":0}}",
    "{\"type\":\"subscribe\",\"view\":{\"width\":1,\"height\":1,\"fps\":61}}",
    "{\"type\":\"subscribe\",\"view\":{\"width\":1.5,\"height\":1}}",
    "{\"type\":\"subscribe\",\"view\":{\"width\":1,\"height\":1,\"format\":\"gif\"}}",
    "{\"type\":\"subscribe\",\"view\":{\"width\":1,\"height\":1,\"format\":\"jpeg\","
    "\"quality\":0}}",
    "{\"type\":\"subscribe\",\"view\":{\"width\":1,\"height\":1,\"format\":\"jpeg\","
    "\"quality\":101}}",
    "{\"type\":\"subscribe\",\"view\":{\"width\":1,\"height\":1,\"max_kbps\":0}}",
    "{\"type\":\"subscribe\",\"view\":{\"width\":1,\"height\":1,\"max_kbps\":-5}}",
    "{\"type\":\"subscribe\",\"view\":{\"width\":1,\"height\":1,\"camera\":{\"fov_deg\":0.5}}}",
    "{\"type\":\"subscribe\",\"view\":{\"width\":1,\"height\":1,\"camera\":{\"zoom\":2}}}",
    "{\"type\":\"subscribe\",\"view\":{\"width\":1,\"height\":1,\"exposure\":"
    "{\"tonemap\":\"aces\"}}}",
    "{\"type\":\"unsubscribe\",\"subscription\":0}",
    "{\"type\":\"unsubscribe\"}",
    "{\"type\":\"probe\",\"quantity\":\"transmittance\",\"altitude_km\":0}",
    "{\"type\":\"probe\",\"quantity\":\"illuminance\",\"sun_zenith_deg\":0,\"mu\":0.5}",
    "{\"type\":\"probe\",\"quantity\":\"radiance\"}",
    "{\"type\":\"probe\",\"quantity\":\"luminance\",\"altitude_km\":0,\"view_zenith_deg\":181,"
    "\"view_azimuth_deg\":0,\"sun_zenith_deg\":0}",
    "{\"type\":\"list_presets\"}",
    "{\"type\":\"list_presets\",\"kind\":\"atmosphere\",\"name\":\"x\"}",
    "{\"type\":\"apply_preset\",\"kind\":\"atmosphere\",\"name\":\"Mars\"}",
    "{\"type\":\"apply_preset\",\"kind\":\"atmosphere\",\"name\":\"mars\",\"transition_s\":60}",
    "{\"type\":\"apply_preset\",\"kind\":\"weather\",\"name\":\"storm\",\"transition_s\":604801}",
    "{\"type\":\"set_weather_map\",\"format\":\"rgba8\",\"data\":\"AAAA\"}",
    "{\"type\":\"set_weather_map\",\"format\":\"gif\",\"data\":\"AAAA\"}",
    "{\"type\":\"set_weather_map\",\"format\":\"png\",\"width\":513,\"data\":\"AAAA\"}",
};

static void test_agreement(const cJSON *schema)
{
    for (size_t i = 0; i < sizeof accepted / sizeof accepted[0]; i++) {
        check_case_name = accepted[i];
        CHECK(parses(accepted[i]));
        CHECK(conforms_text(schema, accepted[i]));
    }
    for (size_t i = 0; i < sizeof refused / sizeof refused[0]; i++) {
        check_case_name = refused[i];
        CHECK(!parses(refused[i]));
        CHECK(!conforms_text(schema, refused[i]));
    }
    check_case_name = "";
}

static const cJSON *at(const cJSON *node, const char *path)
{
    char copy[256];
    snprintf(copy, sizeof copy, "%s", path);
    for (char *name = strtok(copy, "/"); name && node; name = strtok(NULL, "/"))
        node = cJSON_GetObjectItemCaseSensitive(node, name);
    return node;
}

static void test_shape(const cJSON *schema)
{
    check_case_name = "messages schema shape";
    CHECK_STR(cJSON_GetStringValue(at(schema, "$schema")),
              "https://json-schema.org/draft/2020-12/schema");
    const cJSON *options = at(schema, "oneOf");
    int types = 0;
    for (int t = PROTO_MSG_HELLO; proto_msg_type_name((enum proto_msg_type)t); t++, types++) {
        char path[96];
        snprintf(path, sizeof path, "$defs/%s", proto_msg_type_name((enum proto_msg_type)t));
        check_case_name = path;
        CHECK(at(schema, path) != NULL);
    }
    CHECK_INT(cJSON_GetArraySize(options), types);
    check_case_name = "view ranges from the world state's rows";
    const struct proto_field_desc *fov = proto_world_state_find_field("camera.fov_deg");
    CHECK(cJSON_GetNumberValue(at(schema, "$defs/view/properties/camera/properties/fov_deg/"
                                          "minimum")) == fov->min);
    CHECK_STR(cJSON_GetStringValue(at(schema, "$defs/view/properties/camera/properties/fov_deg/"
                                              "description")),
              fov->description);
    check_case_name = "";
}

/* The view's maxima are the limits the schema is made for. */
static void test_limits(void)
{
    check_case_name = "limits";
    struct proto_msg_limits limits;
    proto_msg_limits_default(&limits);
    limits.max_width = 640;
    limits.max_fps = 5;
    cJSON *schema = proto_msg_json_schema(&limits);
    CHECK(cJSON_GetNumberValue(at(schema, "$defs/view/properties/width/maximum")) == 640);
    CHECK(cJSON_GetNumberValue(at(schema, "$defs/view/properties/fps/maximum")) == 5);
    CHECK(cJSON_GetNumberValue(at(schema, "$defs/view/properties/fps/default")) == 5);
    CHECK(!conforms_text(schema,
                         "{\"type\":\"snapshot\",\"id\":1,\"view\":{\"width\":641,\"height\":1}}"));
    cJSON_Delete(schema);
    check_case_name = "";
}

void test_message_schema(const char *protocol_md)
{
    struct proto_msg_limits limits;
    proto_msg_limits_default(&limits);
    cJSON *schema = proto_msg_json_schema(&limits);
    CHECK(schema != NULL);
    if (!schema)
        return;
    test_shape(schema);
    test_documented_examples(schema, protocol_md);
    test_agreement(schema);
    test_limits();
    cJSON_Delete(schema);
}
