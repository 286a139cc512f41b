#include "ws_server.h"

#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <time.h>

#include <libwebsockets.h>

#include "error_text.h"
#include "field_errors.h"
#include "frame_header.h"
#include "http_api.h"
#include "json_guard.h"
#include "log.h"
#include "messages.h"
#include "monotonic_clock.h"

#define SERVER_NAME "skyd " SKYD_VERSION

/* Per-connection data, owned by the service thread (lws allocates it zeroed). */
struct connection {
    struct session *session;
    unsigned long long number; /* for the log: "connection 12" */
    char peer[64];
    bool rejected;         /* over max_clients: gets an error and a close, nothing else */
    char *rx;              /* the message being received */
    size_t rx_capacity;    /* bytes rx holds, terminator included */
    size_t rx_length;      /* bytes received so far (may exceed what is stored) */
    size_t rx_limit;       /* the largest message this one may be */
    bool rx_out_of_memory; /* the message did not fit in memory */
    bool rx_binary;
    double tokens, refilled_at; /* rate limit: a token bucket */
};

struct ws_server {
    struct lws_context *context;
    struct lws_vhost *vhost;
    struct lws_protocols protocols[3];
    struct lws_http_mount mount;
    struct http_api *api;
    struct service_metrics *metrics;
    struct live_settings *settings;
    const struct skyd_config *config;
    struct proto_msg_limits limits;
    struct session_hub *hub;
    struct render_loop *loop;
    char url[128];
    unsigned long long connections; /* opened so far */
    char own_origins[2][96];
    char web_root[4096];
};

static bool origin_allowed(const struct ws_server *srv, const char *origin)
{
    for (int i = 0; i < 2; i++)
        if (strcasecmp(origin, srv->own_origins[i]) == 0)
            return true;
    return live_settings_origin_allowed(srv->settings, origin);
}

/* Browsers always send Origin; other clients need not, and are let in. */
static int confirm_upgrade(struct ws_server *srv, struct lws *wsi)
{
    char origin[256] = "";
    int length = lws_hdr_total_length(wsi, WSI_TOKEN_ORIGIN);
    if (length <= 0)
        return 0;
    if (length >= (int)sizeof origin ||
        lws_hdr_copy(wsi, origin, sizeof origin, WSI_TOKEN_ORIGIN) < 0 ||
        !origin_allowed(srv, origin)) {
        char peer[64] = "";
        net_peer_address(wsi, peer, sizeof peer);
        skyd_log(SKYD_LOG_WARNING, "refused a WebSocket from %s: origin %s is not allowed", peer,
                 origin);
        /* Written whole: lws's own status helpers say HTTP/1.0 at this stage, which strict
         * WebSocket clients refuse to read. */
        static const char response[] = "HTTP/1.1 403 Forbidden\r\n"
                                       "Content-Type: text/plain\r\n"
                                       "Content-Length: 19\r\n"
                                       "Connection: close\r\n"
                                       "\r\n"
                                       "origin not allowed\n";
        unsigned char buffer[LWS_PRE + sizeof response];
        memcpy(buffer + LWS_PRE, response, sizeof response - 1);
        lws_write(wsi, buffer + LWS_PRE, sizeof response - 1, LWS_WRITE_HTTP_HEADERS);
        return -1;
    }
    return 0;
}

/* Every error the lws thread answers is built and counted here. */
static char *build_error(struct ws_server *srv, const struct proto_msg_id *id,
                         enum proto_msg_error_code code, const char *message,
                         const struct proto_field_errors *fields)
{
    char *text = proto_msg_build_error(id, code, message, fields);
    if (text)
        service_metrics_error(srv->metrics, code);
    return text;
}

static void queue_and_wake(struct lws *wsi, struct session *session, char *text)
{
    if (text)
        session_push_text(session, text);
    free(text);
    lws_callback_on_writable(wsi);
}

