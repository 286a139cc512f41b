/* The daemon's log: one line per event on stderr, "skyd: " then "error: ", "warning: ",
 * nothing (info) or "debug: ", then the text. `skyd serve --log-level` sets the least severe
 * level written (info by default). Lines from different threads never interleave. Tokens are
 * never logged. */
#ifndef SKYD_LOG_H
#define SKYD_LOG_H

#include <stdbool.h>

enum skyd_log_level {
    SKYD_LOG_ERROR = 0,
    SKYD_LOG_WARNING = 1,
    SKYD_LOG_INFO = 2,
    SKYD_LOG_DEBUG = 3,
};

/* "error", "warning", "info" or "debug"; false for anything else. */
bool skyd_log_parse_level(const char *name, enum skyd_log_level *level);
void skyd_log_set_level(enum skyd_log_level level);
bool skyd_log_enabled(enum skyd_log_level level);

#if defined(__GNUC__)
__attribute__((format(printf, 2, 3)))
#endif
void skyd_log(enum skyd_log_level level, const char *format, ...);

#endif
