/* Unit tests for client weather maps (protocol/weather_map.c) and the set_weather_map message
 * (protocol/messages.c): base64 against RFC 4648's vectors, texels decoded exactly (no gamma
 * conversion of 16-bit files), size bounds before inflation, and the upload size rule. */
#include "messages.h"
#include "weather_map.h"

#include <png.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"

static void test_base64(void)
{
    /* RFC 4648 section 10. */
    static const char *const plain[] = { "", "f", "fo", "foo", "foob", "fooba", "foobar" };
    static const char *const coded[] = { "",         "Zg==",     "Zm8=",    "Zm9v",
                                         "Zm9vYg==", "Zm9vYmE=", "Zm9vYmFy" };
    char reason[128];
    for (int i = 0; i < 7; i++) {
        char *text = proto_base64_encode((const uint8_t *)plain[i], strlen(plain[i]));
        CHECK(text && strcmp(text, coded[i]) == 0);
        free(text);
        uint8_t *bytes;
        size_t length;
        CHECK(proto_base64_decode(coded[i], strlen(coded[i]), &bytes, &length, reason,
                                  sizeof reason));
        CHECK(length == strlen(plain[i]) && memcmp(bytes, plain[i], length) == 0);
        free(bytes);
    }
    uint8_t random_bytes[1000];
    unsigned state = 12345;
    for (size_t i = 0; i < sizeof random_bytes; i++)
        random_bytes[i] = (uint8_t)((state = state * 1103515245u + 12345u) >> 16);
    for (size_t n = 997; n <= 1000; n++) {
        char *text = proto_base64_encode(random_bytes, n);
        uint8_t *bytes = NULL; /* still NULL, and length 0, when encoding failed */
        size_t length = 0;
        CHECK(text &&
              proto_base64_decode(text, strlen(text), &bytes, &length, reason, sizeof reason));
        CHECK(length == n && memcmp(bytes, random_bytes, n) == 0);
        free(bytes);
        free(text);
    }
    /* clang-format off */
    static const struct {
        const char *text;
        const char *reason;
    } bad[] = {
        {"Zg=", "not a multiple of 4"},
        {"Zg==Zm8=", "offset 2"},   /* padding inside */
        {"Z*==", "offset 1"},
        {"Zm9v\n", "not a multiple of 4"},
        {"Zm9 ", "offset 3"},
        {"====", "offset 0"},
    };
    /* clang-format on */
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        uint8_t *bytes = (uint8_t *)"untouched";
        size_t length = 1;
        CHECK(!proto_base64_decode(bad[i].text, strlen(bad[i].text), &bytes, &length, reason,
                                   sizeof reason));
        CHECK(bytes == NULL && length == 0);
        CHECK_MSG(strstr(reason, bad[i].reason) != NULL, "\"%s\": %s", bad[i].text, reason);
    }
}

/* A PNG in memory through libpng's simplified writer. */
static uint8_t *write_png(uint32_t width, uint32_t height, uint32_t format, const void *pixels,
                          size_t *length)
{
    png_image image;
    memset(&image, 0, sizeof image);
    image.version = PNG_IMAGE_VERSION;
    image.width = width;
    image.height = height;
    image.format = format;
    png_alloc_size_t size = 0;
    if (!png_image_write_to_memory(&image, NULL, &size, 0, pixels, 0, NULL))
        return NULL;
    uint8_t *bytes = malloc(size);
    if (bytes && !png_image_write_to_memory(&image, bytes, &size, 0, pixels, 0, NULL)) {
        free(bytes);
        return NULL;
    }
    *length = size;
    return bytes;
}

