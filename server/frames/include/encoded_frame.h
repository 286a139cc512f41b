/* An encoded frame shared by every session that watches its view: the image file (PNG or
 * JPEG) behind room
 * for the transport's own header (LWS_PRE) and the 48-byte frame header, which the sending
 * thread fills in per session just before it writes. Reference counted; immutable after
 * creation except for that header area, which only the transport thread touches. */
#ifndef SKYD_ENCODED_FRAME_H
#define SKYD_ENCODED_FRAME_H

#include <stddef.h>
#include <stdint.h>

#include "frame_header.h"

struct encoded_frame_meta {
    uint64_t render_sequence; /* increases with every render: a later frame supersedes */
    uint64_t state_revision;
    double simulation_time_s;
    uint32_t width, height;
    enum proto_frame_format format;
    int quality; /* JPEG: 1..100; 0 for PNG */
};

struct encoded_frame;

/* Copies `payload` (length bytes) behind the header room. NULL on allocation failure. */
struct encoded_frame *encoded_frame_create(const struct encoded_frame_meta *meta,
                                           const uint8_t *payload, size_t length);
struct encoded_frame *encoded_frame_ref(struct encoded_frame *frame);
void encoded_frame_unref(struct encoded_frame **frame);

const struct encoded_frame_meta *encoded_frame_meta(const struct encoded_frame *frame);
size_t encoded_frame_payload_length(const struct encoded_frame *frame);
/* The whole binary message: header (48 bytes, to be packed by the sender) then the image. Preceded
 * by LWS_PRE writable bytes. */
uint8_t *encoded_frame_message(struct encoded_frame *frame);
size_t encoded_frame_message_length(const struct encoded_frame *frame);

#endif
