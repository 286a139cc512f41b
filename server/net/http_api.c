#include "http_api.h"

#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include <cjson/cJSON.h>

#include "error_text.h"
#include "field_errors.h"
#include "http_endpoints.h"
#include "json_guard.h"
#include "log.h"
#include "monotonic_clock.h"

/* The id of the messages an HTTP request sends. */
#define HTTP_MESSAGE_ID "http"
/* How long a request may wait for the render loop's reply. */
#define REPLY_TIMEOUT_S 120
/* What Retry-After says to a request refused because the render loop's queue is full, s. */
#define QUEUE_RETRY_AFTER_S 1
/* Requests of one peer address kept for the rate limit; the least recent one gives way. */
#define RATE_PEERS 64

enum endpoint {
    ENDPOINT_NONE = 0,
    ENDPOINT_HEALTH,
    ENDPOINT_METRICS,
    ENDPOINT_STATE, /* GET: the state; PATCH: a patch */
    ENDPOINT_SNAPSHOT,
    ENDPOINT_SCHEMA,
    ENDPOINT_METAR,    /* POST: a METAR applied to the weather */
    ENDPOINT_FORECAST, /* the forecast folder's state */
};

/* One request on a connection (lws keeps this per connection and reuses it for the next request
 * of a kept-alive one). */
struct http_request {
    struct http_request *next_pending; /* in api->pending while its session may answer */
    struct lws *wsi;
    enum endpoint endpoint;
    bool patch; /* a change with a body: PATCH /api/state, POST /api/weather/metar */
    bool pending;
    struct session *session; /* the message's sender, until its reply is written */
    char *body;              /* a PATCH's body as it arrives */
    size_t body_length, body_capacity;
    bool body_too_large;
    /* The response once known. */
    bool ready;
    unsigned status;
    unsigned retry_after_s; /* a Retry-After header when > 0 */
    const char *content_type;
    char *response; /* LWS_PRE bytes, then response_length bytes */
    size_t response_length;
    struct encoded_frame *frame; /* a snapshot's image instead of `response` */
};

struct rate_peer {
    char address[64];
    double tokens, refilled_at, used_at;
};

struct http_api {
    struct live_settings *settings;
    const struct proto_msg_limits *limits;
    struct session_hub *hub;
    struct render_loop *loop;
    struct service_metrics *metrics;
    struct http_request *pending;
    int pending_count; /* bounded by limits.max_queued_http_requests */
    struct rate_peer peers[RATE_PEERS];
    struct lws_http_mount mounts[3];
};

struct http_api *http_api_create(const struct http_api_params *params)
{
    struct http_api *api = calloc(1, sizeof *api);
    if (!api)
        return NULL;
    api->settings = params->settings;
    api->limits = params->limits;
    api->hub = params->hub;
    api->loop = params->loop;
    api->metrics = params->metrics;
    static const char *const points[] = { "/api", "/healthz", "/metrics" };
    for (int i = 0; i < 3; i++) {
        api->mounts[i] = (struct lws_http_mount){
            .mountpoint = points[i],
            .mountpoint_len = (unsigned char)strlen(points[i]),
            .protocol = HTTP_API_PROTOCOL,
            .origin_protocol = LWSMPRO_CALLBACK,
        };
    }
    return api;
}

void net_peer_address(struct lws *wsi, char *out, size_t size)
{
    out[0] = '\0';
    lws_get_peer_simple(wsi, out, size);
    if (strncmp(out, "::ffff:", 7) == 0 && strchr(out, '.')) /* IPv4 on an IPv6 socket */
        memmove(out, out + 7, strlen(out + 7) + 1);
}

size_t http_api_request_size(void)
{
    return sizeof(struct http_request);
}

static void forget_pending(struct http_api *api, struct http_request *r)
{
    if (!r->pending)
        return;
    for (struct http_request **at = &api->pending; *at; at = &(*at)->next_pending) {
        if (*at == r) {
            *at = r->next_pending;
            break;
        }
    }
    r->pending = false;
    r->next_pending = NULL;
    api->pending_count--;
}

