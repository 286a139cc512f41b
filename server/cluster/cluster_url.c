#include "cluster_url.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static bool parse_int(const char *text, size_t length, long lo, long hi, long *out)
{
    if (length == 0 || length > 9)
        return false;
    long value = 0;
    for (size_t i = 0; i < length; i++) {
        if (text[i] < '0' || text[i] > '9')
            return false;
        value = value * 10 + (text[i] - '0');
    }
    if (value < lo || value > hi)
        return false;
    *out = value;
    return true;
}

bool cluster_url_parse(const char *url, struct cluster_address *out, char *why, size_t whylen)
{
    static const char scheme[] = "redis://";
    memset(out, 0, sizeof *out);
    if (strncmp(url, scheme, sizeof scheme - 1) != 0) {
        snprintf(why, whylen, "expected redis://HOST:PORT[/DB], got \"%.64s\"", url);
        return false;
    }
    const char *host = url + sizeof scheme - 1;
    const char *host_end, *after;
    if (*host == '[') { /* [IPv6]:PORT */
        host++;
        host_end = strchr(host, ']');
        if (!host_end) {
            snprintf(why, whylen, "an IPv6 host needs its closing ']'");
            return false;
        }
        after = host_end + 1;
    } else {
        host_end = host + strcspn(host, ":/");
        after = host_end;
    }
    size_t host_length = (size_t)(host_end - host);
    if (host_length == 0 || host_length >= sizeof out->host) {
        snprintf(why, whylen, "the host must be 1 to %zu characters", sizeof out->host - 1);
        return false;
    }
    for (size_t i = 0; i < host_length; i++) {
        char c = host[i];
        bool ok = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') ||
                  c == '.' || c == '-' || c == ':' || c == '_';
        if (!ok) {
            snprintf(why, whylen,
                     "the host has a '%c' (user names and passwords are not "
                     "supported)",
                     c);
            return false;
        }
    }
    if (*after != ':') {
        snprintf(why, whylen, "the port is missing: expected redis://HOST:PORT[/DB]");
        return false;
    }
    const char *port = after + 1;
    size_t port_length = strcspn(port, "/");
    long value = 0;
    if (!parse_int(port, port_length, 1, 65535, &value)) {
        snprintf(why, whylen, "the port must be an integer in [1, 65535]");
        return false;
    }
    out->port = (int)value;
    const char *rest = port + port_length;
    if (*rest == '/') {
        if (!parse_int(rest + 1, strlen(rest + 1), 0, 1000000, &value)) {
            snprintf(why, whylen, "the database after '/' must be a non-negative integer");
            return false;
        }
        out->db = (int)value;
    } else if (*rest) {
        snprintf(why, whylen, "unexpected \"%.32s\" after the port", rest);
        return false;
    }
    memcpy(out->host, host, host_length);
    out->host[host_length] = '\0';
    return true;
}

bool cluster_world_name_check(const char *name, char *why, size_t whylen)
{
    size_t length = strlen(name);
    if (length == 0 || length > CLUSTER_WORLD_MAX) {
        snprintf(why, whylen, "a world name has 1 to %d characters", CLUSTER_WORLD_MAX);
        return false;
    }
    for (size_t i = 0; i < length; i++) {
        char c = name[i];
        if (!((c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') ||
              c == '-' || c == '_')) {
            snprintf(why, whylen, "character %zu ('%c') is not a letter, digit, '-' or '_'", i,
                     c >= 0x20 && c < 0x7f ? c : '?');
            return false;
        }
    }
    return true;
}
