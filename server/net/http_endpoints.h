/* The HTTP API's endpoints: what each request becomes, given what it reads (the metrics, the
 * render loop's health, the query, the body). Each fills an http_answer: a response to write,
 * an error in the protocol's `error` shape, or a protocol message to submit from the
 * request's session. http_api.c routes requests here and carries the answers out; the
 * endpoints neither write to the connection nor talk to the render loop's queue. Internal to
 * server/net. */
#ifndef SKYD_HTTP_ENDPOINTS_H
#define SKYD_HTTP_ENDPOINTS_H

#include <stdbool.h>
#include <stddef.h>

#include "error_text.h"
#include "messages.h"

struct cJSON;
struct lws;
struct render_loop;
struct service_metrics;
struct session_hub;

enum http_answer_kind {
    HTTP_ANSWER_RESPONSE, /* status, content_type and body */
    HTTP_ANSWER_ERROR,    /* code and message; the status is the code's */
    HTTP_ANSWER_SUBMIT,   /* json, sent as a protocol message with role */
};

struct http_answer {
    enum http_answer_kind kind;
    unsigned status;
    const char *content_type;
    char *body; /* malloc'd; NULL: the JSON text "{}" */
    size_t body_length;
    enum proto_msg_error_code code;
    error_text message;
    struct cJSON *json;
    enum proto_msg_role role;
};

/* Frees what the answer holds (its body and JSON). */
void http_answer_release(struct http_answer *answer);

/* GET /healthz: ok, or unavailable when rendering stopped (loop NULL: shutting down) or the
 * render thread has not ticked lately. */
void http_endpoint_health(struct http_answer *out, struct service_metrics *metrics,
                          struct render_loop *loop, struct session_hub *hub);
/* GET /metrics: the Prometheus exposition. */
void http_endpoint_metrics(struct http_answer *out, struct service_metrics *metrics,
                           struct session_hub *hub);
/* GET /api/schema: the world state's JSON Schema. */
void http_endpoint_schema(struct http_answer *out);
/* GET /api/weather/forecast: the forecast folder's state (service_metrics_forecast). */
void http_endpoint_forecast(struct http_answer *out, struct service_metrics *metrics);
/* GET /api/state: a get_state message. */
void http_endpoint_state(struct http_answer *out);
/* GET /api/snapshot: a snapshot message whose view the query parameters of wsi's request
 * fill. */
void http_endpoint_snapshot(struct http_answer *out, struct lws *wsi);
/* POST /api/weather/metar once its body is in: an apply_observation message with the body as
 * its report, either the METAR's text or a JSON object {"metar": "..."} (a body that starts
 * with '{'). */
void http_endpoint_metar(struct http_answer *out, const char *body, size_t length, bool too_large,
                         size_t max_message_bytes);
/* PATCH /api/state once its body is in: a set message with the body as its patch. */
void http_endpoint_patch(struct http_answer *out, const char *body, size_t length, bool too_large,
                         size_t max_message_bytes);

#endif
