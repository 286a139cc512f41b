/* The cluster feed's lines (server/cluster/cluster_feed.c) go through the sink its user hands
 * it, at their level, and nothing of them reaches stderr; without a sink they go to stderr
 * after "skyd: ". The feed is pointed at a port nothing listens on, so its first line is the
 * error that Redis cannot be reached. No Redis here. */
#include <arpa/inet.h>
#include <netinet/in.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "check.h"
#include "cluster_feed.h"

#define WORLD "logged"
#define UNREACHABLE "cluster world \"" WORLD "\": cannot reach Redis"

struct heard {
    pthread_mutex_t lock;
    unsigned lines;
    enum cluster_log_level level; /* of the first line */
    char first[512];
};

static void hear(void *user, enum cluster_log_level level, const char *line)
{
    struct heard *h = user;
    pthread_mutex_lock(&h->lock);
    if (h->lines++ == 0) {
        h->level = level;
        snprintf(h->first, sizeof h->first, "%s", line);
    }
    pthread_mutex_unlock(&h->lock);
}

/* A local port that nothing listens on: bound, then closed. 0 when none could be had. */
static int closed_port(void)
{
    int s = socket(AF_INET, SOCK_STREAM, 0);
    if (s < 0)
        return 0;
    struct sockaddr_in a = { .sin_family = AF_INET, .sin_addr.s_addr = htonl(INADDR_LOOPBACK) };
    socklen_t length = sizeof a;
    int port = 0;
    if (bind(s, (struct sockaddr *)&a, sizeof a) == 0 &&
        getsockname(s, (struct sockaddr *)&a, &length) == 0)
        port = ntohs(a.sin_port);
    close(s);
    return port;
}

static void sleep_ms(long ms)
{
    struct timespec t = { ms / 1000, (ms % 1000) * 1000000L };
    nanosleep(&t, NULL);
}

/* stderr into a temporary file while a feed runs; `saved` keeps the real one. */
static FILE *capture_stderr(int *saved)
{
    FILE *file = tmpfile();
    *saved = dup(STDERR_FILENO);
    if (file && *saved >= 0)
        dup2(fileno(file), STDERR_FILENO);
    return file;
}

static off_t written_size(FILE *file)
{
    struct stat st;
    return fstat(fileno(file), &st) == 0 ? st.st_size : 0;
}

/* Restores stderr and returns what was written to it, in `text`. */
static const char *release_stderr(FILE *file, int saved, char *text, size_t size)
{
    text[0] = '\0';
    if (saved >= 0) {
        dup2(saved, STDERR_FILENO);
        close(saved);
    }
    if (!file)
        return text;
    rewind(file);
    size_t n = fread(text, 1, size - 1, file);
    text[n] = '\0';
    fclose(file);
    return text;
}

static struct cluster_feed *start_feed(const struct cluster_address *address,
                                       struct cluster_log log)
{
    struct cluster_feed_params params = {
        .address = address,
        .world = WORLD,
        .last_id = "0-0",
        .log = log,
    };
    char err[256] = "";
    struct cluster_feed *feed = cluster_feed_create(&params, err, sizeof err);
    CHECK_MSG(feed != NULL, "%s", err);
    return feed;
}

static void through_the_sink(const struct cluster_address *address)
{
    struct heard heard = { .lock = PTHREAD_MUTEX_INITIALIZER, .level = CLUSTER_LOG_DEBUG };
    int saved;
    FILE *file = capture_stderr(&saved);
    struct cluster_feed *feed = start_feed(address, (struct cluster_log){ hear, &heard });
    unsigned lines = 0;
    for (int waited = 0; feed && lines == 0 && waited < 5000; waited += 20) {
        sleep_ms(20);
        pthread_mutex_lock(&heard.lock);
        lines = heard.lines;
        pthread_mutex_unlock(&heard.lock);
    }
    cluster_feed_destroy(&feed);
    char text[2048];
    const char *written = release_stderr(file, saved, text, sizeof text);
    CHECK(lines > 0);
    CHECK_INT(heard.level, CLUSTER_LOG_ERROR);
    CHECK_MSG(strncmp(heard.first, UNREACHABLE, strlen(UNREACHABLE)) == 0, "\"%s\"", heard.first);
    CHECK_STR(written, "");
}

static void on_stderr_without_one(const struct cluster_address *address)
{
    int saved;
    FILE *file = capture_stderr(&saved);
    struct cluster_feed *feed = start_feed(address, (struct cluster_log){ 0 });
    for (int waited = 0; feed && file && written_size(file) == 0 && waited < 5000; waited += 20)
        sleep_ms(20);
    cluster_feed_destroy(&feed);
    char text[2048];
    const char *written = release_stderr(file, saved, text, sizeof text);
    CHECK_MSG(strncmp(written, "skyd: " UNREACHABLE, strlen("skyd: " UNREACHABLE)) == 0, "\"%s\"",
              written);
    CHECK(strlen(written) > 0 && written[strlen(written) - 1] == '\n');
}

int main(void)
{
    int port = closed_port();
    CHECK(port > 0);
    char url[64], why[256] = "";
    snprintf(url, sizeof url, "redis://127.0.0.1:%d", port);
    struct cluster_address address;
    CHECK_MSG(cluster_url_parse(url, &address, why, sizeof why), "%s", why);
    through_the_sink(&address);
    on_stderr_without_one(&address);
    return check_summary();
}