static int on_established(struct ws_server *srv, struct lws *wsi, struct connection *c)
{
    c->number = ++srv->connections;
    net_peer_address(wsi, c->peer, sizeof c->peer);
    char origin[128] = "";
    if (lws_hdr_total_length(wsi, WSI_TOKEN_ORIGIN) < (int)sizeof origin)
        lws_hdr_copy(wsi, origin, sizeof origin, WSI_TOKEN_ORIGIN);
    skyd_log(SKYD_LOG_INFO, "connection %llu from %s%s%s", c->number, c->peer,
             origin[0] ? ", origin " : "", origin);
    c->session = session_create();
    if (!c->session)
        return -1;
    session_set_transport(c->session, wsi);
    c->tokens = srv->limits.control_messages_per_second;
    c->refilled_at = monotonic_seconds();
    if (session_hub_count(srv->hub) >= srv->limits.max_clients) {
        c->rejected = true;
        error_text message;
        snprintf(message, sizeof message, "too many clients: at most %d", srv->limits.max_clients);
        skyd_log(SKYD_LOG_WARNING, "connection %llu refused: %s", c->number, message);
        queue_and_wake(wsi, c->session,
                       build_error(srv, NULL, PROTO_MSG_ERR_LIMIT_REACHED, message, NULL));
        session_request_close(c->session, SESSION_CLOSE_POLICY, "too many clients", true);
        return 0;
    }
    size_t capability_count = 0;
    const char *const *capabilities = proto_msg_default_capabilities(&capability_count);
    queue_and_wake(wsi, c->session,
                   proto_msg_build_hello(SKYD_VERSION, PROTO_ROLE_VIEWER, capabilities,
                                         capability_count, &srv->limits));
    /* Only now among those that events go to: the render thread broadcasts through the hub,
     * and the hello must be the first message a client receives. */
    session_hub_add(srv->hub, c->session);
    return 0;
}

static void on_closed(struct ws_server *srv, struct connection *c)
{
    if (c->number)
        skyd_log(SKYD_LOG_INFO, "connection %llu from %s closed", c->number, c->peer);
    if (c->session) {
        session_mark_closed(c->session);
        if (!c->rejected) {
            session_hub_remove(srv->hub, c->session);
            if (srv->loop)
                render_loop_session_closed(srv->loop, c->session);
        }
        session_unref(&c->session);
    }
    free(c->rx);
    c->rx = NULL;
}

static bool take_token(struct ws_server *srv, struct connection *c)
{
    double rate = srv->limits.control_messages_per_second;
    double now = monotonic_seconds();
    c->tokens += (now - c->refilled_at) * rate;
    if (c->tokens > rate)
        c->tokens = rate; /* burst: one second's worth */
    c->refilled_at = now;
    if (c->tokens < 1.0)
        return false;
    c->tokens -= 1.0;
    return true;
}

/* A whole message has arrived: reject it here (in order, through the loop) or hand it on.
 * Every message costs a token of the rate limit, whatever its fate; a dropped one is still
 * parsed so that the error can carry its id. */
static void on_message(struct ws_server *srv, struct connection *c)
{
    bool allowed = take_token(srv, c);
    char *error = NULL;
    error_text message;
    struct proto_client_msg msg;
    memset(&msg, 0, sizeof msg);
    if (c->rx_binary) {
        error = build_error(srv, NULL, PROTO_MSG_ERR_INVALID_ENCODING,
                            "binary messages are not accepted: send JSON text", NULL);
    } else if (c->rx_out_of_memory) {
        error = build_error(srv, NULL, PROTO_MSG_ERR_INTERNAL,
                            "out of memory while receiving this message", NULL);
    } else if (c->rx_length > c->rx_limit) {
        snprintf(
            message, sizeof message, "message of %zu bytes is larger than %s (%zu)", c->rx_length,
            c->rx_limit > srv->limits.max_message_bytes ? "max_upload_bytes" : "max_message_bytes",
            c->rx_limit);
        error = build_error(srv, NULL, PROTO_MSG_ERR_MESSAGE_TOO_LARGE, message, NULL);
    } else {
        struct proto_msg_parse_error parse_error;
        json_guard_lock();
        enum proto_msg_error_code code = proto_msg_parse(c->rx ? c->rx : "", c->rx_length,
                                                         &srv->limits, &msg, &parse_error);
        json_guard_unlock();
        service_metrics_message(srv->metrics, msg.type);
        if (!allowed) {
            snprintf(message, sizeof message,
                     "more than %g messages per second; this one was "
                     "dropped",
                     srv->limits.control_messages_per_second);
            error = build_error(srv, &msg.id, PROTO_MSG_ERR_RATE_LIMITED, message, NULL);
        } else if (code == PROTO_MSG_OK) {
            render_loop_submit_message(srv->loop, c->session, &msg);
        } else {
            error = build_error(srv, &msg.id, parse_error.code, parse_error.message,
                                &parse_error.fields);
            if (msg.type == PROTO_MSG_AUTH || proto_msg_needs_controller(msg.type))
                skyd_log(SKYD_LOG_WARNING, "%s refused from connection %llu (%s): %s",
                         proto_msg_type_name(msg.type), c->number, c->peer, parse_error.message);
        }
    }
    proto_client_msg_free(&msg);
    if (error)
        render_loop_submit_reply(srv->loop, c->session, error);
    if (c->rx_capacity > srv->limits.max_message_bytes + 1) {
        free(c->rx); /* an upload's buffer is not kept between uploads */
        c->rx = NULL;
        c->rx_capacity = 0;
    }
}