/* Ends whatever the request holds: its session leaves the render loop's books. */
static void release_request(struct http_api *api, struct http_request *r)
{
    forget_pending(api, r);
    if (r->session) {
        session_mark_closed(r->session);
        if (api->loop)
            render_loop_session_closed(api->loop, r->session);
        session_unref(&r->session);
    }
    free(r->body);
    free(r->response);
    if (r->frame)
        encoded_frame_unref(&r->frame);
    struct lws *wsi = r->wsi;
    memset(r, 0, sizeof *r);
    r->wsi = wsi;
}

void http_api_destroy(struct http_api **api_ptr)
{
    struct http_api *api = *api_ptr;
    *api_ptr = NULL;
    if (!api)
        return;
    while (api->pending)
        release_request(api, api->pending);
    free(api);
}

const struct lws_http_mount *http_api_mounts(struct http_api *api,
                                             const struct lws_http_mount *next)
{
    api->mounts[0].mount_next = &api->mounts[1];
    api->mounts[1].mount_next = &api->mounts[2];
    api->mounts[2].mount_next = next;
    return &api->mounts[0];
}

/* ---- responses ---- */

/* The response (copied), written when the connection is writable. */
static void respond(struct http_request *r, unsigned status, const char *content_type,
                    const char *text, size_t length)
{
    free(r->response);
    r->response = malloc(LWS_PRE + length + 1);
    if (r->response) {
        memcpy(r->response + LWS_PRE, text, length);
        r->response_length = length;
    } else {
        r->response_length = 0;
        status = HTTP_STATUS_INTERNAL_SERVER_ERROR;
    }
    r->status = status;
    r->content_type = content_type;
    r->ready = true;
    lws_callback_on_writable(r->wsi);
}

static unsigned status_of_error(enum proto_msg_error_code code)
{
    switch (code) {
    case PROTO_MSG_ERR_MALFORMED_JSON:
    case PROTO_MSG_ERR_INVALID_ENCODING:
    case PROTO_MSG_ERR_UNSUPPORTED_PROTOCOL:
        return HTTP_STATUS_BAD_REQUEST;
    case PROTO_MSG_ERR_MESSAGE_TOO_LARGE:
        return HTTP_STATUS_REQ_ENTITY_TOO_LARGE;
    case PROTO_MSG_ERR_AUTH_FAILED:
        return HTTP_STATUS_UNAUTHORIZED;
    case PROTO_MSG_ERR_FORBIDDEN:
        return HTTP_STATUS_FORBIDDEN;
    case PROTO_MSG_ERR_NOT_FOUND:
        return HTTP_STATUS_NOT_FOUND;
    case PROTO_MSG_ERR_RATE_LIMITED:
    case PROTO_MSG_ERR_LIMIT_REACHED:
        return 429;
    case PROTO_MSG_ERR_INTERNAL:
        return HTTP_STATUS_INTERNAL_SERVER_ERROR;
    case PROTO_MSG_ERR_UNAVAILABLE:
        return HTTP_STATUS_SERVICE_UNAVAILABLE;
    default:
        return 422; /* the message was understood, its fields were not acceptable */
    }
}

/* An error in the protocol's `error` shape, with `status`, or the status the code maps to
 * when status is 0. */
static void respond_error(struct http_api *api, struct http_request *r, unsigned status,
                          enum proto_msg_error_code code, const char *message,
                          const struct proto_field_errors *fields)
{
    json_guard_lock();
    char *text = proto_msg_build_error(NULL, code, message, fields);
    json_guard_unlock();
    service_metrics_error(api->metrics, code);
    respond(r, status ? status : status_of_error(code), "application/json", text ? text : "{}",
            text ? strlen(text) : 2);
    free(text);
}

static void respond_json(struct http_request *r, unsigned status, cJSON *json)
{
    char *text = json ? cJSON_PrintUnformatted(json) : NULL;
    if (text)
        respond(r, status, "application/json", text, strlen(text));
    else
        respond(r, HTTP_STATUS_INTERNAL_SERVER_ERROR, "application/json", "{}", 2);
    free(text);
}

