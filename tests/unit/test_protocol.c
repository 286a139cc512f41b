/* Unit tests for the WebSocket protocol messages (protocol/messages.c) and the binary frame
 * header (protocol/frame_header.c). No sockets.
 *
 * Usage: test_protocol [PROTOCOL_MD]
 * PROTOCOL_MD defaults to protocol/PROTOCOL.md next to this file's directory; every JSON
 * example in it is checked against the tables below, so the document cannot drift.
 */
#include "frame_header.h"
#include "messages.h"
#include "world_state.h"

#include <cjson/cJSON.h>

#include <math.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"

#define COUNT_OF(array) (sizeof(array) / sizeof((array)[0]))

/* ---- helpers ---------------------------------------------------------------------------- */

static struct sky_msg_limits test_limits(void)
{
    struct sky_msg_limits limits;
    sky_msg_limits_default(&limits);
    limits.max_message_bytes = 1024;
    return limits;
}

static enum sky_msg_error_code parse_with(const char *text, size_t length,
                                          const struct sky_msg_limits *limits,
                                          struct sky_client_msg *msg,
                                          struct sky_msg_parse_error *error)
{
    return sky_msg_parse(text, length, limits, msg, error);
}

static enum sky_msg_error_code parse(const char *text, struct sky_client_msg *msg,
                                     struct sky_msg_parse_error *error)
{
    struct sky_msg_limits limits = test_limits();
    return parse_with(text, strlen(text), &limits, msg, error);
}

static const char *first_pointer(const struct sky_msg_parse_error *error)
{
    return error->fields.count > 0 ? error->fields.items[0].pointer : "(none)";
}

/* Parses a builder's output, which must be a JSON object of the given type; frees `text`. */
static cJSON *parse_built(char *text, const char *type)
{
    CHECK(text != NULL);
    if (!text)
        return NULL;
    cJSON *json = cJSON_Parse(text);
    free(text);
    CHECK(cJSON_IsObject(json));
    const cJSON *member = cJSON_GetObjectItemCaseSensitive(json, "type");
    CHECK_STR(cJSON_IsString(member) ? member->valuestring : NULL, type);
    return json;
}

static const cJSON *get(const cJSON *object, const char *name)
{
    return cJSON_GetObjectItemCaseSensitive(object, name);
}

static double number_at(const cJSON *object, const char *name)
{
    const cJSON *member = get(object, name);
    return cJSON_IsNumber(member) ? member->valuedouble : NAN;
}

static const char *string_at(const cJSON *object, const char *name)
{
    const cJSON *member = get(object, name);
    return cJSON_IsString(member) ? member->valuestring : NULL;
}

static char *repeat(char c, size_t count)
{
    char *text = malloc(count + 1);
    memset(text, c, count);
    text[count] = '\0';
    return text;
}

/* ---- the documented examples (also in protocol/PROTOCOL.md, in this order) -------------- */

static const struct {
    const char *text;
    enum sky_msg_type type;
} client_examples[] = {
    {"{\"type\":\"hello\",\"id\":1,\"client\":\"sky-web 0.1\",\"protocol\":1}", SKY_MSG_HELLO},
    {"{\"type\":\"auth\",\"id\":2,\"token\":\"s3cret-token\"}", SKY_MSG_AUTH},
    {"{\"type\":\"get_state\",\"id\":3}", SKY_MSG_GET_STATE},
    {"{\"type\":\"set\",\"id\":4,\"patch\":{\"sun\":{\"elevation_deg\":2,\"azimuth_deg\":250},"
     "\"atmosphere\":{\"mie\":{\"g\":0.76}}}}",
     SKY_MSG_SET},
    {"{\"type\":\"subscribe\",\"id\":\"main-view\",\"view\":{\"camera\":{\"yaw_deg\":200,"
     "\"fov_deg\":60},\"width\":1280,\"height\":720,\"fps\":30,\"exposure\":{\"mode\":"
     "\"manual\",\"ev100\":12},\"format\":\"png\"}}",
     SKY_MSG_SUBSCRIBE},
    {"{\"type\":\"unsubscribe\",\"id\":6,\"subscription\":1}", SKY_MSG_UNSUBSCRIBE},
    {"{\"type\":\"snapshot\",\"id\":7,\"view\":{\"width\":640,\"height\":360}}", SKY_MSG_SNAPSHOT},
    {"{\"type\":\"probe\",\"id\":8,\"quantity\":\"transmittance\",\"altitude_km\":0,\"mu\":0.5}",
     SKY_MSG_PROBE},
    {"{\"type\":\"probe\",\"id\":9,\"quantity\":\"luminance\",\"altitude_km\":0,"
     "\"view_zenith_deg\":45,\"view_azimuth_deg\":90,\"sun_zenith_deg\":30}",
     SKY_MSG_PROBE},
    {"{\"type\":\"probe\",\"id\":10,\"quantity\":\"illuminance\",\"sun_zenith_deg\":0}",
     SKY_MSG_PROBE},
    {"{\"type\":\"list_presets\",\"id\":11,\"kind\":\"atmosphere\"}", SKY_MSG_LIST_PRESETS},
    {"{\"type\":\"apply_preset\",\"id\":12,\"kind\":\"atmosphere\",\"name\":\"mars\"}",
     SKY_MSG_APPLY_PRESET},
    {"{\"type\":\"list_presets\",\"id\":14,\"kind\":\"weather\"}", SKY_MSG_LIST_PRESETS},
    {"{\"type\":\"apply_preset\",\"id\":15,\"kind\":\"weather\",\"name\":\"storm\","
     "\"transition_s\":1200}",
     SKY_MSG_APPLY_PRESET},
    {"{\"type\":\"stats\",\"id\":13}", SKY_MSG_STATS},
    {"{\"type\":\"set_weather_map\",\"id\":16,\"format\":\"rgba8\",\"width\":2,\"height\":1,"
     "\"data\":\"/wCgAIBAoCg=\"}",
     SKY_MSG_SET_WEATHER_MAP},
    {"{\"type\":\"snapshot\",\"id\":17,\"view\":{\"width\":1024,\"height\":512,"
     "\"projection\":\"equirectangular\",\"format\":\"png16\"}}",
     SKY_MSG_SNAPSHOT},
};

static struct sky_msg_id int_id(int64_t number)
{
    struct sky_msg_id id = {.kind = SKY_MSG_ID_INTEGER, .number = number};
    return id;
}

static struct sky_msg_id string_id(const char *text)
{
    struct sky_msg_id id = {.kind = SKY_MSG_ID_STRING};
    snprintf(id.text, sizeof id.text, "%s", text);
    return id;
}

/* The server examples of PROTOCOL.md, in its order, produced by the builders. */
static size_t build_server_examples(char **out, size_t max)
{
    size_t n = 0;
    struct sky_msg_limits limits;
    sky_msg_limits_default(&limits);
    size_t capability_count;
    const char *const *caps = sky_msg_default_capabilities(&capability_count);
    struct sky_world_state state;
    sky_world_state_defaults(&state);
    state.revision = 5;
    struct sky_msg_id id2 = int_id(2), id3 = int_id(3), id4 = int_id(4), id7 = int_id(7);
    struct sky_msg_id id8 = int_id(8), id9 = int_id(9), id10 = int_id(10), id11 = int_id(11);
    struct sky_msg_id id13 = int_id(13);

#define ADD(expression)          \
    do {                         \
        if (n < max)             \
            out[n] = expression; \
        n++;                     \
    } while (0)

    ADD(sky_msg_build_hello("0.1.0", SKY_ROLE_VIEWER, caps, capability_count, &limits));
    ADD(sky_msg_build_state(&id3, &state));
    ADD(sky_msg_build_ack(&id4, 6, SKY_ROLE_NONE));
    ADD(sky_msg_build_ack(&id2, 5, SKY_ROLE_CONTROLLER));

    struct sky_client_msg msg;
    struct sky_msg_parse_error error;
    parse("{\"type\":\"set\",\"id\":4,\"patch\":{\"atmosphere\":{\"bogus\":1}}}", &msg, &error);
    ADD(sky_msg_build_parse_error(&msg, &error));
    sky_client_msg_free(&msg);
    ADD(sky_msg_build_error(&id4, SKY_MSG_ERR_FORBIDDEN, "set needs the controller role", NULL));

    parse(client_examples[4].text, &msg, &error);
    ADD(sky_msg_build_subscribed(&msg.id, 1, &msg.view));
    sky_client_msg_free(&msg);
    ADD(sky_msg_build_frame(NULL, 1, 42));
    ADD(sky_msg_build_frame(&id7, 0, 43));

    struct sky_world_state after = state;
    parse(client_examples[3].text, &msg, &error);
    sky_world_state_apply_json(&after, msg.set.patch, NULL);
    sky_client_msg_free(&msg);
    after.revision = 6;
    char changed[8][SKY_MSG_POINTER_MAX];
    size_t changed_count = sky_msg_state_diff(&state, &after, changed, 8);
    const char *pointers[8];
    for (size_t i = 0; i < changed_count && i < 8; i++)
        pointers[i] = changed[i];
    ADD(sky_msg_build_state_changed(after.revision, pointers, changed_count));

    const char *presets[] = {"earth", "mars"};
    ADD(sky_msg_build_presets(&id11, SKY_PRESET_ATMOSPHERE, presets, 2));
    struct sky_msg_probe_result t = {SKY_PROBE_TRANSMITTANCE, {0.8, 0.67, 0.46}, 0, 0};
    struct sky_msg_probe_result l = {SKY_PROBE_LUMINANCE, {3200, 4100, 6900}, 0, 0};
    struct sky_msg_probe_result e = {SKY_PROBE_ILLUMINANCE, {0, 0, 0}, 120014, 18700};
    ADD(sky_msg_build_probe_result(&id8, &t));
    ADD(sky_msg_build_probe_result(&id9, &l));
    ADD(sky_msg_build_probe_result(&id10, &e));
    const struct sky_msg_pass_time passes[] = {
        {"skyview", 0.42}, {"aerial_perspective", 0.31}, {"composite", 1.9}, {"sun_disk", 0.05}};
    struct sky_msg_stats stats = {29.8, 3, passes, COUNT_OF(passes), 1, 1782043200};
    ADD(sky_msg_build_stats(&id13, &stats));
#undef ADD
    return n;
}

