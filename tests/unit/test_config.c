/* The configuration file: defaults, the shipped config/skyd.json, and every class of bad
 * input reported by JSON Pointer with a stable code, the defaults left in place. */
#include <stdio.h>
#include <stdlib.h>
#include <math.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "check.h"
#include "config.h"
#include "field_errors.h"

static char dir[] = "/tmp/skyd-config-XXXXXX";

static const char *write_temp(const char *name, const char *text)
{
    static char path[256];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    FILE *f = fopen(path, "wb");
    if (f) {
        fputs(text, f);
        fclose(f);
    }
    return path;
}

struct bad_case {
    const char *text;
    const char *pointer;
    int code;
};

int main(int argc, char **argv)
{
    const char *shipped = argc > 1 ? argv[1] : SKYD_SOURCE_DIR "/config/skyd.json";
    if (!mkdtemp(dir))
        return 1;
    struct skyd_config c, defaults;
    struct proto_field_errors errors;
    char msg[512];
    skyd_config_defaults(&defaults);

    CHECK(skyd_config_load(shipped, &c, &errors, msg, sizeof msg));
    CHECK(strcmp(c.listen_address, "127.0.0.1") == 0 && c.listen_port == 8080);
    CHECK(c.max_clients == 64 && c.max_message_bytes == 65536 && c.origin_count == 2);
    /* The shipped daemon starts on the current UTC time, the sun and moon from the ephemeris. */
    CHECK(c.initial_state.clock.sky_bodies == PROTO_BODIES_EPHEMERIS);
    CHECK(c.initial_state.clock.time_scale == 1);
    CHECK(fabs(c.initial_state.clock.utc_unix_s - (double)time(NULL)) < 5);
    CHECK(memcmp(&defaults.initial_state.atmosphere, &c.initial_state.atmosphere,
                 sizeof c.initial_state.atmosphere) == 0);
    CHECK(defaults.initial_state.clock.sky_bodies == PROTO_BODIES_MANUAL);

    const char *partial = write_temp("partial.json",
                                     "{\"listen\":{\"port\":0},\"render\":{\"device\":\"cpu\"},"
                                     "\"allowed_origins\":[\"http://example.test\"]}");
    CHECK(skyd_config_load(partial, &c, &errors, msg, sizeof msg));
    CHECK(c.listen_port == 0 && strcmp(c.render_device, "cpu") == 0);
    CHECK(c.origin_count == 1 && strcmp(c.allowed_origins[0], "http://example.test") == 0);
    CHECK(c.max_fps == defaults.max_fps); /* untouched fields keep their defaults */
    CHECK(!c.read_only && c.controller_token[0] == '\0');

    /* Encoder threads: 0 (the default and the shipped config's) is one per core but the
     * render thread's, 2 to 64; a number given is kept. */
    long cores = sysconf(_SC_NPROCESSORS_ONLN);
    int expected = cores - 1 < 2 ? 2 : cores - 1 > 64 ? 64 : (int)(cores - 1);
    CHECK(defaults.encoder_threads == 0);
    CHECK(skyd_config_encoder_threads(&defaults) == expected);
    const char *three = write_temp("three.json", "{\"render\":{\"encoder_threads\":3}}");
    CHECK(skyd_config_load(three, &c, &errors, msg, sizeof msg));
    CHECK(skyd_config_encoder_threads(&c) == 3);
    const char *negative = write_temp("negative.json", "{\"render\":{\"encoder_threads\":-1}}");
    CHECK(!skyd_config_load(negative, &c, &errors, msg, sizeof msg));
    CHECK(errors.count >= 1 && strcmp(errors.items[0].pointer, "/render/encoder_threads") == 0);

    /* read_only, and the token left as given (control_token.c decides what they mean). */
    const char *read_only = write_temp("read_only.json",
                                       "{\"read_only\":true,\"controller_token\":\"t\"}");
    CHECK(skyd_config_load(read_only, &c, &errors, msg, sizeof msg));
    CHECK(c.read_only && strcmp(c.controller_token, "t") == 0);

    /* A shared world: both members, well formed; the state file is then not used. */
    const char *cluster = write_temp("cluster.json",
                                     "{\"cluster\":{\"redis\":\"redis://127.0.0.1:6380/2\","
                                     "\"world\":\"class-7_b\"}}");
    CHECK(skyd_config_load(cluster, &c, &errors, msg, sizeof msg));
    CHECK(strcmp(c.cluster_redis, "redis://127.0.0.1:6380/2") == 0 &&
          strcmp(c.cluster_world, "class-7_b") == 0);
    CHECK(defaults.cluster_redis[0] == '\0' && defaults.cluster_world[0] == '\0');
    /* With a user and password in the URL, or a user and a password file (read at start). */
    cluster = write_temp("cluster.json",
                         "{\"cluster\":{\"redis\":\"redis://skyd:p%40ss@127.0.0.1:6380\","
                         "\"world\":\"w\"}}");
    CHECK(skyd_config_load(cluster, &c, &errors, msg, sizeof msg));
    CHECK(strcmp(c.cluster_redis, "redis://skyd:p%40ss@127.0.0.1:6380") == 0);
    cluster = write_temp("cluster.json",
                         "{\"cluster\":{\"redis\":\"redis://skyd@127.0.0.1:6380\","
                         "\"world\":\"w\",\"redis_password_file\":\"/run/skyd/redis\"}}");
    CHECK(skyd_config_load(cluster, &c, &errors, msg, sizeof msg));
    CHECK(strcmp(c.cluster_redis_password_file, "/run/skyd/redis") == 0);

    const struct bad_case cases[] = {
        { "{\"cluster\":{\"redis\":\"redis://h:1\",\"world\":\"a b\"}}", "/cluster/world",
          PROTO_FIELD_BAD_VALUE },
        { "{\"cluster\":{\"redis\":\"redis://h:1\",\"world\":\"x/../y\"}}", "/cluster/world",
          PROTO_FIELD_BAD_VALUE },
        { "{\"cluster\":{\"redis\":\"redis://h:1\"}}", "/cluster/world", PROTO_FIELD_MISSING },
        { "{\"cluster\":{\"world\":\"w\"}}", "/cluster/redis", PROTO_FIELD_MISSING },
        { "{\"cluster\":{\"redis\":\"tcp://h:1\",\"world\":\"w\"}}", "/cluster/redis",
          PROTO_FIELD_BAD_VALUE },
        { "{\"cluster\":{\"redis\":\"redis://h\",\"world\":\"w\"}}", "/cluster/redis",
          PROTO_FIELD_BAD_VALUE },
        { "{\"cluster\":{\"redis\":\"redis://h:0\",\"world\":\"w\"}}", "/cluster/redis",
          PROTO_FIELD_BAD_VALUE },
        { "{\"cluster\":{\"redis\":\"redis://h:6379/x\",\"world\":\"w\"}}", "/cluster/redis",
          PROTO_FIELD_BAD_VALUE },
        { "{\"cluster\":{\"redis\":\"redis://u:p%zz@h:6379\",\"world\":\"w\"}}", "/cluster/redis",
          PROTO_FIELD_BAD_VALUE },
        { "{\"cluster\":{\"redis\":\"redis://u:p@h:6379\",\"world\":\"w\","
          "\"redis_password_file\":\"/run/p\"}}",
          "/cluster/redis_password_file", PROTO_FIELD_INCONSISTENT },
        { "{\"cluster\":{\"redis_password_file\":\"/run/p\"}}", "/cluster/redis",
          PROTO_FIELD_MISSING },
        { "{\"cluster\":{\"redis\":\"redis://h:1\",\"world\":\"w\",\"x\":1}}", "/cluster/x",
          PROTO_FIELD_UNKNOWN },
        { "{\"cluster\":{\"redis\":6379,\"world\":\"w\"}}", "/cluster/redis",
          PROTO_FIELD_WRONG_TYPE },
        { "{\"bogus\":1}", "/bogus", PROTO_FIELD_UNKNOWN },
        { "{\"listen\":{\"portt\":1}}", "/listen/portt", PROTO_FIELD_UNKNOWN },
        { "{\"listen\":{\"port\":\"80\"}}", "/listen/port", PROTO_FIELD_WRONG_TYPE },
        { "{\"listen\":{\"port\":70000}}", "/listen/port", PROTO_FIELD_OUT_OF_RANGE },
        { "{\"listen\":{\"port\":80.5}}", "/listen/port", PROTO_FIELD_BAD_VALUE },
        { "{\"listen\":7}", "/listen", PROTO_FIELD_WRONG_TYPE },
        { "{\"render\":{\"validation\":\"yes\"}}", "/render/validation", PROTO_FIELD_WRONG_TYPE },
        { "{\"read_only\":1}", "/read_only", PROTO_FIELD_WRONG_TYPE },
        { "{\"limits\":{\"max_fps\":0}}", "/limits/max_fps", PROTO_FIELD_OUT_OF_RANGE },
        { "{\"limits\":{\"max_clients\":-1}}", "/limits/max_clients", PROTO_FIELD_OUT_OF_RANGE },
        { "{\"limits\":{\"max_queued_http_requests\":0}}", "/limits/max_queued_http_requests",
          PROTO_FIELD_OUT_OF_RANGE },
        { "{\"limits\":{\"max_queued_http_requests\":\"8\"}}", "/limits/max_queued_http_requests",
          PROTO_FIELD_WRONG_TYPE },
        { "{\"allowed_origins\":\"*\"}", "/allowed_origins", PROTO_FIELD_WRONG_TYPE },
        { "{\"allowed_origins\":[1]}", "/allowed_origins/0", PROTO_FIELD_WRONG_TYPE },
        { "[]", "", PROTO_FIELD_WRONG_TYPE },
        { "{\"initial_state\":{\"clock\":{\"time_scale\":-1}}}", "/initial_state/clock/time_scale",
          PROTO_FIELD_OUT_OF_RANGE },
        { "{\"initial_state\":{\"clock\":{\"utc\":\"yesterday\"}}}", "/initial_state/clock/utc",
          PROTO_FIELD_BAD_VALUE },
        { "{\"initial_state\":3}", "/initial_state", PROTO_FIELD_WRONG_TYPE },
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        const char *path = write_temp("bad.json", cases[i].text);
        bool ok = skyd_config_load(path, &c, &errors, msg, sizeof msg);
        CHECK(!ok);
        CHECK(errors.count >= 1);
        if (errors.count >= 1) {
            if (strcmp(errors.items[0].pointer, cases[i].pointer) != 0 ||
                errors.items[0].code != cases[i].code)
                printf("case %zu (%s): got %s code %d, expected %s code %d\n", i, cases[i].text,
                       errors.items[0].pointer, errors.items[0].code, cases[i].pointer,
                       cases[i].code);
            CHECK(strcmp(errors.items[0].pointer, cases[i].pointer) == 0);
            CHECK(errors.items[0].code == cases[i].code);
        }
        CHECK(memcmp(&c, &defaults, sizeof c) == 0); /* nothing half-applied */
    }

    /* Several errors at once are all reported. */
    const char *many = write_temp("many.json", "{\"a\":1,\"listen\":{\"port\":-5},\"b\":2}");
    CHECK(!skyd_config_load(many, &c, &errors, msg, sizeof msg));
    CHECK(errors.total == 3);

    const char *broken = write_temp("broken.json", "{\"listen\": {\"port\": 80,}");
    CHECK(!skyd_config_load(broken, &c, &errors, msg, sizeof msg));
    CHECK(strstr(msg, "invalid JSON at byte") != NULL);
    CHECK(!skyd_config_load("/nonexistent/skyd.json", &c, &errors, msg, sizeof msg));
    CHECK(strstr(msg, "cannot open") != NULL);

    unlink(write_temp("partial.json", ""));
    unlink(write_temp("cluster.json", ""));
    unlink(write_temp("read_only.json", ""));
    unlink(write_temp("bad.json", ""));
    unlink(write_temp("many.json", ""));
    unlink(write_temp("broken.json", ""));
    rmdir(dir);
    return check_summary();
}
