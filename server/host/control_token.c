#include "control_token.h"
#include "error_text.h"
#include "secret_file.h"
#include "state_store.h"

#include <errno.h>
#include <fcntl.h>
#include <stdio.h>
#include <string.h>
#include <sys/random.h>
#include <sys/stat.h>
#include <unistd.h>

#define TOKEN_HEX_LENGTH (2 * CONTROL_TOKEN_RANDOM_BYTES)
/* A token file whose first line is not 32..127 of these is not ours: at least 128 bits. */
#define TOKEN_MIN_LENGTH 32
#define TOKEN_CHARACTERS "0123456789abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ-._~"

static bool random_bytes(unsigned char *out, size_t length, char *err, size_t errlen)
{
    size_t done = 0;
    while (done < length) {
        ssize_t n = getrandom(out + done, length - done, 0);
        if (n < 0 && errno == EINTR)
            continue;
        if (n < 0)
            break;
        done += (size_t)n;
    }
    if (done == length)
        return true;
    int fd = open("/dev/urandom", O_RDONLY | O_CLOEXEC); /* kernels before getrandom(2) */
    for (done = 0; fd >= 0 && done < length;) {
        ssize_t n = read(fd, out + done, length - done);
        if (n < 0 && errno == EINTR)
            continue;
        if (n <= 0)
            break;
        done += (size_t)n;
    }
    int saved = errno;
    if (fd >= 0)
        close(fd);
    if (done == length)
        return true;
    snprintf(err, errlen, "no random bytes for a controller token: %s", strerror(saved));
    return false;
}

bool control_token_generate(char *out, size_t outlen, char *err, size_t errlen)
{
    unsigned char bytes[CONTROL_TOKEN_RANDOM_BYTES];
    if (outlen < TOKEN_HEX_LENGTH + 1) {
        snprintf(err, errlen, "no room for a controller token");
        return false;
    }
    if (!random_bytes(bytes, sizeof bytes, err, errlen))
        return false;
    for (size_t i = 0; i < sizeof bytes; i++)
        snprintf(out + 2 * i, 3, "%02x", bytes[i]);
    memset(bytes, 0, sizeof bytes);
    return true;
}

void control_token_path(const char *state_file, char *out, size_t outlen)
{
    snprintf(out, outlen, "%s.token", state_file);
}

bool control_token_shown(enum control_token_source source)
{
    return source == CONTROL_TOKEN_RESTORED || source == CONTROL_TOKEN_CREATED ||
           source == CONTROL_TOKEN_UNSAVED;
}

enum file_verdict { FILE_ABSENT, FILE_GOOD, FILE_REPLACE };

/* Reads the token file's first line into token. FILE_REPLACE comes with why in note. */
static enum file_verdict read_token_file(const char *path, char *token, size_t tokenlen, char *note,
                                         size_t notelen)
{
    char text[256];
    size_t n = 0;
    switch (secret_file_read(path, text, sizeof text, &n, note, notelen)) {
    case SECRET_FILE_ABSENT:
        note[0] = '\0';
        return FILE_ABSENT;
    case SECRET_FILE_REFUSED:
        return FILE_REPLACE;
    case SECRET_FILE_READ:
        break;
    }
    const char *start = text + strspn(text, " \t");
    size_t length = strspn(start, TOKEN_CHARACTERS);
    const char *rest = start + length + strspn(start + length, " \t\r");
    if (length < TOKEN_MIN_LENGTH || length >= tokenlen || (*rest != '\n' && *rest != '\0')) {
        snprintf(note, notelen,
                 "%s holds no usable token (one line of %d to %zu letters, "
                 "digits and -._~)",
                 path, TOKEN_MIN_LENGTH, tokenlen - 1);
        return FILE_REPLACE;
    }
    memcpy(token, start, length);
    token[length] = '\0';
    return FILE_GOOD;
}

enum control_token_source control_token_settle(struct skyd_config *config, char *note,
                                               size_t notelen)
{
    note[0] = '\0';
    char *token = config->controller_token;
    if (config->read_only) {
        snprintf(note, notelen,
                 "read-only (read_only in the configuration)%s: nobody can "
                 "control this server",
                 token[0] ? ", controller_token ignored" : "");
        memset(token, 0, sizeof config->controller_token);
        return CONTROL_TOKEN_READ_ONLY;
    }
    if (token[0])
        return CONTROL_TOKEN_CONFIGURED;
    error_text err;
    if (!config->state_file[0]) {
        if (!control_token_generate(token, sizeof config->controller_token, err, sizeof err)) {
            snprintf(note, notelen, "%s", err);
            return CONTROL_TOKEN_FAILED;
        }
        return CONTROL_TOKEN_UNSAVED;
    }
    char path[sizeof config->state_file + 8];
    control_token_path(config->state_file, path, sizeof path);
    state_store_remove_temporaries(path);
    error_text why = "";
    switch (read_token_file(path, token, sizeof config->controller_token, why, sizeof why)) {
    case FILE_GOOD:
        return CONTROL_TOKEN_RESTORED;
    case FILE_ABSENT:
    case FILE_REPLACE:
        break;
    }
    if (!control_token_generate(token, sizeof config->controller_token, err, sizeof err)) {
        snprintf(note, notelen, "%s", err);
        return CONTROL_TOKEN_FAILED;
    }
    char line[sizeof config->controller_token + 1];
    int length = snprintf(line, sizeof line, "%s\n", token);
    if (state_store_write_file(path, line, (size_t)length, 0600, err, sizeof err) != 0) {
        snprintf(note, notelen,
                 "%s%scannot keep the controller token (%s): it lasts until "
                 "this process ends",
                 why, why[0] ? "; " : "", err);
        return CONTROL_TOKEN_UNSAVED;
    }
    if (why[0])
        snprintf(note, notelen, "%s: replaced it with a new controller token", why);
    else
        snprintf(note, notelen, "made a controller token, kept in %s", path);
    return CONTROL_TOKEN_CREATED;
}