static void test_png(void)
{
    char reason[160];
    struct proto_weather_map map;
    size_t length = 0;

    const uint8_t rgba[3 * 2 * 4] = { 0, 1, 2, 3, 40, 50, 60, 70, 255, 128, 7,   0,
                                      9, 8, 7, 6, 99, 98, 97, 96, 200, 201, 202, 203 };
    uint8_t *png = write_png(3, 2, PNG_FORMAT_RGBA, rgba, &length);
    CHECK(png != NULL);
    CHECK(proto_weather_map_decode(PROTO_WEATHER_MAP_PNG, png, length, 0, 0, &map, reason,
                                   sizeof reason));
    CHECK(map.width == 3 && map.height == 2 && memcmp(map.rgba, rgba, sizeof rgba) == 0);
    proto_weather_map_free(&map);
    CHECK(proto_weather_map_decode(PROTO_WEATHER_MAP_PNG, png, length, 3, 2, &map, reason,
                                   sizeof reason));
    proto_weather_map_free(&map);
    CHECK(!proto_weather_map_decode(PROTO_WEATHER_MAP_PNG, png, length, 4, 0, &map, reason,
                                    sizeof reason));
    CHECK_MSG(strstr(reason, "3x2") != NULL, "%s", reason);
    CHECK(!proto_weather_map_decode(PROTO_WEATHER_MAP_PNG, png, length / 2, 0, 0, &map, reason,
                                    sizeof reason));
    CHECK(map.rgba == NULL && map.width == 0);
    CHECK(!proto_weather_map_decode(PROTO_WEATHER_MAP_PNG, rgba, sizeof rgba, 0, 0, &map, reason,
                                    sizeof reason));
    CHECK_MSG(strstr(reason, "signature") != NULL, "%s", reason);
    free(png);

    /* RGB: no alpha channel means no precipitation. */
    const uint8_t rgb[2 * 3] = { 10, 20, 30, 250, 251, 252 };
    png = write_png(2, 1, PNG_FORMAT_RGB, rgb, &length);
    CHECK(png && proto_weather_map_decode(PROTO_WEATHER_MAP_PNG, png, length, 0, 0, &map, reason,
                                          sizeof reason));
    const uint8_t rgb_expected[8] = { 10, 20, 30, 0, 250, 251, 252, 0 };
    CHECK(map.rgba && memcmp(map.rgba, rgb_expected, 8) == 0);
    proto_weather_map_free(&map);
    free(png);

    /* 16-bit grey, written linear: the stored value, not an sRGB encoding of it (which
     * libpng's simplified reader would give: about 188 for half). */
    const uint16_t grey16[2] = { 32768, 65535 };
    png = write_png(2, 1, PNG_FORMAT_GRAY | PNG_FORMAT_FLAG_LINEAR, grey16, &length);
    CHECK(png && proto_weather_map_decode(PROTO_WEATHER_MAP_PNG, png, length, 0, 0, &map, reason,
                                          sizeof reason));
    CHECK_MSG(map.rgba && map.rgba[0] == 128 && map.rgba[1] == 128 && map.rgba[3] == 0 &&
                  map.rgba[4] == 255,
              "half grey read as %d", map.rgba ? map.rgba[0] : -1);
    proto_weather_map_free(&map);
    free(png);

    /* Bounds come from the header, before any texel is inflated. */
    uint8_t *wide = calloc((size_t)(PROTO_WEATHER_MAP_MAX_SIDE + 1) * 4, 1);
    png = write_png(PROTO_WEATHER_MAP_MAX_SIDE + 1, 1, PNG_FORMAT_RGBA, wide, &length);
    CHECK(png && !proto_weather_map_decode(PROTO_WEATHER_MAP_PNG, png, length, 0, 0, &map, reason,
                                           sizeof reason));
    CHECK(map.rgba == NULL);
    CHECK_MSG(strstr(reason, "513x1; each side must be 1..512") != NULL, "%s", reason);
    free(png);
    free(wide);
}

static void test_rgba8(void)
{
    char reason[160];
    struct proto_weather_map map;
    uint8_t texels[2 * 3 * 4];
    for (size_t i = 0; i < sizeof texels; i++)
        texels[i] = (uint8_t)(i * 7);
    CHECK(proto_weather_map_decode(PROTO_WEATHER_MAP_RGBA8, texels, sizeof texels, 2, 3, &map,
                                   reason, sizeof reason));
    CHECK(map.width == 2 && map.height == 3 && memcmp(map.rgba, texels, sizeof texels) == 0);
    proto_weather_map_free(&map);
    CHECK(!proto_weather_map_decode(PROTO_WEATHER_MAP_RGBA8, texels, sizeof texels, 3, 2 + 1, &map,
                                    reason, sizeof reason));
    CHECK_MSG(strstr(reason, "36 bytes, got 24") != NULL, "%s", reason);
    CHECK(!proto_weather_map_decode(PROTO_WEATHER_MAP_RGBA8, texels, 0, 0, 3, &map, reason,
                                    sizeof reason));
    CHECK(!proto_weather_map_decode(PROTO_WEATHER_MAP_RGBA8, texels, sizeof texels,
                                    PROTO_WEATHER_MAP_MAX_SIDE + 1, 1, &map, reason,
                                    sizeof reason));
}

