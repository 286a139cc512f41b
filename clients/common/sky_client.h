/* A small blocking WebSocket client for skyd (ws:// and wss://).
 *
 * Each client owns one libwebsockets context that is serviced only inside the calls below, so a
 * client whose owner stops calling them stops reading: the kernel buffers fill up and the
 * server sees a stalled reader. One client must be used by one thread at a time; different
 * clients may be used by different threads at once.
 *
 * Return values of the I/O calls: 0 done, 1 timed out, -1 closed or failed (see
 * sky_client_error, sky_client_close_code, sky_client_close_reason).
 */
#ifndef SKYD_SKY_CLIENT_H
#define SKYD_SKY_CLIENT_H

#include <stddef.h>

#define SKY_CLIENT_MAX_MESSAGE (64u << 20) /* bytes of one reassembled incoming message */

struct sky_client;

enum sky_client_message_kind {
    SKY_CLIENT_TEXT = 1,
    SKY_CLIENT_BINARY = 2,
};

/* One whole WebSocket message. data is malloc'd and always followed by a NUL byte that is not
 * counted in len, so a text message can be used as a C string. */
struct sky_client_message {
    enum sky_client_message_kind kind;
    unsigned char *data;
    size_t len;
};

void sky_client_message_free(struct sky_client_message *msg);

/* Connects to url ("ws://host:port/path", or "wss://host:port/path" through TLS with the
 * server's certificate checked against the system's trusted certificates and the host name)
 * and completes the WebSocket handshake. The port defaults to 80 (ws) or 443 (wss). origin is
 * sent as the Origin header verbatim ("http://example.test"); NULL sends none. Returns NULL and
 * writes a one-line reason to err on failure (bad URL, refused connection, refused handshake,
 * rejected certificate, timeout). A refused handshake names the HTTP status only when
 * libwebsockets could parse it (it reads "HTTP/1.1 NNN" status lines, not "HTTP/1.0 NNN"). */
struct sky_client *sky_client_connect(const char *url, const char *origin, int timeout_ms,
                                      char *err, size_t errlen);

/* How a wss:// connection checks the server's certificate. */
struct sky_client_tls {
    const char *ca_file; /* PEM certificates trusted instead of the system's; NULL: the system's */
    int insecure;        /* nonzero: accept self-signed, expired and other hosts' certificates */
    /* Set by sky_client_connect_tls: nonzero when it failed because the server's certificate
     * was not accepted (err then says why). */
    int certificate_rejected;
};

/* sky_client_connect with TLS settings; tls NULL is sky_client_connect. tls is only read for
 * wss:// URLs. */
struct sky_client *sky_client_connect_tls(const char *url, const char *origin,
                                          struct sky_client_tls *tls, int timeout_ms, char *err,
                                          size_t errlen);

/* Queues one message and services the connection until it has been handed to the kernel.
 * On timeout (1) the message stays queued and goes out during later calls. */
int sky_client_send_text(struct sky_client *client, const char *text, size_t len, int timeout_ms);
int sky_client_send_binary(struct sky_client *client, const void *data, size_t len, int timeout_ms);

/* The next whole message the server sent, in order. Messages received before the close are
 * all delivered before -1 is returned. timeout_ms 0 only takes what has already arrived. On
 * 0 the caller owns *out (sky_client_message_free); otherwise *out is zeroed. */
int sky_client_recv(struct sky_client *client, struct sky_client_message *out, int timeout_ms);

/* 1 while the connection is open (messages may still be queued after it closed). */
int sky_client_is_open(const struct sky_client *client);

/* The code of the server's close frame: 0 while open or when this side closed first, 1005
 * when its close frame carried no code, 1006 when the connection ended without a close frame
 * from the server. */
int sky_client_close_code(const struct sky_client *client);
const char *sky_client_close_reason(const struct sky_client *client); /* "" when none */

/* A one-line description of the last failure, "" when none. */
const char *sky_client_error(const struct sky_client *client);

/* Sends a normal close (1000), waits briefly for the server's reply, frees everything and
 * sets *client to NULL. Safe on NULL and on an already closed connection. */
void sky_client_close(struct sky_client **client);

#endif
