/* The one buffer type for the free-form error texts the server rooms build: an error, a why, a
 * refusal's message. Functions take (char *err, size_t err_size); callers pass
 * `err, sizeof err`.
 *
 * Texts whose size is a limit of the wire stay separate: a WebSocket close reason (RFC 6455
 * caps it at 123 bytes), protocol/'s field error reasons and messages (part of its API and of
 * the messages it encodes), and what clients/ keep. Paths, notes that carry several errors and
 * formatted lists of field errors are not one error text either. */
#ifndef SKYD_ERROR_TEXT_H
#define SKYD_ERROR_TEXT_H

#include <stddef.h>
#include <string.h>

/* Fits "cannot read PATH: <reader's error>" with a configured path (256) named in both parts. */
#define ERROR_TEXT_MAX 1024

typedef char error_text[ERROR_TEXT_MAX];

/* For a text that wraps another error text and so may not fit: `written` is what snprintf
 * returned for text[size]; a text cut short ends in "..." so that no reader takes it whole. */
static inline void error_text_mark_cut(char *text, size_t size, int written)
{
    if (written >= 0 && (size_t)written >= size && size >= 4)
        memcpy(text + size - 4, "...", 4);
}

#endif
