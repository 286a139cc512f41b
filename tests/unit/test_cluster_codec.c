/* What a shared world's entries carry (server/host/world_codec.c, server/cluster/): a state
 * read back from its text is the state, revision included; a weather map read back from its
 * bytes is the map; bytes that are not a map, and bad URLs and world names, are refused with
 * a reason; a URL's user and password are read, and no message or redacted URL holds the
 * password. No Redis here: tests/e2e/test_cluster.py runs the real thing. */
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "cluster_url.h"
#include "world_codec.h"

static void state_round_trip(void)
{
    struct proto_world_state state, back;
    proto_world_state_defaults(&state);
    state.revision = 4242;
    state.weather.humidity = 0.123456789012345;
    state.location.latitude_deg = -33.8688;
    char *text = world_codec_state_text(&state);
    CHECK(text != NULL);
    if (!text)
        return;
    char why[512] = "";
    proto_world_state_defaults(&back);
    CHECK(world_codec_parse_state(text, &back, why, sizeof why));
    CHECK(back.revision == 4242);
    CHECK(back.weather.humidity == state.weather.humidity); /* exact: the text keeps doubles */
    CHECK(back.location.latitude_deg == state.location.latitude_deg);
    char *again = world_codec_state_text(&back);
    CHECK(again && strcmp(again, text) == 0);
    free(again);
    free(text);
    struct proto_world_state untouched = back;
    CHECK(!world_codec_parse_state("{\"revision\":1,\"weather\":{\"humidity\":7}}", &back, why,
                                   sizeof why));
    CHECK(strstr(why, "humidity") != NULL);
    CHECK(memcmp(&untouched, &back, sizeof back) == 0);
}

static void map_round_trip(void)
{
    uint8_t texels[3 * 2 * 4];
    for (size_t i = 0; i < sizeof texels; i++)
        texels[i] = (uint8_t)(i * 11);
    struct proto_weather_map map = { .width = 3, .height = 2, .rgba = texels }, back;
    size_t length = 0;
    unsigned char *bytes = world_codec_map_bytes(&map, &length);
    CHECK(bytes && length == 8 + sizeof texels);
    if (!bytes)
        return;
    CHECK(world_codec_parse_map(bytes, length, &back));
    CHECK(back.width == 3 && back.height == 2 && back.rgba &&
          memcmp(back.rgba, texels, sizeof texels) == 0);
    proto_weather_map_free(&back);
    CHECK(!world_codec_parse_map(bytes, length - 1, &back) && back.rgba == NULL);
    CHECK(!world_codec_parse_map(bytes, 7, &back));
    bytes[0] = 0; /* width 0 */
    CHECK(!world_codec_parse_map(bytes, length, &back));
    free(bytes);
}

/* A user and password in the URL: percent-decoded, the last '@' ends them; messages and the
 * redacted URL never hold the password. */
