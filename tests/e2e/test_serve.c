/* End-to-end tests of `skyd serve` with the C client (clients/common): the daemon runs as a
 * child process on a free port with a config written here. The first run starts on a corrupt
 * state file and covers hello, roles, set/get_state/events, bad input, frames, views, a stalled
 * client, origins and shutdown; the second restarts on the saved state with tight client and
 * rate limits.
 *
 * Usage: test_serve SKYD SCRATCH_DIR
 */
#include <cjson/cJSON.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "serve_support.h"
#include "sky_spawn.h"
#include "world_state.h"

#define TOKEN "serve-c-token"
#define ALLOWED_ORIGIN "http://example.test"
#define MAX_MESSAGE_BYTES 4096
#define INDEX_HTML "<html><body>serve_c</body></html>\n"

struct limits {
    int max_clients;
    double rate; /* control_messages_per_second */
};

/* What the first run leaves in the state file, for the restart. */
struct saved {
    double elevation_deg, azimuth_deg, revision;
};

static char scratch[1024], state_file[1200];

static struct skyd_process *start_daemon(const char *skyd, const char *name, struct limits limits)
{
    char config[1200], log[1200], err[512];
    snprintf(config, sizeof config, "%s/%s.json", scratch, name);
    snprintf(log, sizeof log, "%s/%s.log", scratch, name);
    cJSON *root = cJSON_CreateObject();
    cJSON *listen = cJSON_AddObjectToObject(root, "listen");
    cJSON_AddStringToObject(listen, "address", "127.0.0.1");
    cJSON_AddNumberToObject(listen, "port", 0);
    cJSON_AddStringToObject(root, "web_root", scratch);
    cJSON_AddStringToObject(root, "state_file", state_file);
    cJSON *l = cJSON_AddObjectToObject(root, "limits");
    cJSON_AddNumberToObject(l, "max_message_bytes", MAX_MESSAGE_BYTES);
    cJSON_AddNumberToObject(l, "max_clients", limits.max_clients);
    cJSON_AddNumberToObject(l, "max_width", 1024);
    cJSON_AddNumberToObject(l, "max_height", 768);
    cJSON_AddNumberToObject(l, "max_fps", 60);
    cJSON_AddNumberToObject(l, "control_messages_per_second", limits.rate);
    cJSON_AddStringToObject(root, "controller_token", TOKEN);
    cJSON *origins = cJSON_AddArrayToObject(root, "allowed_origins");
    cJSON_AddItemToArray(origins, cJSON_CreateString(ALLOWED_ORIGIN));
    char *text = cJSON_Print(root);
    cJSON_Delete(root);
    bool written = text && write_file(config, text);
    free(text);
    if (!written)
        return NULL;
    double t0 = now_s();
    struct skyd_process *p = skyd_process_start(skyd, config, NULL, log, 60000, err, sizeof err);
    if (!p)
        printf("starting skyd (%s): %s; its stderr is in %s\n", name, err, log);
    else
        printf("%s: skyd listening on port %d after %.1f s (log %s)\n", name, skyd_process_port(p),
               now_s() - t0, log);
    return p;
}

static bool is_error(const cJSON *reply, const char *code)
{
    bool ok = reply && strcmp(jstr(reply, "/type"), "error") == 0 &&
              strcmp(jstr(reply, "/code"), code) == 0;
    if (!ok) {
        char *text = reply ? cJSON_PrintUnformatted(reply) : NULL;
        printf("expected error %s, got %s\n", code, text ? text : "nothing");
        free(text);
    }
    return ok;
}

