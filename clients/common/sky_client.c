/* Blocking WebSocket client on libwebsockets: one context per client, serviced only inside
 * the public calls. Incoming messages are reassembled into a queue; outgoing ones wait in a
 * queue until the connection is writeable. */
#include "sky_client.h"

#include <libwebsockets.h>
#include <pthread.h>
#include <stdarg.h>
#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

/* Reading stops (TCP flow control) while this many bytes of messages wait in the queue. */
#define QUEUE_PAUSE_BYTES (16u << 20)
#define RX_CHUNK 65536
#define CLOSE_WAIT_MS 2000

enum conn_state { CONN_CONNECTING, CONN_OPEN, CONN_CLOSED };

struct rx_node {
    struct rx_node *next;
    struct sky_client_message msg;
};

struct tx_node {
    struct tx_node *next;
    size_t len;
    bool binary;
    unsigned char buf[]; /* LWS_PRE bytes of room, then the payload */
};

struct sky_client {
    struct lws_context *context;
    struct lws *wsi;
    lws_sorted_usec_list_t wake;
    enum conn_state state;
    bool want_close, paused;
    bool tls;                  /* wss:// */
    bool certificate_rejected; /* the TLS handshake failed on the server's certificate */
    int close_code;
    char close_reason[124];
    char error[256];

    unsigned char *rx; /* message being reassembled */
    size_t rx_len, rx_cap;
    bool rx_active, rx_binary;

    struct rx_node *rx_head, *rx_tail;
    size_t queued_bytes;
    struct tx_node *tx_head, *tx_tail;
};

static int64_t now_us(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (int64_t)ts.tv_sec * 1000000 + ts.tv_nsec / 1000;
}

static void set_error(struct sky_client *c, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(c->error, sizeof c->error, fmt, ap);
    va_end(ap);
}

static void wake_cb(lws_sorted_usec_list_t *sul)
{
    (void)sul;
}

/* One pass of the event loop. lws_service ignores its timeout argument and sleeps until the
 * next scheduled event, so a timer at the deadline bounds the wait. */
static void service_once(struct sky_client *c, int64_t deadline_us)
{
    int64_t wait = deadline_us - now_us();
    if (wait < 1)
        wait = 1;
    lws_sul_schedule(c->context, 0, &c->wake, wake_cb, wait);
    lws_service(c->context, 0);
}

static void rx_reset(struct sky_client *c)
{
    free(c->rx);
    c->rx = NULL;
    c->rx_len = c->rx_cap = 0;
    c->rx_active = false;
}

static int on_receive(struct sky_client *c, struct lws *wsi, const void *in, size_t len)
{
    if (!c->rx_active) {
        c->rx_active = true;
        c->rx_binary = lws_frame_is_binary(wsi) != 0;
        c->rx_len = 0;
    }
    if (len > SKY_CLIENT_MAX_MESSAGE - c->rx_len) {
        set_error(c, "incoming message larger than %u bytes", SKY_CLIENT_MAX_MESSAGE);
        lws_close_reason(wsi, LWS_CLOSE_STATUS_MESSAGE_TOO_LARGE, NULL, 0);
        return -1;
    }
    if (c->rx_len + len + 1 > c->rx_cap) {
        size_t cap = c->rx_cap ? c->rx_cap : 4096;
        while (cap < c->rx_len + len + 1)
            cap *= 2;
        unsigned char *grown = realloc(c->rx, cap);
        if (!grown) {
            set_error(c, "out of memory for a %zu-byte message", c->rx_len + len);
            return -1;
        }
        c->rx = grown;
        c->rx_cap = cap;
    }
    if (len)
        memcpy(c->rx + c->rx_len, in, len);
    c->rx_len += len;
    if (!lws_is_final_fragment(wsi))
        return 0;

    struct rx_node *node = calloc(1, sizeof *node);
    if (!node) {
        set_error(c, "out of memory");
        return -1;
    }
    if (!c->rx) { /* an empty first message */
        c->rx = malloc(1);
        if (!c->rx) {
            free(node);
            set_error(c, "out of memory");
            return -1;
        }
    }
    c->rx[c->rx_len] = 0;
    node->msg.kind = c->rx_binary ? SKY_CLIENT_BINARY : SKY_CLIENT_TEXT;
    node->msg.data = c->rx;
    node->msg.len = c->rx_len;
    c->rx = NULL;
    c->rx_len = c->rx_cap = 0;
    c->rx_active = false;
    if (c->rx_tail)
        c->rx_tail->next = node;
    else
        c->rx_head = node;
    c->rx_tail = node;
    c->queued_bytes += node->msg.len;
    if (c->queued_bytes >= QUEUE_PAUSE_BYTES && !c->paused) {
        c->paused = true;
        lws_rx_flow_control(wsi, 0);
    }
    return 0;
}

