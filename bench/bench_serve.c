/* Frames per second that `skyd serve` delivers to 1, 8 and 32 clients sharing one view, or
 * spread over several views (--views: the daemon then renders each of them).
 *
 * Starts the daemon itself on a free port (or uses --url), then for each view and client count:
 * connects the clients, subscribes client i to view i mod views (views differ in yaw), reads
 * with one thread per client, warms up,
 * counts frames over a measurement window and asks the daemon for its stats. Prints a table and
 * a one-line JSON summary. See --help.
 */
#include <cjson/cJSON.h>
#include <pthread.h>
#include <signal.h>
#include <stdatomic.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "sky_client_json.h"
#include "sky_spawn.h"

#define MAX_COUNTS 8
#define MAX_CLIENTS 256

struct options {
    const char *skyd, *url;
    int counts[MAX_COUNTS], count_n;
    int views[MAX_COUNTS], view_n;
    int width, height;
    double fps, warmup_s, seconds;
    const char *format; /* png or jpeg */
};

struct reader {
    pthread_t thread;
    struct sky_client *client;
    double window_start, window_end; /* monotonic seconds */
    long frames;                     /* in the window */
    long long bytes;
    char error[320];
};

struct result {
    int clients, views;
    double min_fps, mean_fps, max_fps, total_fps, ratio;
    double server_fps;
    long errors;
};

static double now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + ts.tv_nsec * 1e-9;
}

static void sleep_until(double t)
{
    double left;
    while ((left = t - now_s()) > 0) {
        struct timespec ts = { (time_t)left, (long)((left - (double)(time_t)left) * 1e9) };
        nanosleep(&ts, NULL);
    }
}

static void usage(FILE *out)
{
    fprintf(out,
            "usage: skyd_bench_serve [options]\n"
            "  --skyd PATH        skyd binary to start (default %s)\n"
            "  --url URL          use a running daemon instead (ws://host:port/)\n"
            "  --clients LIST     client counts, comma-separated (default 1,8,32)\n"
            "  --views LIST       distinct views the clients spread over, comma-separated;\n"
            "                     each is run with every client count (default 1)\n"
            "  --size WxH         the shared view's size (default 640x360)\n"
            "  --fps N            the view's fps (default 60)\n"
            "  --format NAME      png or jpeg, the frames' encoding (default png)\n"
            "  --warmup S         seconds before counting (default 3)\n"
            "  --seconds S        measurement window (default 10)\n",
            SKYD_BINARY);
}

/* A comma-separated list of 1..MAX_CLIENTS, at most MAX_COUNTS of them. */
static bool parse_list(const char *option, const char *text, int *out, int *count)
{
    *count = 0;
    for (const char *p = text; *p;) {
        char *end;
        long n = strtol(p, &end, 10);
        if (end == p || n < 1 || n > MAX_CLIENTS || (*end && *end != ',') || *count == MAX_COUNTS) {
            fprintf(stderr, "skyd_bench_serve: bad %s '%s' (at most %d of 1..%d)\n", option, text,
                    MAX_COUNTS, MAX_CLIENTS);
            return false;
        }
        out[(*count)++] = (int)n;
        p = *end ? end + 1 : end;
    }
    return *count > 0;
}

