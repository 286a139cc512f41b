#include "config.h"
#include "field_errors.h"
#include "field_schema.h"
#include "text_file.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include <time.h>

#include <cjson/cJSON.h>

#include "cluster_url.h"
#include "error_text.h"
#include "utc_time.h"

#define MAX_CONFIG_BYTES (1 << 20)

/* The configuration's fields, read by the world state's schema engine (protocol/): JSON
 * Pointer "/listen/port" is row "listen.port". "allowed_origins" and "initial_state" have no
 * row: the engine leaves them to apply_origins and apply_initial_state. */
#define OFFSET(member) offsetof(struct skyd_config, member)
#define CAPACITY(member) sizeof(((struct skyd_config *)0)->member)
#define STRING(path_, member, doc)                                                                 \
    {                                                                                              \
        .path = path_, .type = PROTO_FIELD_TYPE_STRING, .offset = OFFSET(member),                  \
        .description = doc, .capacity = CAPACITY(member)                                           \
    }
#define INT(path_, member, lo, hi, doc)                                                            \
    {                                                                                              \
        .path = path_, .type = PROTO_FIELD_TYPE_INT, .offset = OFFSET(member), .min = lo,          \
        .max = hi, .description = doc                                                              \
    }
#define NUMBER(path_, member, lo, hi, doc)                                                         \
    {                                                                                              \
        .path = path_, .type = PROTO_FIELD_TYPE_NUMBER, .offset = OFFSET(member), .min = lo,       \
        .max = hi, .description = doc                                                              \
    }
#define BOOL(path_, member, doc)                                                                   \
    {                                                                                              \
        .path = path_, .type = PROTO_FIELD_TYPE_BOOL, .offset = OFFSET(member), .max = 1,          \
        .description = doc                                                                         \
    }

static const struct proto_field_desc config_fields[] = {
    STRING("listen.address", listen_address, "address to listen on"),
    INT("listen.port", listen_port, 0, 65535, "port; 0 asks the kernel for a free one"),
    STRING("listen.tls_certificate", tls_certificate, "PEM certificate for https/wss"),
    STRING("listen.tls_private_key", tls_private_key, "PEM private key for https/wss"),
    STRING("web_root", web_root,
           "folder of the web client's files; empty: the installed web client (else the "
           "source tree's clients/web)"),
    STRING("presets_dir", presets_dir,
           "folder of the atmosphere/ and weather/ presets; empty: the installed presets (else "
           "the source tree's config/)"),
    STRING("state_file", state_file, "where the world state is kept; empty: nowhere"),
    STRING("render.device", render_device, "the Vulkan device; empty: a GPU, else lavapipe"),
    INT("render.encoder_threads", encoder_threads, 0, 64,
        "PNG and JPEG encoder threads; 0: one per core but the render thread's, at least 2"),
    NUMBER("render.lut_budget_ms", lut_budget_ms, 0, 1000,
           "GPU ms per frame for amortized LUT rebuilds; 0: at once"),
    NUMBER("render.lut_budget_fraction", lut_budget_fraction, 0, 1,
           "and at most this share of the rest of a frame, unless idle time leaves more"),
    NUMBER("render.frame_budget_ms", frame_budget_ms, 0, 1000,
           "GPU ms a frame may take: clouds.quality.resolution auto traces the finest clouds "
           "that fit; 0: none (auto stays at the coarsest)"),
    INT("render.lut_blend_frames", lut_blend_frames, 1, 240,
        "frames over which rebuilt LUTs blend in"),
    NUMBER("state_save_delay_s", state_save_delay_s, 0, 3600,
           "retry delay of a state write the daemon owes itself, s"),
    BOOL("render.validation", render_validation, "Vulkan validation layers"),
    INT("limits.max_message_bytes", max_message_bytes, 256, 16 << 20,
        "largest client message but set_weather_map"),
    INT("limits.max_clients", max_clients, 1, 4096, "connections at once"),
    INT("limits.max_width", max_width, 1, 16384, "widest view, pixels"),
    INT("limits.max_height", max_height, 1, 16384, "tallest view, pixels"),
    NUMBER("limits.max_fps", max_fps, 0.1, 240, "highest frame rate of a subscription"),
    NUMBER("limits.control_messages_per_second", control_messages_per_second, 0.1, 10000,
           "a controller's changes per second"),
    INT("limits.max_upload_bytes", max_upload_bytes, 256, 64 << 20,
        "largest set_weather_map message"),
    INT("limits.max_queued_http_requests", max_queued_http_requests, 1, 4096,
        "HTTP requests waiting for the render loop at once; more are answered 503"),
    STRING("controller_token", controller_token,
           "the token auth asks for; empty: skyd serve makes one, kept in <state_file>.token"),
    BOOL("read_only", read_only, "nobody may control the server: no token, auth is refused"),
    STRING("cluster.redis", cluster_redis,
           "redis://[USER[:PASSWORD]@]HOST:PORT[/DB] holding the shared world; empty: the "
           "state file"),
    STRING("cluster.redis_password_file", cluster_redis_password_file,
           "a file (mode 0600 or stricter) whose first line is the Redis password, instead "
           "of one in the URL"),
    STRING("cluster.world", cluster_world,
           "the shared world's name: 1 to 64 letters, digits, '-' or '_'"),
    STRING("weather.forecast_dir", forecast_dir,
           "folder of GRIB2 forecasts (*.grib2, *.grb2) that weather.source \"forecast\" "
           "follows, the newest valid file; empty: none"),
    NUMBER("weather.forecast_poll_s", forecast_poll_s, 0.1, 3600,
           "how often the forecast folder is looked at for new files, s"),
};