static int write_response(struct http_api *api, struct http_request *r)
{
    uint8_t headers[LWS_PRE + 1024];
    uint8_t *start = headers + LWS_PRE, *p = start, *end = headers + sizeof headers - 1;
    uint8_t *body = (uint8_t *)(r->response ? r->response + LWS_PRE : NULL);
    size_t length = r->response_length;
    if (r->frame) {
        body = encoded_frame_message(r->frame) + PROTO_FRAME_HEADER_SIZE;
        length = encoded_frame_payload_length(r->frame);
    }
    if (lws_add_http_common_headers(r->wsi, r->status, r->content_type, length, &p, end))
        return -1;
    if (lws_add_http_header_by_name(r->wsi, (const unsigned char *)"cache-control:",
                                    (const unsigned char *)"no-store", 8, &p, end))
        return -1;
    if (r->status == HTTP_STATUS_UNAUTHORIZED &&
        lws_add_http_header_by_name(r->wsi, (const unsigned char *)"www-authenticate:",
                                    (const unsigned char *)"Bearer", 6, &p, end))
        return -1;
    char retry_after[16];
    int retry_length = snprintf(retry_after, sizeof retry_after, "%u", r->retry_after_s);
    if (r->retry_after_s > 0 &&
        lws_add_http_header_by_name(r->wsi, (const unsigned char *)"retry-after:",
                                    (const unsigned char *)retry_after, retry_length, &p, end))
        return -1;
    const char *allow = r->endpoint == ENDPOINT_STATE   ? "GET, PATCH"
                        : r->endpoint == ENDPOINT_METAR ? "POST"
                                                        : "GET";
    if (r->status == HTTP_STATUS_METHOD_NOT_ALLOWED &&
        lws_add_http_header_by_name(r->wsi, (const unsigned char *)"allow:",
                                    (const unsigned char *)allow, (int)strlen(allow), &p, end))
        return -1;
    if (lws_finalize_write_http_header(r->wsi, start, &p, end))
        return -1;
    if (length > 0 && lws_write(r->wsi, body, length, LWS_WRITE_HTTP_FINAL) < (int)length)
        return -1;
    if (r->frame)
        service_metrics_frame_sent(api->metrics, length);
    release_request(api, r);
    return lws_http_transaction_completed(r->wsi) ? -1 : 0;
}

/* ---- replies from the render loop ---- */

/* The session's reply, as the HTTP response; false while there is none yet. */
static bool take_reply(struct http_api *api, struct http_request *r)
{
    for (;;) {
        struct session_output out;
        session_next_output(r->session, &out);
        if (out.kind == SESSION_OUTPUT_NONE)
            return false;
        if (out.kind == SESSION_OUTPUT_FRAME) {
            r->frame = encoded_frame_ref(out.frame);
            r->status = HTTP_STATUS_OK;
            r->content_type = encoded_frame_meta(out.frame)->format == PROTO_FRAME_FORMAT_JPEG
                                  ? "image/jpeg"
                                  : "image/png";
            r->ready = true;
            session_output_release(&out);
            return true;
        }
        if (out.kind == SESSION_OUTPUT_CLOSE) {
            respond_error(api, r, 0, PROTO_MSG_ERR_INTERNAL, out.close_reason, NULL);
            session_output_release(&out);
            return true;
        }
        json_guard_lock();
        cJSON *reply = cJSON_ParseWithLength(out.text, out.length);
        json_guard_unlock();
        session_output_release(&out);
        cJSON_DeleteItemFromObjectCaseSensitive(reply, "id");
        const cJSON *type = cJSON_GetObjectItemCaseSensitive(reply, "type");
        const char *kind = cJSON_IsString(type) ? type->valuestring : "";
        if (strcmp(kind, "frame") == 0) { /* the image follows */
            cJSON_Delete(reply);
            continue;
        }
        if (strcmp(kind, "error") == 0) {
            const cJSON *code = cJSON_GetObjectItemCaseSensitive(reply, "code");
            enum proto_msg_error_code value =
                cJSON_IsString(code)
                    ? proto_msg_error_code_named(code->valuestring, strlen(code->valuestring))
                    : PROTO_MSG_OK;
            if (value == PROTO_MSG_OK)
                value = PROTO_MSG_ERR_INTERNAL;
            respond_json(r, status_of_error(value), reply); /* counted where it was built */
        } else if (strcmp(kind, "ack") == 0) {
            cJSON *answer = cJSON_CreateObject();
            cJSON_AddItemToObject(answer, "revision",
                                  cJSON_DetachItemFromObject(reply, "revision"));
            respond_json(r, HTTP_STATUS_OK, answer);
            cJSON_Delete(answer);
        } else {
            cJSON_DeleteItemFromObjectCaseSensitive(reply, "type");
            respond_json(r, HTTP_STATUS_OK, reply);
        }
        cJSON_Delete(reply);
        return true;
    }
}