static bool parse_args(int argc, char **argv, struct options *o)
{
    *o = (struct options){ .skyd = SKYD_BINARY,
                           .counts = { 1, 8, 32 },
                           .count_n = 3,
                           .views = { 1 },
                           .view_n = 1,
                           .width = 640,
                           .height = 360,
                           .fps = 60,
                           .warmup_s = 3,
                           .seconds = 10,
                           .format = "png" };
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i], *v = i + 1 < argc ? argv[i + 1] : NULL;
        if (strcmp(a, "--help") == 0 || strcmp(a, "-h") == 0) {
            usage(stdout);
            exit(0);
        }
        static const char *const known[] = { "--skyd", "--url",    "--clients", "--views", "--size",
                                             "--fps",  "--warmup", "--seconds", "--format" };
        bool is_known = false;
        for (size_t k = 0; k < sizeof known / sizeof known[0]; k++)
            is_known |= strcmp(a, known[k]) == 0;
        if (!is_known || !v) {
            fprintf(stderr, "skyd_bench_serve: %s %s\n", a,
                    is_known ? "needs a value" : "is not an option");
            return false;
        }
        i++;
        if (strcmp(a, "--skyd") == 0) {
            o->skyd = v;
        } else if (strcmp(a, "--url") == 0) {
            o->url = v;
        } else if (strcmp(a, "--clients") == 0 || strcmp(a, "--views") == 0) {
            bool views = a[2] == 'v';
            if (!parse_list(a, v, views ? o->views : o->counts, views ? &o->view_n : &o->count_n))
                return false;
        } else if (strcmp(a, "--format") == 0) {
            if (strcmp(v, "png") != 0 && strcmp(v, "jpeg") != 0) {
                fprintf(stderr, "skyd_bench_serve: --format: expected png or jpeg, got '%s'\n", v);
                return false;
            }
            o->format = v;
        } else if (strcmp(a, "--size") == 0) {
            if (sscanf(v, "%dx%d", &o->width, &o->height) != 2 || o->width < 1 || o->height < 1) {
                fprintf(stderr, "skyd_bench_serve: bad --size '%s'\n", v);
                return false;
            }
        } else { /* --fps, --warmup, --seconds */
            char *end;
            double x = strtod(v, &end);
            bool warmup = strcmp(a, "--warmup") == 0;
            if (*end || !(x >= 0) || (!warmup && x == 0)) {
                fprintf(stderr, "skyd_bench_serve: bad %s '%s'\n", a, v);
                return false;
            }
            if (warmup)
                o->warmup_s = x;
            else if (strcmp(a, "--fps") == 0)
                o->fps = x;
            else
                o->seconds = x;
        }
    }
    return true;
}

static void *read_frames(void *arg)
{
    struct reader *r = arg;
    for (;;) {
        double now = now_s();
        if (now >= r->window_end)
            break;
        int wait_ms = (int)((r->window_end - now) * 1000) + 1;
        struct sky_client_frame f;
        int rc = sky_client_recv_frame(r->client, wait_ms > 1000 ? 1000 : wait_ms, &f, r->error,
                                       sizeof r->error);
        if (rc == 1)
            continue;
        if (rc != 0)
            break;
        now = now_s();
        if (now >= r->window_start && now < r->window_end) {
            r->frames++;
            r->bytes += (long long)f.binary.len;
        }
        sky_client_frame_free(&f);
    }
    return NULL;
}

/* Writes a config for a private daemon into a fresh temporary directory. */
static bool write_config(char *dir, size_t dirlen, char *config, size_t configlen)
{
    snprintf(dir, dirlen, "/tmp/skyd-bench-serve-XXXXXX");
    if (!mkdtemp(dir)) {
        perror("skyd_bench_serve: mkdtemp");
        return false;
    }
    snprintf(config, configlen, "%s/config.json", dir);
    FILE *f = fopen(config, "w");
    if (!f) {
        perror("skyd_bench_serve: config");
        return false;
    }
    fprintf(f,
            "{\"listen\": {\"address\": \"127.0.0.1\", \"port\": 0},\n"
            " \"web_root\": \"%s\", \"state_file\": \"%s/state.json\",\n"
            " \"limits\": {\"max_clients\": %d, \"control_messages_per_second\": 1000}}\n",
            dir, dir, MAX_CLIENTS + 8);
    return fclose(f) == 0;
}

