/* The controller token of `skyd serve` (server/host/control_token.c): a configured token used
 * as it is, read_only, a token for the process alone without a state file, and the token file:
 * made with mode 0600 whatever the umask, read back, replaced when group or others may read it
 * or when it holds no token, and a token kept for the process when it cannot be written; and
 * the secret-file checks the cluster's Redis password file shares with it. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "check.h"
#include "config.h"
#include "control_token.h"
#include "secret_file.h"

static char dir[] = "/tmp/skyd-control-token-XXXXXX";

static bool is_new_token(const char *token)
{
    return strlen(token) == 2 * CONTROL_TOKEN_RANDOM_BYTES &&
           strspn(token, "0123456789abcdef") == strlen(token);
}

static void write_text(const char *path, const char *text, mode_t mode)
{
    FILE *f = fopen(path, "w");
    if (f) {
        fputs(text, f);
        fclose(f);
    }
    chmod(path, mode);
}

static bool file_holds(const char *path, const char *token)
{
    char text[256] = "", expected[256];
    FILE *f = fopen(path, "r");
    if (f) {
        size_t n = fread(text, 1, sizeof text - 1, f);
        text[n] = '\0';
        fclose(f);
    }
    snprintf(expected, sizeof expected, "%s\n", token);
    return strcmp(text, expected) == 0;
}

static unsigned file_mode(const char *path)
{
    struct stat st;
    return stat(path, &st) == 0 ? (unsigned)(st.st_mode & 07777) : 0u;
}

static struct skyd_config with_state_file(const char *state_file)
{
    struct skyd_config c;
    skyd_config_defaults(&c);
    snprintf(c.state_file, sizeof c.state_file, "%s", state_file);
    return c;
}

/* The same checks for any secret file (secret_file.h), as the cluster's Redis password file
 * is read: mode, kind, first line; no reason quotes the secret. */
static void secret_files(void)
{
    char path[300], text[64], why[512];
    size_t length = 0;
    snprintf(path, sizeof path, "%s/redis-password", dir);
    CHECK(secret_file_read(path, text, sizeof text, &length, why, sizeof why) ==
          SECRET_FILE_ABSENT);
    write_text(path, "pa ss#word\r\nignored\n", 0600);
    CHECK(secret_file_read(path, text, sizeof text, &length, why, sizeof why) == SECRET_FILE_READ);
    CHECK(secret_file_first_line(text, length, sizeof text, why, sizeof why));
    CHECK_MSG(strcmp(text, "pa ss#word") == 0, "\"%s\"", text);
    write_text(path, "LEAKY-SECRET\n", 0640);
    CHECK(secret_file_read(path, text, sizeof text, &length, why, sizeof why) ==
          SECRET_FILE_REFUSED);
    CHECK_MSG(strstr(why, "0640") && strstr(why, "group or others") && !strstr(why, "LEAKY") &&
                  !strstr(text, "LEAKY"),
              "%s", why);
    write_text(path, "LEAKY-SECRET\n", 0604);
    CHECK(secret_file_read(path, text, sizeof text, &length, why, sizeof why) ==
          SECRET_FILE_REFUSED);
    char link_path[320];
    snprintf(link_path, sizeof link_path, "%s.link", path);
    chmod(path, 0600);
    CHECK(symlink(path, link_path) == 0);
    CHECK(secret_file_read(link_path, text, sizeof text, &length, why, sizeof why) ==
          SECRET_FILE_REFUSED);
    CHECK_MSG(strstr(why, "symbolic link"), "%s", why);
    const char *bad_lines[] = { "\n", "", "tab\there\n" };
    for (size_t i = 0; i < sizeof bad_lines / sizeof bad_lines[0]; i++) {
        write_text(path, bad_lines[i], 0600);
        CHECK(secret_file_read(path, text, sizeof text, &length, why, sizeof why) ==
              SECRET_FILE_READ);
        CHECK_MSG(!secret_file_first_line(text, length, sizeof text, why, sizeof why), "line %zu",
                  i);
    }
    char long_line[200];
    memset(long_line, 'x', sizeof long_line - 1);
    long_line[sizeof long_line - 1] = '\0';
    write_text(path, long_line, 0600);
    CHECK(secret_file_read(path, text, sizeof text, &length, why, sizeof why) == SECRET_FILE_READ);
    CHECK(!secret_file_first_line(text, length, sizeof text, why, sizeof why) &&
          strstr(why, "longer"));
}

