#define _XOPEN_SOURCE 700 /* realpath */
#include "install_paths.h"

#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

/* The directories `cmake --install` writes to, and whether the source tree is looked at
 * (server/CMakeLists.txt). */
#if !defined(SKYD_INSTALL_PREFIX) || !defined(SKYD_INSTALL_BINDIR) ||                              \
    !defined(SKYD_INSTALL_CONFDIR) || !defined(SKYD_INSTALL_DATADIR) ||                            \
    !defined(SKYD_SOURCE_TREE_FALLBACK)
#error "the install directories come from server/CMakeLists.txt"
#endif

/* The length of path without its trailing slashes ("/" counts as empty: the root). */
static size_t trimmed_length(const char *path)
{
    size_t n = strlen(path);
    while (n > 0 && path[n - 1] == '/')
        n--;
    return n;
}

/* Whether dir (its first dir_len bytes) lies strictly under prefix (its first prefix_len). */
static bool lies_under(const char *dir, size_t dir_len, const char *prefix, size_t prefix_len)
{
    return dir_len > prefix_len && strncmp(dir, prefix, prefix_len) == 0 && dir[prefix_len] == '/';
}

static bool put(char *out, size_t outlen, const char *a, size_t a_len, const char *b, size_t b_len)
{
    if (a_len + b_len + 1 > outlen)
        return false;
    memcpy(out, a, a_len);
    memcpy(out + a_len, b, b_len);
    out[a_len + b_len] = '\0';
    return true;
}

bool install_paths_prefix(const char *exe_dir, const char *built_prefix, const char *built_bindir,
                          char *out, size_t outlen)
{
    size_t exe_len = trimmed_length(exe_dir);
    size_t prefix_len = trimmed_length(built_prefix);
    size_t bin_len = trimmed_length(built_bindir);
    bool at_home = exe_len == bin_len && strncmp(exe_dir, built_bindir, bin_len) == 0;
    if (!at_home && lies_under(built_bindir, bin_len, built_prefix, prefix_len)) {
        /* "/bin" for a bin directory <prefix>/bin: the binary's folder must end with it. */
        const char *tail = built_bindir + prefix_len;
        size_t tail_len = bin_len - prefix_len;
        if (exe_len >= tail_len && strncmp(exe_dir + exe_len - tail_len, tail, tail_len) == 0) {
            size_t moved_len = exe_len - tail_len;
            return moved_len == 0 ? put(out, outlen, "/", 1, "", 0)
                                  : put(out, outlen, exe_dir, moved_len, "", 0);
        }
    }
    return put(out, outlen, built_prefix, strlen(built_prefix), "", 0);
}

bool install_paths_relocate(const char *dir, const char *built_prefix, const char *prefix,
                            char *out, size_t outlen)
{
    size_t dir_len = trimmed_length(dir);
    size_t built_len = trimmed_length(built_prefix);
    if (!lies_under(dir, dir_len, built_prefix, built_len))
        return put(out, outlen, dir, strlen(dir), "", 0);
    return put(out, outlen, prefix, trimmed_length(prefix), dir + built_len, dir_len - built_len);
}

/* The prefix the running binary belongs to (install_paths_prefix of its own folder). */
static void running_prefix(char *out, size_t outlen)
{
    char exe[PATH_MAX];
    if (realpath("/proc/self/exe", exe)) {
        char *slash = strrchr(exe, '/');
        if (slash) {
            *slash = '\0';
            if (install_paths_prefix(exe[0] ? exe : "/", SKYD_INSTALL_PREFIX, SKYD_INSTALL_BINDIR,
                                     out, outlen))
                return;
        }
    }
    snprintf(out, outlen, "%s", SKYD_INSTALL_PREFIX);
}

static bool exists(const char *path, bool directory)
{
    struct stat st;
    return stat(path, &st) == 0 && (directory ? S_ISDIR(st.st_mode) : S_ISREG(st.st_mode));
}

struct place {
    char path[PATH_MAX];
};

/* The places item may be, best first: the installation's, then the source tree's. Returns
 * how many; probe is the file within each that must exist (the presets' atmosphere/ folder,
 * the web client's index.html, the configuration itself: ""). */
static int candidates(enum install_item item, struct place list[2], const char **probe)
{
    const char *installed = item == INSTALL_CONFIG ? SKYD_INSTALL_CONFDIR "/skyd.json"
                            : item == INSTALL_WEB  ? SKYD_INSTALL_DATADIR "/web"
                                                   : SKYD_INSTALL_DATADIR;
    *probe = item == INSTALL_WEB ? "/index.html" : item == INSTALL_PRESETS ? "/atmosphere" : "";
    char prefix[PATH_MAX];
    running_prefix(prefix, sizeof prefix);
    int count = 0;
    if (install_paths_relocate(installed, SKYD_INSTALL_PREFIX, prefix, list[count].path,
                               sizeof list[count].path))
        count++;
#if SKYD_SOURCE_TREE_FALLBACK
    const char *in_source = item == INSTALL_CONFIG ? SKYD_SOURCE_DIR "/config/skyd.json"
                            : item == INSTALL_WEB  ? SKYD_SOURCE_DIR "/clients/web"
                                                   : SKYD_SOURCE_DIR "/config";
    const char *hidden = getenv("SKYD_NO_SOURCE_TREE");
    if (!(hidden && strcmp(hidden, "1") == 0))
        snprintf(list[count++].path, sizeof list[0].path, "%s", in_source);
#endif
    return count;
}

bool install_paths_find(enum install_item item, char *out, size_t outlen)
{
    struct place list[2];
    const char *probe;
    int count = candidates(item, list, &probe);
    for (int i = 0; i < count; i++) {
        char checked[PATH_MAX + 16];
        if (put(checked, sizeof checked, list[i].path, strlen(list[i].path), probe,
                strlen(probe)) &&
            exists(checked, item == INSTALL_PRESETS)) {
            snprintf(out, outlen, "%s", list[i].path);
            return true;
        }
    }
    snprintf(out, outlen, "%s", count > 0 ? list[0].path : "");
    return false;
}

void install_paths_describe(enum install_item item, char *out, size_t outlen)
{
    struct place list[2];
    const char *probe;
    int count = candidates(item, list, &probe);
    snprintf(out, outlen, "%s%s%s", count > 0 ? list[0].path : "", count > 1 ? ", then " : "",
             count > 1 ? list[1].path : "");
}
