/* Binary frame header, version 1: the first 48 bytes of every binary WebSocket message the
 * server sends, followed by payload_length bytes of image data (a PNG or a JPEG file).
 *
 *   offset size  field
 *    0      4    magic "SKYF"
 *    4      2    header_version, u16 = 1
 *    6      2    format, u16 (1 = PNG, 2 = PNG16, 3 = JPEG)
 *    8      8    frame_number, u64
 *   16      8    state_revision, u64
 *   24      8    simulation_time_s, IEEE 754 binary64
 *   32      4    width, u32
 *   36      4    height, u32
 *   40      4    payload_length, u32
 *   44      4    reserved, u32 = 0
 *
 * All integers and the double are little-endian, whatever the host's byte order.
 */
#ifndef SKYD_FRAME_HEADER_H
#define SKYD_FRAME_HEADER_H

#include <stddef.h>
#include <stdint.h>

#define PROTO_FRAME_HEADER_SIZE 48
#define PROTO_FRAME_HEADER_VERSION 1
#define PROTO_FRAME_MAGIC "SKYF"

enum proto_frame_format {
    PROTO_FRAME_FORMAT_PNG = 1, /* 8-bit sRGB RGBA, exposed and tonemapped */
    PROTO_FRAME_FORMAT_PNG16 =
        2, /* 16-bit linear-light RGB before the tonemap (server/frames/include/png_write.h) */
    PROTO_FRAME_FORMAT_JPEG = 3, /* baseline JPEG of the same pixels as PNG, 4:2:0 */
};

struct proto_frame_header {
    enum proto_frame_format format;
    uint64_t frame_number;
    uint64_t state_revision;
    double simulation_time_s;
    uint32_t width, height;  /* >= 1 */
    uint32_t payload_length; /* bytes after the header */
};

/* Stable codes. */
enum proto_frame_header_status {
    PROTO_FRAME_HEADER_OK = 0,
    PROTO_FRAME_HEADER_TOO_SHORT = 1, /* fewer than 48 bytes */
    PROTO_FRAME_HEADER_BAD_MAGIC = 2,
    PROTO_FRAME_HEADER_BAD_VERSION = 3,
    PROTO_FRAME_HEADER_BAD_FORMAT = 4, /* not a known enum proto_frame_format */
    PROTO_FRAME_HEADER_BAD_LENGTH = 5, /* 48 + payload_length != the message's length */
    PROTO_FRAME_HEADER_BAD_RESERVED = 6,
    PROTO_FRAME_HEADER_BAD_VALUE = 7, /* zero width or height, non-finite time */
};

/* "ok", "too_short", "bad_magic", ...; NULL for values that are not codes. */
const char *proto_frame_header_status_name(int status);

/* Writes the 48 bytes for *header (version 1, reserved 0) into out. On error out is left
 * untouched. */
enum proto_frame_header_status proto_frame_header_pack(const struct proto_frame_header *header,
                                                       uint8_t out[PROTO_FRAME_HEADER_SIZE]);

/* Reads and validates the header at the start of a whole binary message of message_length
 * bytes; the payload is message + PROTO_FRAME_HEADER_SIZE. On error *header is left untouched. */
enum proto_frame_header_status proto_frame_header_unpack(const uint8_t *message,
                                                         size_t message_length,
                                                         struct proto_frame_header *header);

#endif
