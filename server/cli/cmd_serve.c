/* skyd serve: the daemon. Wires the threads together: the render loop (Vulkan, world state,
 * ticks), the PNG encoder workers it owns, the libwebsockets service thread (this one), and
 * a signal thread that turns SIGTERM/SIGINT into an orderly stop. */
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
#include "render_loop.h"
#include "session.h"
#include "state_store.h"
#include "ws_server.h"

struct serve_options {
    const char *config_path;
    const char *port;
    const char *state_file;
    const char *web_root;
    const char *config_dir;
    const char *device;
    bool validation;
};

static void usage(FILE *out)
{
    fprintf(out,
            "usage: skyd serve [--config FILE] [--port N] [--state-file PATH] [--web-root DIR]\n"
            "                  [--config-dir DIR] [--device NAME] [--validation]\n"
            "Serves the web client over HTTP and the protocol (protocol/PROTOCOL.md) over\n"
            "WebSocket on one port; prints \"skyd: listening on URL\" when ready. Unless the\n"
            "config sets controller_token or read_only, the next line is \"skyd: control at\n"
            "URL#token=TOKEN\": a token made at the first start, kept in <state_file>.token\n"
            "(mode 0600; replaced when group or others may read it). SIGTERM or SIGINT\n"
            "closes every client (1001), saves the world state and exits 0. A lost\n"
            "Vulkan device is reported and the renderer rebuilt; when that fails (or the\n"
            "device is lost 3 times in a minute) every client is closed (1011), the state is\n"
            "saved and skyd exits 1.\n"
            "  --config FILE      configuration (config/skyd.json when run from the source tree)\n"
            "  --port N           listen port, 0 for any free one (overrides the config)\n"
            "  --state-file PATH  where the world state persists (overrides the config)\n"
            "  --web-root DIR     static files to serve (overrides the config)\n"
            "  --config-dir DIR   presets folder ($SKYD_CONFIG_DIR, else the source config/)\n"
            "  --device NAME      Vulkan device ($SKYD_DEVICE; else the config's render.device)\n"
            "  --validation       Khronos validation layer on\n");
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
        } else {
            fprintf(stderr, "skyd serve: unknown option \"%s\"\n", arg);
            usage(stderr);
            return -1;
        }
        if (!(*target = cli_take_value(argc, argv, &i)))
            return -1;
    }
    return 0;
}