/* Room for `needed` bytes and a terminator, growing by doubling; false when memory ran out. */
static bool reserve_rx(struct connection *c, size_t needed, size_t floor_bytes)
{
    if (needed + 1 <= c->rx_capacity)
        return true;
    size_t capacity = c->rx_capacity ? c->rx_capacity : floor_bytes + 1;
    while (capacity < needed + 1)
        capacity *= 2;
    char *grown = realloc(c->rx, capacity);
    if (!grown)
        return false;
    c->rx = grown;
    c->rx_capacity = capacity;
    return true;
}

/* A controller may send a set_weather_map up to max_upload_bytes; everything else, and anyone
 * else's message, stays within max_message_bytes. */
static size_t message_limit(const struct ws_server *srv, const struct connection *c)
{
    if (c->session && session_role(c->session) == PROTO_ROLE_CONTROLLER)
        return proto_msg_upload_limit(&srv->limits);
    return srv->limits.max_message_bytes;
}

static void on_receive(struct ws_server *srv, struct lws *wsi, struct connection *c, const void *in,
                       size_t len)
{
    if (c->rejected || !srv->loop)
        return;
    if (lws_is_first_fragment(wsi)) {
        c->rx_length = 0;
        c->rx_binary = lws_frame_is_binary(wsi);
        c->rx_limit = message_limit(srv, c);
        c->rx_out_of_memory = false;
    }
    if (!c->rx_binary && c->rx_length + len <= c->rx_limit) {
        if (!reserve_rx(c, c->rx_length + len, srv->limits.max_message_bytes)) {
            c->rx_out_of_memory = true; /* counted, not kept; answered as an internal error */
            c->rx_length += len;
        } else {
            memcpy(c->rx + c->rx_length, in, len);
            c->rx_length += len;
        }
    } else {
        c->rx_length += len; /* past the limit (or binary): counted, not kept */
    }
    if (lws_is_final_fragment(wsi) && lws_remaining_packet_payload(wsi) == 0)
        on_message(srv, c);
}

static int on_writeable(struct ws_server *srv, struct lws *wsi, struct connection *c)
{
    if (!c->session)
        return -1;
    struct session_output out;
    session_next_output(c->session, &out);
    int rc = 0;
    switch (out.kind) {
    case SESSION_OUTPUT_NONE:
        break;
    case SESSION_OUTPUT_TEXT:
        if (lws_write(wsi, (unsigned char *)out.text, out.length, LWS_WRITE_TEXT) < (int)out.length)
            rc = -1;
        break;
    case SESSION_OUTPUT_FRAME: {
        const struct encoded_frame_meta *meta = encoded_frame_meta(out.frame);
        struct proto_frame_header header = {
            .format = meta->format,
            .frame_number = out.frame_number,
            .state_revision = meta->state_revision,
            .simulation_time_s = meta->simulation_time_s,
            .width = meta->width,
            .height = meta->height,
            .payload_length = (uint32_t)encoded_frame_payload_length(out.frame),
        };
        uint8_t *bytes = encoded_frame_message(out.frame);
        size_t length = encoded_frame_message_length(out.frame);
        if (proto_frame_header_pack(&header, bytes) != PROTO_FRAME_HEADER_OK ||
            lws_write(wsi, bytes, length, LWS_WRITE_BINARY) < (int)length)
            rc = -1;
        else
            service_metrics_frame_sent(srv->metrics, length);
        break;
    }
    case SESSION_OUTPUT_CLOSE:
        /* Logged, since a client whose socket is full (one that does not read) may never get
         * the close frame. */
        skyd_log(out.close_code == SESSION_CLOSE_GOING_AWAY ? SKYD_LOG_INFO : SKYD_LOG_WARNING,
                 "closing connection %llu (%s): %d %s", c->number, c->peer, out.close_code,
                 out.close_reason);
        lws_close_reason(wsi, (enum lws_close_status)out.close_code,
                         (unsigned char *)out.close_reason, strlen(out.close_reason));
        rc = -1;
        break;
    }
    session_output_release(&out);
    if (rc == 0 && session_has_output(c->session))
        lws_callback_on_writable(wsi);
    return rc;
}

