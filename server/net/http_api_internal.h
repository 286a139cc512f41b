/* The HTTP API's parts shared by its request handling (http_api.c) and its endpoints
 * (http_endpoints.c), internal to server/net/. */
#ifndef SKYD_HTTP_API_INTERNAL_H
#define SKYD_HTTP_API_INTERNAL_H

#include <stdbool.h>
#include <stddef.h>

#include <cjson/cJSON.h>

#include "http_api.h"

/* /healthz fails when the render thread has not ticked for this long (it ticks at least once
 * a second when idle). */
#define HEALTHY_TICK_AGE_S 5.0
/* The id of the messages an HTTP request sends. */
#define HTTP_MESSAGE_ID "http"
/* How long a request may wait for the render loop's reply. */
#define REPLY_TIMEOUT_S 120
/* Requests of one peer address kept for the rate limit; the least recent one gives way. */
#define RATE_PEERS 64

enum endpoint {
    ENDPOINT_NONE = 0,
    ENDPOINT_HEALTH,
    ENDPOINT_METRICS,
    ENDPOINT_STATE,    /* GET: the state; PATCH: a patch */
    ENDPOINT_SNAPSHOT,
    ENDPOINT_SCHEMA,
};

/* One request on a connection (lws keeps this per connection and reuses it for the next request
 * of a kept-alive one). */
struct http_request {
    struct http_request *next_pending; /* in api->pending while its session may answer */
    struct lws *wsi;
    enum endpoint endpoint;
    bool patch;                        /* PATCH rather than GET */
    bool pending;
    struct session *session;           /* the message's sender, until its reply is written */
    char *body;                        /* a PATCH's body as it arrives */
    size_t body_length, body_capacity;
    bool body_too_large;
    /* The response once known. */
    bool ready;
    unsigned status;
    const char *content_type;
    char *response;                    /* LWS_PRE bytes, then response_length bytes */
    size_t response_length;
    struct encoded_frame *frame;       /* a snapshot's image instead of `response` */
};

struct rate_peer {
    char address[64];
    double tokens, refilled_at, used_at;
};

struct http_api {
    struct live_settings *settings;
    const struct sky_msg_limits *limits;
    struct session_hub *hub;
    struct render_loop *loop;
    struct service_metrics *metrics;
    struct http_request *pending;
    int pending_count;               /* bounded by max_clients */
    struct rate_peer peers[RATE_PEERS];
    struct lws_http_mount mounts[3];
};

/* The response (copied), written when the connection is writable. */
void respond(struct http_request *r, unsigned status, const char *content_type, const char *text,
             size_t length);
/* An error in the protocol's `error` shape, with `status`, or the status its code maps to when
 * status is 0; counted in the metrics. */
void respond_error(struct http_api *api, struct http_request *r, unsigned status,
                   enum sky_msg_error_code code, const char *message,
                   const struct sky_field_errors *fields);
void respond_json(struct http_request *r, unsigned status, cJSON *json);
/* Parses `json` (given the HTTP id) as a protocol message and hands it to the render loop from
 * the request's own session with `role`; a refusal becomes the response. */
void submit_json(struct http_api *api, struct http_request *r, cJSON *json,
                 enum sky_msg_role role);

void answer_health(struct http_api *api, struct http_request *r);
void answer_metrics(struct http_api *api, struct http_request *r);
void answer_schema(struct http_api *api, struct http_request *r);
/* GET /api/snapshot: a snapshot message whose view the query parameters fill. */
void answer_snapshot(struct http_api *api, struct http_request *r);
/* PATCH /api/state once its body is in: a set message with the body as its patch. */
void answer_patch(struct http_api *api, struct http_request *r);

#endif