void http_api_wake(struct http_api *api)
{
    for (struct http_request *r = api->pending; r; r = r->next_pending)
        if (session_has_output(r->session))
            lws_callback_on_writable(r->wsi);
}

void http_api_detach_loop(struct http_api *api)
{
    for (struct http_request *r = api->pending; r; r = r->next_pending) {
        if (r->session) {
            session_mark_closed(r->session);
            session_unref(&r->session);
        }
    }
    api->loop = NULL;
    while (api->pending) {
        struct http_request *r = api->pending;
        forget_pending(api, r);
        respond_error(api, r, HTTP_STATUS_SERVICE_UNAVAILABLE, PROTO_MSG_ERR_INTERNAL,
                      "skyd is shutting down", NULL);
    }
}

/* Hands a parsed message to the render loop from the request's own session. */
static void submit(struct http_api *api, struct http_request *r, struct proto_client_msg *msg,
                   enum proto_msg_role role)
{
    service_metrics_message(api->metrics, msg->type);
    int cap = live_settings_max_queued_http(api->settings);
    if (api->pending_count >= cap) {
        proto_client_msg_free(msg);
        error_text message;
        snprintf(message, sizeof message,
                 "too many HTTP requests are waiting for the render loop: at most %d "
                 "(limits.max_queued_http_requests); try again in %d s",
                 cap, QUEUE_RETRY_AFTER_S);
        respond_error(api, r, HTTP_STATUS_SERVICE_UNAVAILABLE, PROTO_MSG_ERR_UNAVAILABLE, message,
                      NULL);
        r->retry_after_s = QUEUE_RETRY_AFTER_S;
        return;
    }
    r->session = session_create();
    if (!r->session || !api->loop) {
        proto_client_msg_free(msg);
        respond_error(api, r, api->loop ? 0 : HTTP_STATUS_SERVICE_UNAVAILABLE,
                      PROTO_MSG_ERR_INTERNAL, api->loop ? "out of memory" : "skyd is shutting down",
                      NULL);
        return;
    }
    session_set_transport(r->session, r->wsi);
    session_set_role(r->session, role);
    /* lws allows a request 5 s before its response starts; a snapshot of a new view can take
     * longer on a CPU (its clouds are built first). */
    lws_set_timeout(r->wsi, PENDING_TIMEOUT_HTTP_CONTENT, REPLY_TIMEOUT_S);
    r->pending = true;
    r->next_pending = api->pending;
    api->pending = r;
    api->pending_count++;
    render_loop_submit_message(api->loop, r->session, msg);
}

/* Parses `json` (given the HTTP id) as a protocol message and hands it to the render loop from
 * the request's own session with `role`; a refusal becomes the response. */