static const char *const config_caller_members[] = { "allowed_origins", "initial_state" };

static const struct proto_schema config_schema = {
    .fields = config_fields,
    .count = sizeof config_fields / sizeof config_fields[0],
    .caller_members = config_caller_members,
    .caller_member_count = sizeof config_caller_members / sizeof config_caller_members[0],
};

void skyd_config_defaults(struct skyd_config *c)
{
    memset(c, 0, sizeof *c);
    proto_world_state_defaults(&c->initial_state);
    snprintf(c->listen_address, sizeof c->listen_address, "127.0.0.1");
    c->listen_port = 8080;
    snprintf(c->state_file, sizeof c->state_file, "var/skyd-state.json");
    c->encoder_threads = 0;
    c->lut_budget_ms = 8.0;
    c->lut_budget_fraction = 0.05;
    c->frame_budget_ms = 16.0;
    c->lut_blend_frames = 4;
    c->state_save_delay_s = 1.0;
    c->forecast_poll_s = 5.0;
    /* The protocol's own defaults, so that the two cannot drift apart. */
    struct proto_msg_limits limits;
    proto_msg_limits_default(&limits);
    c->max_message_bytes = (int)limits.max_message_bytes;
    c->max_clients = limits.max_clients;
    c->max_width = (int)limits.max_width;
    c->max_height = (int)limits.max_height;
    c->max_fps = limits.max_fps;
    c->control_messages_per_second = limits.control_messages_per_second;
    c->max_upload_bytes = (int)limits.max_upload_bytes;
    c->max_queued_http_requests = 16;
    c->origin_count = 2;
    snprintf(c->allowed_origins[0], sizeof c->allowed_origins[0], "http://127.0.0.1:8080");
    snprintf(c->allowed_origins[1], sizeof c->allowed_origins[1], "http://localhost:8080");
}

static void apply_origins(struct skyd_config *c, const cJSON *value, const char *pointer,
                          struct proto_field_errors *errors)
{
    if (!cJSON_IsArray(value)) {
        proto_field_errors_addf(errors, PROTO_FIELD_WRONG_TYPE, pointer,
                                "expected an array of strings");
        return;
    }
    int n = cJSON_GetArraySize(value);
    if (n > SKYD_CONFIG_MAX_ORIGINS) {
        proto_field_errors_addf(errors, PROTO_FIELD_OUT_OF_RANGE, pointer,
                                "at most %d origins, got %d", SKYD_CONFIG_MAX_ORIGINS, n);
        return;
    }
    int i = 0;
    for (const cJSON *item = value->child; item; item = item->next, i++) {
        char item_pointer[176];
        snprintf(item_pointer, sizeof item_pointer, "%s/%d", pointer, i);
        if (!cJSON_IsString(item) || strlen(item->valuestring) >= sizeof c->allowed_origins[0])
            proto_field_errors_addf(errors, PROTO_FIELD_WRONG_TYPE, item_pointer,
                                    "expected a string of at most %zu characters",
                                    sizeof c->allowed_origins[0] - 1);
        else
            snprintf(c->allowed_origins[i], sizeof c->allowed_origins[i], "%s", item->valuestring);
    }
    c->origin_count = n;
}

