/* The "cluster" section of the configuration: where Redis is ("redis://HOST:PORT[/DB]") and
 * which world the nodes share (a name of letters, digits, '-' and '_'). Pure parsing: the
 * configuration checks these before anything connects. */
#ifndef SKYD_CLUSTER_URL_H
#define SKYD_CLUSTER_URL_H

#include <stdbool.h>
#include <stddef.h>

#define CLUSTER_HOST_MAX 256
#define CLUSTER_WORLD_MAX 64

struct cluster_address {
    char host[CLUSTER_HOST_MAX]; /* a name or an IPv4 address; "[...]" IPv6 without brackets */
    int port;                    /* 1..65535 */
    int db;                      /* 0..(Redis's databases - 1); 0 when the URL has none */
};

/* false with `why` saying what is wrong with the URL. */
bool cluster_url_parse(const char *url, struct cluster_address *out, char *why, size_t whylen);

/* A world name: 1..CLUSTER_WORLD_MAX characters of [A-Za-z0-9_-]. false with `why`. */
bool cluster_world_name_check(const char *name, char *why, size_t whylen);

#endif
