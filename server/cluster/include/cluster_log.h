/* Where the cluster room's lines go. The room cannot see the daemon's log; its user hands it
 * one of these. */
#ifndef SKYD_CLUSTER_LOG_H
#define SKYD_CLUSTER_LOG_H

enum cluster_log_level {
    CLUSTER_LOG_ERROR = 0,
    CLUSTER_LOG_WARNING = 1,
    CLUSTER_LOG_INFO = 2,
    CLUSTER_LOG_DEBUG = 3,
};

/* `write` gets one line per call, without a newline and without the "skyd: " prefix, from
 * the room's own threads (the feed's): it must be thread-safe. No `write`: each line goes to
 * stderr after "skyd: ". */
struct cluster_log {
    void (*write)(void *user, enum cluster_log_level level, const char *line);
    void *user;
};

#endif