static int on_writeable(struct sky_client *c, struct lws *wsi)
{
    struct tx_node *tx = c->tx_head;
    if (!tx) {
        if (c->want_close) {
            lws_close_reason(wsi, LWS_CLOSE_STATUS_NORMAL, NULL, 0);
            return -1;
        }
        return 0;
    }
    int n = lws_write(wsi, tx->buf + LWS_PRE, tx->len,
                      tx->binary ? LWS_WRITE_BINARY : LWS_WRITE_TEXT);
    if (n < 0 || (size_t)n < tx->len) {
        set_error(c, "write of a %zu-byte message failed", tx->len);
        return -1;
    }
    c->tx_head = tx->next;
    if (!c->tx_head)
        c->tx_tail = NULL;
    free(tx);
    if (c->tx_head || c->want_close)
        lws_callback_on_writable(wsi);
    return 0;
}

/* OpenSSL's reason for rejecting a certificate, which lws only logs ("SSL error: REASON
 * (preverify_ok=0;...)"); its connection error then says "error:00000001:lib(0)". The
 * context is serviced in the calling thread, so the log line arrives in it. */
static _Thread_local char tls_failure[128];

static void log_line(int level, const char *line)
{
    const char *reason = strstr(line, "SSL error: ");
    if (!reason) {
        lwsl_emit_stderr(level, line);
        return;
    }
    reason += strlen("SSL error: ");
    size_t n = strcspn(reason, "(\r\n");
    while (n > 0 && reason[n - 1] == ' ')
        n--;
    snprintf(tls_failure, sizeof tls_failure, "%.*s", (int)n, reason);
}

/* The HTTP status of a refused handshake, when lws still holds the response headers. */
static void describe_refusal(struct sky_client *c, struct lws *wsi, const char *why)
{
    char status[64] = "";
    if (wsi && lws_hdr_total_length(wsi, WSI_TOKEN_HTTP) > 0 &&
        lws_hdr_copy(wsi, status, sizeof status, WSI_TOKEN_HTTP) > 0)
        set_error(c, "connection failed: %s (HTTP %s)", why, status);
    else
        set_error(c, "connection failed: %s", why);
}