/* Config, then command line. Returns false after printing why. */
static bool load_config(const struct serve_options *o, struct skyd_config *config)
{
    skyd_config_defaults(config);
    if (o->config_path) {
        struct sky_field_errors errors;
        char msg[512];
        if (!skyd_config_load(o->config_path, config, &errors, msg, sizeof msg)) {
            char detail[2048];
            sky_field_errors_format(&errors, detail, sizeof detail);
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

static void initial_state(const char *state_file, const struct sky_world_state *configured,
                          struct sky_world_state *state)
{
    *state = *configured; /* the config's initial_state, unless a saved state is restored */
    if (!state_file[0])
        return;
    char msg[1024];
    switch (state_store_load(state_file, state, msg, sizeof msg)) {
    case STATE_LOAD_RESTORED:
        fprintf(stderr, "skyd: restored the world state (revision %llu) from %s\n",
                (unsigned long long)state->revision, state_file);
        break;
    case STATE_LOAD_ABSENT:
        fprintf(stderr, "skyd: %s\n", msg);
        break;
    case STATE_LOAD_CORRUPT:
    case STATE_LOAD_FAILED:
        fprintf(stderr, "skyd: error: %s\n", msg);
        break;
    }
}

/* Signals are blocked in every thread; this one waits for them. */
struct signal_watch {
    pthread_t thread;
    sigset_t set;
    volatile sig_atomic_t stop;
    volatile sig_atomic_t done;
    struct ws_server *server;
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
    if (sigwait(&w->set, &signal_number) != 0)
        return NULL;
    if (w->done)
        return NULL;
    fprintf(stderr, "skyd: %s: shutting down\n", strsignal(signal_number));
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

int skyd_cmd_serve(int argc, char **argv)
{
    return_large_blocks_when_freed();
    struct serve_options options = { 0 };
    int rc = parse_options(argc, argv, &options);
    if (rc != 0)
        return rc > 0 ? SKYD_EXIT_OK : SKYD_EXIT_USAGE;
    struct skyd_config config;
    if (!load_config(&options, &config))
        return SKYD_EXIT_USAGE;
    char token_note[1536];
    enum control_token_source token = control_token_settle(&config, token_note,
                                                           sizeof token_note);
    if (token_note[0])
        fprintf(stderr, "skyd: %s\n", token_note);
    if (token == CONTROL_TOKEN_FAILED)
        return SKYD_EXIT_FAILURE;

    char web_root[PATH_MAX];
    if (!realpath(config.web_root, web_root)) {
        fprintf(stderr, "skyd: web root %s: %s (HTTP requests will get 404)\n", config.web_root,
                strerror(errno));
        snprintf(web_root, sizeof web_root, "%s", config.web_root);
    }
    struct cli_common common;
    cli_common_init(&common);
    const char *config_dir = options.config_dir ? options.config_dir : common.config_dir;
    const char *device = options.device ? options.device : getenv("SKYD_DEVICE");
    if (!device && config.render_device[0])
        device = config.render_device;
    const char *validation_env = getenv("SKYD_VALIDATION");
    bool validation = options.validation || config.render_validation ||
                      (validation_env && strcmp(validation_env, "1") == 0);

    struct signal_watch watch = { 0 };
    sigemptyset(&watch.set);
    sigaddset(&watch.set, SIGTERM);
    sigaddset(&watch.set, SIGINT);
    pthread_sigmask(SIG_BLOCK, &watch.set, NULL);
    signal(SIGPIPE, SIG_IGN);

    struct render_loop_params loop_params = { .config = &config,
                                              .device = device,
                                              .validation = validation,
                                              .config_dir = config_dir,
                                              .state_file = config.state_file };
    initial_state(config.state_file, &config.initial_state, &loop_params.initial_state);
    struct session_hub *hub = session_hub_create(NULL, NULL);
    struct service_metrics *metrics = service_metrics_create();
    loop_params.metrics = metrics;
    struct failure_watch failure_watch = { .signals = &watch, .hub = hub };
    loop_params.hub = hub;
    loop_params.on_failure = on_render_failure;
    loop_params.failure_user = &failure_watch;
    char err[512];
    struct render_loop *loop =
        hub && metrics ? render_loop_create(&loop_params, err, sizeof err) : NULL;
    if (!loop) {
        fprintf(stderr, "skyd serve: %s\n", hub && metrics ? err : "out of memory");
        session_hub_destroy(&hub);
        service_metrics_destroy(&metrics);
        return SKYD_EXIT_FAILURE;
    }
    struct ws_server_params server_params = {
        .config = &config, .web_root = web_root, .hub = hub, .loop = loop, .metrics = metrics
    };
    struct ws_server *server = ws_server_create(&server_params, err, sizeof err);
    if (!server) {
        fprintf(stderr, "skyd serve: %s\n", err);
        render_loop_destroy(&loop);
        session_hub_destroy(&hub);
        service_metrics_destroy(&metrics);
        return SKYD_EXIT_FAILURE;
    }
    session_hub_set_wake(hub, ws_server_wake, server);
    watch.server = server;
    if (pthread_create(&watch.thread, NULL, signal_thread, &watch) != 0) {
        fprintf(stderr, "skyd serve: cannot start the signal thread\n");
        session_hub_set_wake(hub, NULL, NULL);
        render_loop_destroy(&loop);
        ws_server_destroy(&server);
        session_hub_destroy(&hub);
        service_metrics_destroy(&metrics);
        return SKYD_EXIT_FAILURE;
    }
    printf("skyd: listening on %s\n", ws_server_url(server));
    if (control_token_shown(token))
        printf("skyd: control at %s#token=%s\n", ws_server_url(server), config.controller_token);
    fflush(stdout);

    ws_server_run(server, &watch.stop);
    char failure[512] = "";
    const char *why = render_loop_failure(loop);
    if (why)
        snprintf(failure, sizeof failure, "%s", why);
    if (failure[0]) /* the replies saying why go out first */
        ws_server_close_all(server, SESSION_CLOSE_INTERNAL_ERROR, "rendering device lost", true,
                            2.0);
    else
        ws_server_close_all(server, SESSION_CLOSE_GOING_AWAY, "skyd shutting down", false, 2.0);
    ws_server_detach_loop(server);
    render_loop_destroy(&loop); /* saves the state */
    session_hub_set_wake(hub, NULL, NULL);
    watch.done = 1;
    pthread_kill(watch.thread, SIGTERM); /* in case no signal came (the service loop failed) */
    pthread_join(watch.thread, NULL);
    ws_server_destroy(&server);
    session_hub_destroy(&hub);
    service_metrics_destroy(&metrics);
    if (failure[0]) {
        fprintf(stderr, "skyd: stopped with the state saved: %s\n", failure);
        return SKYD_EXIT_FAILURE;
    }
    fprintf(stderr, "skyd: stopped\n");
    return SKYD_EXIT_OK;
}
