/* skyctl get, set, preset, weather-map, metar, forecast, probe and stats: one request, one reply
 * each. */
#include "skyctl.h"
#include "weather_map.h"

#include <cjson/cJSON.h>
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Connects, sends msg, prints nothing; the reply goes to *reply on SKYCTL_OK. Frees msg. */
static int one_request(const struct skyctl_options *options, const char *what, cJSON *msg,
                       cJSON **reply)
{
    struct skyctl_session session;
    int rc = skyctl_connect(options, &session);
    if (rc == SKYCTL_OK) {
        rc = skyctl_request(&session, what, msg, reply);
        skyctl_disconnect(&session);
    }
    cJSON_Delete(msg);
    return rc;
}

static cJSON *message(const char *type)
{
    cJSON *msg = cJSON_CreateObject();
    cJSON_AddStringToObject(msg, "type", type);
    return msg;
}

static long revision_of(const cJSON *reply)
{
    const cJSON *revision = cJSON_GetObjectItemCaseSensitive(reply, "revision");
    return cJSON_IsNumber(revision) ? (long)revision->valuedouble : -1;
}

/* --json output of get: {"path": P, "value": V, "revision": R}, or {"state": S, "revision": R}
 * without a path. */
static void print_get_json(const char *path, const cJSON *value, long revision)
{
    cJSON *out = cJSON_CreateObject();
    if (path)
        cJSON_AddStringToObject(out, "path", path);
    cJSON_AddItemToObject(out, path ? "value" : "state", cJSON_Duplicate(value, true));
    cJSON_AddNumberToObject(out, "revision", (double)revision);
    skyctl_print_json_line(out);
    cJSON_Delete(out);
}

int skyctl_get(const struct skyctl_options *options, int argc, char **argv)
{
    if (argc > 2)
        return skyctl_usage_error("get", "takes at most one PATH");
    const char *path = argc == 2 ? argv[1] : NULL;
    cJSON *reply = NULL;
    int rc = one_request(options, "get", message("get_state"), &reply);
    if (rc)
        return rc;
    long revision = revision_of(reply);
    if (path && strcmp(path, "revision") == 0) {
        cJSON *value = cJSON_CreateNumber((double)revision);
        if (options->json)
            print_get_json(path, value, revision);
        else
            printf("%ld\n", revision);
        cJSON_Delete(value);
        cJSON_Delete(reply);
        return SKYCTL_OK;
    }
    const cJSON *state = cJSON_GetObjectItemCaseSensitive(reply, "state");
    const cJSON *value = path ? skyctl_lookup(state, path) : state;
    if (!value) {
        fprintf(stderr, "skyctl get: the world state has no field %s\n", path);
        cJSON_Delete(reply);
        return SKYCTL_USAGE;
    }
    if (options->json)
        print_get_json(path, value, revision);
    else
        skyctl_print_value(value);
    cJSON_Delete(reply);
    return SKYCTL_OK;
}

/* The reply to set, preset and weather-map: its revision, or with --json the whole ack. */
static void print_ack(const struct skyctl_options *options, cJSON *reply)
{
    if (options->json)
        skyctl_print_reply_json(reply);
    else
        printf("revision %ld\n", revision_of(reply));
}

int skyctl_set(const struct skyctl_options *options, int argc, char **argv)
{
    if (argc < 2)
        return skyctl_usage_error("set", "needs at least one PATH=VALUE");
    cJSON *msg = message("set");
    cJSON *patch = cJSON_AddObjectToObject(msg, "patch");
    for (int i = 1; i < argc; i++) {
        char err[320];
        if (!skyctl_assign(patch, argv[i], err, sizeof err)) {
            cJSON_Delete(msg);
            return skyctl_usage_error("set", "%s", err);
        }
    }
    cJSON *reply = NULL;
    int rc = one_request(options, "set", msg, &reply);
    if (rc == SKYCTL_OK)
        print_ack(options, reply);
    cJSON_Delete(reply);
    return rc;
}