static void credentials(void)
{
    struct cluster_address a;
    char why[320], text[CLUSTER_URL_TEXT_MAX];
    CHECK(cluster_url_parse("redis://127.0.0.1:6379", &a, why, sizeof why));
    CHECK(!cluster_address_authenticates(&a) && !a.has_db);
    cluster_url_redacted(&a, text, sizeof text);
    CHECK_MSG(strcmp(text, "redis://127.0.0.1:6379") == 0, "%s", text);

    CHECK(cluster_url_parse("redis://skyd:s3cret-Word@redis.internal:6380/2", &a, why, sizeof why));
    CHECK(strcmp(a.user, "skyd") == 0 && strcmp(a.password, "s3cret-Word") == 0 && a.has_password &&
          cluster_address_authenticates(&a));
    CHECK(strcmp(a.host, "redis.internal") == 0 && a.port == 6380 && a.db == 2 && a.has_db);
    cluster_url_redacted(&a, text, sizeof text);
    CHECK_MSG(strcmp(text, "redis://skyd:***@redis.internal:6380/2") == 0, "%s", text);

    /* Reserved characters, encoded or (for '@', ':' and '/' in the password) not. */
    CHECK(cluster_url_parse("redis://sk%79d:p%40ss%3Aw%2Frd%25@[::1]:6379", &a, why, sizeof why));
    CHECK(strcmp(a.user, "skyd") == 0 && strcmp(a.password, "p@ss:w/rd%") == 0);
    cluster_url_redacted(&a, text, sizeof text);
    CHECK_MSG(strcmp(text, "redis://skyd:***@[::1]:6379") == 0, "%s", text);
    CHECK(cluster_url_parse("redis://skyd:p@ss:w/rd@h:1", &a, why, sizeof why));
    CHECK(strcmp(a.password, "p@ss:w/rd") == 0 && strcmp(a.host, "h") == 0 && a.port == 1);

    /* The default user with a password; a user whose password comes from a file. */
    CHECK(cluster_url_parse("redis://:only-a-password@h:1/0", &a, why, sizeof why));
    CHECK(a.user[0] == '\0' && strcmp(a.password, "only-a-password") == 0);
    cluster_url_redacted(&a, text, sizeof text);
    CHECK_MSG(strcmp(text, "redis://:***@h:1/0") == 0, "%s", text);
    CHECK(cluster_url_parse("redis://skyd@h:1", &a, why, sizeof why));
    CHECK(strcmp(a.user, "skyd") == 0 && !a.has_password && cluster_address_authenticates(&a));
    cluster_url_redacted(&a, text, sizeof text);
    CHECK_MSG(strcmp(text, "redis://skyd@h:1") == 0, "%s", text);

    /* Refusals say why without the password. */
    const char *secret_urls[] = { "rediss://skyd:TOPSECRET@h:1",  "http://skyd:TOPSECRET@h:1",
                                  "redis://skyd:TOPSECRET%4@h:1", "redis://skyd:TOPSECRET@h",
                                  "redis://skyd:TOPSECRET@h:0",   "skyd:TOPSECRET@h:1" };
    for (size_t i = 0; i < sizeof secret_urls / sizeof secret_urls[0]; i++) {
        why[0] = '\0';
        CHECK_MSG(!cluster_url_parse(secret_urls[i], &a, why, sizeof why) && why[0] &&
                      !strstr(why, "TOPSECRET"),
                  "%s: %s", secret_urls[i], why);
        CHECK(!strstr(a.password, "TOPSECRET"));
    }
    CHECK(cluster_url_parse("redis://skyd:x@h:1", &a, why, sizeof why));
    CHECK(!cluster_url_parse("rediss://skyd:TOPSECRET@h:1", &a, why, sizeof why));
    CHECK_MSG(strstr(why, "stunnel"), "%s", why);
    char long_password[CLUSTER_PASSWORD_MAX + 40];
    snprintf(long_password, sizeof long_password, "redis://u:%0*d@h:1", CLUSTER_PASSWORD_MAX, 7);
    CHECK(!cluster_url_parse(long_password, &a, why, sizeof why) && strstr(why, "longer"));
}

static void urls_and_names(void)
{
    struct cluster_address a;
    char why[320];
    CHECK(cluster_url_parse("redis://127.0.0.1:6379", &a, why, sizeof why));
    CHECK(strcmp(a.host, "127.0.0.1") == 0 && a.port == 6379 && a.db == 0);
    CHECK(cluster_url_parse("redis://redis-1.internal:7000/5", &a, why, sizeof why));
    CHECK(strcmp(a.host, "redis-1.internal") == 0 && a.port == 7000 && a.db == 5);
    CHECK(cluster_url_parse("redis://[::1]:6380/2", &a, why, sizeof why));
    CHECK(strcmp(a.host, "::1") == 0 && a.port == 6380 && a.db == 2);
    const char *bad[] = { "",
                          "redis://",
                          "redis://:6379",
                          "redis://h",
                          "redis://h:",
                          "redis://h:65536",
                          "redis://h:-1",
                          "redis://h:6379/",
                          "redis://h:1/a",
                          "redis://h:1x",
                          "rediss://h:1",
                          "redis://@h:1",
                          "redis://u%4:p@h:1",
                          "redis://u:p%zz@h:1",
                          "redis://u:p%00@h:1",
                          "redis://a%20b:p@h:1",
                          "redis://u:p@:1",
                          "redis://[::1:1",
                          "redis://h h:1" };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        why[0] = '\0';
        CHECK_MSG(!cluster_url_parse(bad[i], &a, why, sizeof why) && why[0], "\"%s\"", bad[i]);
    }
    credentials();
    CHECK(cluster_world_name_check("classroom-3_b", why, sizeof why));
    char long_name[CLUSTER_WORLD_MAX + 2];
    memset(long_name, 'w', sizeof long_name - 1);
    long_name[sizeof long_name - 1] = '\0';
    CHECK(!cluster_world_name_check(long_name, why, sizeof why));
    long_name[CLUSTER_WORLD_MAX] = '\0';
    CHECK(cluster_world_name_check(long_name, why, sizeof why));
    CHECK(!cluster_world_name_check("", why, sizeof why));
    CHECK(!cluster_world_name_check("a:b", why, sizeof why) && strstr(why, "':'"));
    CHECK(!cluster_world_name_check("{w}", why, sizeof why));
}

int main(void)
{
    state_round_trip();
    map_round_trip();
    urls_and_names();
    return check_summary();
}
