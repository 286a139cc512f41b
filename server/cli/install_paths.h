/* Where skyd finds the files it ships when neither the command line nor the configuration
 * names them: the configuration file, the presets (a folder holding atmosphere/ and weather/)
 * and the web client. In this order:
 *   1. the installation the running binary belongs to: the directories `cmake --install`
 *      wrote (CMAKE_INSTALL_FULL_SYSCONFDIR/skyd/skyd.json, CMAKE_INSTALL_FULL_DATADIR/skyd
 *      and .../skyd/web), compiled in. A binary found in <P>/bin when it was built for another
 *      prefix (an installation moved as a whole, or `cmake --install --prefix P`) looks under
 *      P instead, for every directory that lies under the prefix it was built for;
 *   2. in a developer's build (SKYD_SOURCE_TREE_FALLBACK, the default; Debian's package turns
 *      it off), the source tree: config/skyd.json, config/ and clients/web; unless
 *      $SKYD_NO_SOURCE_TREE is 1, which makes an installation prove that it is complete.
 * The first of these that exists wins. */
#ifndef SKYD_INSTALL_PATHS_H
#define SKYD_INSTALL_PATHS_H

#include <stdbool.h>
#include <stddef.h>

enum install_item {
    INSTALL_CONFIG,  /* the configuration file skyd serve reads without --config */
    INSTALL_PRESETS, /* <dir>/atmosphere/NAME.json, <dir>/weather/NAME.json */
    INSTALL_WEB,     /* the web client's index.html and its files */
};

/* The first place that exists, in out (up to outlen bytes). False when none does: out then
 * holds the installation's place, which a message about a missing file should name. */
bool install_paths_find(enum install_item item, char *out, size_t outlen);

/* The places looked at, in order ("A, then B"), for messages and --help. */
void install_paths_describe(enum install_item item, char *out, size_t outlen);

/* The prefix a binary in exe_dir belongs to, given the prefix and bin directory it was built
 * for: built_prefix when exe_dir is built_bindir, or when the bin directory does not lie
 * under the prefix; P when exe_dir is P followed by built_bindir's part under the prefix;
 * else built_prefix. Trailing slashes do not count. Writes it to out; false when it does not
 * fit. */
bool install_paths_prefix(const char *exe_dir, const char *built_prefix, const char *built_bindir,
                          char *out, size_t outlen);

/* dir, built for built_prefix, under prefix: prefix followed by dir's part under built_prefix,
 * or dir itself when it does not lie under built_prefix (/etc for a /usr build). False when
 * it does not fit. */
bool install_paths_relocate(const char *dir, const char *built_prefix, const char *prefix,
                            char *out, size_t outlen);

#endif
