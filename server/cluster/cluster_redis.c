#include "cluster_redis.h"

#include <errno.h>
#include <inttypes.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/time.h>

#include "error_text.h"

void cluster_entry_free(struct cluster_entry *e)
{
    if (!e)
        return;
    free(e->state);
    free(e->by);
    free(e->changed);
    free(e->map);
    free(e);
}

void cluster_entry_free_list(struct cluster_entry *e)
{
    while (e) {
        struct cluster_entry *next = e->next;
        cluster_entry_free(e);
        e = next;
    }
}

void cluster_keys_make(const char *world, struct cluster_keys *k)
{
    snprintf(k->rev, sizeof k->rev, "skyd:{%s}:rev", world);
    snprintf(k->state, sizeof k->state, "skyd:{%s}:state", world);
    snprintf(k->map, sizeof k->map, "skyd:{%s}:map", world);
    snprintf(k->stream, sizeof k->stream, "skyd:{%s}:stream", world);
}

static struct timeval seconds_to_timeval(double s)
{
    double whole = floor(s);
    return (struct timeval){ .tv_sec = (time_t)whole, .tv_usec = (suseconds_t)((s - whole) * 1e6) };
}

void cluster_redis_describe(const redisContext *c, const redisReply *reply, char *why,
                            size_t whylen)
{
    if (c && c->err)
        snprintf(why, whylen, "%s", c->errstr[0] ? c->errstr : "connection error");
    else if (reply && reply->type == REDIS_REPLY_ERROR)
        snprintf(why, whylen, "Redis answered: %.300s", reply->str);
    else if (!reply)
        snprintf(why, whylen, "no reply");
    else
        snprintf(why, whylen, "unexpected reply (type %d)", reply->type);
}

/* AUTH [USER] PASSWORD. Neither goes into `why`: Redis's own refusal does not quote them. */
static bool authenticate(redisContext *c, const struct cluster_address *a, char *why, size_t whylen)
{
    const char *argv[3] = { "AUTH" };
    size_t lengths[3] = { 4 };
    int argc = 1;
    if (a->user[0]) {
        argv[argc] = a->user;
        lengths[argc++] = strlen(a->user);
    }
    argv[argc] = a->password;
    lengths[argc++] = strlen(a->password);
    redisReply *r = redisCommandArgv(c, argc, argv, lengths);
    bool ok = r && r->type == REDIS_REPLY_STATUS;
    if (!ok) {
        error_text reason;
        cluster_redis_describe(c, r, reason, sizeof reason);
        snprintf(why, whylen, "Redis refused AUTH as user \"%s\": %s%s",
                 a->user[0] ? a->user : "default", reason,
                 a->has_password ? "" : " (no password was given)");
    }
    if (r)
        freeReplyObject(r);
    return ok;
}

redisContext *cluster_redis_connect(const struct cluster_address *a, double timeout_s,
                                    double command_timeout_s, char *why, size_t whylen)
{
    redisContext *c = redisConnectWithTimeout(a->host, a->port, seconds_to_timeval(timeout_s));
    if (!c) {
        snprintf(why, whylen, "out of memory");
        return NULL;
    }
    if (c->err) {
        snprintf(why, whylen, "%s", c->errstr);
        redisFree(c);
        return NULL;
    }
    if (redisSetTimeout(c, seconds_to_timeval(command_timeout_s)) != REDIS_OK) {
        snprintf(why, whylen, "cannot set the command timeout");
        redisFree(c);
        return NULL;
    }
    if (cluster_address_authenticates(a) && !authenticate(c, a, why, whylen)) {
        redisFree(c);
        return NULL;
    }
    redisReply *r = redisCommand(c, "SELECT %d", a->db);
    bool ok = r && r->type == REDIS_REPLY_STATUS;
    if (!ok && r && r->type == REDIS_REPLY_ERROR && strncmp(r->str, "NOAUTH", 6) == 0) {
        snprintf(why, whylen,
                 "Redis asks for a user and password (%.200s): give them in the URL, "
                 "redis://USER:PASSWORD@HOST:PORT, or the password in a file",
                 r->str);
    } else if (!ok) {
        error_text reason;
        cluster_redis_describe(c, r, reason, sizeof reason);
        snprintf(why, whylen, "SELECT %d: %s", a->db, reason);
    }
    if (r)
        freeReplyObject(r);
    if (!ok) {
        redisFree(c);
        return NULL;
    }
    return c;
}

/* KEYS rev state map stream; ARGV (optional) initial revision, initial state. An absent map
 * reads as "" (a nil would end a Lua array). */
static const char SNAPSHOT_SCRIPT[] =
    "if #ARGV == 2 and redis.call('EXISTS', KEYS[1]) == 0 then\n"
    "  redis.call('SET', KEYS[2], ARGV[2])\n"
    "  redis.call('SET', KEYS[1], ARGV[1])\n"
    "end\n"
    "local rev = redis.call('GET', KEYS[1])\n"
    "if not rev then return {} end\n"
    "local last = redis.call('XREVRANGE', KEYS[4], '+', '-', 'COUNT', 1)\n"
    "local id = '0-0'\n"
    "if #last > 0 then id = last[1][1] end\n"
    "return {rev, redis.call('GET', KEYS[2]) or '', id, redis.call('GET', KEYS[3]) or ''}\n";

