#include "cluster_url.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define URL_FORM "redis://[USER[:PASSWORD]@]HOST:PORT[/DB]"

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

static int hex_digit(char c)
{
    if (c >= '0' && c <= '9')
        return c - '0';
    if (c >= 'a' && c <= 'f')
        return c - 'a' + 10;
    if (c >= 'A' && c <= 'F')
        return c - 'A' + 10;
    return -1;
}

/* `length` bytes of a URL's user or password, percent-decoded into out (capacity outlen).
 * false when a '%' is not followed by two hex digits, a byte decodes to NUL, or it does not
 * fit; `what` names the part in the reason, which never quotes the text. */
static bool decode_part(const char *text, size_t length, char *out, size_t outlen, const char *what,
                        char *why, size_t whylen)
{
    size_t n = 0;
    for (size_t i = 0; i < length; i++) {
        int c = (unsigned char)text[i];
        if (c == '%') {
            int hi = i + 2 < length ? hex_digit(text[i + 1]) : -1;
            int lo = i + 2 < length ? hex_digit(text[i + 2]) : -1;
            if (hi < 0 || lo < 0) {
                snprintf(why, whylen,
                         "the %s has a '%%' that is not followed by two hex digits (write a "
                         "'%%' as %%25)",
                         what);
                return false;
            }
            c = hi * 16 + lo;
            i += 2;
        }
        if (c == 0) {
            snprintf(why, whylen, "the %s holds a NUL byte", what);
            return false;
        }
        if (n + 1 >= outlen) {
            snprintf(why, whylen, "the %s is longer than %zu bytes", what, outlen - 1);
            return false;
        }
        out[n++] = (char)c;
    }
    out[n] = '\0';
    return true;
}

/* USER[:PASSWORD] before the '@'. */
static bool parse_userinfo(const char *info, size_t length, struct cluster_address *out, char *why,
                           size_t whylen)
{
    if (length == 0) {
        snprintf(why, whylen, "nothing before the '@': expected %s", URL_FORM);
        return false;
    }
    const char *colon = memchr(info, ':', length);
    size_t user_length = colon ? (size_t)(colon - info) : length;
    if (!decode_part(info, user_length, out->user, sizeof out->user, "user name", why, whylen))
        return false;
    for (const char *c = out->user; *c; c++) {
        if ((unsigned char)*c <= ' ' || *c == 0x7f) {
            snprintf(why, whylen, "the user name has a space or a control character");
            return false;
        }
    }
    if (!colon)
        return true;
    out->has_password = true;
    return decode_part(colon + 1, length - user_length - 1, out->password, sizeof out->password,
                       "password", why, whylen);
}

static bool parse_url(const char *url, struct cluster_address *out, char *why, size_t whylen)
{
    static const char scheme[] = "redis://";
    if (strncmp(url, scheme, sizeof scheme - 1) != 0) {
        /* Only the scheme is quoted: the rest may hold a password. */
        const char *end = strstr(url, "://");
        int shown = end && end - url <= 16 ? (int)(end - url) : 0;
        if (shown == 6 && strncmp(url, "rediss", 6) == 0)
            snprintf(why, whylen,
                     "rediss:// (TLS) is not spoken by skyd: connect to a TLS tunnel on "
                     "loopback, e.g. stunnel, with redis:// (docs/SCALING.md)");
        else if (shown > 0)
            snprintf(why, whylen, "expected %s, got a URL of scheme \"%.*s\"", URL_FORM, shown,
                     url);
        else
            snprintf(why, whylen, "expected %s", URL_FORM);
        return false;
    }
    const char *rest = url + sizeof scheme - 1;
    /* The last '@' ends the user and password, so that a password may hold '@' and '/'. */
    const char *at = strrchr(rest, '@');
    if (at) {
        if (!parse_userinfo(rest, (size_t)(at - rest), out, why, whylen))
            return false;
        rest = at + 1;
    }
    const char *host = rest;
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
            snprintf(why, whylen, "the host has a '%c'", c >= 0x20 && c < 0x7f ? c : '?');
            return false;
        }
    }
    if (*after != ':') {
        snprintf(why, whylen, "the port is missing: expected %s", URL_FORM);
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
    const char *tail = port + port_length;
    if (*tail == '/') {
        if (!parse_int(tail + 1, strlen(tail + 1), 0, 1000000, &value)) {
            snprintf(why, whylen, "the database after '/' must be a non-negative integer");
            return false;
        }
        out->db = (int)value;
        out->has_db = true;
    } else if (*tail) {
        snprintf(why, whylen, "unexpected \"%.32s\" after the port", tail);
        return false;
    }
    memcpy(out->host, host, host_length);
    out->host[host_length] = '\0';
    return true;
}

bool cluster_url_parse(const char *url, struct cluster_address *out, char *why, size_t whylen)
{
    memset(out, 0, sizeof *out);
    if (parse_url(url, out, why, whylen))
        return true;
    memset(out, 0, sizeof *out); /* no part of a refused URL, its password least of all */
    return false;
}

void cluster_url_redacted(const struct cluster_address *a, char *out, size_t outlen)
{
    char db[24] = "";
    if (a->has_db)
        snprintf(db, sizeof db, "/%d", a->db);
    bool ipv6 = strchr(a->host, ':') != NULL;
    bool userinfo = a->user[0] || a->has_password;
    snprintf(out, outlen, "redis://%s%s%s%s%s%s:%d%s", a->user, a->has_password ? ":***" : "",
             userinfo ? "@" : "", ipv6 ? "[" : "", a->host, ipv6 ? "]" : "", a->port, db);
}

bool cluster_address_authenticates(const struct cluster_address *a)
{
    return a->has_password || a->user[0];
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
