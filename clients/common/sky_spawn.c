#include "sky_spawn.h"

#include <errno.h>
#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#define MAX_EXTRA_ARGS 16

struct skyd_process {
    pid_t pid;
    int stdout_fd; /* kept open so skyd never writes to a closed pipe */
    int port;
    bool exited;
    int status;
    char url[128];
};

static int64_t now_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (int64_t)ts.tv_sec * 1000 + ts.tv_nsec / 1000000;
}

static void sleep_ms(int ms)
{
    struct timespec ts = { ms / 1000, (long)(ms % 1000) * 1000000L };
    nanosleep(&ts, NULL);
}

/* In the child: stdout to the pipe, stderr to the log, nothing else inherited (a client socket
 * of the parent held open by skyd would keep that connection alive). */
static void exec_child(const char *const *argv, int out_fd, const char *log_path)
{
    if (dup2(out_fd, STDOUT_FILENO) < 0)
        _exit(127);
    if (log_path) {
        int log_fd = open(log_path, O_WRONLY | O_CREAT | O_APPEND, 0644);
        if (log_fd < 0 || dup2(log_fd, STDERR_FILENO) < 0)
            _exit(127);
    }
    long max_fd = sysconf(_SC_OPEN_MAX);
    if (max_fd < 0 || max_fd > 65536)
        max_fd = 65536;
    for (int fd = 3; fd < max_fd; fd++)
        close(fd);
    sigset_t none;
    sigemptyset(&none);
    sigprocmask(SIG_SETMASK, &none, NULL);
    signal(SIGPIPE, SIG_DFL);
    execv(argv[0], (char *const *)argv);
    fprintf(stderr, "skyd_process: cannot run %s: %s\n", argv[0], strerror(errno));
    _exit(127);
}

static void describe_status(int status, char *buf, size_t len)
{
    if (status >= 128)
        snprintf(buf, len, "killed by signal %d", status - 128);
    else
        snprintf(buf, len, "exit status %d", status);
}

/* Reads stdout until the listening line; the port, or -1 with err filled. */
static int read_port(struct skyd_process *p, int timeout_ms, char *err, size_t errlen)
{
    char line[512];
    size_t used = 0;
    int64_t deadline = now_ms() + timeout_ms;
    for (;;) {
        char *nl = memchr(line, '\n', used);
        if (nl) {
            *nl = 0;
            char host[64];
            int port = 0;
            if (sscanf(line, "skyd: listening on http://%63[^:]:%d/", host, &port) == 2 &&
                port > 0 && port < 65536) {
                snprintf(p->url, sizeof p->url, "ws://%s:%d/", host, port);
                return port;
            }
            snprintf(err, errlen, "unexpected first line on skyd's stdout: '%s'", line);
            return -1;
        }
        if (used >= sizeof line - 1) {
            snprintf(err, errlen, "skyd's first stdout line is longer than %zu bytes", sizeof line);
            return -1;
        }
        int64_t left = deadline - now_ms();
        if (left <= 0) {
            snprintf(err, errlen, "skyd printed no listening line within %d ms", timeout_ms);
            return -1;
        }
        struct pollfd pfd = { p->stdout_fd, POLLIN, 0 };
        int n = poll(&pfd, 1, (int)(left > 1000 ? 1000 : left));
        if (n < 0 && errno != EINTR) {
            snprintf(err, errlen, "poll: %s", strerror(errno));
            return -1;
        }
        if (n <= 0)
            continue;
        ssize_t got = read(p->stdout_fd, line + used, sizeof line - 1 - used);
        if (got < 0 && errno == EINTR)
            continue;
        if (got <= 0) {
            int status = skyd_process_wait(p, 5000);
            char how[64] = "still running";
            if (status >= 0)
                describe_status(status, how, sizeof how);
            snprintf(err, errlen, "skyd closed stdout before listening (%s)", how);
            return -1;
        }
        used += (size_t)got;
    }
}

struct skyd_process *skyd_process_start(const char *skyd, const char *config_path,
                                        const char *const *extra_args, const char *log_path,
                                        int timeout_ms, char *err, size_t errlen)
{
    const char *argv[5 + MAX_EXTRA_ARGS] = { skyd, "serve", "--config", config_path };
    size_t argc = 4;
    for (size_t i = 0; extra_args && extra_args[i]; i++) {
        if (i == MAX_EXTRA_ARGS) {
            snprintf(err, errlen, "more than %d extra arguments", MAX_EXTRA_ARGS);
            return NULL;
        }
        argv[argc++] = extra_args[i];
    }
    argv[argc] = NULL;

    struct skyd_process *p = calloc(1, sizeof *p);
    int fds[2];
    if (!p || pipe(fds) != 0) {
        snprintf(err, errlen, "cannot create a pipe: %s", strerror(errno));
        free(p);
        return NULL;
    }
    fflush(NULL);
    p->pid = fork();
    if (p->pid < 0) {
        snprintf(err, errlen, "fork: %s", strerror(errno));
        close(fds[0]);
        close(fds[1]);
        free(p);
        return NULL;
    }
    if (p->pid == 0)
        exec_child(argv, fds[1], log_path);
    close(fds[1]);
    p->stdout_fd = fds[0];
    fcntl(p->stdout_fd, F_SETFD, FD_CLOEXEC);
    p->port = read_port(p, timeout_ms, err, errlen);
    if (p->port < 0) {
        skyd_process_free(&p);
        return NULL;
    }
    return p;
}

int skyd_process_port(const struct skyd_process *process)
{
    return process->port;
}

pid_t skyd_process_pid(const struct skyd_process *process)
{
    return process->pid;
}

const char *skyd_process_url(const struct skyd_process *process)
{
    return process->url;
}

int skyd_process_signal(struct skyd_process *process, int signo)
{
    if (process->exited)
        return -1;
    return kill(process->pid, signo);
}

int skyd_process_wait(struct skyd_process *p, int timeout_ms)
{
    int64_t deadline = now_ms() + timeout_ms;
    while (!p->exited) {
        int status;
        pid_t got = waitpid(p->pid, &status, WNOHANG);
        if (got == p->pid) {
            p->exited = true;
            p->status = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
            break;
        }
        if (got < 0 && errno != EINTR) {
            p->exited = true;
            p->status = 255;
            break;
        }
        if (now_ms() >= deadline)
            return -1;
        sleep_ms(10);
    }
    return p->status;
}

void skyd_process_free(struct skyd_process **process)
{
    struct skyd_process *p = process ? *process : NULL;
    if (!p)
        return;
    *process = NULL;
    if (!p->exited) {
        kill(p->pid, SIGKILL);
        skyd_process_wait(p, 10000);
    }
    close(p->stdout_fd);
    free(p);
}