static void submit_json(struct http_api *api, struct http_request *r, cJSON *json,
                        enum proto_msg_role role)
{
    /* A snapshot's image is announced to its id; the response drops it again. */
    cJSON_AddStringToObject(json, "id", HTTP_MESSAGE_ID);
    char *text = json ? cJSON_PrintUnformatted(json) : NULL;
    if (!text) {
        respond_error(api, r, 0, PROTO_MSG_ERR_INTERNAL, "out of memory", NULL);
        return;
    }
    struct proto_client_msg msg;
    struct proto_msg_parse_error error;
    json_guard_lock();
    enum proto_msg_error_code code = proto_msg_parse(text, strlen(text), api->limits, &msg, &error);
    json_guard_unlock();
    free(text);
    if (code != PROTO_MSG_OK) {
        service_metrics_message(api->metrics, msg.type);
        if (proto_msg_needs_controller(msg.type)) {
            char peer[64] = "";
            net_peer_address(r->wsi, peer, sizeof peer);
            skyd_log(SKYD_LOG_WARNING, "%s from %s refused: %s",
                     r->endpoint == ENDPOINT_METAR ? "POST /api/weather/metar" : "PATCH /api/state",
                     peer, error.message);
        }
        respond_error(api, r, 0, code, error.message, &error.fields);
        return;
    }
    submit(api, r, &msg, role);
}

/* An endpoint's answer, carried out on the request. */
static void carry_out(struct http_api *api, struct http_request *r, struct http_answer *answer)
{
    switch (answer->kind) {
    case HTTP_ANSWER_RESPONSE:
        respond(r, answer->status, answer->content_type, answer->body ? answer->body : "{}",
                answer->body ? answer->body_length : 2);
        break;
    case HTTP_ANSWER_ERROR:
        respond_error(api, r, 0, answer->code, answer->message, NULL);
        break;
    case HTTP_ANSWER_SUBMIT:
        submit_json(api, r, answer->json, answer->role);
        break;
    }
    http_answer_release(answer);
}

static void answer_patch(struct http_api *api, struct http_request *r)
{
    struct http_answer answer;
    if (r->endpoint == ENDPOINT_METAR)
        http_endpoint_metar(&answer, r->body, r->body_length, r->body_too_large,
                            api->limits->max_message_bytes);
    else
        http_endpoint_patch(&answer, r->body, r->body_length, r->body_too_large,
                            api->limits->max_message_bytes);
    carry_out(api, r, &answer);
}

/* ---- requests ---- */

static bool take_rate_token(struct http_api *api, struct lws *wsi)
{
    char address[64] = "";
    net_peer_address(wsi, address, sizeof address);
    double now = monotonic_seconds(), rate = api->limits->control_messages_per_second;
    struct rate_peer *peer = NULL, *oldest = &api->peers[0];
    for (int i = 0; i < RATE_PEERS && !peer; i++) {
        if (strcmp(api->peers[i].address, address) == 0 && api->peers[i].used_at > 0)
            peer = &api->peers[i];
        else if (api->peers[i].used_at < oldest->used_at)
            oldest = &api->peers[i];
    }
    if (!peer) {
        peer = oldest;
        *peer = (struct rate_peer){ .tokens = rate, .refilled_at = now };
        snprintf(peer->address, sizeof peer->address, "%s", address);
    }
    peer->used_at = now;
    peer->tokens += (now - peer->refilled_at) * rate;
    if (peer->tokens > rate)
        peer->tokens = rate; /* burst: one second's worth, as on a WebSocket */
    peer->refilled_at = now;
    if (peer->tokens < 1.0)
        return false;
    peer->tokens -= 1.0;
    return true;
}

/* The bearer token's check; the Authorization header's value is never logged or echoed. */
static enum live_token_check check_bearer_token(struct http_api *api, struct lws *wsi)
{
    char header[256] = "";
    int length = lws_hdr_total_length(wsi, WSI_TOKEN_HTTP_AUTHORIZATION);
    if (length <= 7 || length >= (int)sizeof header ||
        lws_hdr_copy(wsi, header, sizeof header, WSI_TOKEN_HTTP_AUTHORIZATION) < 0 ||
        strncasecmp(header, "Bearer ", 7) != 0)
        header[7] = '\0'; /* no bearer token: checked as an empty one */
    return live_settings_check_token(api->settings, header + 7);
}

