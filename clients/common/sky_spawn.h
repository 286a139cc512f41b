/* Runs `skyd serve` as a child process for tests and benchmarks: starts it, reads the port
 * from its "skyd: listening on http://HOST:PORT/" line, signals it and collects its status. */
#ifndef SKYD_SKY_SPAWN_H
#define SKYD_SKY_SPAWN_H

#include <stddef.h>
#include <sys/types.h>

struct skyd_process;

/* Starts `skyd serve --config config_path` followed by extra_args (NULL-terminated, may be
 * NULL) with stdout on a pipe, and waits up to timeout_ms for the listening line. stderr goes
 * to log_path (appended) or, when NULL, stays the caller's. Returns NULL with a reason in err
 * when skyd cannot start, exits or stays silent; the child is then reaped. */
struct skyd_process *skyd_process_start(const char *skyd, const char *config_path,
                                        const char *const *extra_args, const char *log_path,
                                        int timeout_ms, char *err, size_t errlen);

int skyd_process_port(const struct skyd_process *process);
pid_t skyd_process_pid(const struct skyd_process *process);
/* "ws://HOST:PORT/" */
const char *skyd_process_url(const struct skyd_process *process);

/* Sends a signal (SIGTERM to shut down). 0 on success. */
int skyd_process_signal(struct skyd_process *process, int signo);

/* Waits up to timeout_ms for the process to exit: its exit status (0..255), 128 + N when
 * signal N ended it, -1 when it is still running. Repeated calls after the exit return the
 * same status. */
int skyd_process_wait(struct skyd_process *process, int timeout_ms);

/* Kills the process (SIGKILL) when it still runs, reaps it and frees; *process = NULL. */
void skyd_process_free(struct skyd_process **process);

#endif