/* ---- parse table ------------------------------------------------------------------------ */

struct parse_case {
    const char *name;
    const char *text;
    enum sky_msg_error_code code;
    enum sky_msg_type type;  /* checked when not SKY_MSG_NONE */
    const char *pointer;     /* first field error's pointer; checked when not NULL */
};

#define OK(name, text, type) {name, text, SKY_MSG_OK, type, NULL}
#define BAD(name, text, code, pointer) {name, text, SKY_MSG_ERR_##code, SKY_MSG_NONE, pointer}

static const struct parse_case parse_cases[] = {
    OK("hello empty", "{\"type\":\"hello\"}", SKY_MSG_HELLO),
    OK("whitespace around", " \t\r\n{ \"type\" : \"stats\" }\n ", SKY_MSG_STATS),
    OK("string id", "{\"type\":\"get_state\",\"id\":\"r-1\"}", SKY_MSG_GET_STATE),
    OK("max integer id", "{\"type\":\"stats\",\"id\":9007199254740991}", SKY_MSG_STATS),
    OK("min integer id", "{\"type\":\"stats\",\"id\":-9007199254740991}", SKY_MSG_STATS),
    OK("64-byte id", "{\"type\":\"stats\",\"id\":\"" "0123456789012345678901234567890123456789"
       "012345678901234567890123\"}", SKY_MSG_STATS),
    OK("utf-8 client", "{\"type\":\"hello\",\"client\":\"h\xc3\xa9llo \xe2\x98\x80 \xf0\x9f\x8c\x85\"}",
       SKY_MSG_HELLO),
    OK("escaped slash and unicode", "{\"type\":\"hello\",\"client\":\"a\\/b\\u00e9\"}", SKY_MSG_HELLO),
    OK("inconsistent patch deferred", "{\"type\":\"set\",\"patch\":{\"atmosphere\":"
       "{\"bottom_radius_km\":7000}}}", SKY_MSG_SET),
    OK("empty patch", "{\"type\":\"set\",\"patch\":{}}", SKY_MSG_SET),
    OK("rgb patch", "{\"type\":\"set\",\"patch\":{\"atmosphere\":{\"ground_albedo\":[0.1,0.2,0.3]}}}",
       SKY_MSG_SET),
    OK("view at limits", "{\"type\":\"snapshot\",\"view\":{\"width\":3840,\"height\":2160,"
       "\"fps\":60,\"camera\":{\"altitude_km\":100000,\"yaw_deg\":-360,\"pitch_deg\":90,"
       "\"fov_deg\":170},\"exposure\":{\"mode\":\"auto\",\"ev100\":-10,\"compensation_ev\":10}}}",
       SKY_MSG_SNAPSHOT),
    OK("view minimum", "{\"type\":\"subscribe\",\"view\":{\"width\":1,\"height\":1,\"fps\":0.5,"
       "\"camera\":{},\"exposure\":{}}}", SKY_MSG_SUBSCRIBE),
    OK("probe at range ends", "{\"type\":\"probe\",\"quantity\":\"luminance\",\"altitude_km\":100000,"
       "\"view_zenith_deg\":180,\"view_azimuth_deg\":-360,\"sun_zenith_deg\":0}", SKY_MSG_PROBE),
    OK("probe mu -1", "{\"type\":\"probe\",\"quantity\":\"transmittance\",\"altitude_km\":0,"
       "\"mu\":-1}", SKY_MSG_PROBE),
    OK("preset name charset", "{\"type\":\"apply_preset\",\"kind\":\"atmosphere\","
       "\"name\":\"a-z_0-9\"}", SKY_MSG_APPLY_PRESET),

    BAD("empty message", "", MALFORMED_JSON, ""),
    BAD("blank message", "   ", MALFORMED_JSON, ""),
    BAD("unterminated object", "{\"type\":\"stats\"", MALFORMED_JSON, ""),
    BAD("trailing garbage", "{\"type\":\"stats\"} x", MALFORMED_JSON, ""),
    BAD("two objects", "{\"type\":\"stats\"}{\"type\":\"stats\"}", MALFORMED_JSON, ""),
    BAD("single quotes", "{'type':'stats'}", MALFORMED_JSON, ""),
    BAD("trailing comma", "{\"type\":\"stats\",}", MALFORMED_JSON, ""),
    BAD("lone surrogate escape", "{\"type\":\"hello\",\"client\":\"\\ud800\"}", MALFORMED_JSON, ""),
    BAD("array", "[{\"type\":\"stats\"}]", NOT_AN_OBJECT, ""),
    BAD("string", "\"stats\"", NOT_AN_OBJECT, ""),
    BAD("number", "42", NOT_AN_OBJECT, ""),
    BAD("null", "null", NOT_AN_OBJECT, ""),
    BAD("escaped NUL", "{\"type\":\"auth\",\"token\":\"ab\\u0000cd\"}", BAD_VALUE, ""),
    BAD("invalid utf-8 byte", "{\"type\":\"hello\",\"client\":\"\xff\"}", INVALID_ENCODING, ""),
    BAD("overlong utf-8", "{\"type\":\"hello\",\"client\":\"\xc0\xaf\"}", INVALID_ENCODING, ""),
    BAD("utf-8 surrogate", "{\"type\":\"hello\",\"client\":\"\xed\xa0\x80\"}", INVALID_ENCODING, ""),
    BAD("truncated utf-8", "{\"type\":\"hello\",\"client\":\"\xe2\x98\"}", INVALID_ENCODING, ""),
    BAD("above U+10FFFF", "{\"type\":\"hello\",\"client\":\"\xf4\x90\x80\x80\"}", INVALID_ENCODING, ""),

    BAD("empty object", "{}", MISSING_FIELD, "/type"),
    BAD("type number", "{\"type\":5}", WRONG_TYPE, "/type"),
    BAD("type null", "{\"type\":null}", WRONG_TYPE, "/type"),
    BAD("unknown type", "{\"type\":\"bogus\"}", UNKNOWN_TYPE, "/type"),
    BAD("type case", "{\"type\":\"Stats\"}", UNKNOWN_TYPE, "/type"),
    BAD("unknown top-level field", "{\"type\":\"stats\",\"extra\":1}", UNKNOWN_FIELD, "/extra"),
    BAD("field of another type", "{\"type\":\"get_state\",\"patch\":{}}", UNKNOWN_FIELD, "/patch"),
    BAD("escaped field name", "{\"type\":\"stats\",\"a/b~c\":1}", UNKNOWN_FIELD, "/a~1b~0c"),
    BAD("duplicate type", "{\"type\":\"stats\",\"type\":\"stats\"}", BAD_VALUE, "/type"),
    BAD("id bool", "{\"type\":\"stats\",\"id\":true}", WRONG_TYPE, "/id"),
    BAD("id object", "{\"type\":\"stats\",\"id\":{}}", WRONG_TYPE, "/id"),
    BAD("id null", "{\"type\":\"stats\",\"id\":null}", WRONG_TYPE, "/id"),
    BAD("id fraction", "{\"type\":\"stats\",\"id\":1.5}", BAD_VALUE, "/id"),
    BAD("id 2^53", "{\"type\":\"stats\",\"id\":9007199254740992}", OUT_OF_RANGE, "/id"),
    BAD("id 1e300", "{\"type\":\"stats\",\"id\":1e300}", OUT_OF_RANGE, "/id"),
    BAD("id empty", "{\"type\":\"stats\",\"id\":\"\"}", OUT_OF_RANGE, "/id"),
    BAD("id 65 bytes", "{\"type\":\"stats\",\"id\":\"" "0123456789012345678901234567890123456789"
        "0123456789012345678901234\"}", OUT_OF_RANGE, "/id"),

    BAD("hello client number", "{\"type\":\"hello\",\"client\":1}", WRONG_TYPE, "/client"),
    BAD("hello client 65 bytes", "{\"type\":\"hello\",\"client\":\""
        "01234567890123456789012345678901234567890123456789012345678901234\"}", OUT_OF_RANGE,
        "/client"),
    BAD("hello protocol 2", "{\"type\":\"hello\",\"protocol\":2}", UNSUPPORTED_PROTOCOL, "/protocol"),
    BAD("hello protocol 0", "{\"type\":\"hello\",\"protocol\":0}", OUT_OF_RANGE, "/protocol"),
    BAD("hello protocol string", "{\"type\":\"hello\",\"protocol\":\"1\"}", WRONG_TYPE, "/protocol"),
    BAD("hello token", "{\"type\":\"hello\",\"token\":\"x\"}", UNKNOWN_FIELD, "/token"),

    BAD("auth no token", "{\"type\":\"auth\"}", MISSING_FIELD, "/token"),
    BAD("auth token number", "{\"type\":\"auth\",\"token\":5}", WRONG_TYPE, "/token"),
    BAD("auth empty token", "{\"type\":\"auth\",\"token\":\"\"}", OUT_OF_RANGE, "/token"),

    BAD("set no patch", "{\"type\":\"set\"}", MISSING_FIELD, "/patch"),
    BAD("set patch array", "{\"type\":\"set\",\"patch\":[]}", WRONG_TYPE, "/patch"),
    BAD("set patch string", "{\"type\":\"set\",\"patch\":\"sun\"}", WRONG_TYPE, "/patch"),
    BAD("set unknown field", "{\"type\":\"set\",\"patch\":{\"atmosphere\":{\"bogus\":1}}}",
        UNKNOWN_FIELD, "/patch/atmosphere/bogus"),
    BAD("set unknown group", "{\"type\":\"set\",\"patch\":{\"seasons\":{}}}", UNKNOWN_FIELD,
        "/patch/seasons"),
    BAD("set out of range", "{\"type\":\"set\",\"patch\":{\"sun\":{\"elevation_deg\":95}}}",
        OUT_OF_RANGE, "/patch/sun/elevation_deg"),
    BAD("set wrong type", "{\"type\":\"set\",\"patch\":{\"sun\":{\"elevation_deg\":\"high\"}}}",
        WRONG_TYPE, "/patch/sun/elevation_deg"),
    BAD("set bad enum", "{\"type\":\"set\",\"patch\":{\"sun\":{\"limb_darkening\":\"x\"}}}",
        BAD_VALUE, "/patch/sun/limb_darkening"),
    BAD("set rgb element", "{\"type\":\"set\",\"patch\":{\"atmosphere\":{\"mie\":{\"g\":[0.8,1,0.8]}}}}",
        OUT_OF_RANGE, "/patch/atmosphere/mie/g/1"),
    BAD("set revision", "{\"type\":\"set\",\"patch\":{\"revision\":3}}", BAD_VALUE,
        "/patch/revision"),
    BAD("set group not object", "{\"type\":\"set\",\"patch\":{\"sun\":1}}", WRONG_TYPE, "/patch/sun"),

    BAD("subscribe no view", "{\"type\":\"subscribe\"}", MISSING_FIELD, "/view"),
    BAD("view array", "{\"type\":\"subscribe\",\"view\":[]}", WRONG_TYPE, "/view"),
    BAD("view no width", "{\"type\":\"subscribe\",\"view\":{\"height\":10}}", MISSING_FIELD,
        "/view/width"),
    BAD("view no height", "{\"type\":\"snapshot\",\"view\":{\"width\":10}}", MISSING_FIELD,
        "/view/height"),
    BAD("view width 0", "{\"type\":\"subscribe\",\"view\":{\"width\":0,\"height\":10}}",
        OUT_OF_RANGE, "/view/width"),
    BAD("view width over max", "{\"type\":\"subscribe\",\"view\":{\"width\":3841,\"height\":10}}",
        OUT_OF_RANGE, "/view/width"),
    BAD("view height over max", "{\"type\":\"subscribe\",\"view\":{\"width\":10,\"height\":2161}}",
        OUT_OF_RANGE, "/view/height"),
    BAD("view width fraction", "{\"type\":\"subscribe\",\"view\":{\"width\":10.5,\"height\":10}}",
        BAD_VALUE, "/view/width"),
    BAD("view width string", "{\"type\":\"subscribe\",\"view\":{\"width\":\"10\",\"height\":10}}",
        WRONG_TYPE, "/view/width"),
    BAD("view width negative", "{\"type\":\"subscribe\",\"view\":{\"width\":-1,\"height\":10}}",
        OUT_OF_RANGE, "/view/width"),
    BAD("view fps 0", "{\"type\":\"subscribe\",\"view\":{\"width\":1,\"height\":1,\"fps\":0}}",
        OUT_OF_RANGE, "/view/fps"),
    BAD("view fps negative", "{\"type\":\"subscribe\",\"view\":{\"width\":1,\"height\":1,\"fps\":-5}}",
        OUT_OF_RANGE, "/view/fps"),
    BAD("view fps over max", "{\"type\":\"subscribe\",\"view\":{\"width\":1,\"height\":1,\"fps\":61}}",
        OUT_OF_RANGE, "/view/fps"),
    BAD("view fps bool", "{\"type\":\"subscribe\",\"view\":{\"width\":1,\"height\":1,\"fps\":true}}",
        WRONG_TYPE, "/view/fps"),
    BAD("view format jpeg", "{\"type\":\"subscribe\",\"view\":{\"width\":1,\"height\":1,"
        "\"format\":\"jpeg\"}}", BAD_VALUE, "/view/format"),
    BAD("view format number", "{\"type\":\"subscribe\",\"view\":{\"width\":1,\"height\":1,"
        "\"format\":1}}", WRONG_TYPE, "/view/format"),
    BAD("view projection unknown", "{\"type\":\"subscribe\",\"view\":{\"width\":2,\"height\":1,"
        "\"projection\":\"fisheye\"}}", BAD_VALUE, "/view/projection"),
    BAD("view projection number", "{\"type\":\"snapshot\",\"view\":{\"width\":2,\"height\":1,"
        "\"projection\":1}}", WRONG_TYPE, "/view/projection"),
    BAD("equirectangular not 2:1", "{\"type\":\"snapshot\",\"view\":{\"width\":300,"
        "\"height\":200,\"projection\":\"equirectangular\"}}", INCONSISTENT, "/view/width"),
    BAD("view unknown field", "{\"type\":\"subscribe\",\"view\":{\"width\":1,\"height\":1,"
        "\"depth\":1}}", UNKNOWN_FIELD, "/view/depth"),
    BAD("camera array", "{\"type\":\"subscribe\",\"view\":{\"width\":1,\"height\":1,\"camera\":[]}}",
        WRONG_TYPE, "/view/camera"),
    BAD("camera unknown", "{\"type\":\"subscribe\",\"view\":{\"width\":1,\"height\":1,"
        "\"camera\":{\"zoom\":2}}}", UNKNOWN_FIELD, "/view/camera/zoom"),
    BAD("camera altitude", "{\"type\":\"subscribe\",\"view\":{\"width\":1,\"height\":1,"
        "\"camera\":{\"altitude_km\":-1}}}", OUT_OF_RANGE, "/view/camera/altitude_km"),
    BAD("camera yaw", "{\"type\":\"subscribe\",\"view\":{\"width\":1,\"height\":1,"
        "\"camera\":{\"yaw_deg\":361}}}", OUT_OF_RANGE, "/view/camera/yaw_deg"),
    BAD("camera pitch", "{\"type\":\"subscribe\",\"view\":{\"width\":1,\"height\":1,"
        "\"camera\":{\"pitch_deg\":-91}}}", OUT_OF_RANGE, "/view/camera/pitch_deg"),
    BAD("camera fov", "{\"type\":\"subscribe\",\"view\":{\"width\":1,\"height\":1,"
        "\"camera\":{\"fov_deg\":0.5}}}", OUT_OF_RANGE, "/view/camera/fov_deg"),
    BAD("camera fov string", "{\"type\":\"subscribe\",\"view\":{\"width\":1,\"height\":1,"
        "\"camera\":{\"fov_deg\":\"wide\"}}}", WRONG_TYPE, "/view/camera/fov_deg"),
    BAD("camera duplicate", "{\"type\":\"subscribe\",\"view\":{\"width\":1,\"height\":1,"
        "\"camera\":{\"fov_deg\":50,\"fov_deg\":60}}}", BAD_VALUE, "/view/camera/fov_deg"),
    BAD("exposure string", "{\"type\":\"subscribe\",\"view\":{\"width\":1,\"height\":1,"
        "\"exposure\":\"auto\"}}", WRONG_TYPE, "/view/exposure"),
    BAD("exposure mode", "{\"type\":\"subscribe\",\"view\":{\"width\":1,\"height\":1,"
        "\"exposure\":{\"mode\":\"program\"}}}", BAD_VALUE, "/view/exposure/mode"),
    BAD("exposure mode number", "{\"type\":\"subscribe\",\"view\":{\"width\":1,\"height\":1,"
        "\"exposure\":{\"mode\":1}}}", WRONG_TYPE, "/view/exposure/mode"),
    BAD("exposure ev100", "{\"type\":\"subscribe\",\"view\":{\"width\":1,\"height\":1,"
        "\"exposure\":{\"ev100\":26}}}", OUT_OF_RANGE, "/view/exposure/ev100"),
    BAD("exposure compensation", "{\"type\":\"subscribe\",\"view\":{\"width\":1,\"height\":1,"
        "\"exposure\":{\"compensation_ev\":-10.5}}}", OUT_OF_RANGE, "/view/exposure/compensation_ev"),
    BAD("exposure tonemap", "{\"type\":\"subscribe\",\"view\":{\"width\":1,\"height\":1,"
        "\"exposure\":{\"tonemap\":\"aces\"}}}", UNKNOWN_FIELD, "/view/exposure/tonemap"),

    BAD("unsubscribe none", "{\"type\":\"unsubscribe\"}", MISSING_FIELD, "/subscription"),
    BAD("unsubscribe 0", "{\"type\":\"unsubscribe\",\"subscription\":0}", OUT_OF_RANGE,
        "/subscription"),
    BAD("unsubscribe string", "{\"type\":\"unsubscribe\",\"subscription\":\"1\"}", WRONG_TYPE,
        "/subscription"),
    BAD("unsubscribe fraction", "{\"type\":\"unsubscribe\",\"subscription\":1.5}", BAD_VALUE,
        "/subscription"),

    BAD("probe no quantity", "{\"type\":\"probe\",\"sun_zenith_deg\":0}", MISSING_FIELD, "/quantity"),
    BAD("probe bad quantity", "{\"type\":\"probe\",\"quantity\":\"radiance\"}", BAD_VALUE,
        "/quantity"),
    BAD("probe quantity number", "{\"type\":\"probe\",\"quantity\":1}", WRONG_TYPE, "/quantity"),
    BAD("probe missing mu", "{\"type\":\"probe\",\"quantity\":\"transmittance\",\"altitude_km\":0}",
        MISSING_FIELD, "/mu"),
    BAD("probe unused parameter", "{\"type\":\"probe\",\"quantity\":\"illuminance\","
        "\"sun_zenith_deg\":0,\"mu\":0.5}", UNKNOWN_FIELD, "/mu"),
    BAD("probe altitude", "{\"type\":\"probe\",\"quantity\":\"transmittance\",\"altitude_km\":100001,"
        "\"mu\":0}", OUT_OF_RANGE, "/altitude_km"),
    BAD("probe mu", "{\"type\":\"probe\",\"quantity\":\"transmittance\",\"altitude_km\":0,"
        "\"mu\":1.0001}", OUT_OF_RANGE, "/mu"),
    BAD("probe mu string", "{\"type\":\"probe\",\"quantity\":\"transmittance\",\"altitude_km\":0,"
        "\"mu\":\"0\"}", WRONG_TYPE, "/mu"),
    BAD("probe view zenith", "{\"type\":\"probe\",\"quantity\":\"luminance\",\"altitude_km\":0,"
        "\"view_zenith_deg\":181,\"view_azimuth_deg\":0,\"sun_zenith_deg\":0}", OUT_OF_RANGE,
        "/view_zenith_deg"),
    BAD("probe view azimuth", "{\"type\":\"probe\",\"quantity\":\"luminance\",\"altitude_km\":0,"
        "\"view_zenith_deg\":0,\"view_azimuth_deg\":-361,\"sun_zenith_deg\":0}", OUT_OF_RANGE,
        "/view_azimuth_deg"),
    BAD("probe sun zenith", "{\"type\":\"probe\",\"quantity\":\"illuminance\",\"sun_zenith_deg\":-1}",
        OUT_OF_RANGE, "/sun_zenith_deg"),

    BAD("list_presets no kind", "{\"type\":\"list_presets\"}", MISSING_FIELD, "/kind"),
    BAD("list_presets kind", "{\"type\":\"list_presets\",\"kind\":\"climate\"}", BAD_VALUE, "/kind"),
    BAD("transition_s negative", "{\"type\":\"apply_preset\",\"kind\":\"weather\",\"name\":"
        "\"storm\",\"transition_s\":-1}", OUT_OF_RANGE, "/transition_s"),
    BAD("transition_s too long", "{\"type\":\"apply_preset\",\"kind\":\"weather\",\"name\":"
        "\"storm\",\"transition_s\":604801}", OUT_OF_RANGE, "/transition_s"),
    BAD("transition_s text", "{\"type\":\"apply_preset\",\"kind\":\"weather\",\"name\":"
        "\"storm\",\"transition_s\":\"20 min\"}", WRONG_TYPE, "/transition_s"),
    BAD("transition_s of an atmosphere", "{\"type\":\"apply_preset\",\"kind\":\"atmosphere\","
        "\"name\":\"mars\",\"transition_s\":60}", BAD_VALUE, "/transition_s"),
    BAD("list_presets kind number", "{\"type\":\"list_presets\",\"kind\":1}", WRONG_TYPE, "/kind"),
    BAD("list_presets name", "{\"type\":\"list_presets\",\"kind\":\"atmosphere\",\"name\":\"x\"}",
        UNKNOWN_FIELD, "/name"),
    BAD("apply_preset no name", "{\"type\":\"apply_preset\",\"kind\":\"atmosphere\"}",
        MISSING_FIELD, "/name"),
    BAD("apply_preset upper case", "{\"type\":\"apply_preset\",\"kind\":\"atmosphere\","
        "\"name\":\"Mars\"}", BAD_VALUE, "/name"),
    BAD("apply_preset path", "{\"type\":\"apply_preset\",\"kind\":\"atmosphere\","
        "\"name\":\"../earth\"}", BAD_VALUE, "/name"),
    BAD("apply_preset empty", "{\"type\":\"apply_preset\",\"kind\":\"atmosphere\",\"name\":\"\"}",
        BAD_VALUE, "/name"),
    BAD("apply_preset 65 bytes", "{\"type\":\"apply_preset\",\"kind\":\"atmosphere\",\"name\":\""
        "aaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaa\"}", BAD_VALUE, "/name"),
    BAD("apply_preset name number", "{\"type\":\"apply_preset\",\"kind\":\"atmosphere\","
        "\"name\":3}", WRONG_TYPE, "/name"),
    BAD("stats with field", "{\"type\":\"stats\",\"reset\":true}", UNKNOWN_FIELD, "/reset"),
};

