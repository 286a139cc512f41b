/* A file that holds a secret: the controller token's file, the cluster's Redis password file.
 * It is read only when it is a regular file (not through a symbolic link) that neither group
 * nor others may read, write or search: a secret others could read may have leaked. Nothing
 * here quotes what the file holds. Internal to server/host/. */
#ifndef SKYD_SECRET_FILE_H
#define SKYD_SECRET_FILE_H

#include <stdbool.h>
#include <stddef.h>

enum secret_file_result {
    SECRET_FILE_READ,    /* text holds the file's first textlen - 1 bytes, NUL-terminated */
    SECRET_FILE_ABSENT,  /* no such file */
    SECRET_FILE_REFUSED, /* unreadable, not a regular file, or open to group or others */
};

/* Reads `path`; *length is the number of bytes read (the text may hold NUL bytes). why says
 * what is wrong with the file for SECRET_FILE_ABSENT and SECRET_FILE_REFUSED. */
enum secret_file_result secret_file_read(const char *path, char *text, size_t textlen,
                                         size_t *length, char *why, size_t whylen);

/* The first line of a secret file's text (up to '\n', without a '\r' before it), in place:
 * false with why when it is empty, holds a NUL byte or a control character, or the text
 * filled the buffer without a line's end (the line may go on). */
bool secret_file_first_line(char *text, size_t length, size_t textlen, char *why, size_t whylen);

#endif
