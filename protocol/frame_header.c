#include "frame_header.h"

#include <math.h>
#include <string.h>

/* The double travels as its IEEE 754 bit pattern, copied through a u64. */
_Static_assert(sizeof(double) == sizeof(uint64_t), "double must be 64 bits");

static const char *const status_names[] = {
    "ok",         "too_short",  "bad_magic",    "bad_version",
    "bad_format", "bad_length", "bad_reserved", "bad_value",
};

const char *proto_frame_header_status_name(int status)
{
    if (status < 0 || status >= (int)(sizeof status_names / sizeof status_names[0]))
        return NULL;
    return status_names[status];
}

static void put_u16(uint8_t *p, uint16_t v)
{
    p[0] = (uint8_t)v;
    p[1] = (uint8_t)(v >> 8);
}

static void put_u32(uint8_t *p, uint32_t v)
{
    for (int i = 0; i < 4; i++)
        p[i] = (uint8_t)(v >> (8 * i));
}

static void put_u64(uint8_t *p, uint64_t v)
{
    for (int i = 0; i < 8; i++)
        p[i] = (uint8_t)(v >> (8 * i));
}

static uint16_t get_u16(const uint8_t *p)
{
    return (uint16_t)(p[0] | (p[1] << 8));
}

static uint32_t get_u32(const uint8_t *p)
{
    uint32_t v = 0;
    for (int i = 3; i >= 0; i--)
        v = (v << 8) | p[i];
    return v;
}

static uint64_t get_u64(const uint8_t *p)
{
    uint64_t v = 0;
    for (int i = 7; i >= 0; i--)
        v = (v << 8) | p[i];
    return v;
}

static int format_is_known(uint32_t format)
{
    return format == PROTO_FRAME_FORMAT_PNG || format == PROTO_FRAME_FORMAT_PNG16 ||
           format == PROTO_FRAME_FORMAT_JPEG;
}

enum proto_frame_header_status proto_frame_header_pack(const struct proto_frame_header *header,
                                                       uint8_t out[PROTO_FRAME_HEADER_SIZE])
{
    if (!header || !out)
        return PROTO_FRAME_HEADER_BAD_VALUE;
    if (!format_is_known((uint32_t)header->format))
        return PROTO_FRAME_HEADER_BAD_FORMAT;
    if (header->width == 0 || header->height == 0 || !isfinite(header->simulation_time_s))
        return PROTO_FRAME_HEADER_BAD_VALUE;
    uint64_t time_bits;
    memcpy(&time_bits, &header->simulation_time_s, sizeof time_bits);
    memcpy(out, PROTO_FRAME_MAGIC, 4);
    put_u16(out + 4, PROTO_FRAME_HEADER_VERSION);
    put_u16(out + 6, (uint16_t)header->format);
    put_u64(out + 8, header->frame_number);
    put_u64(out + 16, header->state_revision);
    put_u64(out + 24, time_bits);
    put_u32(out + 32, header->width);
    put_u32(out + 36, header->height);
    put_u32(out + 40, header->payload_length);
    put_u32(out + 44, 0);
    return PROTO_FRAME_HEADER_OK;
}

enum proto_frame_header_status proto_frame_header_unpack(const uint8_t *message,
                                                         size_t message_length,
                                                         struct proto_frame_header *header)
{
    if (!message || message_length < PROTO_FRAME_HEADER_SIZE)
        return PROTO_FRAME_HEADER_TOO_SHORT;
    if (memcmp(message, PROTO_FRAME_MAGIC, 4) != 0)
        return PROTO_FRAME_HEADER_BAD_MAGIC;
    if (get_u16(message + 4) != PROTO_FRAME_HEADER_VERSION)
        return PROTO_FRAME_HEADER_BAD_VERSION;
    uint16_t format = get_u16(message + 6);
    if (!format_is_known(format))
        return PROTO_FRAME_HEADER_BAD_FORMAT;
    uint32_t payload_length = get_u32(message + 40);
    if (message_length - PROTO_FRAME_HEADER_SIZE != payload_length)
        return PROTO_FRAME_HEADER_BAD_LENGTH;
    if (get_u32(message + 44) != 0)
        return PROTO_FRAME_HEADER_BAD_RESERVED;
    uint64_t time_bits = get_u64(message + 24);
    double simulation_time_s;
    memcpy(&simulation_time_s, &time_bits, sizeof simulation_time_s);
    uint32_t width = get_u32(message + 32), height = get_u32(message + 36);
    if (width == 0 || height == 0 || !isfinite(simulation_time_s))
        return PROTO_FRAME_HEADER_BAD_VALUE;
    if (!header)
        return PROTO_FRAME_HEADER_OK;
    header->format = (enum proto_frame_format)format;
    header->frame_number = get_u64(message + 8);
    header->state_revision = get_u64(message + 16);
    header->simulation_time_s = simulation_time_s;
    header->width = width;
    header->height = height;
    header->payload_length = payload_length;
    return PROTO_FRAME_HEADER_OK;
}