static void test_parse_table(void)
{
    for (size_t i = 0; i < COUNT_OF(parse_cases); i++) {
        const struct parse_case *c = &parse_cases[i];
        check_case_name = c->name;
        struct sky_client_msg msg;
        struct sky_msg_parse_error error;
        enum sky_msg_error_code code = parse(c->text, &msg, &error);
        CHECK_STR(sky_msg_error_name(code), sky_msg_error_name(c->code));
        CHECK_INT(error.code, code);
        if (c->type != SKY_MSG_NONE)
            CHECK_STR(sky_msg_type_name(msg.type), sky_msg_type_name(c->type));
        if (c->pointer)
            CHECK_STR(first_pointer(&error), c->pointer);
        if (code == SKY_MSG_OK) {
            CHECK_INT(error.fields.total, 0);
        } else {
            CHECK(error.fields.count >= 1);
            CHECK(error.message[0] != '\0');
            CHECK(msg.type != SKY_MSG_SET || msg.set.patch == NULL);
            char *reply = sky_msg_build_parse_error(&msg, &error);
            cJSON *json = parse_built(reply, "error");
            CHECK_STR(string_at(json, "code"), sky_msg_error_name(c->code));
            cJSON_Delete(json);
        }
        sky_client_msg_free(&msg);
    }
    check_case_name = "";
}

