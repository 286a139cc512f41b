/* The settings a running daemon can change without dropping anyone (SIGHUP): the protocol
 * limits and the HTTP API's queue, the controller token and read-only mode, and the allowed origins. The service
 * thread and the render thread read them through here, under one lock, so that a reload
 * takes effect for the next connection, message or auth at once and never half-way. */
#ifndef SKYD_LIVE_SETTINGS_H
#define SKYD_LIVE_SETTINGS_H

#include <stdbool.h>
#include <stddef.h>

#include "config.h"
#include "messages.h"

struct live_settings;

/* From a loaded configuration whose controller_token is final ("" when nobody controls). */
struct live_settings *live_settings_create(const struct skyd_config *config);
void live_settings_destroy(struct live_settings **settings);

void live_settings_limits(struct live_settings *s, struct proto_msg_limits *limits);
/* limits.max_queued_http_requests: HTTP requests that may wait for the render loop at once. */
int live_settings_max_queued_http(struct live_settings *s);
bool live_settings_origin_allowed(struct live_settings *s, const char *origin);

enum live_token_check {
    LIVE_TOKEN_MATCHES = 0,
    LIVE_TOKEN_WRONG,
    LIVE_TOKEN_NONE,      /* no token is configured: nobody can control */
    LIVE_TOKEN_READ_ONLY, /* "read_only": true: nobody can control */
};
/* Compares in constant time for the token's length. */
enum live_token_check live_settings_check_token(struct live_settings *s, const char *given);

/* Takes the reloadable fields of `next` and describes what changed ("limits.max_clients 64 ->
 * 8; controller token changed; ..."; "nothing" when none did) in `changes`. Tokens are never
 * written into it. */
void live_settings_update(struct live_settings *s, const struct skyd_config *next, char *changes,
                          size_t changes_size);

#endif
