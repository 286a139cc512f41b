/* The controller token of `skyd serve`. A token set in the configuration is used as it is.
 * Without one, the daemon makes one at its first start (256 bits from the kernel's random
 * source, as 64 hex digits) and keeps it beside the state file in "<state_file>.token"
 * (mode 0600, written atomically), so that it survives restarts; with no state file it lasts
 * as long as the process. A token file that group or others may read, or that holds no token
 * this daemon would make, is replaced by a new token: a token others could read may have
 * leaked. "read_only" in the configuration means no token at all: nobody controls. */
#ifndef SKYD_CONTROL_TOKEN_H
#define SKYD_CONTROL_TOKEN_H

#include <stdbool.h>
#include <stddef.h>

#include "config.h"

#define CONTROL_TOKEN_RANDOM_BYTES 32

enum control_token_source {
    CONTROL_TOKEN_CONFIGURED, /* the configuration's controller_token */
    CONTROL_TOKEN_READ_ONLY,  /* read_only: controller_token is empty, auth is refused */
    CONTROL_TOKEN_RESTORED,   /* read from the token file */
    CONTROL_TOKEN_CREATED,    /* made now and kept in the token file */
    CONTROL_TOKEN_UNSAVED,    /* made now, for this process only */
    CONTROL_TOKEN_FAILED,     /* no random bytes to be had: the daemon cannot start */
};

/* Gives config->controller_token the token `skyd serve` uses. note says what happened when
 * that is worth a line on stderr ("" otherwise); it never holds the token. */
enum control_token_source control_token_settle(struct skyd_config *config, char *note,
                                               size_t notelen);

/* Whether the token is one the daemon made or read, to be shown to whoever started it
 * (the configuration's own is never printed). */
bool control_token_shown(enum control_token_source source);

/* "<state_file>.token". */
void control_token_path(const char *state_file, char *out, size_t outlen);

/* A new token: CONTROL_TOKEN_RANDOM_BYTES random bytes as lower-case hex. outlen must hold
 * 2 * CONTROL_TOKEN_RANDOM_BYTES + 1 bytes. False with a reason in err. */
bool control_token_generate(char *out, size_t outlen, char *err, size_t errlen);

#endif
