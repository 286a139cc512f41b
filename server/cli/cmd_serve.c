/* skyd serve: the daemon. Wires the threads together: the render loop (Vulkan, world state,
 * ticks), the PNG encoder workers it owns, the libwebsockets service thread (this one), and
 * a signal thread that turns SIGTERM/SIGINT into an orderly stop and SIGHUP into a reload
 * (serve_reload.h), and the service manager's notifications (service_notify.h). */
#define _XOPEN_SOURCE 700 /* realpath */
#include <errno.h>
#include <limits.h>
#include <pthread.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>
#ifdef __GLIBC__
#include <malloc.h>
#endif

#include "cli_args.h"
#include "commands.h"
#include "config.h"
#include "control_token.h"
#include "error_text.h"
#include "field_errors.h"
#include "install_paths.h"
#include "log.h"
#include "render_loop.h"
#include "serve_reload.h"
#include "service_metrics.h"
#include "service_notify.h"
#include "session.h"
#include "shared_world.h"
#include "world_files.h"
#include "ws_server.h"

struct serve_options {
    const char *config_path;
    const char *port;
    const char *state_file;
    const char *web_root;
    const char *config_dir;
    const char *device;
    const char *log_level;
    bool validation;
    char found_config[PATH_MAX]; /* the config_path install_paths.h found */
};

static void usage(FILE *out)
{
    fprintf(out,
            "usage: skyd serve [--config FILE] [--port N] [--state-file PATH] [--web-root DIR]\n"
            "                  [--config-dir DIR] [--device NAME] [--log-level LEVEL]\n"
            "                  [--validation]\n"
            "Serves the web client over HTTP and the protocol (protocol/PROTOCOL.md) over\n"
            "WebSocket on one port; prints \"skyd: listening on URL\" when ready. Unless the\n"
            "config sets controller_token or read_only, the next line is \"skyd: control at\n"
            "URL#token=TOKEN\": a token made at the first start, kept in <state_file>.token\n"
            "(mode 0600; replaced when group or others may read it). SIGTERM or SIGINT\n"
            "closes every client (1001), saves the world state and exits 0. A lost\n"
            "Vulkan device is reported and the renderer rebuilt; when that fails (or the\n"
            "device is lost 3 times in a minute) every client is closed (1011), the state is\n"
            "saved and skyd exits 1. SIGHUP reloads the limits, the token, read_only, the\n"
            "origins and the presets without dropping anyone, and logs what changed. With\n"
            "NOTIFY_SOCKET set (systemd, config/skyd.service) it reports READY=1, RELOADING=1,\n"
            "STOPPING=1 and pings the watchdog while it is healthy.\n"
            "  --config FILE      configuration (default: the first that exists of the places\n"
            "                     below)\n"
            "  --port N           listen port, 0 for any free one (overrides the config)\n"
            "  --state-file PATH  where the world state persists (overrides the config)\n"
            "  --web-root DIR     static files to serve (overrides the config's web_root)\n"
            "  --config-dir DIR   presets folder ($SKYD_CONFIG_DIR; overrides the config's\n"
            "                     presets_dir)\n"
            "  --device NAME      Vulkan device ($SKYD_DEVICE; else the config's render.device)\n"
            "  --log-level LEVEL  error, warning, info (default: connections, reloads) or debug\n"
            "  --validation       Khronos validation layer on\n");
    char where[3][2 * PATH_MAX + 16];
    install_paths_describe(INSTALL_CONFIG, where[0], sizeof where[0]);
    install_paths_describe(INSTALL_WEB, where[1], sizeof where[1]);
    install_paths_describe(INSTALL_PRESETS, where[2], sizeof where[2]);
    fprintf(out,
            "Looked up, in this order, when the command line (and for the web client and\n"
            "presets, the configuration) names none:\n"
            "  configuration  %s\n"
            "  web client     %s\n"
            "  presets        %s\n",
            where[0], where[1], where[2]);
}

