/* The libwebsockets side of the daemon: one thread that serves the web client's files and the
 * HTTP API (http_api.h) over HTTP and the protocol over WebSocket on the same port. It only moves bytes: it reassembles
 * messages (bounded by max_message_bytes), checks Origin, the client limit and the message
 * rate, parses with protocol/, and hands each message to the render loop in order; it writes
 * what the sessions have queued when woken. */
#ifndef SKYD_WS_SERVER_H
#define SKYD_WS_SERVER_H

#include <signal.h>
#include <stdbool.h>
#include <stddef.h>

#include "config.h"
#include "live_settings.h"
#include "render_loop.h"
#include "service_metrics.h"
#include "session.h"

struct ws_server_params {
    const struct skyd_config *config; /* listen address, port, TLS, limits, origins */
    const char *web_root;             /* absolute path of the static files */
    struct session_hub *hub;
    struct render_loop *loop;
    struct service_metrics *metrics; /* messages, errors and frames sent; /metrics, /healthz */
    struct live_settings *settings;  /* limits, origins, token: what a reload may change */
};

struct ws_server;

struct ws_server *ws_server_create(const struct ws_server_params *params, char *err, size_t errlen);
void ws_server_destroy(struct ws_server **server);

/* The base URL, with the port listened on (the kernel's pick when the config says 0). */
const char *ws_server_url(const struct ws_server *server);

/* Serves until *stop becomes non-zero (set it, then call ws_server_wake). */
void ws_server_run(struct ws_server *server, volatile sig_atomic_t *stop);
/* Closes every connection with `code` and `reason` (1001 "skyd shutting down" at a signal),
 * after what is queued for it when after_output, and serves until they are gone or timeout_s
 * passes. */
void ws_server_close_all(struct ws_server *server, int code, const char *reason, bool after_output,
                         double timeout_s);
/* The render loop is about to go: messages still arriving are dropped. */
void ws_server_detach_loop(struct ws_server *server);

/* Wakes the service thread; callable from any thread (the hub's wake callback). */
void ws_server_wake(void *server);

#endif