static void request_writable(struct session *session, void *user)
{
    (void)user;
    if (session_has_output(session))
        lws_callback_on_writable(session_transport(session));
}

static int callback(struct lws *wsi, enum lws_callback_reasons reason, void *user, void *in,
                    size_t len)
{
    struct ws_server *srv = lws_context_user(lws_get_context(wsi));
    struct connection *c = user;
    if (srv && (reason == LWS_CALLBACK_ESTABLISHED || reason == LWS_CALLBACK_RECEIVE))
        live_settings_limits(srv->settings, &srv->limits); /* as the last reload left them */
    switch (reason) {
    case LWS_CALLBACK_HTTP_CONFIRM_UPGRADE:
        return confirm_upgrade(srv, wsi);
    case LWS_CALLBACK_ESTABLISHED:
        return on_established(srv, wsi, c);
    case LWS_CALLBACK_RECEIVE:
        on_receive(srv, wsi, c, in, len);
        return 0;
    case LWS_CALLBACK_SERVER_WRITEABLE:
        return on_writeable(srv, wsi, c);
    case LWS_CALLBACK_CLOSED:
        on_closed(srv, c);
        return 0;
    case LWS_CALLBACK_EVENT_WAIT_CANCELLED:
        if (srv) {
            session_hub_for_each(srv->hub, request_writable, NULL);
            http_api_wake(srv->api);
        }
        return 0;
    default:
        return lws_callback_http_dummy(wsi, reason, user, in, len);
    }
}

static int http_callback(struct lws *wsi, enum lws_callback_reasons reason, void *user, void *in,
                         size_t len)
{
    struct ws_server *srv = lws_context_user(lws_get_context(wsi));
    if (!srv || !srv->api)
        return lws_callback_http_dummy(wsi, reason, user, in, len);
    if (reason == LWS_CALLBACK_HTTP || reason == LWS_CALLBACK_HTTP_BODY)
        live_settings_limits(srv->settings, &srv->limits);
    return http_api_callback(srv->api, wsi, reason, user, in, len);
}

static void log_line(int level, const char *line)
{
    skyd_log(level & LLL_ERR    ? SKYD_LOG_ERROR
             : level & LLL_WARN ? SKYD_LOG_WARNING
                                : SKYD_LOG_INFO,
             "lws: %s", line);
}

struct ws_server *ws_server_create(const struct ws_server_params *params, char *err, size_t errlen)
{
    struct ws_server *srv = calloc(1, sizeof *srv);
    if (!srv) {
        snprintf(err, errlen, "out of memory");
        return NULL;
    }
    const struct skyd_config *cfg = params->config;
    srv->config = cfg;
    srv->hub = params->hub;
    srv->loop = params->loop;
    srv->metrics = params->metrics;
    srv->settings = params->settings;
    live_settings_limits(params->settings, &srv->limits);
    struct http_api_params api = { .settings = params->settings,
                                   .limits = &srv->limits,
                                   .hub = params->hub,
                                   .loop = params->loop,
                                   .metrics = params->metrics };
    srv->api = http_api_create(&api);
    if (!srv->api) {
        snprintf(err, errlen, "out of memory");
        free(srv);
        return NULL;
    }
    snprintf(srv->web_root, sizeof srv->web_root, "%s", params->web_root);