static void test_hello(const char *url, struct limits limits)
{
    cJSON *hello = NULL;
    struct sky_client *c = serve_connect(url, NULL, &hello);
    CHECK(c != NULL);
    CHECK(jnum(hello, "/protocol") == 1);
    CHECK(strcmp(jstr(hello, "/role"), "viewer") == 0);
    CHECK(jnum(hello, "/limits/max_message_bytes") == MAX_MESSAGE_BYTES);
    CHECK(jnum(hello, "/limits/max_clients") == limits.max_clients);
    CHECK(jnum(hello, "/limits/max_width") == 1024);
    CHECK(jnum(hello, "/limits/max_height") == 768);
    CHECK(jnum(hello, "/limits/max_fps") == 60);
    CHECK(jnum(hello, "/limits/control_messages_per_second") == limits.rate);
    CHECK(jarray_has_string(jget(hello, "/capabilities"), "subscribe"));
    CHECK(jarray_has_string(jget(hello, "/capabilities"), "png"));
    cJSON_Delete(hello);
    sky_client_close(&c);
}

/* The first run starts on a corrupt state file: moved aside, defaults in force. */
static void test_corrupt_state_moved(const char *url)
{
    CHECK(count_files_with_prefix(scratch, "state.json.corrupt-") == 1);
    struct proto_world_state defaults;
    proto_world_state_defaults(&defaults);
    struct sky_client *c = serve_connect(url, NULL, NULL);
    cJSON *state = c ? serve_request(c, "{\"type\":\"get_state\"}") : NULL;
    CHECK(strcmp(jstr(state, "/type"), "state") == 0);
    CHECK_NEAR(jnum(state, "/state/sun/elevation_deg"), defaults.sun.elevation_deg, 1e-9);
    CHECK_NEAR(jnum(state, "/state/atmosphere/bottom_radius_km"),
               defaults.atmosphere.bottom_radius_km, 1e-9);
    cJSON_Delete(state);
    sky_client_close(&c);
}

/* Roles, set -> ack -> get_state, the event to another client; returns the controller. */
static struct sky_client *test_set_round_trip(const char *url, struct saved *saved)
{
    struct sky_client *viewer = serve_connect(url, NULL, NULL);
    struct sky_client *ctl = serve_connect(url, NULL, NULL);
    CHECK(viewer && ctl);
    if (!viewer || !ctl) {
        sky_client_close(&viewer);
        sky_client_close(&ctl);
        return NULL;
    }
    cJSON *r = serve_request(ctl, "{\"type\":\"auth\",\"token\":\"wrong\"}");
    CHECK(is_error(r, "auth_failed"));
    cJSON_Delete(r);
    r = serve_request(ctl, "{\"type\":\"auth\",\"token\":\"" TOKEN "\"}");
    CHECK(strcmp(jstr(r, "/type"), "ack") == 0 && strcmp(jstr(r, "/role"), "controller") == 0);
    cJSON_Delete(r);

    r = serve_request(viewer, "{\"type\":\"get_state\"}");
    double rev0 = jnum(r, "/revision"), elev0 = jnum(r, "/state/sun/elevation_deg");
    CHECK(rev0 >= 0 && elev0 == elev0);
    cJSON_Delete(r);

    r = serve_request(viewer, "{\"type\":\"set\",\"patch\":{\"sun\":{\"elevation_deg\":12.5}}}");
    CHECK(is_error(r, "forbidden"));
    cJSON_Delete(r);
    r = serve_request(viewer, "{\"type\":\"get_state\"}");
    CHECK(jnum(r, "/revision") == rev0);
    CHECK(jnum(r, "/state/sun/elevation_deg") == elev0);
    cJSON_Delete(r);

    r = serve_request(ctl, "{\"type\":\"set\",\"patch\":{\"sun\":{\"elevation_deg\":12.5}}}");
    CHECK(strcmp(jstr(r, "/type"), "ack") == 0);
    CHECK(jnum(r, "/revision") == rev0 + 1);
    cJSON_Delete(r);
    r = serve_request(ctl, "{\"type\":\"get_state\"}");
    CHECK(jnum(r, "/revision") == rev0 + 1);
    CHECK(jnum(r, "/state/sun/elevation_deg") == 12.5);
    saved->elevation_deg = 12.5;
    saved->azimuth_deg = jnum(r, "/state/sun/azimuth_deg");
    saved->revision = jnum(r, "/revision");
    cJSON_Delete(r);

