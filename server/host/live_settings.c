#include "live_settings.h"

#include <pthread.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

struct live_settings {
    pthread_mutex_t lock;
    struct proto_msg_limits limits;
    int max_queued_http;
    char token[sizeof(((struct skyd_config *)NULL)->controller_token)];
    bool read_only;
    int origin_count;
    char origins[SKYD_CONFIG_MAX_ORIGINS][sizeof(((struct skyd_config *)NULL)->allowed_origins[0])];
};

static void take(struct live_settings *s, const struct skyd_config *config)
{
    skyd_config_limits(config, &s->limits);
    s->max_queued_http = config->max_queued_http_requests;
    snprintf(s->token, sizeof s->token, "%s", config->read_only ? "" : config->controller_token);
    s->read_only = config->read_only;
    s->origin_count = config->origin_count;
    for (int i = 0; i < config->origin_count; i++)
        snprintf(s->origins[i], sizeof s->origins[i], "%s", config->allowed_origins[i]);
}

struct live_settings *live_settings_create(const struct skyd_config *config)
{
    struct live_settings *s = calloc(1, sizeof *s);
    if (!s)
        return NULL;
    pthread_mutex_init(&s->lock, NULL);
    take(s, config);
    return s;
}

void live_settings_destroy(struct live_settings **settings)
{
    struct live_settings *s = *settings;
    *settings = NULL;
    if (!s)
        return;
    pthread_mutex_destroy(&s->lock);
    free(s);
}

void live_settings_limits(struct live_settings *s, struct proto_msg_limits *limits)
{
    pthread_mutex_lock(&s->lock);
    *limits = s->limits;
    pthread_mutex_unlock(&s->lock);
}

int live_settings_max_queued_http(struct live_settings *s)
{
    pthread_mutex_lock(&s->lock);
    int cap = s->max_queued_http;
    pthread_mutex_unlock(&s->lock);
    return cap;
}

bool live_settings_origin_allowed(struct live_settings *s, const char *origin)
{
    pthread_mutex_lock(&s->lock);
    bool allowed = false;
    for (int i = 0; i < s->origin_count && !allowed; i++)
        allowed = strcasecmp(origin, s->origins[i]) == 0;
    pthread_mutex_unlock(&s->lock);
    return allowed;
}

enum live_token_check live_settings_check_token(struct live_settings *s, const char *given)
{
    pthread_mutex_lock(&s->lock);
    enum live_token_check result = LIVE_TOKEN_MATCHES;
    if (s->read_only) {
        result = LIVE_TOKEN_READ_ONLY;
    } else if (!s->token[0]) {
        result = LIVE_TOKEN_NONE;
    } else {
        size_t a = strlen(given), b = strlen(s->token);
        unsigned char diff = (unsigned char)(a != b);
        for (size_t i = 0; i < b; i++)
            diff |= (unsigned char)(s->token[i] ^ (i < a ? given[i] : 0));
        if (diff)
            result = LIVE_TOKEN_WRONG;
    }
    pthread_mutex_unlock(&s->lock);
    return result;
}

struct change_text {
    char *text;
    size_t size, used;
};

static void note(struct change_text *t, const char *format, ...)
{
    if (t->used >= t->size)
        return;
    if (t->used > 0)
        t->used += (size_t)snprintf(t->text + t->used, t->size - t->used, "; ");
    if (t->used >= t->size)
        return;
    va_list args;
    va_start(args, format);
    t->used += (size_t)vsnprintf(t->text + t->used, t->size - t->used, format, args);
    va_end(args);
}

void live_settings_update(struct live_settings *s, const struct skyd_config *next, char *changes,
                          size_t changes_size)
{
    struct live_settings fresh;
    memset(&fresh, 0, sizeof fresh);
    take(&fresh, next);
    struct change_text t = { changes, changes_size, 0 };
    if (changes_size)
        changes[0] = '\0';
    pthread_mutex_lock(&s->lock);
    const struct proto_msg_limits *a = &s->limits, *b = &fresh.limits;
#define LIMIT(member, format, cast)                                                                \
    if (a->member != b->member)                                                                    \
        note(&t, "limits.%s " format " -> " format, #member, (cast)a->member, (cast)b->member);
    LIMIT(max_message_bytes, "%zu", size_t)
    LIMIT(max_clients, "%d", int)
    LIMIT(max_width, "%u", unsigned)
    LIMIT(max_height, "%u", unsigned)
    LIMIT(max_fps, "%g", double)
    LIMIT(control_messages_per_second, "%g", double)
    LIMIT(max_upload_bytes, "%zu", size_t)
#undef LIMIT
    if (s->max_queued_http != fresh.max_queued_http)
        note(&t, "limits.max_queued_http_requests %d -> %d", s->max_queued_http,
             fresh.max_queued_http);
    if (s->read_only != fresh.read_only)
        note(&t, "read_only %s -> %s", s->read_only ? "true" : "false",
             fresh.read_only ? "true" : "false");
    else if (strcmp(s->token, fresh.token) != 0)
        note(&t, "controller token %s",
             !fresh.token[0] ? "removed"
             : !s->token[0]  ? "set"
                             : "changed");
    bool origins_differ = s->origin_count != fresh.origin_count;
    for (int i = 0; i < s->origin_count && !origins_differ; i++)
        origins_differ = strcmp(s->origins[i], fresh.origins[i]) != 0;
    if (origins_differ)
        note(&t, "allowed_origins: %d -> %d entries", s->origin_count, fresh.origin_count);
    s->limits = fresh.limits;
    s->max_queued_http = fresh.max_queued_http;
    memcpy(s->token, fresh.token, sizeof s->token);
    s->read_only = fresh.read_only;
    s->origin_count = fresh.origin_count;
    memcpy(s->origins, fresh.origins, sizeof s->origins);
    pthread_mutex_unlock(&s->lock);
    if (t.used == 0)
        note(&t, "nothing");
}