/* ---- parser details --------------------------------------------------------------------- */

static void test_offsets_and_limits(void)
{
    struct sky_msg_limits limits = test_limits();
    struct sky_client_msg msg;
    struct sky_msg_parse_error error;

    check_case_name = "trailing garbage offset";
    CHECK_INT(parse("{\"type\":\"stats\"}  x", &msg, &error), SKY_MSG_ERR_MALFORMED_JSON);
    CHECK_INT(error.offset, 18);

    check_case_name = "syntax error offset";
    CHECK_INT(parse("{\"type\" \"stats\"}", &msg, &error), SKY_MSG_ERR_MALFORMED_JSON);
    CHECK_INT(error.offset, 8);

    check_case_name = "raw NUL byte";
    static const char with_nul[] = "{\"type\":\"auth\",\"token\":\"ab\0cd\"}";
    CHECK_INT(parse_with(with_nul, sizeof with_nul - 1, &limits, &msg, &error),
              SKY_MSG_ERR_MALFORMED_JSON);
    CHECK_INT(error.offset, 26);
    check_case_name = "NUL after the object";
    static const char nul_after[] = "{\"type\":\"stats\"}\0";
    CHECK_INT(parse_with(nul_after, sizeof nul_after - 1, &limits, &msg, &error),
              SKY_MSG_ERR_MALFORMED_JSON);
    CHECK_INT(error.offset, 16);

    check_case_name = "length bounds the text";
    static const char longer[] = "{\"type\":\"stats\"}{garbage";
    CHECK_INT(parse_with(longer, 16, &limits, &msg, &error), SKY_MSG_OK);
    CHECK_INT(msg.type, SKY_MSG_STATS);

    check_case_name = "invalid utf-8 offset";
    CHECK_INT(parse("{\"type\":\"hello\",\"client\":\"ab\x80\"}", &msg, &error),
              SKY_MSG_ERR_INVALID_ENCODING);
    CHECK_INT(error.offset, 28);

    check_case_name = "message at the size limit";
    char *text = repeat(' ', limits.max_message_bytes);
    memcpy(text, "{\"type\":\"stats\"}", 16);
    CHECK_INT(parse_with(text, limits.max_message_bytes, &limits, &msg, &error), SKY_MSG_OK);
    check_case_name = "message over the size limit";
    struct sky_msg_limits no_uploads = limits;
    no_uploads.max_upload_bytes = 0; /* else a set_weather_map may be larger (test_weather_map) */
    text[0] = '\x01'; /* never looked at: the size check comes first */
    CHECK_INT(parse_with(text, limits.max_message_bytes + 1, &no_uploads, &msg, &error),
              SKY_MSG_ERR_MESSAGE_TOO_LARGE);
    CHECK_STR(first_pointer(&error), "");
    free(text);

    check_case_name = "token at and over its limit";
    char token_message[600];
    char *token = repeat('t', SKY_MSG_TOKEN_MAX + 1);
    snprintf(token_message, sizeof token_message, "{\"type\":\"auth\",\"token\":\"%s\"}", token);
    CHECK_INT(parse(token_message, &msg, &error), SKY_MSG_ERR_OUT_OF_RANGE);
    token[SKY_MSG_TOKEN_MAX] = '\0';
    snprintf(token_message, sizeof token_message, "{\"type\":\"auth\",\"token\":\"%s\"}", token);
    CHECK_INT(parse(token_message, &msg, &error), SKY_MSG_OK);
    CHECK_INT(strlen(msg.auth.token), SKY_MSG_TOKEN_MAX);
    free(token);

    check_case_name = "deep nesting";
    struct sky_msg_limits large = limits;
    large.max_message_bytes = 1 << 20;
    char *deep = repeat('[', 100000);
    CHECK_INT(parse_with(deep, 100000, &large, &msg, &error), SKY_MSG_ERR_MALFORMED_JSON);
    free(deep);

    check_case_name = "many unknown fields";
    size_t used = 0;
    char *many = malloc(large.max_message_bytes);
    used += (size_t)sprintf(many, "{\"type\":\"stats\"");
    for (int i = 0; i < 5000; i++)
        used += (size_t)sprintf(many + used, ",\"f%d\":%d", i, i);
    used += (size_t)sprintf(many + used, "}");
    CHECK_INT(parse_with(many, used, &large, &msg, &error), SKY_MSG_ERR_UNKNOWN_FIELD);
    CHECK_INT(error.fields.total, 5000);
    CHECK_INT(error.fields.count, SKY_MAX_FIELD_ERRORS);
    char *reply = sky_msg_build_parse_error(&msg, &error);
    cJSON *json = parse_built(reply, "error");
    CHECK_DOUBLE(number_at(json, "fields_omitted"), 5000 - SKY_MAX_FIELD_ERRORS);
    CHECK_INT(cJSON_GetArraySize(get(json, "fields")), SKY_MAX_FIELD_ERRORS);
    cJSON_Delete(json);
    free(many);

    check_case_name = "every failure is listed";
    CHECK_INT(parse("{\"type\":\"subscribe\",\"id\":\"v\",\"view\":{\"width\":0,\"height\":0,"
                    "\"fps\":100}}", &msg, &error), SKY_MSG_ERR_OUT_OF_RANGE);
    CHECK_INT(error.fields.total, 3);
    CHECK_STR(error.fields.items[1].pointer, "/view/height");
    CHECK_STR(error.fields.items[2].pointer, "/view/fps");
    CHECK_INT(error.fields.items[2].code, SKY_MSG_ERR_OUT_OF_RANGE);

    check_case_name = "no limits";
    CHECK_INT(sky_msg_parse("{}", 2, NULL, &msg, &error), SKY_MSG_ERR_INTERNAL);
    check_case_name = "";
}