    r = serve_expect(viewer, "event", SERVE_REPLY_MS);
    CHECK(strcmp(jstr(r, "/event"), "state_changed") == 0);
    CHECK(jnum(r, "/revision") == rev0 + 1);
    CHECK(jarray_has_string(jget(r, "/changed"), "/sun/elevation_deg"));
    CHECK(!jarray_has_string(jget(r, "/changed"), "/sun/azimuth_deg"));
    cJSON_Delete(r);
    sky_client_close(&viewer);
    return ctl;
}

/* Each bad message gets its error and leaves the connection and the state as they were. */
static void test_bad_input(const char *url)
{
    struct sky_client *c = serve_connect(url, NULL, NULL);
    CHECK(c != NULL);
    if (!c)
        return;
    cJSON *r = serve_request(c, "{\"type\":\"get_state\"}");
    double rev = jnum(r, "/revision");
    cJSON_Delete(r);

    r = serve_send_expect(c, "{\"type\":\"get_state\",", "error");
    CHECK(is_error(r, "malformed_json"));
    cJSON_Delete(r);
    r = serve_request(c, "{\"type\":\"no_such_type\"}");
    CHECK(is_error(r, "unknown_type"));
    cJSON_Delete(r);
    CHECK(sky_client_send_binary(c, "\x01\x02\x03", 3, SERVE_REPLY_MS) == 0);
    r = serve_expect(c, "error", SERVE_REPLY_MS);
    CHECK(is_error(r, "invalid_encoding"));
    cJSON_Delete(r);
    char big[MAX_MESSAGE_BYTES + 200];
    int n = snprintf(big, sizeof big, "{\"type\":\"get_state\",\"pad\":\"");
    memset(big + n, 'x', sizeof big - (size_t)n - 3);
    memcpy(big + sizeof big - 3, "\"}", 3);
    r = serve_send_expect(c, big, "error");
    CHECK(is_error(r, "message_too_large"));
    cJSON_Delete(r);

    r = serve_request(c, "{\"type\":\"get_state\"}");
    CHECK(strcmp(jstr(r, "/type"), "state") == 0 && jnum(r, "/revision") == rev);
    cJSON_Delete(r);
    sky_client_close(&c);
}

/* Reads one frame and checks its header and PNG against the expected size. */
static bool read_frame(struct sky_client *c, int timeout_ms, uint32_t width, uint32_t height,
                       struct sky_client_frame *f)
{
    char err[320];
    int rc = sky_client_recv_frame(c, timeout_ms, f, err, sizeof err);
    CHECK(rc == 0);
    if (rc) {
        printf("frame %ux%u: %s\n", width, height, err);
        return false;
    }
    uint32_t w = 0, h = 0;
    bool constant = true;
    CHECK(f->header.format == PROTO_FRAME_FORMAT_PNG);
    CHECK(f->header.width == width && f->header.height == height);
    CHECK(png_inspect(f->payload, f->header.payload_length, &w, &h, &constant));
    CHECK(w == width && h == height);
    CHECK(!constant);
    return true;
}