int main(void)
{
    if (!mkdtemp(dir))
        return 1;
    char note[2048], err[256], state[200], path[300], first[128];
    snprintf(state, sizeof state, "%s/var/state.json", dir); /* var/ does not exist yet */
    control_token_path(state, path, sizeof path);
    CHECK(strcmp(path + strlen(path) - strlen("state.json.token"), "state.json.token") == 0);

    char a[128], b[128];
    CHECK(control_token_generate(a, sizeof a, err, sizeof err) && is_new_token(a));
    CHECK(control_token_generate(b, sizeof b, err, sizeof err) && strcmp(a, b) != 0);
    CHECK(!control_token_generate(b, 2 * CONTROL_TOKEN_RANDOM_BYTES, err, sizeof err));

    /* A configured token is used as it is, no file made, nothing said. */
    struct skyd_config c = with_state_file(state);
    snprintf(c.controller_token, sizeof c.controller_token, "my-own-token");
    CHECK(control_token_settle(&c, note, sizeof note) == CONTROL_TOKEN_CONFIGURED);
    CHECK(strcmp(c.controller_token, "my-own-token") == 0 && note[0] == '\0');
    CHECK(!control_token_shown(CONTROL_TOKEN_CONFIGURED));
    CHECK(access(path, F_OK) != 0);

    /* read_only wins over a configured token; the note never holds it. */
    c.read_only = true;
    CHECK(control_token_settle(&c, note, sizeof note) == CONTROL_TOKEN_READ_ONLY);
    CHECK(c.controller_token[0] == '\0' && strstr(note, "read-only") && !strstr(note, "my-own"));
    CHECK(!control_token_shown(CONTROL_TOKEN_READ_ONLY));
    c = with_state_file(state);
    c.read_only = true;
    CHECK(control_token_settle(&c, note, sizeof note) == CONTROL_TOKEN_READ_ONLY);
    CHECK(c.controller_token[0] == '\0' && access(path, F_OK) != 0);

    /* No state file: a token for this process, no file anywhere. */
    c = with_state_file("");
    CHECK(control_token_settle(&c, note, sizeof note) == CONTROL_TOKEN_UNSAVED);
    CHECK(is_new_token(c.controller_token) && control_token_shown(CONTROL_TOKEN_UNSAVED));

    /* The first start makes the file (and its directory), mode 0600 even under umask 0. */
    mode_t old_umask = umask(0);
    c = with_state_file(state);
    CHECK(control_token_settle(&c, note, sizeof note) == CONTROL_TOKEN_CREATED);
    umask(old_umask);
    CHECK(is_new_token(c.controller_token) && control_token_shown(CONTROL_TOKEN_CREATED));
    CHECK(strstr(note, path) && !strstr(note, c.controller_token));
    CHECK(file_holds(path, c.controller_token));
    CHECK_MSG(file_mode(path) == 0600, "mode %04o", file_mode(path));
    snprintf(first, sizeof first, "%s", c.controller_token);

    /* The next start reads it back; a temporary a killed daemon left is removed. */
    char stale[400];
    snprintf(stale, sizeof stale, "%s.tmp12345", path);
    write_text(stale, "half", 0600);
    c = with_state_file(state);
    CHECK(control_token_settle(&c, note, sizeof note) == CONTROL_TOKEN_RESTORED);
    CHECK(strcmp(c.controller_token, first) == 0 && note[0] == '\0');
    CHECK(access(stale, F_OK) != 0);

    /* Surrounding blanks and CRLF are trimmed; a token the user put there is kept. */
    write_text(path, "  ABCDEFGHIJKLMNOPQRSTUVWXYZ-._~0123456789 \r\nsecond line\n", 0600);
    c = with_state_file(state);
    CHECK(control_token_settle(&c, note, sizeof note) == CONTROL_TOKEN_RESTORED);
    CHECK(strcmp(c.controller_token, "ABCDEFGHIJKLMNOPQRSTUVWXYZ-._~0123456789") == 0);

    /* Readable by others: replaced by a new token, 0600 again, and said so. */
    write_text(path, first, 0644);
    c = with_state_file(state);
    CHECK(control_token_settle(&c, note, sizeof note) == CONTROL_TOKEN_CREATED);
    CHECK(is_new_token(c.controller_token) && strcmp(c.controller_token, first) != 0);
    CHECK(strstr(note, "0644") && strstr(note, "replaced") && !strstr(note, first));
    CHECK(file_holds(path, c.controller_token) && file_mode(path) == 0600);
    write_text(path, first, 0640); /* group alone is enough */
    c = with_state_file(state);
    CHECK(control_token_settle(&c, note, sizeof note) == CONTROL_TOKEN_CREATED);
    CHECK(strcmp(c.controller_token, first) != 0 && file_mode(path) == 0600);

    /* Not a token: too short, empty, bad characters. */
    const char *junk[] = { "short\n", "", "\n", "a token with spaces in it, long enough to pass\n",
                           "0123456789abcdef0123456789abcdef#fragment\n" };
    for (size_t i = 0; i < sizeof junk / sizeof junk[0]; i++) {
        write_text(path, junk[i], 0600);
        c = with_state_file(state);
        CHECK_MSG(control_token_settle(&c, note, sizeof note) == CONTROL_TOKEN_CREATED, "junk %zu",
                  i);
        CHECK_MSG(strstr(note, "no usable token") && file_holds(path, c.controller_token),
                  "junk %zu: %s", i, note);
    }

    /* A directory in its place: cannot be replaced, so the token lasts for the process. */
    char blocked_state[200], blocked[300];
    snprintf(blocked_state, sizeof blocked_state, "%s/blocked.json", dir);
    control_token_path(blocked_state, blocked, sizeof blocked);
    CHECK(mkdir(blocked, 0700) == 0);
    c = with_state_file(blocked_state);
    CHECK(control_token_settle(&c, note, sizeof note) == CONTROL_TOKEN_UNSAVED);
    CHECK(is_new_token(c.controller_token) && strstr(note, "not a regular file") &&
          strstr(note, "until this process ends"));
    /* Nor can a file be made under a regular file. */
    snprintf(blocked_state, sizeof blocked_state, "%s/var/state.json.token/state.json", dir);
    c = with_state_file(blocked_state);
    CHECK(control_token_settle(&c, note, sizeof note) == CONTROL_TOKEN_UNSAVED);
    CHECK(is_new_token(c.controller_token));

    secret_files();

    char command[128];
    snprintf(command, sizeof command, "rm -rf %s", dir);
    if (system(command) != 0)
        printf("note: could not remove %s\n", dir);
    return check_summary();
}