static void print_stats(struct sky_client *control, double *server_fps)
{
    cJSON *stats = NULL;
    char err[320];
    const char *req = "{\"type\":\"stats\",\"id\":\"bench\"}";
    if (sky_client_send_text(control, req, strlen(req), 10000) != 0 ||
        sky_client_recv_json(control, "stats", 10000, &stats, err, sizeof err) != 0) {
        printf("  stats: no reply (%s)\n", sky_client_error(control));
        return;
    }
    char *text = cJSON_PrintUnformatted(stats);
    printf("  stats: %s\n", text ? text : "?");
    free(text);
    const cJSON *fps = cJSON_GetObjectItemCaseSensitive(stats, "fps");
    if (cJSON_IsNumber(fps))
        *server_fps = fps->valuedouble;
    cJSON_Delete(stats);
}

static bool run_count(const char *url, const struct options *o, int n, int views,
                      struct result *res)
{
    char view[200], err[320];
    struct reader *readers = calloc((size_t)n, sizeof *readers);
    struct sky_client *control = sky_client_connect(url, NULL, 10000, err, sizeof err);
    bool ok = readers && control;
    if (!control)
        fprintf(stderr, "skyd_bench_serve: control client: %s\n", err);
    for (int i = 0; ok && i < n; i++) {
        cJSON *reply = NULL;
        err[0] = '\0';
        snprintf(view, sizeof view,
                 "{\"type\":\"subscribe\",\"id\":1,\"view\":{\"width\":%d,\"height\":%d,"
                 "\"fps\":%g,\"format\":\"%s\",\"camera\":{\"yaw_deg\":%g}}}",
                 o->width, o->height, o->fps, o->format, -180.0 + 360.0 * (i % views) / views);
        readers[i].client = sky_client_connect(url, NULL, 10000, err, sizeof err);
        ok = readers[i].client &&
             sky_client_send_text(readers[i].client, view, strlen(view), 10000) == 0 &&
             sky_client_recv_json(readers[i].client, "subscribed", 10000, &reply, err,
                                  sizeof err) == 0;
        if (!ok)
            fprintf(stderr, "skyd_bench_serve: client %d of %d: %s\n", i + 1, n,
                    err[0] || !readers[i].client ? err : sky_client_error(readers[i].client));
        cJSON_Delete(reply);
    }
    double start = now_s() + o->warmup_s, end = start + o->seconds;
    int started = 0;
    for (int i = 0; ok && i < n; i++, started++) {
        readers[i].window_start = start;
        readers[i].window_end = end;
        if (pthread_create(&readers[i].thread, NULL, read_frames, &readers[i]) != 0) {
            fprintf(stderr, "skyd_bench_serve: pthread_create failed\n");
            ok = false;
            break;
        }
    }
    double server_fps = -1;
    if (ok) {
        sleep_until(end - 0.5);
        print_stats(control, &server_fps);
    }
    for (int i = 0; i < started; i++)
        pthread_join(readers[i].thread, NULL);

    *res =
        (struct result){ .clients = n, .views = views, .min_fps = 1e30, .server_fps = server_fps };
    for (int i = 0; ok && i < n; i++) {
        double fps = readers[i].frames / o->seconds;
        res->min_fps = fps < res->min_fps ? fps : res->min_fps;
        res->max_fps = fps > res->max_fps ? fps : res->max_fps;
        res->total_fps += fps;
        if (readers[i].error[0] && !sky_client_is_open(readers[i].client)) {
            res->errors++;
            fprintf(stderr, "skyd_bench_serve: client %d: %s\n", i + 1, readers[i].error);
        }
    }
    res->mean_fps = n ? res->total_fps / n : 0;
    for (int i = 0; readers && i < n; i++)
        sky_client_close(&readers[i].client);
    sky_client_close(&control);
    free(readers);
    return ok;
}