/* Frames follow a subscription; after a set they carry the new revision. */
static void test_frames(const char *url, struct sky_client *ctl, struct saved *saved)
{
    struct sky_client *v = serve_connect(url, NULL, NULL);
    long sub = v ? serve_subscribe(v, "{\"width\":320,\"height\":180,\"fps\":10}") : -1;
    CHECK(sub >= 1);
    struct sky_client_frame f;
    if (sub < 1 || !read_frame(v, SERVE_FIRST_FRAME_MS, 320, 180, &f)) {
        sky_client_close(&v);
        return;
    }
    CHECK(jnum(f.announce, "/subscription") == sub);
    uint64_t number = f.header.frame_number, rev = f.header.state_revision;
    sky_client_frame_free(&f);

    cJSON *ack = ctl ? serve_request(ctl, "{\"type\":\"set\",\"patch\":{\"sun\":{\"azimuth_deg\":"
                                          "200}}}")
                     : NULL;
    double new_rev = jnum(ack, "/revision");
    CHECK(strcmp(jstr(ack, "/type"), "ack") == 0 && new_rev > (double)rev);
    cJSON_Delete(ack);
    saved->azimuth_deg = 200;
    saved->revision = new_rev;

    bool reached = false, consecutive = true, monotonic = true;
    for (int i = 0; i < 60 && !reached; i++) {
        if (!read_frame(v, SERVE_REPLY_MS, 320, 180, &f))
            break;
        consecutive &= f.header.frame_number == number + 1;
        monotonic &= f.header.state_revision >= rev;
        number = f.header.frame_number;
        rev = f.header.state_revision;
        reached = (double)rev == new_rev;
        sky_client_frame_free(&f);
    }
    CHECK(reached);
    CHECK(consecutive);
    CHECK(monotonic);
    if (reached && read_frame(v, SERVE_REPLY_MS, 320, 180, &f)) {
        CHECK((double)f.header.state_revision == new_rev);
        sky_client_frame_free(&f);
    }
    sky_client_close(&v);
}

/* Two clients, two views, each its own size; a snapshot; subscription limits. */
static void test_views(const char *url)
{
    struct sky_client *a = serve_connect(url, NULL, NULL);
    struct sky_client *b = serve_connect(url, NULL, NULL);
    CHECK(a && b);
    if (a && b) {
        long sa = serve_subscribe(a, "{\"width\":160,\"height\":90,\"fps\":10}");
        long sb = serve_subscribe(b, "{\"width\":200,\"height\":120,\"fps\":10,"
                                     "\"camera\":{\"yaw_deg\":90}}");
        CHECK(sa >= 1 && sb >= 1);
        struct sky_client_frame f;
        for (int i = 0; i < 2; i++) {
            if (read_frame(a, SERVE_FIRST_FRAME_MS, 160, 90, &f))
                sky_client_frame_free(&f);
            if (read_frame(b, SERVE_FIRST_FRAME_MS, 200, 120, &f))
                sky_client_frame_free(&f);
        }
        char text[96];
        snprintf(text, sizeof text, "{\"type\":\"unsubscribe\",\"subscription\":%ld}", sb);
        cJSON *r = serve_request(b, text);
        CHECK(strcmp(jstr(r, "/type"), "ack") == 0);
        cJSON_Delete(r);
        r = serve_request(b, "{\"type\":\"unsubscribe\",\"subscription\":999}");
        CHECK(is_error(r, "not_found"));
        cJSON_Delete(r);

        const char *snap = "{\"type\":\"snapshot\",\"id\":\"snap-1\",\"view\":"
                           "{\"width\":64,\"height\":48}}";
        CHECK(sky_client_send_text(b, snap, strlen(snap), SERVE_REPLY_MS) == 0);
        bool got = false;
        for (int i = 0; i < 20 && !got; i++) {
            if (!read_frame(b, SERVE_REPLY_MS, 64, 48, &f))
                break;
            got = strcmp(jstr(f.announce, "/id"), "snap-1") == 0;
            CHECK(got && !jget(f.announce, "/subscription"));
            sky_client_frame_free(&f);
        }
        CHECK(got);
    }
    sky_client_close(&a);
    if (b) {
        int ok = 0;
        for (int i = 0; i < 4; i++)
            ok += serve_subscribe(b, "{\"width\":8,\"height\":8,\"fps\":1}") >= 1;
        CHECK(ok == 4);
        cJSON *r = serve_request(b, "{\"type\":\"subscribe\",\"view\":{\"width\":8,\"height\":8}}");
        CHECK(is_error(r, "limit_reached"));
        cJSON_Delete(r);
    }
    sky_client_close(&b);
}

