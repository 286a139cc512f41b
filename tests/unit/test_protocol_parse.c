/* test_protocol's parse table: every message of the table parses to its code, type and
 * first field error (test_protocol.h). */
#include "test_protocol.h"

/* ---- parse table ------------------------------------------------------------------------ */

struct parse_case {
    const char *name;
    const char *text;
    enum proto_msg_error_code code;
    enum proto_msg_type type; /* checked when not PROTO_MSG_NONE */
    const char *pointer;      /* first field error's pointer; checked when not NULL */
};

/* clang-format off */
#define OK(name, text, type) {name, text, PROTO_MSG_OK, type, NULL}
#define BAD(name, text, code, pointer) {name, text, PROTO_MSG_ERR_##code, PROTO_MSG_NONE, pointer}

static const struct parse_case parse_cases[] = {
    OK("hello empty", "{\"type\":\"hello\"}", PROTO_MSG_HELLO),
    OK("whitespace around", " \t\r\n{ \"type\" : \"stats\" }\n ", PROTO_MSG_STATS),
    OK("string id", "{\"type\":\"get_state\",\"id\":\"r-1\"}", PROTO_MSG_GET_STATE),
    OK("max integer id", "{\"type\":\"stats\",\"id\":9007199254740991}", PROTO_MSG_STATS),
    OK("min integer id", "{\"type\":\"stats\",\"id\":-9007199254740991}", PROTO_MSG_STATS),
    OK("64-byte id", "{\"type\":\"stats\",\"id\":\"" "0123456789012345678901234567890123456789"
       "012345678901234567890123\"}", PROTO_MSG_STATS),
    OK("utf-8 client", "{\"type\":\"hello\",\"client\":\"h\xc3\xa9llo \xe2\x98\x80 \xf0\x9f\x8c\x85\"}",
       PROTO_MSG_HELLO),
    OK("escaped slash and unicode", "{\"type\":\"hello\",\"client\":\"a\\/b\\u00e9\"}", PROTO_MSG_HELLO),
    OK("inconsistent patch deferred", "{\"type\":\"set\",\"patch\":{\"atmosphere\":"
       "{\"bottom_radius_km\":7000}}}", PROTO_MSG_SET),
    OK("empty patch", "{\"type\":\"set\",\"patch\":{}}", PROTO_MSG_SET),
    OK("rgb patch", "{\"type\":\"set\",\"patch\":{\"atmosphere\":{\"ground_albedo\":[0.1,0.2,0.3]}}}",
       PROTO_MSG_SET),
    OK("view at limits", "{\"type\":\"snapshot\",\"id\":1,\"view\":{\"width\":3840,\"height\":2160,"
       "\"fps\":60,\"camera\":{\"altitude_km\":100000,\"yaw_deg\":-360,\"pitch_deg\":90,"
       "\"fov_deg\":170},\"exposure\":{\"mode\":\"auto\",\"ev100\":-10,\"compensation_ev\":10}}}",
       PROTO_MSG_SNAPSHOT),
    OK("view jpeg", "{\"type\":\"subscribe\",\"view\":{\"width\":1,\"height\":1,"
       "\"format\":\"jpeg\"}}", PROTO_MSG_SUBSCRIBE),
    OK("view jpeg quality ends", "{\"type\":\"subscribe\",\"view\":{\"width\":1,\"height\":1,"
       "\"format\":\"jpeg\",\"quality\":1,"
       "\"max_kbps\":1000000}}", PROTO_MSG_SUBSCRIBE),
    OK("view jpeg quality 100", "{\"type\":\"subscribe\",\"view\":{\"width\":1,\"height\":1,"
       "\"format\":\"jpeg\",\"quality\":100,"
       "\"max_kbps\":0.001}}", PROTO_MSG_SUBSCRIBE),
    OK("view png max_kbps", "{\"type\":\"subscribe\",\"view\":{\"width\":1,\"height\":1,"
       "\"format\":\"png\",\"max_kbps\":500}}", PROTO_MSG_SUBSCRIBE),
    OK("view minimum", "{\"type\":\"subscribe\",\"view\":{\"width\":1,\"height\":1,\"fps\":0.5,"
       "\"camera\":{},\"exposure\":{}}}", PROTO_MSG_SUBSCRIBE),
    OK("probe at range ends", "{\"type\":\"probe\",\"quantity\":\"luminance\",\"altitude_km\":100000,"
       "\"view_zenith_deg\":180,\"view_azimuth_deg\":-360,\"sun_zenith_deg\":0}", PROTO_MSG_PROBE),
    OK("probe mu -1", "{\"type\":\"probe\",\"quantity\":\"transmittance\",\"altitude_km\":0,"
       "\"mu\":-1}", PROTO_MSG_PROBE),
    OK("preset name charset", "{\"type\":\"apply_preset\",\"kind\":\"atmosphere\","
       "\"name\":\"a-z_0-9\"}", PROTO_MSG_APPLY_PRESET),

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
    BAD("snapshot without id", "{\"type\":\"snapshot\",\"view\":{\"width\":2,\"height\":2}}",
        MISSING_FIELD, "/id"),
    BAD("view no height", "{\"type\":\"snapshot\",\"id\":1,\"view\":{\"width\":10}}", MISSING_FIELD,
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
    BAD("view format unknown", "{\"type\":\"subscribe\",\"view\":{\"width\":1,\"height\":1,"
        "\"format\":\"gif\"}}", BAD_VALUE, "/view/format"),
    BAD("view quality with png", "{\"type\":\"subscribe\",\"view\":{\"width\":1,\"height\":1,"
        "\"format\":\"png\",\"quality\":80}}", INCONSISTENT, "/view/quality"),
    BAD("view quality without format", "{\"type\":\"subscribe\",\"view\":{\"width\":1,\"height\":1,"
        "\"quality\":80}}", INCONSISTENT, "/view/quality"),
    BAD("view quality with png16", "{\"type\":\"subscribe\",\"view\":{\"width\":1,\"height\":1,"
        "\"format\":\"png16\",\"quality\":80}}", INCONSISTENT, "/view/quality"),
    BAD("view quality 0", "{\"type\":\"subscribe\",\"view\":{\"width\":1,\"height\":1,"
        "\"format\":\"jpeg\",\"quality\":0}}", OUT_OF_RANGE, "/view/quality"),
    BAD("view quality 101", "{\"type\":\"subscribe\",\"view\":{\"width\":1,\"height\":1,"
        "\"format\":\"jpeg\",\"quality\":101}}", OUT_OF_RANGE, "/view/quality"),
    BAD("view quality fraction", "{\"type\":\"subscribe\",\"view\":{\"width\":1,\"height\":1,"
        "\"format\":\"jpeg\",\"quality\":80.5}}", BAD_VALUE, "/view/quality"),
    BAD("view quality string", "{\"type\":\"subscribe\",\"view\":{\"width\":1,\"height\":1,"
        "\"format\":\"jpeg\",\"quality\":\"80\"}}", WRONG_TYPE, "/view/quality"),
    BAD("view max_kbps 0", "{\"type\":\"subscribe\",\"view\":{\"width\":1,\"height\":1,"
        "\"max_kbps\":0}}", OUT_OF_RANGE, "/view/max_kbps"),
    BAD("view max_kbps negative", "{\"type\":\"subscribe\",\"view\":{\"width\":1,\"height\":1,"
        "\"format\":\"jpeg\",\"max_kbps\":-100}}", OUT_OF_RANGE, "/view/max_kbps"),
    BAD("view max_kbps over 1e6", "{\"type\":\"subscribe\",\"view\":{\"width\":1,\"height\":1,"
        "\"max_kbps\":1000001}}", OUT_OF_RANGE, "/view/max_kbps"),
    BAD("view format number", "{\"type\":\"subscribe\",\"view\":{\"width\":1,\"height\":1,"
        "\"format\":1}}", WRONG_TYPE, "/view/format"),
    BAD("view projection unknown", "{\"type\":\"subscribe\",\"view\":{\"width\":2,\"height\":1,"
        "\"projection\":\"fisheye\"}}", BAD_VALUE, "/view/projection"),
    BAD("view projection number", "{\"type\":\"snapshot\",\"id\":1,\"view\":{\"width\":2,\"height\":1,"
        "\"projection\":1}}", WRONG_TYPE, "/view/projection"),
    BAD("equirectangular not 2:1", "{\"type\":\"snapshot\",\"id\":1,\"view\":{\"width\":300,"
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
/* clang-format on */

void test_parse_table(void)
{
    for (size_t i = 0; i < COUNT_OF(parse_cases); i++) {
        const struct parse_case *c = &parse_cases[i];
        check_case_name = c->name;
        struct proto_client_msg msg;
        struct proto_msg_parse_error error;
        enum proto_msg_error_code code = parse(c->text, &msg, &error);
        CHECK_STR(proto_msg_error_name(code), proto_msg_error_name(c->code));
        CHECK_INT(error.code, code);
        if (c->type != PROTO_MSG_NONE)
            CHECK_STR(proto_msg_type_name(msg.type), proto_msg_type_name(c->type));
        if (c->pointer)
            CHECK_STR(first_pointer(&error), c->pointer);
        if (code == PROTO_MSG_OK) {
            CHECK_INT(error.fields.total, 0);
        } else {
            CHECK(error.fields.count >= 1);
            CHECK(error.message[0] != '\0');
            CHECK(msg.type != PROTO_MSG_SET || msg.set.patch == NULL);
            char *reply = proto_msg_build_parse_error(&msg, &error);
            cJSON *json = parse_built(reply, "error");
            CHECK_STR(string_at(json, "code"), proto_msg_error_name(c->code));
            cJSON_Delete(json);
        }
        proto_client_msg_free(&msg);
    }
    check_case_name = "";
}