static int callback(struct lws *wsi, enum lws_callback_reasons reason, void *user, void *in,
                    size_t len)
{
    (void)user;
    struct lws_context *context = lws_get_context(wsi);
    struct sky_client *c = context ? lws_context_user(context) : NULL;
    if (!c)
        return 0;

    switch (reason) {
    case LWS_CALLBACK_OPENSSL_PERFORM_SERVER_CERT_VERIFICATION:
        /* Called only for what lws did not accept itself (the LCCSCF_ALLOW_* flags); len is
         * OpenSSL's preverify_ok. Returning 0 keeps its verdict. */
        if (len == 0)
            c->certificate_rejected = true;
        break;
    case LWS_CALLBACK_CLIENT_CONNECTION_ERROR: {
        char why[128];
        snprintf(why, sizeof why, "%.*s", in ? (int)len : 0, in ? (const char *)in : "");
        if (!why[0] || !in)
            snprintf(why, sizeof why, "unknown error");
        if (c->certificate_rejected)
            set_error(c, "the server's certificate was not accepted: %s",
                      tls_failure[0] ? tls_failure : why);
        else if (c->tls && strstr(why, "SSL"))
            set_error(c, "the TLS handshake failed, is it a TLS port? (%s)", why);
        else
            describe_refusal(c, wsi, why);
        c->state = CONN_CLOSED;
        c->wsi = NULL;
        break;
    }
    case LWS_CALLBACK_CLIENT_ESTABLISHED:
        c->state = CONN_OPEN;
        break;
    case LWS_CALLBACK_CLIENT_RECEIVE:
        return on_receive(c, wsi, in, len);
    case LWS_CALLBACK_CLIENT_WRITEABLE:
        return on_writeable(c, wsi);
    case LWS_CALLBACK_WS_PEER_INITIATED_CLOSE: {
        const unsigned char *p = in;
        if (p && len >= 2) {
            c->close_code = p[0] << 8 | p[1];
            size_t n = len - 2 < sizeof c->close_reason - 1 ? len - 2 : sizeof c->close_reason - 1;
            memcpy(c->close_reason, p + 2, n);
            c->close_reason[n] = 0;
        } else {
            c->close_code = LWS_CLOSE_STATUS_NO_STATUS;
        }
        return 0; /* lws echoes the close */
    }
    case LWS_CALLBACK_CLIENT_CLOSED:
        if (c->state == CONN_OPEN && !c->close_code && !c->want_close)
            c->close_code = LWS_CLOSE_STATUS_ABNORMAL_CLOSE;
        if (c->state == CONN_OPEN && !c->error[0] && !c->want_close)
            set_error(c, "connection closed by the server (code %d%s%s)", c->close_code,
                      c->close_reason[0] ? ", " : "", c->close_reason);
        c->state = CONN_CLOSED;
        c->wsi = NULL;
        rx_reset(c);
        break;
    case LWS_CALLBACK_WSI_DESTROY:
        if (c->wsi == wsi)
            c->wsi = NULL;
        if (c->state != CONN_CLOSED && !c->error[0])
            set_error(c, "connection closed");
        if (c->state == CONN_OPEN && !c->close_code)
            c->close_code = LWS_CLOSE_STATUS_ABNORMAL_CLOSE;
        c->state = CONN_CLOSED;
        break;
    default:
        break;
    }
    return 0;
}

static const struct lws_protocols protocols[] = {
    { "skyd-client", callback, 0, RX_CHUNK, 0, NULL, 0 },
    { NULL, NULL, 0, 0, 0, NULL, 0 },
};

static void quiet_lws(void)
{
    lws_set_log_level(LLL_ERR, log_line);
}

static void client_free(struct sky_client *c)
{
    if (c->context) {
        lws_sul_cancel(&c->wake);
        lws_context_destroy(c->context);
    }
    rx_reset(c);
    while (c->rx_head) {
        struct rx_node *next = c->rx_head->next;
        free(c->rx_head->msg.data);
        free(c->rx_head);
        c->rx_head = next;
    }
    while (c->tx_head) {
        struct tx_node *next = c->tx_head->next;
        free(c->tx_head);
        c->tx_head = next;
    }
    free(c);
}

/* Splits "ws://host:port/path" or "wss://..." (port 80 or 443 when absent); parsed holds the
 * pieces. */
static bool parse_url(const char *url, char *parsed, size_t size, const char **address, int *port,
                      char *path, size_t path_size, bool *tls)
{
    const char *prot = NULL, *rest = NULL;
    if (!url || strlen(url) >= size)
        return false;
    *tls = strncmp(url, "wss://", 6) == 0;
    if (!*tls && strncmp(url, "ws://", 5) != 0)
        return false;
    snprintf(parsed, size, "%s", url);
    if (lws_parse_uri(parsed, &prot, address, port, &rest) != 0 || !(*address)[0] || *port <= 0 ||
        *port > 65535)
        return false;
    /* lws drops the path's leading '/', except for a bare "/" */
    snprintf(path, path_size, "%s%s", rest[0] == '/' ? "" : "/", rest);
    return true;
}