/* Frames received in `seconds`, dropping everything else. */
static double measure_fps(struct sky_client *c, double seconds)
{
    double t0 = now_s(), end = t0 + seconds;
    int frames = 0;
    while (now_s() < end) {
        struct sky_client_frame f;
        char err[320];
        int rc = sky_client_recv_frame(c, (int)((end - now_s()) * 1000) + 1, &f, err, sizeof err);
        if (rc == 0) {
            frames++;
            sky_client_frame_free(&f);
        } else if (rc != 1) {
            printf("measuring fps: %s\n", err);
            break;
        }
    }
    return frames / (now_s() - t0);
}

/* Reads the stalled client's backlog until two consecutive frames are more than a second of
 * simulation time apart (the server skipped frames while the socket was full): true when
 * found. */
static bool backlog_has_gap(struct sky_client *c)
{
    double prev = -1;
    long bytes = 0;
    for (int i = 0; i < 1000; i++) {
        struct sky_client_frame f;
        char err[320];
        if (sky_client_recv_frame(c, SERVE_REPLY_MS, &f, err, sizeof err) != 0) {
            printf("stalled client after it reads again: %s\n", err);
            return false;
        }
        double t = f.header.simulation_time_s;
        bytes += (long)f.binary.len;
        sky_client_frame_free(&f);
        if (prev >= 0 && t - prev > 1.0) {
            printf("stalled client: a backlog of %d frames (%ld KiB), then %.1f s skipped\n", i,
                   bytes / 1024, t - prev);
            return true;
        }
        prev = t;
    }
    printf("stalled client: 1000 frames without a gap: frames queued while it stalled\n");
    return false;
}

/* A client that subscribes at a high rate and never reads must not slow a reading client. Its
 * four subscriptions share the reader's rendering, so it adds no render work, only bytes: the
 * server's socket to it fills in a second or two. */
static void test_stalled_client(const char *url)
{
    const char *view = "{\"width\":320,\"height\":180,\"fps\":10}";
    struct sky_client *reader = serve_connect(url, NULL, NULL);
    long sub = reader ? serve_subscribe(reader, view) : -1;
    CHECK(sub >= 1);
    if (sub < 1) {
        sky_client_close(&reader);
        return;
    }
    measure_fps(reader, 1.0); /* settle */
    double alone = measure_fps(reader, 4.0);

    struct sky_client *stalled = serve_connect(url, NULL, NULL);
    int subscribed = 0;
    for (int i = 0; stalled && i < 4; i++)
        subscribed += serve_subscribe(stalled, "{\"width\":320,\"height\":180,\"fps\":60}") >= 1;
    CHECK(subscribed == 4);
    measure_fps(reader, 3.0); /* while the server's socket to the stalled client fills */
    double with_stalled = measure_fps(reader, 4.0);
    printf("stalled client: reader %.1f fps alone, %.1f fps beside a stalled client (%.2fx)\n",
           alone, with_stalled, alone > 0 ? with_stalled / alone : 0.0);
    CHECK(alone >= 5.0);
    CHECK(with_stalled >= 0.7 * alone);

    /* Reading again, it gets its backlog, then newer frames: it lost frames, it was not
     * dropped, and nothing queued without bound. */
    CHECK(stalled && backlog_has_gap(stalled));
    sky_client_close(&stalled);
    sky_client_close(&reader);
}

/* Origins: foreign ones are refused with HTTP 403, allowed and the server's own get in. */
static void test_origins(const char *url, int port)
{
    char err[320], own[64];
    struct sky_client *c = sky_client_connect(url, "http://evil.test", 10000, err, sizeof err);
    CHECK(c == NULL);
    if (c)
        printf("foreign origin: accepted\n");
    sky_client_close(&c);
    CHECK(http_status(port, "/", WS_UPGRADE_HEADERS "Origin: http://evil.test\r\n", NULL, 0) ==
          403);
    CHECK(http_status(port, "/", WS_UPGRADE_HEADERS "Origin: " ALLOWED_ORIGIN "\r\n", NULL, 0) ==
          101);
    char body[256];
    CHECK(http_status(port, "/", "", body, sizeof body) == 200);
    CHECK(strcmp(body, INDEX_HTML) == 0);
    c = serve_connect(url, ALLOWED_ORIGIN, NULL);
    CHECK(c != NULL);
    sky_client_close(&c);
    snprintf(own, sizeof own, "http://127.0.0.1:%d", port);
    c = serve_connect(url, own, NULL);
    CHECK(c != NULL);
    sky_client_close(&c);
}