    lws_set_log_level(LLL_ERR | LLL_WARN | LLL_USER, log_line);
    srv->protocols[0] = (struct lws_protocols){
        .name = "skyd",
        .callback = callback,
        .per_session_data_size = sizeof(struct connection),
        .rx_buffer_size = 0,
    };
    srv->protocols[1] = (struct lws_protocols){
        .name = HTTP_API_PROTOCOL,
        .callback = http_callback,
        .per_session_data_size = http_api_request_size(),
    };
    srv->mount = (struct lws_http_mount){
        .mountpoint = "/",
        .mountpoint_len = 1,
        .origin = srv->web_root,
        .def = "index.html",
        .origin_protocol = LWSMPRO_FILE,
    };
    bool tls = cfg->tls_certificate[0] != '\0';
    struct lws_context_creation_info info;
    memset(&info, 0, sizeof info);
    info.port = cfg->listen_port;
    info.iface = cfg->listen_address;
    info.protocols = srv->protocols;
    info.mounts = http_api_mounts(srv->api, &srv->mount);
    info.user = srv;
    info.server_string = SERVER_NAME;
    info.options = LWS_SERVER_OPTION_HTTP_HEADERS_SECURITY_BEST_PRACTICES_ENFORCE;
    if (tls) {
        info.options |= LWS_SERVER_OPTION_DO_SSL_GLOBAL_INIT;
        info.ssl_cert_filepath = cfg->tls_certificate;
        info.ssl_private_key_filepath = cfg->tls_private_key;
    }
    srv->context = lws_create_context(&info);
    srv->vhost = srv->context ? lws_get_vhost_by_name(srv->context, "default") : NULL;
    if (!srv->context || !srv->vhost || lws_get_vhost_listen_port(srv->vhost) <= 0) {
        snprintf(err, errlen, "cannot listen on %s:%d%s", cfg->listen_address, cfg->listen_port,
                 tls ? " with TLS (check the certificate and key)" : "");
        ws_server_destroy(&srv);
        return NULL;
    }
    int port = lws_get_vhost_listen_port(srv->vhost);
    const char *scheme = tls ? "https" : "http";
    snprintf(srv->url, sizeof srv->url, "%s://%s:%d/", scheme, cfg->listen_address, port);
    snprintf(srv->own_origins[0], sizeof srv->own_origins[0], "%s://%s:%d", scheme,
             cfg->listen_address, port);
    snprintf(srv->own_origins[1], sizeof srv->own_origins[1], "%s://localhost:%d", scheme, port);
    return srv;
}

void ws_server_destroy(struct ws_server **server)
{
    struct ws_server *srv = *server;
    *server = NULL;
    if (!srv)
        return;
    srv->loop = NULL;
    if (srv->context)
        lws_context_destroy(srv->context);
    http_api_destroy(&srv->api);
    free(srv);
}

const char *ws_server_url(const struct ws_server *server)
{
    return server->url;
}

void ws_server_run(struct ws_server *server, volatile sig_atomic_t *stop)
{
    while (!*stop)
        if (lws_service(server->context, 0) < 0)
            break;
}

struct close_request {
    int code;
    const char *reason;
    bool after_output;
};

static void close_session(struct session *session, void *user)
{
    const struct close_request *request = user;
    session_request_close(session, request->code, request->reason, request->after_output);
}

void ws_server_close_all(struct ws_server *server, int code, const char *reason, bool after_output,
                         double timeout_s)
{
    struct close_request request = { code, reason, after_output };
    session_hub_for_each(server->hub, close_session, &request);
    lws_cancel_service(server->context);
    double deadline = monotonic_seconds() + timeout_s;
    while (session_hub_count(server->hub) > 0 && monotonic_seconds() < deadline)
        if (lws_service(server->context, 0) < 0)
            break;
}

void ws_server_detach_loop(struct ws_server *server)
{
    http_api_detach_loop(server->api);
    server->loop = NULL;
}

void ws_server_wake(void *server)
{
    struct ws_server *srv = server;
    lws_cancel_service(srv->context);
}
