/* Wire names shared by the parser (messages.c) and the builders (message_build.c), indexed
 * by their enums; not part of the public interface. */
#ifndef SKYD_MESSAGE_NAMES_H
#define SKYD_MESSAGE_NAMES_H

#include <stdbool.h>
#include <stddef.h>

#define PROTO_MSG_ROLE_NAMES 3        /* enum proto_msg_role; [0] none */
#define PROTO_MSG_QUANTITY_NAMES 3    /* enum proto_probe_quantity */
#define PROTO_MSG_PRESET_KIND_NAMES 2 /* enum proto_preset_kind */
#define PROTO_MSG_FORMAT_NAMES 4      /* enum proto_frame_format; [0] none */
#define PROTO_MSG_PROJECTION_NAMES 2  /* enum proto_view_projection */

extern const char *const proto_msg_role_names[PROTO_MSG_ROLE_NAMES];
extern const char *const proto_msg_quantity_names[PROTO_MSG_QUANTITY_NAMES];
extern const char *const proto_msg_preset_kind_names[PROTO_MSG_PRESET_KIND_NAMES];
extern const char *const proto_msg_format_names[PROTO_MSG_FORMAT_NAMES];
extern const char *const proto_msg_projection_names[PROTO_MSG_PROJECTION_NAMES];

/* Helpers both sides use. */
/* [a-z0-9_-]{1,PROTO_MSG_PRESET_NAME_MAX}: preset and pass names. */
bool proto_msg_preset_name_is_valid(const char *name);
/* Length of the valid UTF-8 sequence at s (at most `left` bytes), 0 when invalid. */
size_t proto_msg_utf8_sequence(const unsigned char *s, size_t left);

#endif