/* preset [--kind K] [--transition-s S] NAME | preset --list [--kind K] */
int skyctl_preset(const struct skyctl_options *options, int argc, char **argv)
{
    const char *kind = "atmosphere";
    const char *name = NULL;
    double transition_s = -1;
    bool list = false;
    for (int i = 1; i < argc; i++) {
        if (strcmp(argv[i], "--list") == 0) {
            list = true;
        } else if (strcmp(argv[i], "--kind") == 0 && i + 1 < argc) {
            kind = argv[++i];
        } else if (strcmp(argv[i], "--transition-s") == 0 && i + 1 < argc) {
            if (!skyctl_parse_number(argv[++i], 0, 1e9, &transition_s))
                return skyctl_usage_error("preset", "--transition-s needs seconds >= 0, not %s",
                                          argv[i]);
        } else if (argv[i][0] == '-') {
            return skyctl_usage_error("preset", "unknown option or missing value: %s", argv[i]);
        } else if (!name) {
            name = argv[i];
        } else {
            return skyctl_usage_error("preset", "takes one NAME");
        }
    }
    if (list == (name != NULL))
        return skyctl_usage_error("preset", "give either NAME or --list");
    cJSON *msg = message(list ? "list_presets" : "apply_preset");
    cJSON_AddStringToObject(msg, "kind", kind);
    if (!list) {
        cJSON_AddStringToObject(msg, "name", name);
        if (transition_s >= 0)
            cJSON_AddNumberToObject(msg, "transition_s", transition_s);
    }
    cJSON *reply = NULL;
    int rc = one_request(options, list ? "preset --list" : "preset", msg, &reply);
    if (rc == SKYCTL_OK && options->json && list) {
        skyctl_print_reply_json(reply);
    } else if (rc == SKYCTL_OK && list) {
        const cJSON *entry;
        cJSON_ArrayForEach(entry, cJSON_GetObjectItemCaseSensitive(reply, "names"))
        {
            if (cJSON_IsString(entry))
                printf("%s\n", entry->valuestring);
        }
    } else if (rc == SKYCTL_OK) {
        print_ack(options, reply);
    }
    cJSON_Delete(reply);
    return rc;
}

/* A whole file, at most max_bytes; NULL with a reason on stderr. */
static unsigned char *read_file(const char *path, size_t max_bytes, size_t *length)
{
    FILE *f = fopen(path, "rb");
    if (!f) {
        fprintf(stderr, "skyctl weather-map: cannot open %s: %s\n", path, strerror(errno));
        return NULL;
    }
    unsigned char *bytes = malloc(max_bytes + 1);
    size_t n = bytes ? fread(bytes, 1, max_bytes + 1, f) : 0;
    bool failed = !bytes || ferror(f) || n > max_bytes;
    fclose(f);
    if (failed) {
        fprintf(stderr, "skyctl weather-map: %s: %s\n", path,
                !bytes          ? "out of memory"
                : n > max_bytes ? "too large"
                                : "read error");
        free(bytes);
        return NULL;
    }
    *length = n;
    return bytes;
}

/* weather-map FILE.png: the client weather map (PROTOCOL.md, set_weather_map). */
int skyctl_weather_map(const struct skyctl_options *options, int argc, char **argv)
{
    if (argc != 2)
        return skyctl_usage_error("weather-map", "takes one FILE.png");
    size_t length = 0;
    unsigned char *png = read_file(argv[1], 16u << 20, &length);
    if (!png)
        return SKYCTL_USAGE;
    char *data = proto_base64_encode(png, length);
    free(png);
    if (!data) {
        fprintf(stderr, "skyctl weather-map: out of memory\n");
        return SKYCTL_USAGE;
    }
    cJSON *msg = message("set_weather_map");
    cJSON_AddStringToObject(msg, "format", "png");
    cJSON_AddStringToObject(msg, "data", data);
    free(data);
    cJSON *reply = NULL;
    int rc = one_request(options, "weather-map", msg, &reply);
    if (rc == SKYCTL_OK)
        print_ack(options, reply);
    cJSON_Delete(reply);
    return rc;
}

/* metar "TEXT": apply_observation (PROTOCOL.md). Prints the new revision and a line per group
 * the world could not place; with --json the whole reply. */