static int parse_options(int argc, char **argv, struct serve_options *o)
{
    for (int i = 0; i < argc; i++) {
        const char *arg = argv[i];
        const char **target = NULL;
        if (strcmp(arg, "--help") == 0 || strcmp(arg, "-h") == 0) {
            usage(stdout);
            return 1;
        } else if (strcmp(arg, "--validation") == 0) {
            o->validation = true;
            continue;
        } else if (strcmp(arg, "--config") == 0) {
            target = &o->config_path;
        } else if (strcmp(arg, "--port") == 0) {
            target = &o->port;
        } else if (strcmp(arg, "--state-file") == 0) {
            target = &o->state_file;
        } else if (strcmp(arg, "--web-root") == 0) {
            target = &o->web_root;
        } else if (strcmp(arg, "--config-dir") == 0) {
            target = &o->config_dir;
        } else if (strcmp(arg, "--device") == 0) {
            target = &o->device;
        } else if (strcmp(arg, "--log-level") == 0) {
            target = &o->log_level;
        } else {
            fprintf(stderr, "skyd serve: unknown option \"%s\"\n", arg);
            usage(stderr);
            return -1;
        }
        if (!(*target = cli_take_value(argc, argv, &i)))
            return -1;
    }
    enum skyd_log_level level = SKYD_LOG_INFO;
    if (o->log_level && !skyd_log_parse_level(o->log_level, &level)) {
        fprintf(stderr,
                "skyd serve: --log-level: expected error, warning, info or debug, got "
                "\"%s\"\n",
                o->log_level);
        return -1;
    }
    skyd_log_set_level(level);
    return 0;
}

/* Config, then command line. Returns false after printing why. */
static bool load_config(const void *options, struct skyd_config *config)
{
    const struct serve_options *o = options;
    skyd_config_defaults(config);
    if (o->config_path) {
        struct proto_field_errors errors;
        error_text msg;
        if (!skyd_config_load(o->config_path, config, &errors, msg, sizeof msg)) {
            char detail[2048];
            proto_field_errors_format(&errors, detail, sizeof detail);
            fprintf(stderr, "skyd serve: %s\n%s", msg, detail);
            return false;
        }
    }
    if (o->port) {
        unsigned port;
        if (!cli_parse_uint("--port", o->port, 0, 65535, &port))
            return false;
        config->listen_port = (int)port;
    }
    if (o->state_file)
        snprintf(config->state_file, sizeof config->state_file, "%s", o->state_file);
    if (o->web_root)
        snprintf(config->web_root, sizeof config->web_root, "%s", o->web_root);
    if ((config->tls_certificate[0] != '\0') != (config->tls_private_key[0] != '\0')) {
        fprintf(stderr, "skyd serve: /listen/tls_certificate and /listen/tls_private_key go "
                        "together: set both or neither\n");
        return false;
    }
    return true;
}

/* Signals are blocked in every thread; this one waits for them. */
struct signal_watch {
    pthread_t thread;
    sigset_t set;
    volatile sig_atomic_t stop;
    volatile sig_atomic_t done;
    struct ws_server *server;
    struct serve_reload *reload; /* SIGHUP */
};

/* The render loop cannot go on (render_loop_params.on_failure, on the render thread): the
 * service loop stops as after a signal. The hub's wake is the server's once it exists;
 * before that, ws_server_run sees `stop` when it starts. */
struct failure_watch {
    struct signal_watch *signals;
    struct session_hub *hub;
};

static void on_render_failure(void *user)
{
    struct failure_watch *f = user;
    f->signals->stop = 1;
    session_hub_wake(f->hub);
}

static void *signal_thread(void *arg)
{
    struct signal_watch *w = arg;
    int signal_number = 0;
    for (;;) {
        if (sigwait(&w->set, &signal_number) != 0 || w->done)
            return NULL;
        if (signal_number != SIGHUP)
            break;
        serve_reload_run(w->reload);
    }
    skyd_log(SKYD_LOG_INFO, "%s: shutting down", strsignal(signal_number));
    w->stop = 1;
    /* Keeps waking the service loop so that it notices and its close deadline is checked. */
    while (!w->done) {
        ws_server_wake(w->server);
        nanosleep(&(struct timespec){ .tv_nsec = 50 * 1000 * 1000 }, NULL);
    }
    return NULL;
}

/* lavapipe keeps device memory in malloc'd blocks, and the daemon allocates and frees
 * image-sized ones of many sizes as views, cloud histories, weather maps and snapshots come and
 * go. glibc gives a block above its mmap threshold a mapping of its own, returned when freed,
 * but raises the threshold to the size of every such block freed (up to 32 MiB); from then on
 * blocks of that size come from the heap, whose free space between live blocks is kept. The
 * soak's daemon grew about 30 MiB a real minute that way. A fixed threshold keeps every large
 * block in a mapping of its own. */
static void return_large_blocks_when_freed(void)
{
#ifdef __GLIBC__
    mallopt(M_MMAP_THRESHOLD, 128 * 1024);
#endif
}

