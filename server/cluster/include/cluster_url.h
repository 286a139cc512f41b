/* The "cluster" section of the configuration: where Redis is
 * ("redis://[USER[:PASSWORD]@]HOST:PORT[/DB]") and which world the nodes share (a name of
 * letters, digits, '-' and '_'). Pure parsing: the configuration checks these before anything
 * connects. A password never leaves this struct in text: messages name the cluster by
 * cluster_url_redacted, and no error of the parser quotes it. */
#ifndef SKYD_CLUSTER_URL_H
#define SKYD_CLUSTER_URL_H

#include <stdbool.h>
#include <stddef.h>

#define CLUSTER_HOST_MAX 256
#define CLUSTER_USER_MAX 128
#define CLUSTER_PASSWORD_MAX 512
#define CLUSTER_WORLD_MAX 64
/* Room for cluster_url_redacted's text. */
#define CLUSTER_URL_TEXT_MAX (CLUSTER_HOST_MAX + CLUSTER_USER_MAX + 48)

struct cluster_address {
    char host[CLUSTER_HOST_MAX]; /* a name or an IPv4 address; "[...]" IPv6 without brackets */
    int port;                    /* 1..65535 */
    int db;                      /* 0..(Redis's databases - 1); 0 when the URL has none */
    bool has_db;                 /* the URL named the database */
    /* Redis 6+ ACL user ("" = the default user) and password ("" = none: no AUTH), both
     * percent-decoded. has_password tells a password given in the URL, even an empty one. */
    char user[CLUSTER_USER_MAX];
    char password[CLUSTER_PASSWORD_MAX];
    bool has_password;
};

/* false with `why` saying what is wrong with the URL (never quoting its password). */
bool cluster_url_parse(const char *url, struct cluster_address *out, char *why, size_t whylen);

/* The address as a URL for messages and logs: "redis://USER:***@HOST:PORT/DB" when it has a
 * password ("redis://USER@..." with a user and no password), the database when the URL named
 * one. Never the password. */
void cluster_url_redacted(const struct cluster_address *address, char *out, size_t outlen);

/* Whether AUTH is sent on connecting: a password, or a user (whose password may come from
 * elsewhere, or who is nopass). */
bool cluster_address_authenticates(const struct cluster_address *address);

/* A world name: 1..CLUSTER_WORLD_MAX characters of [A-Za-z0-9_-]. false with `why`. */
bool cluster_world_name_check(const char *name, char *why, size_t whylen);

#endif