/* "initial_state": a world-state patch over the defaults; "clock.utc": "now" is replaced by
 * the current time. Errors point into the configuration ("/initial_state/..."). */
static void apply_initial_state(struct skyd_config *c, const cJSON *value,
                                struct proto_field_errors *errors)
{
    if (!cJSON_IsObject(value)) {
        proto_field_errors_addf(errors, PROTO_FIELD_WRONG_TYPE, "/initial_state",
                                "expected a world-state patch (an object)");
        return;
    }
    cJSON *patch = cJSON_Duplicate(value, true);
    cJSON *clock = patch ? cJSON_GetObjectItemCaseSensitive(patch, "clock") : NULL;
    cJSON *utc = cJSON_IsObject(clock) ? cJSON_GetObjectItemCaseSensitive(clock, "utc") : NULL;
    if (cJSON_IsString(utc) && strcmp(utc->valuestring, "now") == 0) {
        struct timespec now;
        clock_gettime(CLOCK_REALTIME, &now);
        char text[40];
        proto_time_format_iso8601((double)now.tv_sec, text, sizeof text);
        cJSON_ReplaceItemInObjectCaseSensitive(clock, "utc", cJSON_CreateString(text));
    }
    struct proto_field_errors found;
    if (!patch) {
        proto_field_errors_addf(errors, PROTO_FIELD_BAD_VALUE, "/initial_state", "out of memory");
    } else if (!proto_world_state_apply_json(&c->initial_state, patch, &found)) {
        for (int i = 0; i < found.count; i++) {
            char pointer[160];
            snprintf(pointer, sizeof pointer, "/initial_state%s", found.items[i].pointer);
            proto_field_errors_add(errors, found.items[i].code, pointer, found.items[i].reason);
        }
    }
    cJSON_Delete(patch);
}

/* "cluster": both members or neither, each well formed (nothing connects here). */
static void check_cluster(const struct skyd_config *c, struct proto_field_errors *errors)
{
    if (!c->cluster_redis[0] && !c->cluster_world[0] && !c->cluster_redis_password_file[0])
        return;
    error_text why;
    struct cluster_address address;
    if (!c->cluster_redis[0]) {
        proto_field_errors_addf(errors, PROTO_FIELD_MISSING, "/cluster/redis",
                                "a cluster needs its Redis: redis://HOST:PORT[/DB]");
    } else if (!cluster_url_parse(c->cluster_redis, &address, why, sizeof why)) {
        proto_field_errors_addf(errors, PROTO_FIELD_BAD_VALUE, "/cluster/redis", "%s", why);
    } else if (address.has_password && c->cluster_redis_password_file[0]) {
        proto_field_errors_addf(errors, PROTO_FIELD_INCONSISTENT, "/cluster/redis_password_file",
                                "the URL in /cluster/redis has a password already: give it once");
    }
    memset(&address, 0, sizeof address); /* the password */
    if (!c->cluster_world[0])
        proto_field_errors_addf(errors, PROTO_FIELD_MISSING, "/cluster/world",
                                "a cluster needs the name of the world its nodes share");
    else if (!cluster_world_name_check(c->cluster_world, why, sizeof why))
        proto_field_errors_addf(errors, PROTO_FIELD_BAD_VALUE, "/cluster/world", "%s", why);
}

/* The rows through the engine, then the two members without rows. */
static void apply_config(struct skyd_config *c, const cJSON *root,
                         struct proto_field_errors *errors)
{
    proto_schema_apply_json(&config_schema, c, root, "", errors, NULL);
    const cJSON *origins = cJSON_GetObjectItemCaseSensitive(root, "allowed_origins");
    if (origins)
        apply_origins(c, origins, "/allowed_origins", errors);
    const cJSON *initial = cJSON_GetObjectItemCaseSensitive(root, "initial_state");
    if (initial)
        apply_initial_state(c, initial, errors);
    check_cluster(c, errors);
}

void skyd_config_limits(const struct skyd_config *c, struct proto_msg_limits *limits)
{
    limits->max_message_bytes = (size_t)c->max_message_bytes;
    limits->max_clients = c->max_clients;
    limits->max_width = (uint32_t)c->max_width;
    limits->max_height = (uint32_t)c->max_height;
    limits->max_fps = c->max_fps;
    limits->control_messages_per_second = c->control_messages_per_second;
    limits->max_upload_bytes = (size_t)c->max_upload_bytes;
}

