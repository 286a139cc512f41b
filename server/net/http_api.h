/* The HTTP API on the WebSocket port (protocol/PROTOCOL.md, "HTTP API"): GET /healthz,
 * GET /metrics, GET /api/state, PATCH /api/state, GET /api/snapshot, GET /api/schema.
 *
 * A request that needs the world (state, patch, snapshot) becomes a protocol message from a
 * session of its own, which the render loop answers like any other: a patch is checked, applied
 * and announced to the WebSocket clients exactly as a `set`. The session is not in the hub (it
 * gets no events and is not counted as a client); its reply becomes the HTTP response, errors
 * in the protocol's `error` shape. Only the service thread calls these. */
#ifndef SKYD_HTTP_API_H
#define SKYD_HTTP_API_H

#include <stddef.h>

#include <libwebsockets.h>

#include "live_settings.h"
#include "messages.h"
#include "render_loop.h"
#include "service_metrics.h"
#include "session.h"

struct http_api_params {
    struct live_settings *settings;        /* the controller token and read-only mode */
    const struct proto_msg_limits *limits; /* kept current by the caller */
    struct session_hub *hub;               /* the WebSocket clients, for skyd_clients */
    struct render_loop *loop;
    struct service_metrics *metrics;
};

struct http_api;

struct http_api *http_api_create(const struct http_api_params *params);
void http_api_destroy(struct http_api **api);

/* The render loop is going: requests waiting for it are answered 503, new ones too. */
void http_api_detach_loop(struct http_api *api);

/* The name of the lws protocol whose callback calls http_api_callback, and the API's mounts,
 * chained in front of `next` (the static files); they live as long as the api. */
#define HTTP_API_PROTOCOL "skyd-http"
const struct lws_http_mount *http_api_mounts(struct http_api *api,
                                             const struct lws_http_mount *next);
/* The protocol's per-connection data size. */
size_t http_api_request_size(void);

/* The protocol's callback. */
int http_api_callback(struct http_api *api, struct lws *wsi, enum lws_callback_reasons reason,
                      void *user, void *in, size_t len);

/* The peer's address for logs and rate limits ("127.0.0.1", not "::ffff:127.0.0.1"). */
void net_peer_address(struct lws *wsi, char *out, size_t size);

/* Some session gained output: requests whose reply is ready are scheduled for writing. */
void http_api_wake(struct http_api *api);

#endif
