#include "encoded_frame.h"

#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>

#include <libwebsockets.h>

#include "frame_header.h"

struct encoded_frame {
    atomic_int refs;
    struct encoded_frame_meta meta;
    size_t payload_length;
    uint8_t *buffer; /* LWS_PRE + PROTO_FRAME_HEADER_SIZE + payload_length */
};

struct encoded_frame *encoded_frame_create(const struct encoded_frame_meta *meta,
                                           const uint8_t *payload, size_t payload_length)
{
    struct encoded_frame *f = calloc(1, sizeof *f);
    if (!f)
        return NULL;
    f->buffer = malloc(LWS_PRE + PROTO_FRAME_HEADER_SIZE + payload_length);
    if (!f->buffer) {
        free(f);
        return NULL;
    }
    atomic_init(&f->refs, 1);
    f->meta = *meta;
    f->payload_length = payload_length;
    memset(f->buffer, 0, LWS_PRE + PROTO_FRAME_HEADER_SIZE);
    memcpy(f->buffer + LWS_PRE + PROTO_FRAME_HEADER_SIZE, payload, payload_length);
    return f;
}

struct encoded_frame *encoded_frame_ref(struct encoded_frame *frame)
{
    atomic_fetch_add_explicit(&frame->refs, 1, memory_order_relaxed);
    return frame;
}

void encoded_frame_unref(struct encoded_frame **frame)
{
    struct encoded_frame *f = *frame;
    *frame = NULL;
    if (!f || atomic_fetch_sub_explicit(&f->refs, 1, memory_order_acq_rel) != 1)
        return;
    free(f->buffer);
    free(f);
}

const struct encoded_frame_meta *encoded_frame_meta(const struct encoded_frame *frame)
{
    return &frame->meta;
}

size_t encoded_frame_payload_length(const struct encoded_frame *frame)
{
    return frame->payload_length;
}

uint8_t *encoded_frame_message(struct encoded_frame *frame)
{
    return frame->buffer + LWS_PRE;
}

size_t encoded_frame_message_length(const struct encoded_frame *frame)
{
    return PROTO_FRAME_HEADER_SIZE + frame->payload_length;
}