/* SIGTERM: every client gets close 1001, the daemon exits 0. */
static void test_shutdown(struct skyd_process **daemon, struct sky_client **clients, int count)
{
    CHECK(skyd_process_signal(*daemon, SIGTERM) == 0);
    for (int i = 0; i < count; i++) {
        struct sky_client_message m;
        int rc;
        while ((rc = sky_client_recv(clients[i], &m, SERVE_REPLY_MS)) == 0)
            sky_client_message_free(&m);
        CHECK(rc == -1);
        CHECK(sky_client_close_code(clients[i]) == 1001);
        CHECK(strcmp(sky_client_close_reason(clients[i]), "skyd shutting down") == 0);
        if (sky_client_close_code(clients[i]) != 1001)
            printf("shutdown: client %d: %s\n", i, sky_client_error(clients[i]));
        sky_client_close(&clients[i]);
    }
    int status = skyd_process_wait(*daemon, 30000);
    CHECK(status == 0);
    if (status != 0)
        printf("skyd exit status after SIGTERM: %d (-1: still running)\n", status);
    skyd_process_free(daemon);
}

static void test_restored(const char *url, const struct saved *saved)
{
    struct sky_client *c = serve_connect(url, NULL, NULL);
    cJSON *r = c ? serve_request(c, "{\"type\":\"get_state\"}") : NULL;
    CHECK(jnum(r, "/state/sun/elevation_deg") == saved->elevation_deg);
    CHECK(jnum(r, "/state/sun/azimuth_deg") == saved->azimuth_deg);
    CHECK(jnum(r, "/revision") == saved->revision);
    cJSON_Delete(r);
    sky_client_close(&c);
}

/* max_clients 2: the third connection gets limit_reached and close 1008; a freed place is
 * taken again. */
static void test_max_clients(const char *url)
{
    struct sky_client *a = serve_connect(url, NULL, NULL);
    struct sky_client *b = serve_connect(url, NULL, NULL);
    CHECK(a && b);
    char err[320];
    struct sky_client *c = sky_client_connect(url, NULL, 10000, err, sizeof err);
    CHECK(c != NULL);
    if (c) {
        cJSON *r = serve_expect(c, NULL, SERVE_REPLY_MS);
        CHECK(is_error(r, "limit_reached"));
        cJSON_Delete(r);
        struct sky_client_message m;
        int rc;
        while ((rc = sky_client_recv(c, &m, SERVE_REPLY_MS)) == 0)
            sky_client_message_free(&m);
        CHECK(rc == -1 && sky_client_close_code(c) == 1008);
        CHECK(strcmp(sky_client_close_reason(c), "too many clients") == 0);
    } else {
        printf("third client: %s\n", err);
    }
    sky_client_close(&c);
    sky_client_close(&b);
    struct sky_client *d = NULL;
    for (double end = now_s() + 5; !d && now_s() < end; sleep_s(0.2)) {
        d = sky_client_connect(url, NULL, 10000, err, sizeof err);
        cJSON *r = d ? serve_expect(d, NULL, SERVE_REPLY_MS) : NULL;
        if (strcmp(jstr(r, "/type"), "hello") != 0)
            sky_client_close(&d);
        cJSON_Delete(r);
    }
    CHECK(d != NULL);
    sky_client_close(&d);
    sky_client_close(&a);
}