static enum endpoint endpoint_of(const char *path)
{
    static const struct {
        const char *path;
        enum endpoint endpoint;
    } routes[] = {
        { "/healthz", ENDPOINT_HEALTH },
        { "/metrics", ENDPOINT_METRICS },
        { "/api/state", ENDPOINT_STATE },
        { "/api/snapshot", ENDPOINT_SNAPSHOT },
        { "/api/schema", ENDPOINT_SCHEMA },
        { "/api/weather/metar", ENDPOINT_METAR },
        { "/api/weather/forecast", ENDPOINT_FORECAST },
    };
    for (size_t i = 0; i < sizeof routes / sizeof routes[0]; i++)
        if (strcmp(path, routes[i].path) == 0)
            return routes[i].endpoint;
    return ENDPOINT_NONE;
}

static bool body_follows(struct lws *wsi)
{
    char length[32] = "";
    if (lws_hdr_total_length(wsi, WSI_TOKEN_HTTP_CONTENT_LENGTH) <= 0 ||
        lws_hdr_copy(wsi, length, sizeof length, WSI_TOKEN_HTTP_CONTENT_LENGTH) < 0)
        return false;
    return strtoull(length, NULL, 10) > 0;
}

/* The request line is in: route it, or wait for a PATCH's body. */
static int on_request(struct http_api *api, struct http_request *r, struct lws *wsi)
{
    release_request(api, r);
    r->wsi = wsi;
    static const enum lws_token_indexes methods[] = { WSI_TOKEN_GET_URI,    WSI_TOKEN_PATCH_URI,
                                                      WSI_TOKEN_POST_URI,   WSI_TOKEN_PUT_URI,
                                                      WSI_TOKEN_DELETE_URI, WSI_TOKEN_OPTIONS_URI,
                                                      WSI_TOKEN_HEAD_URI };
    char path[256] = "";
    size_t method = 0;
    while (method < sizeof methods / sizeof methods[0] &&
           lws_hdr_total_length(wsi, methods[method]) <= 0)
        method++;
    if (method < sizeof methods / sizeof methods[0])
        lws_hdr_copy(wsi, path, sizeof path, methods[method]);
    r->endpoint = endpoint_of(path);
    /* GET everywhere but on /api/weather/metar, which takes POST; PATCH on /api/state. */
    bool get = method == 0 && r->endpoint != ENDPOINT_METAR;
    r->patch = (method == 1 && r->endpoint == ENDPOINT_STATE) ||
               (method == 2 && r->endpoint == ENDPOINT_METAR);
    const char *change = r->endpoint == ENDPOINT_METAR ? "POST /api/weather/metar"
                                                       : "PATCH /api/state";
    if (r->endpoint == ENDPOINT_NONE) {
        respond_error(api, r, HTTP_STATUS_NOT_FOUND, PROTO_MSG_ERR_NOT_FOUND,
                      "no such endpoint: see PROTOCOL.md, \"HTTP API\"", NULL);
        return 0;
    }
    if (!get && !r->patch) {
        error_text message;
        snprintf(message, sizeof message, "%s allows only %s", path,
                 r->endpoint == ENDPOINT_STATE   ? "GET and PATCH"
                 : r->endpoint == ENDPOINT_METAR ? "POST"
                                                 : "GET");
        respond_error(api, r, HTTP_STATUS_METHOD_NOT_ALLOWED, PROTO_MSG_ERR_BAD_VALUE, message,
                      NULL);
        return 0;
    }
    bool limited = r->endpoint != ENDPOINT_HEALTH && r->endpoint != ENDPOINT_METRICS;
    if (limited && !take_rate_token(api, wsi)) {
        error_text message;
        snprintf(message, sizeof message, "more than %g requests per second from this address",
                 api->limits->control_messages_per_second);
        respond_error(api, r, 0, PROTO_MSG_ERR_RATE_LIMITED, message, NULL);
        return 0;
    }
    enum live_token_check token = r->patch ? check_bearer_token(api, wsi) : LIVE_TOKEN_MATCHES;
    if (token != LIVE_TOKEN_MATCHES) {
        char peer[64] = "";
        net_peer_address(wsi, peer, sizeof peer);
        skyd_log(SKYD_LOG_WARNING, "%s from %s: auth failed (%s)", change, peer,
                 token == LIVE_TOKEN_WRONG ? "wrong or missing bearer token" : "nobody controls");
        respond_error(api, r, 0, PROTO_MSG_ERR_AUTH_FAILED,
                      token == LIVE_TOKEN_READ_ONLY
                          ? "this server is read-only (read_only in its configuration): nobody "
                            "can control it"
                      : token == LIVE_TOKEN_NONE
                          ? "this server has no controller token: nobody can control it"
                      : r->endpoint == ENDPOINT_METAR
                          ? "POST needs the header Authorization: Bearer <controller token>"
                          : "PATCH needs the header Authorization: Bearer <controller token>",
                      NULL);
        return 0;
    }
    struct http_answer answer;
    switch (r->endpoint) {
    case ENDPOINT_HEALTH:
        http_endpoint_health(&answer, api->metrics, api->loop, api->hub);
        break;
    case ENDPOINT_METRICS:
        http_endpoint_metrics(&answer, api->metrics, api->hub);
        break;
    case ENDPOINT_SCHEMA:
        http_endpoint_schema(&answer);
        break;
    case ENDPOINT_FORECAST:
        http_endpoint_forecast(&answer, api->metrics);
        break;
    case ENDPOINT_SNAPSHOT:
        http_endpoint_snapshot(&answer, wsi);
        break;
    case ENDPOINT_METAR:
    case ENDPOINT_STATE:
        if (r->patch) {
            if (!body_follows(wsi))
                answer_patch(api, r); /* no body: refused as not JSON */
            return 0;
        }
        http_endpoint_state(&answer);
        break;
    case ENDPOINT_NONE:
        return 0;
    }
    carry_out(api, r, &answer);
    return 0;
}

