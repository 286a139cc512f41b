#include "cluster_store.h"

#include <inttypes.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "cluster_redis.h"
#include "cluster_url.h"
#include "error_text.h"

/* At start a slow Redis is waited for; later a connection is made again on the render thread,
 * when a change comes, so an unreachable host may hold up frames only this long, and at most
 * once per back-off (RETRY_MAX_S). */
static const double START_CONNECT_TIMEOUT_S = 2.0, CONNECT_TIMEOUT_S = 0.25;
static const double COMMAND_TIMEOUT_S = 2.0;
static const double RETRY_MIN_S = 0.1, RETRY_MAX_S = 2.0;

struct cluster_store {
    struct cluster_address address;
    struct cluster_keys keys;
    char url[CLUSTER_URL_TEXT_MAX]; /* without the password */
    char world[CLUSTER_WORLD_MAX + 1];
    char name[CLUSTER_URL_TEXT_MAX + CLUSTER_WORLD_MAX + 16];
    redisContext *redis;
    double retry_at, retry_delay; /* when a lost connection is tried again, and the back-off */
    /* A reason from hiredis or from us, kept to 300 characters (%.300s) so that what
     * connected() and its callers add around it (a retry delay, a host and port, a world's
     * name) still fits an error_text. */
    error_text last_error;
};

static double now_seconds(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + (double)t.tv_nsec * 1e-9;
}

/* A connection, made again when it was lost and the back-off allows. */
static bool connected(struct cluster_store *s, double timeout_s, char *why, size_t whylen)
{
    if (s->redis)
        return true;
    double now = now_seconds();
    if (now < s->retry_at) {
        /* In tenths of a second: the back-off never exceeds RETRY_MAX_S. */
        unsigned tenths = (unsigned)((s->retry_at - now) * 10.0 + 0.5);
        snprintf(why, whylen, "%.300s (trying again in %u.%u s)", s->last_error, tenths / 10,
                 tenths % 10);
        return false;
    }
    s->redis = cluster_redis_connect(&s->address, timeout_s, COMMAND_TIMEOUT_S, s->last_error,
                                     sizeof s->last_error);
    if (s->redis) {
        s->retry_delay = RETRY_MIN_S;
        return true;
    }
    s->retry_at = now + s->retry_delay;
    s->retry_delay = s->retry_delay * 2 > RETRY_MAX_S ? RETRY_MAX_S : s->retry_delay * 2;
    snprintf(why, whylen, "%.300s", s->last_error);
    return false;
}

/* A command failed on the connection: it is dropped and made again later. */
static void lost(struct cluster_store *s, const char *why)
{
    snprintf(s->last_error, sizeof s->last_error, "%.300s", why);
    if (s->redis && s->redis->err) {
        redisFree(s->redis);
        s->redis = NULL;
        s->retry_at = 0; /* the next command tries at once, then backs off */
    }
}

struct cluster_store *cluster_store_create(const struct cluster_store_params *p, char *err,
                                           size_t errlen)
{
    struct cluster_store *s = calloc(1, sizeof *s);
    if (!s) {
        snprintf(err, errlen, "out of memory");
        return NULL;
    }
    error_text why;
    if (!cluster_url_parse(p->url, &s->address, why, sizeof why) ||
        !cluster_world_name_check(p->world, why, sizeof why)) {
        snprintf(err, errlen, "cluster: %s", why);
        cluster_store_destroy(&s);
        return NULL;
    }
    if (p->password && s->address.has_password) {
        snprintf(err, errlen,
                 "cluster: the URL has a password and a password file gives one too: give it "
                 "once");
        cluster_store_destroy(&s);
        return NULL;
    }
    if (p->password) {
        if (strlen(p->password) >= sizeof s->address.password) {
            snprintf(err, errlen, "cluster: the password is longer than %zu bytes",
                     sizeof s->address.password - 1);
            cluster_store_destroy(&s);
            return NULL;
        }
        snprintf(s->address.password, sizeof s->address.password, "%s", p->password);
        s->address.has_password = true;
    }
    cluster_url_redacted(&s->address, s->url, sizeof s->url);
    snprintf(s->world, sizeof s->world, "%s", p->world);
    snprintf(s->name, sizeof s->name, "%s world \"%s\"", s->url, p->world);
    cluster_keys_make(p->world, &s->keys);
    s->retry_delay = RETRY_MIN_S;
    if (!connected(s, START_CONNECT_TIMEOUT_S, why, sizeof why)) {
        snprintf(err, errlen, "cannot reach the cluster's Redis at %s: %s", s->url, why);
        cluster_store_destroy(&s);
        return NULL;
    }
    return s;
}

void cluster_store_destroy(struct cluster_store **store)
{
    struct cluster_store *s = store ? *store : NULL;
    if (!s)
        return;
    if (s->redis)
        redisFree(s->redis);
    /* The password leaves no copy in freed memory. */
    memset(&s->address, 0, sizeof s->address);
    free(s);
    *store = NULL;
}

