#include "config.h"
#include "text_file.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include <cjson/cJSON.h>

#include "utc_time.h"

#define MAX_CONFIG_BYTES (1 << 20)

enum config_type { CFG_STRING, CFG_INT, CFG_NUMBER, CFG_BOOL, CFG_ORIGINS };

struct config_field {
    const char *pointer; /* JSON Pointer of the field */
    enum config_type type;
    size_t offset;
    size_t capacity; /* strings: buffer size */
    double min, max; /* numbers */
};

#define FIELD_STRING(p, member) \
    { p, CFG_STRING, offsetof(struct skyd_config, member), \
      sizeof(((struct skyd_config *)0)->member), 0, 0 }
#define FIELD_INT(p, member, lo, hi) { p, CFG_INT, offsetof(struct skyd_config, member), 0, lo, hi }
#define FIELD_NUMBER(p, member, lo, hi) \
    { p, CFG_NUMBER, offsetof(struct skyd_config, member), 0, lo, hi }

static const struct config_field fields[] = {
    FIELD_STRING("/listen/address", listen_address),
    FIELD_INT("/listen/port", listen_port, 0, 65535),
    FIELD_STRING("/listen/tls_certificate", tls_certificate),
    FIELD_STRING("/listen/tls_private_key", tls_private_key),
    FIELD_STRING("/web_root", web_root),
    FIELD_STRING("/state_file", state_file),
    FIELD_STRING("/render/device", render_device),
    FIELD_INT("/render/encoder_threads", encoder_threads, 1, 64),
    FIELD_NUMBER("/render/lut_budget_ms", lut_budget_ms, 0, 1000),
    FIELD_NUMBER("/render/lut_budget_fraction", lut_budget_fraction, 0, 1),
    FIELD_INT("/render/lut_blend_frames", lut_blend_frames, 1, 240),
    FIELD_NUMBER("/state_save_delay_s", state_save_delay_s, 0, 3600),
    { "/render/validation", CFG_BOOL, offsetof(struct skyd_config, render_validation), 0, 0, 0 },
    FIELD_INT("/limits/max_message_bytes", max_message_bytes, 256, 16 << 20),
    FIELD_INT("/limits/max_clients", max_clients, 1, 4096),
    FIELD_INT("/limits/max_width", max_width, 1, 16384),
    FIELD_INT("/limits/max_height", max_height, 1, 16384),
    FIELD_NUMBER("/limits/max_fps", max_fps, 0.1, 240),
    FIELD_NUMBER("/limits/control_messages_per_second", control_messages_per_second, 0.1, 10000),
    FIELD_INT("/limits/max_upload_bytes", max_upload_bytes, 256, 64 << 20),
    FIELD_STRING("/controller_token", controller_token),
    { "/allowed_origins", CFG_ORIGINS, 0, 0, 0, 0 },
};
#define FIELD_COUNT (sizeof fields / sizeof fields[0])

void skyd_config_defaults(struct skyd_config *c)
{
    memset(c, 0, sizeof *c);
    sky_world_state_defaults(&c->initial_state);
    snprintf(c->listen_address, sizeof c->listen_address, "127.0.0.1");
    c->listen_port = 8080;
    snprintf(c->web_root, sizeof c->web_root, "clients/web");
    snprintf(c->state_file, sizeof c->state_file, "var/skyd-state.json");
    c->encoder_threads = 2;
    c->lut_budget_ms = 2.0;
    c->lut_budget_fraction = 0.05;
    c->lut_blend_frames = 4;
    c->state_save_delay_s = 1.0;
    /* The protocol's own defaults, so that the two cannot drift apart. */
    struct sky_msg_limits limits;
    sky_msg_limits_default(&limits);
    c->max_message_bytes = (int)limits.max_message_bytes;
    c->max_clients = limits.max_clients;
    c->max_width = (int)limits.max_width;
    c->max_height = (int)limits.max_height;
    c->max_fps = limits.max_fps;
    c->control_messages_per_second = limits.control_messages_per_second;
    c->max_upload_bytes = (int)limits.max_upload_bytes;
    c->origin_count = 2;
    snprintf(c->allowed_origins[0], sizeof c->allowed_origins[0], "http://127.0.0.1:8080");
    snprintf(c->allowed_origins[1], sizeof c->allowed_origins[1], "http://localhost:8080");
}

static const struct config_field *find_field(const char *pointer)
{
    for (size_t i = 0; i < FIELD_COUNT; i++)
        if (strcmp(fields[i].pointer, pointer) == 0)
            return &fields[i];
    return NULL;
}

/* True when some field lives below `pointer` (so it names an object of the schema). */
static bool is_group(const char *pointer)
{
    size_t n = strlen(pointer);
    for (size_t i = 0; i < FIELD_COUNT; i++)
        if (strncmp(fields[i].pointer, pointer, n) == 0 && fields[i].pointer[n] == '/')
            return true;
    return false;
}