/* Everything a serving daemon holds, torn down in one place. */
struct serve_parts {
    struct signal_watch watch;
    bool watch_started;
    struct failure_watch failure_watch;
    struct session_hub *hub;
    struct service_metrics *metrics;
    struct live_settings *settings;
    struct render_loop *loop;
    struct ws_server *server;
    struct service_notify *notify;
    struct serve_reload reload;
    struct shared_world *shared_world; /* outlives the loop */
};

/* The watchdog's question: the render thread ticks and rendering works. */
static bool serve_healthy(void *user, char *why, size_t len)
{
    struct serve_parts *parts = user;
    const char *failure = render_loop_failure(parts->loop);
    struct service_metrics_tick tick = service_metrics_last_tick(parts->metrics);
    struct timespec now;
    clock_gettime(CLOCK_MONOTONIC, &now);
    double age = (double)now.tv_sec + (double)now.tv_nsec * 1e-9 - tick.at_s;
    if (failure)
        snprintf(why, len, "rendering stopped: %s", failure);
    else if (age > 5.0)
        snprintf(why, len, "the render thread has not ticked for %.1f s", age);
    return !failure && age <= 5.0;
}

static void serve_teardown(struct serve_parts *parts)
{
    if (parts->hub)
        session_hub_set_wake(parts->hub, NULL, NULL);
    render_loop_destroy(&parts->loop);
    shared_world_close(&parts->shared_world);
    if (parts->watch_started) {
        parts->watch.done = 1;
        pthread_kill(parts->watch.thread, SIGTERM); /* in case no signal came */
        pthread_join(parts->watch.thread, NULL);
    }
    service_notify_destroy(&parts->notify);
    ws_server_destroy(&parts->server);
    session_hub_destroy(&parts->hub);
    live_settings_destroy(&parts->settings);
    service_metrics_destroy(&parts->metrics);
}

static int serve_fail(struct serve_parts *parts, const char *why)
{
    fprintf(stderr, "skyd serve: %s\n", why);
    serve_teardown(parts);
    return SKYD_EXIT_FAILURE;
}