const char *cluster_store_name(const struct cluster_store *s)
{
    return s->name;
}
const char *cluster_store_url(const struct cluster_store *s)
{
    return s->url;
}
const char *cluster_store_world(const struct cluster_store *s)
{
    return s->world;
}
const struct cluster_address *cluster_store_address(const struct cluster_store *s)
{
    return &s->address;
}

struct cluster_entry *cluster_store_open(struct cluster_store *s, uint64_t initial_revision,
                                         const char *initial_state, char *err, size_t errlen)
{
    error_text why;
    if (!connected(s, CONNECT_TIMEOUT_S, why, sizeof why)) {
        snprintf(err, errlen, "cannot reach the cluster %s: %s", s->name, why);
        return NULL;
    }
    bool absent = false;
    struct cluster_entry *e = cluster_redis_snapshot(s->redis, &s->keys, initial_revision,
                                                     initial_state, &absent, why, sizeof why);
    if (!e) {
        snprintf(err, errlen, "cannot read the world of the cluster %s: %s", s->name, why);
        lost(s, why);
    }
    return e;
}

/* KEYS rev state map stream; ARGV expected revision, new revision, state, by, changed,
 * stream length kept, map ("": none). */
static const char COMMIT_SCRIPT[] =
    "local current = tonumber(redis.call('GET', KEYS[1]))\n"
    "if current == nil then return {0, -1} end\n"
    "if current ~= tonumber(ARGV[1]) then return {0, current} end\n"
    "local fields = {'rev', ARGV[2], 'state', ARGV[3], 'by', ARGV[4], 'changed', ARGV[5]}\n"
    "if ARGV[7] ~= '' then\n"
    "  redis.call('SET', KEYS[3], ARGV[7])\n"
    "  fields[#fields + 1] = 'map'\n"
    "  fields[#fields + 1] = ARGV[7]\n"
    "end\n"
    "local id = redis.call('XADD', KEYS[4], 'MAXLEN', '~', ARGV[6], '*', unpack(fields))\n"
    "redis.call('SET', KEYS[2], ARGV[3])\n"
    "redis.call('SET', KEYS[1], ARGV[2])\n"
    "return {1, id}\n";

enum cluster_commit_result cluster_store_commit(struct cluster_store *s, uint64_t expected,
                                                const char *state, const char *by,
                                                const char *changed, const unsigned char *map,
                                                size_t map_length, uint64_t *current,
                                                char id[CLUSTER_ID_MAX], char *err, size_t errlen)
{
    *current = expected;
    id[0] = '\0';
    error_text why;
    if (!connected(s, CONNECT_TIMEOUT_S, why, sizeof why)) {
        snprintf(err, errlen, "the cluster %s is unavailable: %s", s->name, why);
        return CLUSTER_UNAVAILABLE;
    }
    char expected_text[24], revision_text[24], keep[24];
    snprintf(expected_text, sizeof expected_text, "%" PRIu64, expected);
    snprintf(revision_text, sizeof revision_text, "%" PRIu64, expected + 1);
    snprintf(keep, sizeof keep, "%d", CLUSTER_STREAM_KEEP);
    const char *argv[] = { "EVAL",
                           COMMIT_SCRIPT,
                           "4",
                           s->keys.rev,
                           s->keys.state,
                           s->keys.map,
                           s->keys.stream,
                           expected_text,
                           revision_text,
                           state,
                           by,
                           changed,
                           keep,
                           map ? (const char *)map : "" };
    size_t lengths[14];
    for (int i = 0; i < 13; i++)
        lengths[i] = strlen(argv[i]);
    lengths[13] = map ? map_length : 0;
    redisReply *r = redisCommandArgv(s->redis, 14, argv, lengths);
    bool shaped = r && r->type == REDIS_REPLY_ARRAY && r->elements == 2 &&
                  r->element[0]->type == REDIS_REPLY_INTEGER;
    if (!shaped) {
        cluster_redis_describe(s->redis, r, why, sizeof why);
        snprintf(err, errlen, "the cluster %s is unavailable: %s", s->name, why);
        lost(s, why);
        if (r)
            freeReplyObject(r);
        return CLUSTER_UNAVAILABLE;
    }
    enum cluster_commit_result result = CLUSTER_UNAVAILABLE;
    const redisReply *second = r->element[1];
    if (r->element[0]->integer == 1 && second->type == REDIS_REPLY_STRING &&
        second->len < CLUSTER_ID_MAX) {
        memcpy(id, second->str, second->len);
        id[second->len] = '\0';
        *current = expected + 1;
        result = CLUSTER_COMMITTED;
    } else if (second->type == REDIS_REPLY_INTEGER && second->integer >= 0) {
        *current = (uint64_t)second->integer;
        result = CLUSTER_CONFLICT;
    } else {
        snprintf(err, errlen,
                 "the cluster %s is unavailable: the world is gone from Redis "
                 "(was it flushed, or restarted without its append-only file?)",
                 s->name);
    }
    freeReplyObject(r);
    return result;
}