static void test_parsed_values(void)
{
    struct sky_client_msg msg;
    struct sky_msg_parse_error error;

    check_case_name = "hello values";
    CHECK_INT(parse(client_examples[0].text, &msg, &error), SKY_MSG_OK);
    CHECK(msg.hello.has_client);
    CHECK_STR(msg.hello.client, "sky-web 0.1");
    CHECK_INT(msg.hello.protocol, 1);
    CHECK_INT(msg.id.kind, SKY_MSG_ID_INTEGER);
    CHECK_INT(msg.id.number, 1);

    check_case_name = "auth values";
    CHECK_INT(parse(client_examples[1].text, &msg, &error), SKY_MSG_OK);
    CHECK_STR(msg.auth.token, "s3cret-token");

    check_case_name = "id kinds";
    CHECK_INT(parse("{\"type\":\"stats\"}", &msg, &error), SKY_MSG_OK);
    CHECK_INT(msg.id.kind, SKY_MSG_ID_NONE);
    CHECK_INT(parse("{\"type\":\"stats\",\"id\":-9007199254740991}", &msg, &error), SKY_MSG_OK);
    CHECK_INT(msg.id.number, -9007199254740991LL);
    CHECK_INT(parse("{\"id\":\"q\",\"type\":\"stats\"}", &msg, &error), SKY_MSG_OK);
    CHECK_INT(msg.id.kind, SKY_MSG_ID_STRING);
    CHECK_STR(msg.id.text, "q");

    check_case_name = "id kept when the rest fails";
    CHECK_INT(parse("{\"type\":\"bogus\",\"id\":\"keep-me\"}", &msg, &error),
              SKY_MSG_ERR_UNKNOWN_TYPE);
    CHECK_STR(msg.id.text, "keep-me");
    cJSON *json = parse_built(sky_msg_build_parse_error(&msg, &error), "error");
    CHECK_STR(string_at(json, "id"), "keep-me");
    CHECK_STR(string_at(json, "code"), "unknown_type");
    cJSON_Delete(json);
    CHECK_INT(parse("{\"type\":\"set\",\"id\":77,\"patch\":{\"sun\":{\"bogus\":1}}}", &msg, &error),
              SKY_MSG_ERR_UNKNOWN_FIELD);
    CHECK_INT(msg.type, SKY_MSG_SET);
    CHECK(msg.set.patch == NULL);
    json = parse_built(sky_msg_build_parse_error(&msg, &error), "error");
    CHECK_DOUBLE(number_at(json, "id"), 77);
    const cJSON *field = cJSON_GetArrayItem(get(json, "fields"), 0);
    CHECK_STR(string_at(field, "pointer"), "/patch/sun/bogus");
    CHECK_STR(string_at(field, "code"), "unknown_field");
    CHECK(string_at(field, "reason") != NULL);
    cJSON_Delete(json);

    check_case_name = "invalid id not echoed";
    CHECK_INT(parse("{\"type\":\"stats\",\"id\":1.5}", &msg, &error), SKY_MSG_ERR_BAD_VALUE);
    CHECK_INT(msg.id.kind, SKY_MSG_ID_NONE);
    json = parse_built(sky_msg_build_parse_error(&msg, &error), "error");
    CHECK(get(json, "id") == NULL);
    cJSON_Delete(json);

    check_case_name = "patch is detached and applies";
    CHECK_INT(parse(client_examples[3].text, &msg, &error), SKY_MSG_OK);
    CHECK(cJSON_IsObject(msg.set.patch));
    struct sky_world_state state;
    sky_world_state_defaults(&state);
    CHECK(sky_world_state_apply_json(&state, msg.set.patch, NULL));
    CHECK_DOUBLE(state.sun.elevation_deg, 2);
    CHECK_DOUBLE(state.atmosphere.mie_g[2], 0.76);
    sky_client_msg_free(&msg);
    CHECK(msg.set.patch == NULL);
    sky_client_msg_free(&msg);

    check_case_name = "inconsistency is left to the apply";
    CHECK_INT(parse("{\"type\":\"set\",\"patch\":{\"atmosphere\":{\"bottom_radius_km\":7000}}}",
                    &msg, &error), SKY_MSG_OK);
    struct sky_field_errors apply_errors;
    CHECK(!sky_world_state_apply_json(&state, msg.set.patch, &apply_errors));
    CHECK_INT(apply_errors.items[0].code, SKY_MSG_ERR_INCONSISTENT);
    json = parse_built(sky_msg_build_error(NULL, SKY_MSG_ERR_INCONSISTENT, "rejected",
                                           &apply_errors), "error");
    CHECK_STR(string_at(json, "code"), "inconsistent");
    CHECK_STR(string_at(cJSON_GetArrayItem(get(json, "fields"), 0), "code"), "inconsistent");
    cJSON_Delete(json);
    sky_client_msg_free(&msg);

    check_case_name = "view defaults";
    CHECK_INT(parse(client_examples[6].text, &msg, &error), SKY_MSG_OK);
    CHECK_INT(msg.view.width, 640);
    CHECK_INT(msg.view.height, 360);
    CHECK_DOUBLE(msg.view.fps, 10);
    CHECK_INT(msg.view.format, SKY_FRAME_FORMAT_PNG);
    CHECK_INT(msg.view.projection, SKY_VIEW_PROJECTION_PERSPECTIVE);
    CHECK(!msg.view.has_altitude_km && !msg.view.has_yaw_deg && !msg.view.has_pitch_deg &&
          !msg.view.has_fov_deg);
    CHECK(!msg.view.has_exposure_mode && !msg.view.has_ev100 && !msg.view.has_compensation_ev);
    struct sky_msg_limits slow = test_limits();
    slow.max_fps = 4;
    const char *snapshot = client_examples[6].text;
    CHECK_INT(parse_with(snapshot, strlen(snapshot), &slow, &msg, &error), SKY_MSG_OK);
    CHECK_DOUBLE(msg.view.fps, 4);

    check_case_name = "view environment map";
    CHECK_INT(parse(client_examples[COUNT_OF(client_examples) - 1].text, &msg, &error), SKY_MSG_OK);
    CHECK_INT(msg.view.projection, SKY_VIEW_PROJECTION_EQUIRECTANGULAR);
    CHECK_INT(msg.view.format, SKY_FRAME_FORMAT_PNG16);
    CHECK_INT(msg.view.width, 2 * msg.view.height);

    check_case_name = "view given";
    CHECK_INT(parse(client_examples[4].text, &msg, &error), SKY_MSG_OK);
    CHECK(msg.view.has_yaw_deg && msg.view.has_fov_deg && !msg.view.has_pitch_deg);
    CHECK_DOUBLE(msg.view.yaw_deg, 200);
    CHECK_DOUBLE(msg.view.fov_deg, 60);
    CHECK_DOUBLE(msg.view.fps, 30);
    CHECK(msg.view.has_exposure_mode && msg.view.has_ev100 && !msg.view.has_compensation_ev);
    CHECK_INT(msg.view.exposure_mode, SKY_EXPOSURE_MANUAL);
    CHECK_DOUBLE(msg.view.ev100, 12);

    check_case_name = "view resolve";
    struct sky_camera_state camera;
    struct sky_exposure_state exposure;
    sky_world_state_defaults(&state);
    sky_msg_view_resolve(&msg.view, &state, &camera, &exposure);
    CHECK_DOUBLE(camera.yaw_deg, 200);
    CHECK_DOUBLE(camera.fov_deg, 60);
    CHECK_DOUBLE(camera.pitch_deg, state.camera.pitch_deg);
    CHECK_DOUBLE(camera.altitude_km, state.camera.altitude_km);
    CHECK_INT(exposure.mode, SKY_EXPOSURE_MANUAL);
    CHECK_DOUBLE(exposure.ev100, 12);
    CHECK_DOUBLE(exposure.compensation_ev, state.exposure.compensation_ev);
    CHECK_INT(exposure.tonemap, state.exposure.tonemap);

    check_case_name = "probe values";
    CHECK_INT(parse(client_examples[8].text, &msg, &error), SKY_MSG_OK);
    CHECK_INT(msg.probe.quantity, SKY_PROBE_LUMINANCE);
    CHECK_DOUBLE(msg.probe.view_zenith_deg, 45);
    CHECK_DOUBLE(msg.probe.view_azimuth_deg, 90);
    CHECK_DOUBLE(msg.probe.sun_zenith_deg, 30);
    CHECK_INT(parse(client_examples[7].text, &msg, &error), SKY_MSG_OK);
    CHECK_INT(msg.probe.quantity, SKY_PROBE_TRANSMITTANCE);
    CHECK_DOUBLE(msg.probe.mu, 0.5);

    check_case_name = "preset values";
    CHECK_INT(parse(client_examples[11].text, &msg, &error), SKY_MSG_OK);
    CHECK_INT(msg.preset.kind, SKY_PRESET_ATMOSPHERE);
    CHECK_STR(msg.preset.name, "mars");
    CHECK(!msg.preset.has_transition);
    CHECK_INT(parse(client_examples[13].text, &msg, &error), SKY_MSG_OK);
    CHECK_INT(msg.preset.kind, SKY_PRESET_WEATHER);
    CHECK_STR(msg.preset.name, "storm");
    CHECK(msg.preset.has_transition);
    CHECK_DOUBLE(msg.preset.transition_s, 1200);
    CHECK_INT(parse(client_examples[5].text, &msg, &error), SKY_MSG_OK);
    CHECK_INT(msg.unsubscribe.subscription, 1);

    check_case_name = "roles";
    for (int t = SKY_MSG_HELLO; t <= SKY_MSG_STATS; t++) {
        bool expected = t == SKY_MSG_SET || t == SKY_MSG_APPLY_PRESET;
        CHECK_INT(protocol_message_needs_controller((enum sky_msg_type)t), expected);
        CHECK(sky_msg_type_name((enum sky_msg_type)t) != NULL);
    }
    CHECK(sky_msg_type_name(SKY_MSG_NONE) == NULL);

    check_case_name = "error names";
    static const struct {
        int code;
        const char *name;
    } names[] = {
        {SKY_MSG_ERR_UNKNOWN_FIELD, "unknown_field"}, {SKY_MSG_ERR_WRONG_TYPE, "wrong_type"},
        {SKY_MSG_ERR_OUT_OF_RANGE, "out_of_range"}, {SKY_MSG_ERR_BAD_VALUE, "bad_value"},
        {SKY_MSG_ERR_INCONSISTENT, "inconsistent"}, {SKY_MSG_ERR_MISSING_FIELD, "missing_field"},
        {SKY_MSG_ERR_MALFORMED_JSON, "malformed_json"},
        {SKY_MSG_ERR_MESSAGE_TOO_LARGE, "message_too_large"},
        {SKY_MSG_ERR_NOT_AN_OBJECT, "not_an_object"}, {SKY_MSG_ERR_UNKNOWN_TYPE, "unknown_type"},
        {SKY_MSG_ERR_INVALID_ENCODING, "invalid_encoding"},
        {SKY_MSG_ERR_UNSUPPORTED_PROTOCOL, "unsupported_protocol"},
        {SKY_MSG_ERR_FORBIDDEN, "forbidden"}, {SKY_MSG_ERR_AUTH_FAILED, "auth_failed"},
        {SKY_MSG_ERR_RATE_LIMITED, "rate_limited"}, {SKY_MSG_ERR_NOT_FOUND, "not_found"},
        {SKY_MSG_ERR_LIMIT_REACHED, "limit_reached"}, {SKY_MSG_ERR_INTERNAL, "internal"},
        {SKY_FIELD_UNKNOWN, "unknown_field"}, {SKY_FIELD_INCONSISTENT, "inconsistent"},
    };
    for (size_t i = 0; i < COUNT_OF(names); i++)
        CHECK_STR(sky_msg_error_name(names[i].code), names[i].name);
    CHECK(sky_msg_error_name(13) == NULL);
    CHECK(sky_msg_error_name(-1) == NULL);
    CHECK(sky_msg_error_name(1000) == NULL);
    check_case_name = "";
}

