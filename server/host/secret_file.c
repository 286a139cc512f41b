#include "secret_file.h"

#include <errno.h>
#include <fcntl.h>
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>
#include <stdbool.h>
#include <unistd.h>

enum secret_file_result secret_file_read(const char *path, char *text, size_t textlen,
                                         size_t *length, char *why, size_t whylen)
{
    *length = 0;
    text[0] = '\0';
    int fd = open(path, O_RDONLY | O_NOFOLLOW | O_CLOEXEC);
    if (fd < 0) {
        int error = errno;
        if (error == ENOENT) {
            snprintf(why, whylen, "%s does not exist", path);
            return SECRET_FILE_ABSENT;
        }
        if (error == ELOOP)
            snprintf(why, whylen, "%s is a symbolic link: name the file itself", path);
        else
            snprintf(why, whylen, "cannot read %s (%s)", path, strerror(error));
        return SECRET_FILE_REFUSED;
    }
    struct stat st;
    ssize_t n = -1;
    if (fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) {
        snprintf(why, whylen, "%s is not a regular file", path);
    } else if (st.st_mode & (S_IRWXG | S_IRWXO)) {
        snprintf(why, whylen,
                 "%s was open to group or others (mode %04o), so what it holds may have "
                 "leaked",
                 path, (unsigned)(st.st_mode & 07777));
    } else {
        size_t done = 0;
        while (done + 1 < textlen) {
            n = read(fd, text + done, textlen - 1 - done);
            if (n < 0 && errno == EINTR)
                continue;
            if (n <= 0)
                break;
            done += (size_t)n;
        }
        if (n < 0)
            snprintf(why, whylen, "cannot read %s (%s)", path, strerror(errno));
        else
            n = (ssize_t)done;
        text[done] = '\0';
        *length = done;
    }
    close(fd);
    return n < 0 ? SECRET_FILE_REFUSED : SECRET_FILE_READ;
}

bool secret_file_first_line(char *text, size_t length, size_t textlen, char *why, size_t whylen)
{
    char *end = memchr(text, '\n', length);
    if (!end && length + 1 >= textlen) {
        snprintf(why, whylen, "its first line is longer than %zu bytes", textlen - 2);
        return false;
    }
    size_t line = end ? (size_t)(end - text) : length;
    if (line > 0 && text[line - 1] == '\r')
        line--;
    text[line] = '\0';
    if (line == 0) {
        snprintf(why, whylen, "its first line is empty");
        return false;
    }
    for (size_t i = 0; i < line; i++) {
        unsigned char c = (unsigned char)text[i];
        if (c < 0x20 || c == 0x7f) {
            snprintf(why, whylen, "its first line holds a control character (byte %zu)", i);
            return false;
        }
    }
    return true;
}