static void print_summary(const struct options *o, const struct result *results, int count)
{
    printf("\n%6s %8s %10s %10s %10s %10s %8s %10s\n", "views", "clients", "min fps", "mean fps",
           "max fps", "total fps", "ratio", "server fps");
    for (int i = 0; i < count; i++) {
        const struct result *r = &results[i];
        printf("%6d %8d %10.2f %10.2f %10.2f %10.2f %8.3f %10.2f\n", r->views, r->clients,
               r->min_fps, r->mean_fps, r->max_fps, r->total_fps, r->ratio, r->server_fps);
    }
    printf("{\"bench\":\"serve\",\"width\":%d,\"height\":%d,\"fps\":%g,\"format\":\"%s\","
           "\"warmup_s\":%g,\"seconds\":%g,\"results\":[",
           o->width, o->height, o->fps, o->format, o->warmup_s, o->seconds);
    for (int i = 0; i < count; i++) {
        const struct result *r = &results[i];
        printf(
            "%s{\"views\":%d,\"clients\":%d,\"min_fps\":%.3f,\"mean_fps\":%.3f,\"total_fps\":%.3f,"
            "\"ratio\":%.4f,\"server_fps\":%.3f,\"errors\":%ld}",
            i ? "," : "", r->views, r->clients, r->min_fps, r->mean_fps, r->total_fps, r->ratio,
            r->server_fps, r->errors);
    }
    printf("]}\n");
}

int main(int argc, char **argv)
{
    struct options o;
    if (!parse_args(argc, argv, &o)) {
        usage(stderr);
        return 2;
    }
    signal(SIGPIPE, SIG_IGN);
    setvbuf(stdout, NULL, _IOLBF, 0);

    struct skyd_process *daemon = NULL;
    char dir[256] = "", config[512], log[512], err[512];
    const char *url = o.url;
    if (!url) {
        if (!write_config(dir, sizeof dir, config, sizeof config))
            return 1;
        snprintf(log, sizeof log, "%s/skyd.log", dir);
        daemon = skyd_process_start(o.skyd, config, NULL, log, 60000, err, sizeof err);
        if (!daemon) {
            fprintf(stderr, "skyd_bench_serve: %s (log: %s)\n", err, log);
            return 1;
        }
        url = skyd_process_url(daemon);
        printf("skyd %s started (log %s)\n", url, log);
    }
    printf("view %dx%d at %g fps; warm-up %g s, window %g s\n", o.width, o.height, o.fps,
           o.warmup_s, o.seconds);

    struct result results[MAX_COUNTS * MAX_COUNTS];
    int done = 0;
    bool ok = true;
    for (int k = 0; k < o.view_n * o.count_n && ok; k++) {
        int views = o.views[k / o.count_n], clients = o.counts[k % o.count_n];
        printf("%d client%s over %d view%s:\n", clients, clients == 1 ? "" : "s", views,
               views == 1 ? "" : "s");
        ok = run_count(url, &o, clients, views, &results[done]);
        if (ok) {
            const struct result *r = &results[done];
            printf("  per client min %.2f mean %.2f fps, total %.2f fps\n", r->min_fps, r->mean_fps,
                   r->total_fps);
            done++;
        }
    }
    /* Ratios are to the first single-client run, or to the first run when none has 1 client. */
    const struct result *base = done ? &results[0] : NULL;
    for (int i = done - 1; i >= 0; i--)
        if (results[i].clients == 1)
            base = &results[i];
    for (int i = 0; i < done; i++)
        results[i].ratio = base->mean_fps > 0 ? results[i].mean_fps / base->mean_fps : 0;
    if (done)
        print_summary(&o, results, done);

    int status = 0;
    if (daemon) {
        skyd_process_signal(daemon, SIGTERM);
        status = skyd_process_wait(daemon, 30000);
        skyd_process_free(&daemon);
        if (status != 0) {
            fprintf(stderr, "skyd_bench_serve: skyd exit status %d after SIGTERM (log %s)\n",
                    status, log);
        } else if (ok) { /* nothing worth keeping */
            char path[600];
            const char *files[] = { "config.json", "state.json", "skyd.log" };
            for (size_t i = 0; i < sizeof files / sizeof files[0]; i++) {
                snprintf(path, sizeof path, "%s/%s", dir, files[i]);
                remove(path);
            }
            rmdir(dir);
        }
    }
    return ok && status == 0 ? 0 : 1;
}
