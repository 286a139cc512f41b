#include "text_file.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

char *text_file_read(const char *path, size_t max_bytes, size_t *length)
{
    FILE *file = fopen(path, "rb");
    if (!file)
        return NULL;
    char *contents = NULL;
    int saved_errno = 0;
    struct stat info;
    if (fstat(fileno(file), &info) != 0) {
        saved_errno = errno;
    } else if (!S_ISREG(info.st_mode)) {
        saved_errno = EINVAL;
    } else if ((size_t)info.st_size > max_bytes) {
        saved_errno = EFBIG;
    } else {
        size_t capacity = (size_t)info.st_size;
        contents = malloc(capacity + 1);
        if (!contents) {
            saved_errno = ENOMEM;
        } else {
            /* Reads no more than the size seen: a file growing meanwhile stays bounded. */
            *length = fread(contents, 1, capacity, file);
            contents[*length] = '\0';
            if (ferror(file)) {
                saved_errno = EIO;
                free(contents);
                contents = NULL;
            }
        }
    }
    fclose(file);
    errno = saved_errno;
    return contents;
}

void text_file_describe_error(const char *path, size_t max_bytes, char *msg, size_t msglen)
{
    if (errno == EFBIG)
        snprintf(msg, msglen, "%s: larger than %zu bytes", path, max_bytes);
    else if (errno == EINVAL)
        snprintf(msg, msglen, "%s: not a regular file", path);
    else
        snprintf(msg, msglen, "cannot open %s: %s", path, strerror(errno));
}