static void on_body(struct http_api *api, struct http_request *r, const void *in, size_t len)
{
    if (r->ready || r->body_too_large)
        return;
    if (r->body_length + len > api->limits->max_message_bytes) {
        r->body_too_large = true;
        return;
    }
    if (r->body_length + len + 1 > r->body_capacity) {
        size_t capacity = (r->body_length + len + 1) * 2;
        if (capacity > api->limits->max_message_bytes + 1)
            capacity = api->limits->max_message_bytes + 1;
        char *grown = realloc(r->body, capacity);
        if (!grown) {
            r->body_too_large = true;
            return;
        }
        r->body = grown;
        r->body_capacity = capacity;
    }
    memcpy(r->body + r->body_length, in, len);
    r->body_length += len;
    r->body[r->body_length] = '\0';
}

int http_api_callback(struct http_api *api, struct lws *wsi, enum lws_callback_reasons reason,
                      void *user, void *in, size_t len)
{
    struct http_request *r = user;
    switch (reason) {
    case LWS_CALLBACK_HTTP:
        return on_request(api, r, wsi);
    case LWS_CALLBACK_HTTP_BODY:
        on_body(api, r, in, len);
        return 0;
    case LWS_CALLBACK_HTTP_BODY_COMPLETION:
        if (!r->ready && !r->session)
            answer_patch(api, r);
        return 0;
    case LWS_CALLBACK_HTTP_WRITEABLE:
        if (!r->ready && r->session && !take_reply(api, r))
            return 0;
        return r->ready ? write_response(api, r) : 0;
    case LWS_CALLBACK_CLOSED_HTTP:
    case LWS_CALLBACK_HTTP_DROP_PROTOCOL:
        release_request(api, r);
        return 0;
    default:
        return lws_callback_http_dummy(wsi, reason, user, in, len);
    }
}