/* control_messages_per_second 5: a burst of 15 is answered in order, partly rate_limited. */
static void test_rate_limit(const char *url)
{
    struct sky_client *c = serve_connect(url, NULL, NULL);
    CHECK(c != NULL);
    if (!c)
        return;
    double t0 = now_s();
    for (int i = 1; i <= 15; i++) {
        char text[64];
        int n = snprintf(text, sizeof text, "{\"type\":\"get_state\",\"id\":%d}", i);
        CHECK(sky_client_send_text(c, text, (size_t)n, SERVE_REPLY_MS) == 0);
    }
    int states = 0, limited = 0, in_order = 1;
    for (int i = 1; i <= 15; i++) {
        cJSON *r = serve_expect(c, NULL, SERVE_REPLY_MS);
        if (!r)
            break;
        /* A dropped message is not parsed, so its rate_limited error may lack the id. */
        in_order &= jnum(r, "/id") == i || !jget(r, "/id");
        states += strcmp(jstr(r, "/type"), "state") == 0;
        limited += strcmp(jstr(r, "/code"), "rate_limited") == 0;
        cJSON_Delete(r);
    }
    double elapsed = now_s() - t0;
    printf("rate limit: %d answered, %d rate_limited in %.2f s\n", states, limited, elapsed);
    CHECK(in_order);
    CHECK(states + limited == 15);
    CHECK(limited >= 1);
    CHECK(states >= 5);
    CHECK_LE(states, 5 + 5 * elapsed + 1);
    sky_client_close(&c);
}

int main(int argc, char **argv)
{
    if (argc != 3) {
        fprintf(stderr, "usage: test_serve SKYD SCRATCH_DIR\n");
        return 2;
    }
    signal(SIGPIPE, SIG_IGN);
    setvbuf(stdout, NULL, _IOLBF, 0);
    snprintf(scratch, sizeof scratch, "%s", argv[2]);
    snprintf(state_file, sizeof state_file, "%s/state.json", scratch);
    char index_html[1200];
    snprintf(index_html, sizeof index_html, "%s/index.html", scratch);
    if (!scratch_reset(scratch) || !write_file(state_file, "{\"revision\": 3, \"sun\": [") ||
        !write_file(index_html, INDEX_HTML))
        return 1;
    double t0 = now_s();

    struct limits first = { 16, 1000 };
    struct skyd_process *daemon = start_daemon(argv[1], "first", first);
    CHECK(daemon != NULL);
    struct saved saved = { 0 };
    if (daemon) {
        const char *url = skyd_process_url(daemon);
        test_hello(url, first);
        test_corrupt_state_moved(url);
        struct sky_client *ctl = test_set_round_trip(url, &saved);
        test_bad_input(url);
        test_frames(url, ctl, &saved);
        test_views(url);
        test_stalled_client(url);
        test_origins(url, skyd_process_port(daemon));
        struct sky_client *clients[3] = { ctl, serve_connect(url, NULL, NULL),
                                          serve_connect(url, NULL, NULL) };
        if (clients[2])
            serve_subscribe(clients[2], "{\"width\":32,\"height\":18,\"fps\":5}");
        CHECK(ctl && clients[1] && clients[2]);
        if (ctl && clients[1] && clients[2])
            test_shutdown(&daemon, clients, 3);
        for (int i = 0; i < 3; i++)
            sky_client_close(&clients[i]);
        skyd_process_free(&daemon);
        printf("first run: %.1f s\n", now_s() - t0);
    }

    struct limits second = { 2, 5 };
    daemon = start_daemon(argv[1], "second", second);
    CHECK(daemon != NULL);
    if (daemon) {
        const char *url = skyd_process_url(daemon);
        test_hello(url, second);
        test_restored(url, &saved);
        test_max_clients(url);
        test_rate_limit(url);
        test_shutdown(&daemon, NULL, 0);
    }
    printf("total: %.1f s\n", now_s() - t0);
    return check_summary();
}