static char *weather_message(const char *format, int width, int height, const uint8_t *bytes,
                             size_t length, size_t padding)
{
    char *data = proto_base64_encode(bytes, length);
    size_t size = strlen(data) + padding + 256;
    char *text = malloc(size);
    int n = snprintf(text, size, "{\"type\":\"set_weather_map\",\"id\":9,\"format\":\"%s\",",
                     format);
    if (width)
        n += snprintf(text + n, size - (size_t)n, "\"width\":%d,\"height\":%d,", width, height);
    n += snprintf(text + n, size - (size_t)n, "\"data\":\"%s\"", data);
    memset(text + n, ' ', padding);
    snprintf(text + n + padding, size - (size_t)n - padding, "}");
    free(data);
    return text;
}

static void test_message(void)
{
    struct proto_msg_limits limits;
    proto_msg_limits_default(&limits);
    limits.max_message_bytes = 1024;
    limits.max_upload_bytes = 8192;
    struct proto_client_msg msg;
    struct proto_msg_parse_error error;
    CHECK(proto_msg_needs_controller(PROTO_MSG_SET_WEATHER_MAP));

    uint8_t texels[32 * 32 * 4];
    for (size_t i = 0; i < sizeof texels; i++)
        texels[i] = (uint8_t)(i * 13 + 1);
    /* 5.5 KB of base64: above max_message_bytes, within max_upload_bytes. */
    char *text = weather_message("rgba8", 32, 32, texels, sizeof texels, 0);
    CHECK(strlen(text) > limits.max_message_bytes);
    CHECK(proto_msg_parse(text, strlen(text), &limits, &msg, &error) == PROTO_MSG_OK);
    CHECK(msg.type == PROTO_MSG_SET_WEATHER_MAP && msg.id.number == 9);
    CHECK(msg.weather_map.width == 32 && msg.weather_map.height == 32 &&
          memcmp(msg.weather_map.rgba, texels, sizeof texels) == 0);
    proto_client_msg_free(&msg);
    CHECK(msg.weather_map.rgba == NULL);
    free(text);

    /* Past max_upload_bytes: refused before parsing. */
    text = weather_message("rgba8", 32, 32, texels, sizeof texels, 4096);
    CHECK(proto_msg_parse(text, strlen(text), &limits, &msg, &error) ==
          PROTO_MSG_ERR_MESSAGE_TOO_LARGE);
    proto_client_msg_free(&msg);
    free(text);

    /* Any other type above max_message_bytes is too large, id echoed. */
    char big[2048];
    int n = snprintf(big, sizeof big, "{\"type\":\"get_state\",\"id\":5");
    memset(big + n, ' ', 1500);
    snprintf(big + n + 1500, sizeof big - (size_t)n - 1500, "}");
    CHECK(proto_msg_parse(big, strlen(big), &limits, &msg, &error) ==
          PROTO_MSG_ERR_MESSAGE_TOO_LARGE);
    CHECK(msg.id.number == 5);
    CHECK_MSG(strstr(error.message, "only set_weather_map") != NULL, "%s", error.message);
    proto_client_msg_free(&msg);

    /* A PNG needs no width and height; wrong ones are refused. */
    size_t length = 0;
    uint8_t *png = write_png(4, 2, PNG_FORMAT_RGBA, texels, &length);
    text = weather_message("png", 0, 0, png, length, 0);
    CHECK(proto_msg_parse(text, strlen(text), &limits, &msg, &error) == PROTO_MSG_OK);
    CHECK(msg.weather_map.width == 4 && msg.weather_map.height == 2 &&
          memcmp(msg.weather_map.rgba, texels, 32) == 0);
    proto_client_msg_free(&msg);
    free(text);
    text = weather_message("png", 4, 3, png, length, 0);
    CHECK(proto_msg_parse(text, strlen(text), &limits, &msg, &error) == PROTO_MSG_ERR_BAD_VALUE);
    CHECK(strcmp(error.fields.items[0].pointer, "/data") == 0);
    CHECK(msg.weather_map.rgba == NULL);
    proto_client_msg_free(&msg);
    free(text);
    free(png);

    /* clang-format off */
    static const struct {
        const char *text;
        enum proto_msg_error_code code;
        const char *pointer;
    } bad[] = {
        {"{\"type\":\"set_weather_map\",\"format\":\"rgba8\",\"height\":1,\"data\":\"AAAAAA==\"}",
         PROTO_MSG_ERR_MISSING_FIELD, "/width"},
        {"{\"type\":\"set_weather_map\",\"format\":\"png\"}", PROTO_MSG_ERR_MISSING_FIELD, "/data"},
        {"{\"type\":\"set_weather_map\",\"data\":\"\"}", PROTO_MSG_ERR_MISSING_FIELD, "/format"},
        {"{\"type\":\"set_weather_map\",\"format\":\"tiff\",\"data\":\"\"}", PROTO_MSG_ERR_BAD_VALUE,
         "/format"},
        {"{\"type\":\"set_weather_map\",\"format\":\"rgba8\",\"width\":1,\"height\":1,"
         "\"data\":[1]}", PROTO_MSG_ERR_WRONG_TYPE, "/data"},
        {"{\"type\":\"set_weather_map\",\"format\":\"rgba8\",\"width\":1.5,\"height\":1,"
         "\"data\":\"AAAAAA==\"}", PROTO_MSG_ERR_BAD_VALUE, "/width"},
        {"{\"type\":\"set_weather_map\",\"format\":\"rgba8\",\"width\":1,\"height\":0,"
         "\"data\":\"AAAAAA==\"}", PROTO_MSG_ERR_OUT_OF_RANGE, "/height"},
        {"{\"type\":\"set_weather_map\",\"format\":\"rgba8\",\"width\":1,\"height\":1,"
         "\"data\":\"AAAA\"}", PROTO_MSG_ERR_BAD_VALUE, "/data"},
        {"{\"type\":\"set_weather_map\",\"format\":\"rgba8\",\"width\":1,\"height\":1,"
         "\"data\":\"AAAAAA==\",\"tile\":true}", PROTO_MSG_ERR_UNKNOWN_FIELD, "/tile"},
    };
    /* clang-format on */
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        enum proto_msg_error_code code = proto_msg_parse(bad[i].text, strlen(bad[i].text), &limits,
                                                         &msg, &error);
        CHECK_MSG(code == bad[i].code && error.fields.count > 0 &&
                      strcmp(error.fields.items[0].pointer, bad[i].pointer) == 0,
                  "case %zu: code %d, %s", i, (int)code, error.message);
        CHECK(msg.weather_map.rgba == NULL);
        proto_client_msg_free(&msg);
    }
    const char *good = "{\"type\":\"set_weather_map\",\"format\":\"rgba8\",\"width\":1,"
                       "\"height\":1,\"data\":\"AQIDBA==\"}";
    CHECK(proto_msg_parse(good, strlen(good), &limits, &msg, &error) == PROTO_MSG_OK);
    CHECK(msg.weather_map.rgba && msg.weather_map.rgba[0] == 1 && msg.weather_map.rgba[3] == 4);
    proto_client_msg_free(&msg);

    char *hello = proto_msg_build_hello("1", PROTO_ROLE_VIEWER, NULL, 0, &limits);
    CHECK(hello && strstr(hello, "\"max_upload_bytes\":8192") != NULL);
    free(hello);
}

/* A deep copy: its own texels, equal to the original's; a map without texels copies as one. */
static void test_copy(void)
{
    uint8_t texels[8] = { 1, 2, 3, 4, 250, 251, 252, 253 };
    struct proto_weather_map from = { .rgba = texels, .width = 2, .height = 1 }, to;
    CHECK(proto_weather_map_copy(&from, &to));
    CHECK(to.rgba != NULL && to.rgba != texels);
    CHECK(to.width == 2 && to.height == 1);
    CHECK(to.rgba && memcmp(to.rgba, texels, sizeof texels) == 0);
    proto_weather_map_free(&to);
    struct proto_weather_map none = { 0 };
    CHECK(proto_weather_map_copy(&none, &to));
    CHECK(to.rgba == NULL && to.width == 0 && to.height == 0);
}

int main(void)
{
    test_base64();
    test_png();
    test_rgba8();
    test_message();
    test_copy();
    return check_summary();
}
