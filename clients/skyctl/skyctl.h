/* skyctl: the command-line client of skyd. Exit codes are part of its interface (README,
 * `skyctl --help`): scripts rely on them. */
#ifndef SKYD_SKYCTL_H
#define SKYD_SKYCTL_H

#include <stdbool.h>
#include <stddef.h>

struct cJSON;
struct sky_client;

enum skyctl_exit {
    SKYCTL_OK = 0,
    SKYCTL_SERVER_ERROR = 1, /* the server answered `error`; the message names the field */
    SKYCTL_USAGE = 2,        /* bad command line */
    SKYCTL_CONNECTION = 3,   /* cannot connect, connection lost, or no reply in time */
};

struct skyctl_options {
    const char *url;     /* ws://HOST:PORT/ or wss://HOST:PORT/ */
    const char *token;   /* NULL: stay a viewer */
    int timeout_ms;      /* connecting, and each reply */
    const char *ca_file; /* wss: the PEM certificates to trust instead of the system's */
    bool insecure;       /* wss: accept any server certificate */
    bool json;           /* --json: one JSON object per line on stdout instead of text */
};

/* One connection: hello read, auth done when a token was given. */
struct skyctl_session {
    struct sky_client *client;
    long next_id;
    int timeout_ms;
};

/* Connects, reads `hello`, and authenticates when options->token is set. Returns an exit
 * code after printing why on stderr. */
int skyctl_connect(const struct skyctl_options *options, struct skyctl_session *session);
void skyctl_disconnect(struct skyctl_session *session);

/* Sends msg (ownership stays with the caller) with a fresh integer id and waits for the reply
 * carrying it; events and frames before it are dropped. On SKYCTL_OK the caller owns *reply.
 * An `error` reply is printed on stderr as "skyctl: WHAT: ..." with each field entry's
 * pointer and reason, and gives SKYCTL_SERVER_ERROR. */
int skyctl_request(struct skyctl_session *session, const char *what, struct cJSON *msg,
                   struct cJSON **reply);

/* Prints an `error` message on stderr, one line per field entry. */
void skyctl_print_error(const char *what, const struct cJSON *error);

/* Adds "a.b.c=VALUE" to root as {"a":{"b":{"c":VALUE}}}. VALUE is JSON when it parses as
 * JSON (numbers, arrays, true, "quoted"), otherwise a string (2026-06-21T18:00:00Z, hm98).
 * Returns false with a reason in err. */
bool skyctl_assign(struct cJSON *root, const char *assignment, char *err, size_t errlen);

/* The member at a dotted path ("sun.elevation_deg") or JSON Pointer ("/sun/elevation_deg");
 * NULL when there is none. */
const struct cJSON *skyctl_lookup(const struct cJSON *root, const char *path);

/* Prints a JSON value: strings bare, everything else as (indented) JSON. */
void skyctl_print_value(const struct cJSON *value);

/* --json output: value as one line of compact JSON, flushed. */
void skyctl_print_json_line(const struct cJSON *value);

/* --json output of a server reply: the message less its id. */
void skyctl_print_reply_json(struct cJSON *reply);

/* The commands; argv[0] is the command's name. */
int skyctl_get(const struct skyctl_options *options, int argc, char **argv);
int skyctl_weather_map(const struct skyctl_options *options, int argc, char **argv);
int skyctl_metar(const struct skyctl_options *options, int argc, char **argv);
int skyctl_forecast(const struct skyctl_options *options, int argc, char **argv);
int skyctl_set(const struct skyctl_options *options, int argc, char **argv);
int skyctl_preset(const struct skyctl_options *options, int argc, char **argv);
int skyctl_probe(const struct skyctl_options *options, int argc, char **argv);
int skyctl_stats(const struct skyctl_options *options, int argc, char **argv);
int skyctl_snapshot(const struct skyctl_options *options, int argc, char **argv);
int skyctl_watch(const struct skyctl_options *options, int argc, char **argv);

/* Usage errors: prints "skyctl CMD: MESSAGE" and the hint to --help; returns SKYCTL_USAGE. */
int skyctl_usage_error(const char *command, const char *format, ...)
    __attribute__((format(printf, 2, 3)));

/* Parses a decimal number in [lo, hi]; false when it is not one. */
bool skyctl_parse_number(const char *text, double lo, double hi, double *out);

#endif
