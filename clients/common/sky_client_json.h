/* JSON and frame helpers on top of sky_client: send a cJSON value, wait for a text message of
 * a given type, receive one announced frame (the `frame` text message and the binary message
 * that follows it). Same return values as sky_client, plus SKY_CLIENT_BAD when the server
 * broke the protocol (err says how). */
#ifndef SKYD_SKY_CLIENT_JSON_H
#define SKYD_SKY_CLIENT_JSON_H

#include <stddef.h>

#include "frame_header.h"
#include "sky_client.h"

struct cJSON;

#define SKY_CLIENT_BAD 2

/* Sends msg as compact JSON text. */
int sky_client_send_json(struct sky_client *client, const struct cJSON *msg, int timeout_ms);

/* Receives text messages until one is a JSON object whose "type" is `type` (any object when
 * type is NULL); everything before it, binary messages included, is dropped. timeout_ms
 * bounds the whole wait. On 0 the caller owns *out (cJSON_Delete). A text message that is not
 * a JSON object with a string "type" is SKY_CLIENT_BAD. */
int sky_client_recv_json(struct sky_client *client, const char *type, int timeout_ms,
                         struct cJSON **out, char *err, size_t errlen);

struct sky_client_frame {
    struct cJSON *announce;           /* the `frame` text message */
    struct proto_frame_header header; /* unpacked and validated */
    struct sky_client_message binary;
    const unsigned char *payload; /* binary.data + PROTO_FRAME_HEADER_SIZE */
};

/* Waits for the next `frame` text message (dropping other messages before it) and the binary
 * message that must follow it; checks the header (proto_frame_header_unpack) and that both carry
 * the same frame_number. On 0 free *out with sky_client_frame_free. */
int sky_client_recv_frame(struct sky_client *client, int timeout_ms, struct sky_client_frame *out,
                          char *err, size_t errlen);

void sky_client_frame_free(struct sky_client_frame *frame);

#endif