static void apply_origins(struct skyd_config *c, const cJSON *value, const char *pointer,
                          struct sky_field_errors *errors)
{
    if (!cJSON_IsArray(value)) {
        sky_field_errors_addf(errors, SKY_FIELD_WRONG_TYPE, pointer,
                              "expected an array of strings");
        return;
    }
    int n = cJSON_GetArraySize(value);
    if (n > SKYD_CONFIG_MAX_ORIGINS) {
        sky_field_errors_addf(errors, SKY_FIELD_OUT_OF_RANGE, pointer, "at most %d origins, got %d",
                              SKYD_CONFIG_MAX_ORIGINS, n);
        return;
    }
    int i = 0;
    for (const cJSON *item = value->child; item; item = item->next, i++) {
        char item_pointer[176];
        snprintf(item_pointer, sizeof item_pointer, "%s/%d", pointer, i);
        if (!cJSON_IsString(item) || strlen(item->valuestring) >= sizeof c->allowed_origins[0])
            sky_field_errors_addf(errors, SKY_FIELD_WRONG_TYPE, item_pointer,
                                  "expected a string of at most %zu characters",
                                  sizeof c->allowed_origins[0] - 1);
        else
            snprintf(c->allowed_origins[i], sizeof c->allowed_origins[i], "%s", item->valuestring);
    }
    c->origin_count = n;
}

static void apply_leaf(struct skyd_config *c, const struct config_field *f, const cJSON *value,
                       const char *pointer, struct sky_field_errors *errors)
{
    char *base = (char *)c;
    switch (f->type) {
    case CFG_STRING:
        if (!cJSON_IsString(value))
            sky_field_errors_addf(errors, SKY_FIELD_WRONG_TYPE, pointer, "expected a string");
        else if (strlen(value->valuestring) >= f->capacity)
            sky_field_errors_addf(errors, SKY_FIELD_OUT_OF_RANGE, pointer,
                                  "longer than %zu characters", f->capacity - 1);
        else
            snprintf(base + f->offset, f->capacity, "%s", value->valuestring);
        break;
    case CFG_BOOL:
        if (!cJSON_IsBool(value))
            sky_field_errors_addf(errors, SKY_FIELD_WRONG_TYPE, pointer, "expected true or false");
        else
            *(bool *)(base + f->offset) = cJSON_IsTrue(value);
        break;
    case CFG_INT:
    case CFG_NUMBER: {
        if (!cJSON_IsNumber(value)) {
            sky_field_errors_addf(errors, SKY_FIELD_WRONG_TYPE, pointer, "expected a number");
            break;
        }
        double v = value->valuedouble;
        if (!isfinite(v) || v < f->min || v > f->max) {
            sky_field_errors_addf(errors, SKY_FIELD_OUT_OF_RANGE, pointer,
                                  "must be in [%g, %g], got %g", f->min, f->max, v);
        } else if (f->type == CFG_INT && v != floor(v)) {
            sky_field_errors_addf(errors, SKY_FIELD_BAD_VALUE, pointer,
                                  "must be a whole number, got %g", v);
        } else if (f->type == CFG_INT) {
            *(int *)(base + f->offset) = (int)v;
        } else {
            *(double *)(base + f->offset) = v;
        }
        break;
    }
    case CFG_ORIGINS:
        apply_origins(c, value, pointer, errors);
        break;
    }
}

/* "initial_state": a world-state patch over the defaults; "clock.utc": "now" is replaced by
 * the current time. Errors point into the configuration ("/initial_state/..."). */
static void apply_initial_state(struct skyd_config *c, const cJSON *value,
                                struct sky_field_errors *errors)
{
    if (!cJSON_IsObject(value)) {
        sky_field_errors_addf(errors, SKY_FIELD_WRONG_TYPE, "/initial_state",
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
        sky_time_format_iso8601((double)now.tv_sec, text, sizeof text);
        cJSON_ReplaceItemInObjectCaseSensitive(clock, "utc", cJSON_CreateString(text));
    }
    struct sky_field_errors found;
    if (!patch) {
        sky_field_errors_addf(errors, SKY_FIELD_BAD_VALUE, "/initial_state", "out of memory");
    } else if (!sky_world_state_apply_json(&c->initial_state, patch, &found)) {
        for (int i = 0; i < found.count; i++) {
            char pointer[160];
            snprintf(pointer, sizeof pointer, "/initial_state%s", found.items[i].pointer);
            sky_field_errors_add(errors, found.items[i].code, pointer, found.items[i].reason);
        }
    }
    cJSON_Delete(patch);
}

static void apply_object(struct skyd_config *c, const cJSON *object, const char *prefix,
                         struct sky_field_errors *errors)
{
    for (const cJSON *member = object->child; member; member = member->next) {
        char pointer[160];
        snprintf(pointer, sizeof pointer, "%s/%s", prefix, member->string);
        const struct config_field *f = find_field(pointer);
        if (strcmp(pointer, "/initial_state") == 0)
            apply_initial_state(c, member, errors);
        else if (f)
            apply_leaf(c, f, member, pointer, errors);
        else if (is_group(pointer) && cJSON_IsObject(member))
            apply_object(c, member, pointer, errors);
        else if (is_group(pointer))
            sky_field_errors_addf(errors, SKY_FIELD_WRONG_TYPE, pointer, "expected an object");
        else
            sky_field_errors_addf(errors, SKY_FIELD_UNKNOWN, pointer, "unknown field");
    }
}

void skyd_config_limits(const struct skyd_config *c, struct sky_msg_limits *limits)
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
                      struct sky_field_errors *errors, char *msg, size_t msglen)
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
                       struct skyd_config *config, struct sky_field_errors *errors, char *msg,
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
        snprintf(msg, msglen, "%s: invalid JSON at byte %ld", name,
                 end ? (long)(end - copy) : 0L);
        free(copy);
        return false;
    }
    struct skyd_config candidate;
    skyd_config_defaults(&candidate);
    if (!cJSON_IsObject(root))
        sky_field_errors_addf(errors, SKY_FIELD_WRONG_TYPE, "",
                              "the configuration must be a JSON object");
    else
        apply_object(&candidate, root, "", errors);
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
