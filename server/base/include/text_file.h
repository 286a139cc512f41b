/* Reading a whole, bounded text file (configuration, presets, the saved state). */
#ifndef SKYD_TEXT_FILE_H
#define SKYD_TEXT_FILE_H

#include <stddef.h>

/* Reads a regular file of at most max_bytes, NUL-terminated; *length gets its size. On failure
 * returns NULL with errno set: EFBIG when too large, EINVAL when not a regular file, else the
 * system's reason. */
char *text_file_read(const char *path, size_t max_bytes, size_t *length);

/* "cannot open PATH: reason", "PATH: larger than N bytes", ... for the errno text_file_read left. */
void text_file_describe_error(const char *path, size_t max_bytes, char *msg, size_t msglen);

#endif