struct sky_client *sky_client_connect(const char *url, const char *origin, int timeout_ms,
                                      char *err, size_t errlen)
{
    return sky_client_connect_tls(url, origin, NULL, timeout_ms, err, errlen);
}

struct sky_client *sky_client_connect_tls(const char *url, const char *origin,
                                          struct sky_client_tls *tls, int timeout_ms, char *err,
                                          size_t errlen)
{
    static pthread_once_t once = PTHREAD_ONCE_INIT;
    pthread_once(&once, quiet_lws);
    if (err && errlen)
        err[0] = 0;
    if (tls)
        tls->certificate_rejected = 0;
    tls_failure[0] = '\0';

    char parsed[512], path[512], host[300];
    const char *address = NULL;
    int port = 0;
    bool use_tls = false;
    if (!parse_url(url, parsed, sizeof parsed, &address, &port, path, sizeof path, &use_tls)) {
        snprintf(err, errlen, "bad URL '%s': expected ws://host:port/path or wss://host:port/path",
                 url ? url : "");
        return NULL;
    }
    snprintf(host, sizeof host, "%s:%d", address, port);

    struct sky_client *c = calloc(1, sizeof *c);
    if (!c) {
        snprintf(err, errlen, "out of memory");
        return NULL;
    }
    struct lws_context_creation_info info;
    memset(&info, 0, sizeof info);
    info.port = CONTEXT_PORT_NO_LISTEN;
    info.protocols = protocols;
    info.gid = -1;
    info.uid = -1;
    info.user = c;
    info.options = LWS_SERVER_OPTION_JUST_USE_RAW_ORIGIN; /* send origin as given */
    info.fd_limit_per_thread = 4; /* the socket and the cancel pipe, with a spare */
    info.pt_serv_buf_size = RX_CHUNK;
    if (use_tls) {
        info.options |= LWS_SERVER_OPTION_DO_SSL_GLOBAL_INIT;
        info.client_ssl_ca_filepath = tls ? tls->ca_file : NULL;
    }
    c->tls = use_tls;
    c->context = lws_create_context(&info);
    if (!c->context) {
        snprintf(err, errlen, "lws_create_context failed");
        free(c);
        return NULL;
    }

    struct lws_client_connect_info ci;
    memset(&ci, 0, sizeof ci);
    ci.context = c->context;
    ci.address = address;
    ci.port = port;
    ci.path = path;
    ci.host = host;
    ci.origin = origin;
    ci.ietf_version_or_minus_one = -1;
    ci.local_protocol_name = protocols[0].name;
    ci.pwsi = &c->wsi;
    if (use_tls) {
        ci.ssl_connection = LCCSCF_USE_SSL;
        if (tls && tls->insecure)
            ci.ssl_connection |= LCCSCF_ALLOW_SELFSIGNED | LCCSCF_SKIP_SERVER_CERT_HOSTNAME_CHECK |
                                 LCCSCF_ALLOW_EXPIRED | LCCSCF_ALLOW_INSECURE;
    }
    if (!lws_client_connect_via_info(&ci) && c->state != CONN_CLOSED) {
        set_error(c, "connection to %s failed", host);
        c->state = CONN_CLOSED;
    }
    int64_t deadline = now_us() + (int64_t)timeout_ms * 1000;
    while (c->state == CONN_CONNECTING && now_us() < deadline)
        service_once(c, deadline);
    if (c->state != CONN_OPEN) {
        if (tls)
            tls->certificate_rejected = c->certificate_rejected;
        if (c->state == CONN_CONNECTING)
            snprintf(err, errlen, "%s: no WebSocket handshake within %d ms", url, timeout_ms);
        else
            snprintf(err, errlen, "%s: %s", url, c->error[0] ? c->error : "connection failed");
        client_free(c);
        return NULL;
    }
    return c;
}