bool skyd_config_load(const char *path, struct skyd_config *config,
                      struct proto_field_errors *errors, char *msg, size_t msglen)
{
    size_t length = 0;
    char *text = text_file_read(path, MAX_CONFIG_BYTES, &length);
    if (!text) {
        text_file_describe_error(path, MAX_CONFIG_BYTES, msg, msglen); /* reads errno */
        memset(errors, 0, sizeof *errors);
        skyd_config_defaults(config);
        return false;
    }
    bool ok = skyd_config_parse(text, length, path, config, errors, msg, msglen);
    free(text);
    return ok;
}

bool skyd_config_parse(const char *text, size_t length, const char *name,
                       struct skyd_config *config, struct proto_field_errors *errors, char *msg,
                       size_t msglen)
{
    memset(errors, 0, sizeof *errors);
    skyd_config_defaults(config);
    const char *nul = memchr(text, '\0', length);
    if (nul) {
        snprintf(msg, msglen, "%s: NUL byte at %ld", name, (long)(nul - text));
        return false;
    }
    char *copy = malloc(length + 1);
    if (!copy) {
        snprintf(msg, msglen, "%s: out of memory", name);
        return false;
    }
    memcpy(copy, text, length);
    copy[length] = '\0';
    const char *end = NULL;
    cJSON *root = cJSON_ParseWithOpts(copy, &end, true);
    if (!root) {
        snprintf(msg, msglen, "%s: invalid JSON at byte %ld", name, end ? (long)(end - copy) : 0L);
        free(copy);
        return false;
    }
    struct skyd_config candidate;
    skyd_config_defaults(&candidate);
    if (!cJSON_IsObject(root))
        proto_field_errors_addf(errors, PROTO_FIELD_WRONG_TYPE, "",
                                "the configuration must be a JSON object");
    else
        apply_config(&candidate, root, errors);
    cJSON_Delete(root);
    free(copy);
    if (errors->total > 0) {
        snprintf(msg, msglen, "%s: %d invalid field%s", name, errors->total,
                 errors->total == 1 ? "" : "s");
        return false;
    }
    *config = candidate;
    return true;
}

cJSON *skyd_config_json_schema(void)
{
    struct skyd_config defaults;
    skyd_config_defaults(&defaults);
    cJSON *values = proto_schema_to_json(&config_schema, &defaults);
    cJSON *root = values ? proto_schema_json_schema(&config_schema, values, "skyd configuration")
                         : NULL;
    cJSON_Delete(values);
    cJSON *properties = cJSON_GetObjectItemCaseSensitive(root, "properties");
    /* The two members without rows. */
    cJSON *origins = properties ? cJSON_AddObjectToObject(properties, "allowed_origins") : NULL;
    cJSON *item = origins ? cJSON_AddObjectToObject(origins, "items") : NULL;
    cJSON *list = origins ? cJSON_AddArrayToObject(origins, "default") : NULL;
    bool ok = item && list && cJSON_AddStringToObject(origins, "type", "array") &&
              cJSON_AddStringToObject(item, "type", "string") &&
              cJSON_AddNumberToObject(item, "maxLength",
                                      (double)sizeof defaults.allowed_origins[0] - 1) &&
              cJSON_AddNumberToObject(origins, "maxItems", SKYD_CONFIG_MAX_ORIGINS) &&
              cJSON_AddStringToObject(origins, "description",
                                      "Origin headers a browser client may connect from");
    for (int i = 0; ok && i < defaults.origin_count; i++)
        ok = cJSON_AddItemToArray(list, cJSON_CreateString(defaults.allowed_origins[i]));
    cJSON *initial = ok ? cJSON_AddObjectToObject(properties, "initial_state") : NULL;
    ok = initial && cJSON_AddStringToObject(initial, "type", "object") &&
         cJSON_AddStringToObject(initial, "description",
                                 "a world-state patch over the defaults (skyd schema); "
                                 "clock.utc may be \"now\"");
    if (!ok) {
        cJSON_Delete(root);
        return NULL;
    }
    return root;
}

int skyd_config_encoder_threads(const struct skyd_config *c)
{
    if (c->encoder_threads > 0)
        return c->encoder_threads;
    /* The render thread keeps a core; frames are encoded on the others, pipelined (each frame
     * a job any worker takes), so a fast device is not held to two encodes at a time. */
    long cores = sysconf(_SC_NPROCESSORS_ONLN);
    long threads = cores > 1 ? cores - 1 : 1;
    return (int)(threads < 2 ? 2 : threads > 64 ? 64 : threads);
}