/* ---- builders --------------------------------------------------------------------------- */

static void test_builders(void)
{
    struct sky_msg_limits limits;
    sky_msg_limits_default(&limits);
    size_t capability_count;
    const char *const *caps = sky_msg_default_capabilities(&capability_count);
    struct sky_msg_id id = string_id("abc"), id5 = int_id(5);

    check_case_name = "hello";
    cJSON *json = parse_built(
        sky_msg_build_hello("1.2.3", SKY_ROLE_CONTROLLER, caps, capability_count, &limits), "hello");
    CHECK_DOUBLE(number_at(json, "protocol"), SKY_PROTOCOL_VERSION);
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
    CHECK(sky_msg_build_hello("1", SKY_ROLE_NONE, caps, capability_count, &limits) == NULL);
    CHECK(sky_msg_build_hello(NULL, SKY_ROLE_VIEWER, caps, capability_count, &limits) == NULL);
    CHECK(sky_msg_build_hello("1", SKY_ROLE_VIEWER, caps, capability_count, NULL) == NULL);
    struct sky_msg_limits bad = limits;
    bad.max_fps = NAN;
    CHECK(sky_msg_build_hello("1", SKY_ROLE_VIEWER, caps, capability_count, &bad) == NULL);
    bad = limits;
    bad.max_clients = -1;
    CHECK(sky_msg_build_hello("1", SKY_ROLE_VIEWER, caps, capability_count, &bad) == NULL);

    check_case_name = "state";
    struct sky_world_state state;
    sky_world_state_defaults(&state);
    state.revision = 41;
    json = parse_built(sky_msg_build_state(&id, &state), "state");
    CHECK_STR(string_at(json, "id"), "abc");
    CHECK_DOUBLE(number_at(json, "revision"), 41);
    const cJSON *state_json = get(json, "state");
    CHECK(get(state_json, "revision") == NULL);
    CHECK_DOUBLE(number_at(get(state_json, "sun"), "elevation_deg"), 45);
    struct sky_world_state copy;
    sky_world_state_defaults(&copy);
    copy.sun.elevation_deg = 3;
    CHECK(sky_world_state_apply_json(&copy, state_json, NULL));
    CHECK_DOUBLE(copy.sun.elevation_deg, 45);
    struct sky_field_errors patch_errors;
    sky_field_errors_clear(&patch_errors);
    CHECK(sky_msg_validate_patch(state_json, "/patch", &patch_errors));
    cJSON_Delete(json);
    state.sun.elevation_deg = NAN;
    CHECK(sky_msg_build_state(&id, &state) == NULL);
    state.sun.elevation_deg = INFINITY;
    CHECK(sky_msg_build_state(&id, &state) == NULL);
    CHECK(sky_msg_build_state(&id, NULL) == NULL);

    check_case_name = "ack";
    json = parse_built(sky_msg_build_ack(&id5, 9007199254740991ULL, SKY_ROLE_NONE), "ack");
    CHECK_DOUBLE(number_at(json, "id"), 5);
    CHECK_DOUBLE(number_at(json, "revision"), 9007199254740991.0);
    CHECK(get(json, "role") == NULL);
    cJSON_Delete(json);
    json = parse_built(sky_msg_build_ack(NULL, 0, SKY_ROLE_CONTROLLER), "ack");
    CHECK(get(json, "id") == NULL);
    CHECK_STR(string_at(json, "role"), "controller");
    cJSON_Delete(json);
    CHECK(sky_msg_build_ack(&id5, 9007199254740992ULL, SKY_ROLE_NONE) == NULL);
    struct sky_msg_id bad_id = int_id(9007199254740992LL);
    CHECK(sky_msg_build_ack(&bad_id, 1, SKY_ROLE_NONE) == NULL);
    bad_id = string_id("");
    CHECK(sky_msg_build_ack(&bad_id, 1, SKY_ROLE_NONE) == NULL);
    bad_id.kind = (enum sky_msg_id_kind)7;
    CHECK(sky_msg_build_ack(&bad_id, 1, SKY_ROLE_NONE) == NULL);
    CHECK(sky_msg_build_ack(NULL, 1, (enum sky_msg_role)9) == NULL);

    check_case_name = "error";
    struct sky_field_errors fields;
    sky_field_errors_clear(&fields);
    sky_field_errors_add(&fields, SKY_MSG_ERR_OUT_OF_RANGE, "/view/fps", "too fast");
    sky_field_errors_add(&fields, SKY_MSG_ERR_MISSING_FIELD, "/view/width", "required");
    json = parse_built(sky_msg_build_error(&id5, SKY_MSG_ERR_OUT_OF_RANGE, "bad view", &fields),
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
    json = parse_built(sky_msg_build_error(NULL, SKY_MSG_ERR_RATE_LIMITED, NULL, NULL), "error");
    CHECK_INT(cJSON_GetArraySize(get(json, "fields")), 0);
    CHECK_STR(string_at(json, "message"), "");
    cJSON_Delete(json);
    CHECK(sky_msg_build_error(NULL, SKY_MSG_OK, "x", NULL) == NULL);
    CHECK(sky_msg_build_error(NULL, (enum sky_msg_error_code)99, "x", NULL) == NULL);
    sky_field_errors_add(&fields, 99, "/x", "unknown code");
    CHECK(sky_msg_build_error(NULL, SKY_MSG_ERR_BAD_VALUE, "x", &fields) == NULL);

    check_case_name = "error text is made UTF-8";
    char *text = sky_msg_build_error(NULL, SKY_MSG_ERR_BAD_VALUE, "cut \xe2\x98", NULL);
    CHECK(text != NULL);
    json = parse_built(text, "error");
    CHECK_STR(string_at(json, "message"), "cut ??");
    cJSON_Delete(json);

    check_case_name = "subscribed round trip";
    struct sky_client_msg msg, again;
    struct sky_msg_parse_error error;
    CHECK_INT(parse(client_examples[4].text, &msg, &error), SKY_MSG_OK);
    json = parse_built(sky_msg_build_subscribed(&msg.id, 3, &msg.view), "subscribed");
    CHECK_STR(string_at(json, "id"), "main-view");
    CHECK_DOUBLE(number_at(json, "subscription"), 3);
    cJSON *request = cJSON_CreateObject();
    cJSON_AddStringToObject(request, "type", "subscribe");
    cJSON_AddItemToObject(request, "view", cJSON_DetachItemFromObject(json, "view"));
    char *request_text = cJSON_PrintUnformatted(request);
    CHECK_INT(parse(request_text, &again, &error), SKY_MSG_OK);
    CHECK(memcmp(&again.view, &msg.view, sizeof msg.view) == 0);
    free(request_text);
    cJSON_Delete(request);
    cJSON_Delete(json);
    CHECK(sky_msg_build_subscribed(&msg.id, 0, &msg.view) == NULL);
    msg.view.fov_deg = NAN;
    CHECK(sky_msg_build_subscribed(&msg.id, 1, &msg.view) == NULL);
    CHECK(sky_msg_build_subscribed(&msg.id, 1, NULL) == NULL);

    check_case_name = "frame";
    json = parse_built(sky_msg_build_frame(NULL, 2, 100), "frame");
    CHECK_DOUBLE(number_at(json, "subscription"), 2);
    CHECK_DOUBLE(number_at(json, "frame_number"), 100);
    CHECK(get(json, "id") == NULL);
    cJSON_Delete(json);
    json = parse_built(sky_msg_build_frame(&id, 0, 101), "frame");
    CHECK_STR(string_at(json, "id"), "abc");
    CHECK(get(json, "subscription") == NULL);
    cJSON_Delete(json);
    CHECK(sky_msg_build_frame(&id, 2, 1) == NULL);
    CHECK(sky_msg_build_frame(NULL, 0, 1) == NULL);

    check_case_name = "state_changed";
    struct sky_world_state before, after;
    sky_world_state_defaults(&before);
    after = before;
    after.camera.fov_deg = 30;
    after.sun.elevation_deg = 10;
    after.render.skyview_lut[1] = 200;
    char changed[2][SKY_MSG_POINTER_MAX];
    CHECK_INT(sky_msg_state_diff(&before, &after, changed, 2), 3);
    CHECK_STR(changed[0], "/sun/elevation_deg");
    CHECK_STR(changed[1], "/camera/fov_deg");
    CHECK_INT(sky_msg_state_diff(&before, &before, changed, 2), 0);
    const char *pointers[] = {changed[0], changed[1]};
    json = parse_built(sky_msg_build_state_changed(8, pointers, 2), "event");
    CHECK_STR(string_at(json, "event"), "state_changed");
    CHECK_DOUBLE(number_at(json, "revision"), 8);
    CHECK_STR(cJSON_GetArrayItem(get(json, "changed"), 1)->valuestring, "/camera/fov_deg");
    cJSON_Delete(json);
    const char *not_pointers[] = {"sun.elevation_deg"};
    CHECK(sky_msg_build_state_changed(8, not_pointers, 1) == NULL);
    CHECK(sky_msg_build_state_changed(8, NULL, 1) == NULL);

    check_case_name = "presets";
    const char *names[] = {"earth", "mars"};
    json = parse_built(sky_msg_build_presets(&id, SKY_PRESET_ATMOSPHERE, names, 2), "presets");
    CHECK_STR(string_at(json, "kind"), "atmosphere");
    CHECK_STR(cJSON_GetArrayItem(get(json, "names"), 1)->valuestring, "mars");
    cJSON_Delete(json);
    json = parse_built(sky_msg_build_presets(NULL, SKY_PRESET_ATMOSPHERE, NULL, 0), "presets");
    CHECK_INT(cJSON_GetArraySize(get(json, "names")), 0);
    cJSON_Delete(json);
    const char *bad_names[] = {"earth", "Bad Name"};
    CHECK(sky_msg_build_presets(NULL, SKY_PRESET_ATMOSPHERE, bad_names, 2) == NULL);
    CHECK(sky_msg_build_presets(NULL, (enum sky_preset_kind)3, names, 2) == NULL);

    check_case_name = "probe_result";
    struct sky_msg_probe_result result = {SKY_PROBE_TRANSMITTANCE, {0.5, 0.25, 0.125}, 0, 0};
    json = parse_built(sky_msg_build_probe_result(&id5, &result), "probe_result");
    CHECK_STR(string_at(json, "quantity"), "transmittance");
    CHECK_DOUBLE(cJSON_GetArrayItem(get(json, "transmittance"), 2)->valuedouble, 0.125);
    CHECK(get(json, "luminance") == NULL);
    cJSON_Delete(json);
    result.quantity = SKY_PROBE_LUMINANCE;
    json = parse_built(sky_msg_build_probe_result(NULL, &result), "probe_result");
    CHECK_INT(cJSON_GetArraySize(get(json, "luminance")), 3);
    cJSON_Delete(json);
    result.quantity = SKY_PROBE_ILLUMINANCE;
    result.sun_lux = 120014;
    result.sky_lux = 15000.5;
    json = parse_built(sky_msg_build_probe_result(NULL, &result), "probe_result");
    CHECK_DOUBLE(number_at(json, "sun_lux"), 120014);
    CHECK_DOUBLE(number_at(json, "sky_lux"), 15000.5);
    cJSON_Delete(json);
    result.sky_lux = INFINITY;
    CHECK(sky_msg_build_probe_result(NULL, &result) == NULL);
    result.quantity = SKY_PROBE_LUMINANCE;
    result.rgb[1] = NAN;
    CHECK(sky_msg_build_probe_result(NULL, &result) == NULL);
    result.quantity = (enum sky_probe_quantity)5;
    CHECK(sky_msg_build_probe_result(NULL, &result) == NULL);

    check_case_name = "stats";
    struct sky_msg_pass_time passes[] = {{"skyview", 0.5}, {"composite", 1.25}};
    struct sky_msg_stats stats = {30, 2, passes, 2, 0.5, 1782043200.25};
    json = parse_built(sky_msg_build_stats(NULL, &stats), "stats");
    CHECK_DOUBLE(number_at(json, "simulation_time_s"), 1782043200.25);
    CHECK_DOUBLE(number_at(json, "fps"), 30);
    CHECK_DOUBLE(number_at(json, "clients"), 2);
    CHECK_DOUBLE(number_at(get(json, "passes"), "composite"), 1.25);
    CHECK_DOUBLE(number_at(json, "lut_rebuild_progress"), 0.5);
    cJSON_Delete(json);
    stats.lut_rebuild_progress = 1.5;
    CHECK(sky_msg_build_stats(NULL, &stats) == NULL);
    stats.lut_rebuild_progress = NAN;
    CHECK(sky_msg_build_stats(NULL, &stats) == NULL);
    stats.lut_rebuild_progress = 1;
    stats.simulation_time_s = INFINITY;
    CHECK(sky_msg_build_stats(NULL, &stats) == NULL);
    stats.simulation_time_s = 0;
    passes[1].name = "skyview";
    CHECK(sky_msg_build_stats(NULL, &stats) == NULL);
    passes[1].name = "composite";
    passes[1].ms = -1;
    CHECK(sky_msg_build_stats(NULL, &stats) == NULL);
    passes[1].ms = 1;
    stats.fps = INFINITY;
    CHECK(sky_msg_build_stats(NULL, &stats) == NULL);
    check_case_name = "";
}

/* ---- frame header ----------------------------------------------------------------------- */

static void test_frame_header(void)
{
    check_case_name = "frame header layout";
    struct sky_frame_header header = {
        .format = SKY_FRAME_FORMAT_PNG,
        .frame_number = 0x0102030405060708ULL,
        .state_revision = 0x1112131415161718ULL,
        .simulation_time_s = 1.5, /* 0x3FF8000000000000 */
        .width = 640,
        .height = 360,
        .payload_length = 1000,
    };
    static const uint8_t expected[SKY_FRAME_HEADER_SIZE] = {
        'S', 'K', 'Y', 'F', 0x01, 0x00, 0x01, 0x00,                 /* magic, version, format */
        0x08, 0x07, 0x06, 0x05, 0x04, 0x03, 0x02, 0x01,             /* frame_number */
        0x18, 0x17, 0x16, 0x15, 0x14, 0x13, 0x12, 0x11,             /* state_revision */
        0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0xF8, 0x3F,             /* simulation_time_s */
        0x80, 0x02, 0x00, 0x00, 0x68, 0x01, 0x00, 0x00,             /* width, height */
        0xE8, 0x03, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00,             /* payload_length, reserved */
    };
    uint8_t message[SKY_FRAME_HEADER_SIZE + 1000];
    memset(message, 0xAB, sizeof message);
    CHECK_INT(sky_frame_header_pack(&header, message), SKY_FRAME_HEADER_OK);
    for (int i = 0; i < SKY_FRAME_HEADER_SIZE; i++) {
        if (message[i] != expected[i]) {
            CHECK_INT(i, -1);
            printf("    byte %d: 0x%02X, expected 0x%02X\n", i, message[i], expected[i]);
        }
    }
    CHECK_INT(message[SKY_FRAME_HEADER_SIZE], 0xAB);

    check_case_name = "frame header round trip";
    struct sky_frame_header read;
    memset(&read, 0, sizeof read);
    CHECK_INT(sky_frame_header_unpack(message, sizeof message, &read), SKY_FRAME_HEADER_OK);
    CHECK_INT(read.format, SKY_FRAME_FORMAT_PNG);
    CHECK(read.frame_number == header.frame_number);
    CHECK(read.state_revision == header.state_revision);
    CHECK_DOUBLE(read.simulation_time_s, 1.5);
    CHECK_INT(read.width, 640);
    CHECK_INT(read.height, 360);
    CHECK_INT(read.payload_length, 1000);
    struct sky_frame_header extreme = {SKY_FRAME_FORMAT_PNG, UINT64_MAX, UINT64_MAX - 1,
                                       -12345.678901234567, UINT32_MAX, 1, 0};
    uint8_t bare[SKY_FRAME_HEADER_SIZE];
    CHECK_INT(sky_frame_header_pack(&extreme, bare), SKY_FRAME_HEADER_OK);
    CHECK_INT(sky_frame_header_unpack(bare, sizeof bare, &read), SKY_FRAME_HEADER_OK);
    CHECK(read.frame_number == UINT64_MAX && read.state_revision == UINT64_MAX - 1);
    CHECK_DOUBLE(read.simulation_time_s, -12345.678901234567);
    CHECK_INT(read.width, UINT32_MAX);
    CHECK_INT(read.payload_length, 0);

    static const struct {
        const char *name;
        int offset;     /* byte to change, or -1 */
        uint8_t value;
        size_t length;  /* message length given to unpack */
        enum sky_frame_header_status status;
    } rejections[] = {
        {"too short", -1, 0, SKY_FRAME_HEADER_SIZE - 1, SKY_FRAME_HEADER_TOO_SHORT},
        {"empty", -1, 0, 0, SKY_FRAME_HEADER_TOO_SHORT},
        {"bad magic", 0, 's', sizeof message, SKY_FRAME_HEADER_BAD_MAGIC},
        {"bad magic end", 3, 'G', sizeof message, SKY_FRAME_HEADER_BAD_MAGIC},
        {"version 2", 4, 2, sizeof message, SKY_FRAME_HEADER_BAD_VERSION},
        {"version 0x101", 5, 1, sizeof message, SKY_FRAME_HEADER_BAD_VERSION},
        {"format 0", 6, 0, sizeof message, SKY_FRAME_HEADER_BAD_FORMAT},
        {"format 3", 6, 3, sizeof message, SKY_FRAME_HEADER_BAD_FORMAT},
        {"format 0x101", 7, 1, sizeof message, SKY_FRAME_HEADER_BAD_FORMAT},
        {"payload short by one", -1, 0, sizeof message - 1, SKY_FRAME_HEADER_BAD_LENGTH},
        {"payload long by one", 40, 0xE7, sizeof message, SKY_FRAME_HEADER_BAD_LENGTH},
        {"payload length high byte", 43, 1, sizeof message, SKY_FRAME_HEADER_BAD_LENGTH},
        {"header only", -1, 0, SKY_FRAME_HEADER_SIZE, SKY_FRAME_HEADER_BAD_LENGTH},
        {"reserved", 47, 1, sizeof message, SKY_FRAME_HEADER_BAD_RESERVED},
        {"zero width", 32, 0, sizeof message, SKY_FRAME_HEADER_BAD_VALUE},
        {"NaN time", 30, 0xFF, sizeof message, SKY_FRAME_HEADER_BAD_VALUE},
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
        struct sky_frame_header untouched = header;
        enum sky_frame_header_status status =
            sky_frame_header_unpack(copy, rejections[i].length, &untouched);
        CHECK_STR(sky_frame_header_status_name(status),
                  sky_frame_header_status_name(rejections[i].status));
        CHECK(memcmp(&untouched, &header, sizeof header) == 0);
    }
    check_case_name = "frame header format png16";
    uint8_t png16[sizeof message];
    memcpy(png16, message, sizeof png16);
    png16[6] = SKY_FRAME_FORMAT_PNG16;
    struct sky_frame_header read16;
    CHECK_INT(sky_frame_header_unpack(png16, sizeof png16, &read16), SKY_FRAME_HEADER_OK);
    CHECK_INT(read16.format, SKY_FRAME_FORMAT_PNG16);

    check_case_name = "frame header pack rejections";
    CHECK_INT(sky_frame_header_unpack(NULL, 100, NULL), SKY_FRAME_HEADER_TOO_SHORT);
    struct sky_frame_header bad = header;
    bad.simulation_time_s = NAN;
    CHECK_INT(sky_frame_header_pack(&bad, bare), SKY_FRAME_HEADER_BAD_VALUE);
    bad = header;
    bad.format = (enum sky_frame_format)7;
    CHECK_INT(sky_frame_header_pack(&bad, bare), SKY_FRAME_HEADER_BAD_FORMAT);
    bad = header;
    bad.height = 0;
    CHECK_INT(sky_frame_header_pack(&bad, bare), SKY_FRAME_HEADER_BAD_VALUE);
    CHECK_STR(sky_frame_header_status_name(SKY_FRAME_HEADER_BAD_LENGTH), "bad_length");
    CHECK(sky_frame_header_status_name(8) == NULL);
    check_case_name = "";
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

static char *read_file(const char *path)
{
    FILE *file = fopen(path, "rb");
    if (!file)
        return NULL;
    fseek(file, 0, SEEK_END);
    long size = ftell(file);
    fseek(file, 0, SEEK_SET);
    char *text = size >= 0 ? malloc((size_t)size + 1) : NULL;
    if (text) {
        size_t got = fread(text, 1, (size_t)size, file);
        text[got] = '\0';
    }
    fclose(file);
    return text;
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
    for (size_t i = 0; i < COUNT_OF(client_examples); i++) {
        struct sky_client_msg msg;
        struct sky_msg_parse_error error;
        CHECK_INT(parse(client_examples[i].text, &msg, &error), SKY_MSG_OK);
        if (error.code != SKY_MSG_OK)
            printf("    %s: %s\n", client_examples[i].text, error.message);
        CHECK_STR(sky_msg_type_name(msg.type), sky_msg_type_name(client_examples[i].type));
        sky_client_msg_free(&msg);
    }

    char *doc = read_file(doc_path);
    check_case_name = doc_path;
    CHECK(doc != NULL);
    if (!doc)
        return;
    char *blocks[64];
    check_case_name = "PROTOCOL.md client examples";
    size_t count = doc_blocks(doc, "client", blocks, 64);
    CHECK_INT(count, COUNT_OF(client_examples));
    for (size_t i = 0; i < count && i < 64; i++) {
        cJSON *documented = cJSON_Parse(blocks[i]);
        cJSON *tabled = i < COUNT_OF(client_examples) ? cJSON_Parse(client_examples[i].text) : NULL;
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