static int send_message(struct sky_client *c, const void *data, size_t len, bool binary,
                        int timeout_ms)
{
    if (!c)
        return -1;
    if (c->state != CONN_OPEN || !c->wsi) {
        if (!c->error[0])
            set_error(c, "send on a closed connection");
        return -1;
    }
    if (len > SKY_CLIENT_MAX_MESSAGE) {
        set_error(c, "outgoing message of %zu bytes is larger than %u", len,
                  SKY_CLIENT_MAX_MESSAGE);
        return -1;
    }
    struct tx_node *tx = malloc(sizeof *tx + LWS_PRE + len);
    if (!tx) {
        set_error(c, "out of memory");
        return -1;
    }
    tx->next = NULL;
    tx->len = len;
    tx->binary = binary;
    if (len)
        memcpy(tx->buf + LWS_PRE, data, len);
    if (c->tx_tail)
        c->tx_tail->next = tx;
    else
        c->tx_head = tx;
    c->tx_tail = tx;
    lws_callback_on_writable(c->wsi);

    int64_t deadline = now_us() + (int64_t)timeout_ms * 1000;
    for (;;) {
        if (c->state != CONN_OPEN || !c->wsi)
            return -1;
        if (!c->tx_head && !lws_partial_buffered(c->wsi))
            return 0;
        if (now_us() >= deadline)
            return 1;
        service_once(c, deadline);
    }
}

int sky_client_send_text(struct sky_client *client, const char *text, size_t len, int timeout_ms)
{
    return send_message(client, text, len, false, timeout_ms);
}

int sky_client_send_binary(struct sky_client *client, const void *data, size_t len, int timeout_ms)
{
    return send_message(client, data, len, true, timeout_ms);
}

int sky_client_recv(struct sky_client *c, struct sky_client_message *out, int timeout_ms)
{
    memset(out, 0, sizeof *out);
    if (!c)
        return -1;
    int64_t deadline = now_us() + (int64_t)timeout_ms * 1000;
    bool serviced = false;
    for (;;) {
        struct rx_node *node = c->rx_head;
        if (node) {
            c->rx_head = node->next;
            if (!c->rx_head)
                c->rx_tail = NULL;
            c->queued_bytes -= node->msg.len;
            *out = node->msg;
            free(node);
            if (c->paused && c->queued_bytes < QUEUE_PAUSE_BYTES / 2 && c->wsi) {
                c->paused = false;
                lws_rx_flow_control(c->wsi, 1 | LWS_RXFLOW_REASON_FLAG_PROCESS_NOW);
            }
            return 0;
        }
        if (c->state != CONN_OPEN)
            return -1;
        if (serviced && now_us() >= deadline)
            return 1;
        service_once(c, deadline);
        serviced = true;
    }
}

void sky_client_message_free(struct sky_client_message *msg)
{
    if (!msg)
        return;
    free(msg->data);
    memset(msg, 0, sizeof *msg);
}

int sky_client_is_open(const struct sky_client *client)
{
    return client && client->state == CONN_OPEN;
}

int sky_client_close_code(const struct sky_client *client)
{
    return client ? client->close_code : 0;
}

const char *sky_client_close_reason(const struct sky_client *client)
{
    return client ? client->close_reason : "";
}

const char *sky_client_error(const struct sky_client *client)
{
    return client ? client->error : "no client";
}

void sky_client_close(struct sky_client **client)
{
    struct sky_client *c = client ? *client : NULL;
    if (!c)
        return;
    *client = NULL;
    if (c->state == CONN_OPEN && c->wsi) {
        c->want_close = true;
        lws_callback_on_writable(c->wsi);
        int64_t deadline = now_us() + (int64_t)CLOSE_WAIT_MS * 1000;
        while (c->state == CONN_OPEN && now_us() < deadline)
            service_once(c, deadline);
    }
    client_free(c);
}