int skyd_cmd_serve(int argc, char **argv)
{
    return_large_blocks_when_freed();
    struct serve_options options = { 0 };
    int rc = parse_options(argc, argv, &options);
    if (rc != 0)
        return rc > 0 ? SKYD_EXIT_OK : SKYD_EXIT_USAGE;
    if (!options.config_path) {
        if (install_paths_find(INSTALL_CONFIG, options.found_config, sizeof options.found_config)) {
            options.config_path = options.found_config;
        } else {
            char where[2 * PATH_MAX + 16];
            install_paths_describe(INSTALL_CONFIG, where, sizeof where);
            skyd_log(SKYD_LOG_INFO, "no configuration file at %s: the built-in defaults", where);
        }
    }
    struct skyd_config config;
    if (!load_config(&options, &config))
        return SKYD_EXIT_USAGE;
    if (options.config_path)
        skyd_log(SKYD_LOG_INFO, "configuration %s", options.config_path);
    char token_note[1536];
    enum control_token_source token = control_token_settle(&config, token_note, sizeof token_note);
    if (token_note[0])
        skyd_log(SKYD_LOG_INFO, "%s", token_note);
    if (token == CONTROL_TOKEN_FAILED)
        return SKYD_EXIT_FAILURE;

    char web_root[PATH_MAX];
    char web_found[PATH_MAX];
    const char *web_wanted = config.web_root;
    if (!web_wanted[0]) {
        if (!install_paths_find(INSTALL_WEB, web_found, sizeof web_found)) {
            char where[2 * PATH_MAX + 16];
            install_paths_describe(INSTALL_WEB, where, sizeof where);
            skyd_log(SKYD_LOG_INFO, "no web client at %s", where);
        }
        web_wanted = web_found;
    }
    if (!realpath(web_wanted, web_root)) {
        skyd_log(SKYD_LOG_INFO, "web root %s: %s (HTTP requests will get 404)", web_wanted,
                 strerror(errno));
        snprintf(web_root, sizeof web_root, "%s", web_wanted);
    }
    /* Presets: --config-dir, $SKYD_CONFIG_DIR, the config's presets_dir, install_paths.h. */
    struct cli_common common;
    cli_common_init(&common);
    const char *config_dir = options.config_dir ? options.config_dir : common.config_dir;
    if (!config_dir && config.presets_dir[0])
        config_dir = config.presets_dir;
    if (!config_dir)
        config_dir = cli_presets_dir(&common);
    const char *device = options.device ? options.device : getenv("SKYD_DEVICE");
    if (!device && config.render_device[0])
        device = config.render_device;
    const char *validation_env = getenv("SKYD_VALIDATION");
    bool validation = options.validation || config.render_validation ||
                      (validation_env && strcmp(validation_env, "1") == 0);

    struct serve_parts parts = { .watch.reload = &parts.reload };
    sigemptyset(&parts.watch.set);
    sigaddset(&parts.watch.set, SIGTERM);
    sigaddset(&parts.watch.set, SIGINT);
    sigaddset(&parts.watch.set, SIGHUP);
    pthread_sigmask(SIG_BLOCK, &parts.watch.set, NULL);
    signal(SIGPIPE, SIG_IGN);

    struct render_loop_params loop_params = { .config = &config,
                                              .device = device,
                                              .validation = validation,
                                              .config_dir = config_dir,
                                              .state_file = config.state_file };
    error_text err;
    if (config.cluster_redis[0]) {
        if (!(parts.shared_world = shared_world_open(&config, &loop_params.initial_state, err,
                                                     sizeof err)))
            return serve_fail(&parts, err);
        loop_params.state_file = ""; /* the shared world lives in Redis */
        loop_params.shared_world = parts.shared_world;
    } else {
        world_files_resume_state(config.state_file, &config.initial_state,
                                 &loop_params.initial_state);
    }
    parts.hub = session_hub_create(NULL, NULL);
    parts.metrics = service_metrics_create();
    parts.settings = live_settings_create(&config);
    if (!parts.hub || !parts.metrics || !parts.settings)
        return serve_fail(&parts, "out of memory");
    loop_params.metrics = parts.metrics;
    loop_params.settings = parts.settings;
    parts.failure_watch = (struct failure_watch){ .signals = &parts.watch, .hub = parts.hub };
    loop_params.hub = parts.hub;
    loop_params.on_failure = on_render_failure;
    loop_params.failure_user = &parts.failure_watch;
    if (!(parts.loop = render_loop_create(&loop_params, err, sizeof err)))
        return serve_fail(&parts, err);
    struct ws_server_params server_params = { .config = &config,
                                              .web_root = web_root,
                                              .hub = parts.hub,
                                              .loop = parts.loop,
                                              .metrics = parts.metrics,
                                              .settings = parts.settings };
    if (!(parts.server = ws_server_create(&server_params, err, sizeof err)))
        return serve_fail(&parts, err);
    session_hub_set_wake(parts.hub, ws_server_wake, parts.server);
    parts.watch.server = parts.server;
    if (!(parts.notify = service_notify_create(serve_healthy, &parts)))
        return serve_fail(&parts, "cannot start the watchdog thread");
    parts.reload = (struct serve_reload){ .load = load_config,
                                          .options = &options,
                                          .running = config,
                                          .token_source = token,
                                          .settings = parts.settings,
                                          .notify = parts.notify,
                                          .config_dir = config_dir,
                                          .url = ws_server_url(parts.server) };
    serve_reload_init(&parts.reload);
    if (pthread_create(&parts.watch.thread, NULL, signal_thread, &parts.watch) != 0)
        return serve_fail(&parts, "cannot start the signal thread");
    parts.watch_started = true;
    printf("skyd: listening on %s\n", ws_server_url(parts.server));
    if (control_token_shown(token))
        printf("skyd: control at %s#token=%s\n", ws_server_url(parts.server),
               config.controller_token);
    fflush(stdout);
    service_notify_ready(parts.notify, ws_server_url(parts.server));

    ws_server_run(parts.server, &parts.watch.stop);
    service_notify_stopping(parts.notify);
    error_text failure = "";
    const char *why = render_loop_failure(parts.loop);
    if (why)
        snprintf(failure, sizeof failure, "%s", why);
    if (failure[0]) /* the replies saying why go out first */
        ws_server_close_all(parts.server, SESSION_CLOSE_INTERNAL_ERROR, "rendering device lost",
                            true, 2.0);
    else
        ws_server_close_all(parts.server, SESSION_CLOSE_GOING_AWAY, "skyd shutting down", false,
                            2.0);
    ws_server_detach_loop(parts.server);
    serve_teardown(&parts); /* the render loop saves the state */
    if (failure[0]) {
        skyd_log(SKYD_LOG_INFO, "stopped with the state saved: %s", failure);
        return SKYD_EXIT_FAILURE;
    }
    skyd_log(SKYD_LOG_INFO, "stopped");
    return SKYD_EXIT_OK;
}