int skyctl_metar(const struct skyctl_options *options, int argc, char **argv)
{
    if (argc != 2)
        return skyctl_usage_error("metar", "takes one REPORT (quote it: \"METAR EGLL ...\")");
    cJSON *msg = message("apply_observation");
    cJSON_AddStringToObject(msg, "metar", argv[1]);
    cJSON *reply = NULL;
    int rc = one_request(options, "metar", msg, &reply);
    if (rc == SKYCTL_OK && options->json) {
        skyctl_print_reply_json(reply);
    } else if (rc == SKYCTL_OK) {
        printf("revision %ld\n", revision_of(reply));
        const cJSON *item;
        cJSON_ArrayForEach(item, cJSON_GetObjectItemCaseSensitive(reply, "unmapped"))
        {
            const char *group =
                cJSON_GetStringValue(cJSON_GetObjectItemCaseSensitive(item, "group"));
            const char *etage =
                cJSON_GetStringValue(cJSON_GetObjectItemCaseSensitive(item, "etage"));
            const char *reason =
                cJSON_GetStringValue(cJSON_GetObjectItemCaseSensitive(item, "reason"));
            printf("unmapped %s%s%s%s: %s\n", group ? group : "?", etage ? " (" : "",
                   etage ? etage : "", etage ? ")" : "", reason ? reason : "");
        }
    }
    cJSON_Delete(reply);
    return rc;
}

/* forecast: follow the daemon's forecast folder (weather.source "forecast", PROTOCOL.md "The
 * forecast folder"); prints the new revision. A daemon with no forecast read refuses, saying
 * why. */
int skyctl_forecast(const struct skyctl_options *options, int argc, char **argv)
{
    (void)argv;
    if (argc != 1)
        return skyctl_usage_error("forecast", "takes no argument");
    cJSON *msg = message("set");
    cJSON *weather = cJSON_AddObjectToObject(cJSON_AddObjectToObject(msg, "patch"), "weather");
    cJSON_AddStringToObject(weather, "source", "forecast");
    cJSON *reply = NULL;
    int rc = one_request(options, "forecast", msg, &reply);
    if (rc == SKYCTL_OK)
        print_ack(options, reply);
    cJSON_Delete(reply);
    return rc;
}

/* probe QUANTITY NAME=VALUE... */
int skyctl_probe(const struct skyctl_options *options, int argc, char **argv)
{
    if (argc < 2)
        return skyctl_usage_error("probe", "needs a QUANTITY (transmittance, luminance, "
                                           "illuminance)");
    cJSON *msg = message("probe");
    cJSON_AddStringToObject(msg, "quantity", argv[1]);
    for (int i = 2; i < argc; i++) {
        char err[320];
        if (!skyctl_assign(msg, argv[i], err, sizeof err)) {
            cJSON_Delete(msg);
            return skyctl_usage_error("probe", "%s", err);
        }
    }
    cJSON *reply = NULL;
    int rc = one_request(options, "probe", msg, &reply);
    if (rc == SKYCTL_OK && options->json) {
        skyctl_print_reply_json(reply);
    } else if (rc == SKYCTL_OK) {
        cJSON_DeleteItemFromObjectCaseSensitive(reply, "type");
        cJSON_DeleteItemFromObjectCaseSensitive(reply, "id");
        skyctl_print_value(reply);
    }
    cJSON_Delete(reply);
    return rc;
}

int skyctl_stats(const struct skyctl_options *options, int argc, char **argv)
{
    (void)argv;
    if (argc != 1)
        return skyctl_usage_error("stats", "takes no arguments");
    cJSON *reply = NULL;
    int rc = one_request(options, "stats", message("stats"), &reply);
    if (rc == SKYCTL_OK && options->json) {
        skyctl_print_reply_json(reply);
    } else if (rc == SKYCTL_OK) {
        cJSON_DeleteItemFromObjectCaseSensitive(reply, "type");
        cJSON_DeleteItemFromObjectCaseSensitive(reply, "id");
        skyctl_print_value(reply);
    }
    cJSON_Delete(reply);
    return rc;
}
