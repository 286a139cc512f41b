/* Where skyd keeps what it can make again but would rather not (the generated cloud noise):
 * the first of
 *   $SKYD_CACHE_DIR     set but empty: no cache at all;
 *   $CACHE_DIRECTORY    systemd's, for a unit with CacheDirectory= (the first of a list);
 *   $XDG_CACHE_HOME/skyd  when absolute;
 *   $HOME/.cache/skyd   when HOME is absolute.
 * The directory is made when first written to. */
#ifndef SKYD_CACHE_DIR_H
#define SKYD_CACHE_DIR_H

#include <stdbool.h>
#include <stddef.h>

/* The cache directory in out; false (out "") when there is none or it does not fit. */
bool skyd_cache_dir(char *out, size_t outlen);

#endif