static char *dup_bytes(const char *s, size_t length)
{
    char *copy = malloc(length + 1);
    if (copy) {
        memcpy(copy, s, length);
        copy[length] = '\0';
    }
    return copy;
}

static bool parse_revision(const char *text, size_t length, uint64_t *out)
{
    if (length == 0 || length > 16)
        return false;
    uint64_t value = 0;
    for (size_t i = 0; i < length; i++) {
        if (text[i] < '0' || text[i] > '9')
            return false;
        value = value * 10 + (uint64_t)(text[i] - '0');
    }
    *out = value;
    return true;
}

struct cluster_entry *cluster_redis_snapshot(redisContext *c, const struct cluster_keys *k,
                                             uint64_t initial_revision, const char *initial_state,
                                             bool *absent, char *why, size_t whylen)
{
    *absent = false;
    char revision[24];
    snprintf(revision, sizeof revision, "%" PRIu64, initial_revision);
    const char *argv[] = { "EVAL",    SNAPSHOT_SCRIPT, "4",
                           k->rev,    k->state,        k->map,
                           k->stream, revision,        initial_state ? initial_state : "" };
    size_t lengths[9];
    for (int i = 0; i < 9; i++)
        lengths[i] = strlen(argv[i]);
    redisReply *r = redisCommandArgv(c, initial_state ? 9 : 7, argv, lengths);
    if (!r || r->type != REDIS_REPLY_ARRAY || (r->elements != 0 && r->elements != 4)) {
        cluster_redis_describe(c, r, why, whylen);
        if (r)
            freeReplyObject(r);
        return NULL;
    }
    if (r->elements == 0) {
        *absent = true;
        snprintf(why, whylen, "the world does not exist");
        freeReplyObject(r);
        return NULL;
    }
    struct cluster_entry *e = calloc(1, sizeof *e);
    bool ok = e != NULL;
    for (size_t i = 0; ok && i < 4; i++)
        ok = r->element[i]->type == REDIS_REPLY_STRING;
    ok = ok && parse_revision(r->element[0]->str, r->element[0]->len, &e->revision) &&
         r->element[2]->len < sizeof e->id;
    if (ok) {
        e->snapshot = true;
        memcpy(e->id, r->element[2]->str, r->element[2]->len);
        e->state = dup_bytes(r->element[1]->str, r->element[1]->len);
        e->by = dup_bytes("", 0);
        e->changed = dup_bytes("", 0);
        ok = e->state && e->by && e->changed;
        if (ok && r->element[3]->len > 0) {
            e->map = (unsigned char *)dup_bytes(r->element[3]->str, r->element[3]->len);
            e->map_length = r->element[3]->len;
            ok = e->map != NULL;
        }
    }
    if (!ok)
        snprintf(why, whylen, e ? "the world's keys hold unexpected values" : "out of memory");
    freeReplyObject(r);
    if (!ok) {
        cluster_entry_free(e);
        return NULL;
    }
    return e;
}

struct cluster_entry *cluster_redis_parse_entry(const redisReply *item, char *why, size_t whylen)
{
    if (item->type != REDIS_REPLY_ARRAY || item->elements != 2 ||
        item->element[0]->type != REDIS_REPLY_STRING || item->element[0]->len >= CLUSTER_ID_MAX ||
        item->element[1]->type != REDIS_REPLY_ARRAY) {
        snprintf(why, whylen, "a stream entry of unexpected shape");
        return NULL;
    }
    struct cluster_entry *e = calloc(1, sizeof *e);
    if (!e) {
        snprintf(why, whylen, "out of memory");
        return NULL;
    }
    memcpy(e->id, item->element[0]->str, item->element[0]->len);
    const redisReply *fields = item->element[1];
    bool has_revision = false, ok = true;
    for (size_t i = 0; ok && i + 1 < fields->elements; i += 2) {
        const redisReply *name = fields->element[i], *value = fields->element[i + 1];
        if (name->type != REDIS_REPLY_STRING || value->type != REDIS_REPLY_STRING)
            continue;
        if (strcmp(name->str, "rev") == 0) {
            has_revision = parse_revision(value->str, value->len, &e->revision);
        } else if (strcmp(name->str, "state") == 0 && !e->state) {
            ok = (e->state = dup_bytes(value->str, value->len)) != NULL;
        } else if (strcmp(name->str, "by") == 0 && !e->by) {
            ok = (e->by = dup_bytes(value->str, value->len)) != NULL;
        } else if (strcmp(name->str, "changed") == 0 && !e->changed) {
            ok = (e->changed = dup_bytes(value->str, value->len)) != NULL;
        } else if (strcmp(name->str, "map") == 0 && !e->map) {
            ok = (e->map = (unsigned char *)dup_bytes(value->str, value->len)) != NULL;
            e->map_length = value->len;
        }
    }
    if (ok && (!has_revision || !e->state || !e->by || !e->changed)) {
        snprintf(why, whylen, "stream entry %s lacks rev, state, by or changed", e->id);
        cluster_entry_free(e);
        return NULL;
    }
    if (!ok) {
        snprintf(why, whylen, "out of memory");
        cluster_entry_free(e);
        return NULL;
    }
    return e;
}
