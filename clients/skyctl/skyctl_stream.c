/* skyctl snapshot and watch: the commands that receive binary frames. */
#include "skyctl.h"

#include <cjson/cJSON.h>
#include <errno.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/stat.h>
#include <unistd.h>

#include "frame_header.h"
#include "sky_client.h"
#include "sky_client_json.h"

static volatile sig_atomic_t interrupted;

static void on_signal(int signo)
{
    (void)signo;
    interrupted = 1;
}

/* Options shared by snapshot and watch: the view object, --out (snapshot: the file, watch:
 * the directory), and watch's --count and --no-frames. */
struct view_args {
    cJSON *view;
    const char *out;
    double count;
    bool frames;
    bool json; /* --json */
};

static int parse_view_args(const char *command, int argc, char **argv, struct view_args *a,
                           double default_width, double default_height)
{
    double width = default_width, height = default_height, fps = 0;
    a->view = cJSON_CreateObject();
    for (int i = 1; i < argc; i++) {
        const char *arg = argv[i];
        bool has_value = i + 1 < argc;
        char err[320];
        if (strcmp(arg, "--out") == 0 && has_value) {
            a->out = argv[++i];
        } else if (strcmp(arg, "--width") == 0 && has_value) {
            if (!skyctl_parse_number(argv[++i], 1, 1e6, &width))
                return skyctl_usage_error(command, "--width needs a positive number");
        } else if (strcmp(arg, "--height") == 0 && has_value) {
            if (!skyctl_parse_number(argv[++i], 1, 1e6, &height))
                return skyctl_usage_error(command, "--height needs a positive number");
        } else if (strcmp(arg, "--fps") == 0 && has_value) {
            if (!skyctl_parse_number(argv[++i], 1e-3, 1e6, &fps))
                return skyctl_usage_error(command, "--fps needs a positive number");
        } else if (strcmp(arg, "--count") == 0 && has_value) {
            if (!skyctl_parse_number(argv[++i], 1, 1e15, &a->count))
                return skyctl_usage_error(command, "--count needs a positive integer");
        } else if (strcmp(arg, "--no-frames") == 0) {
            a->frames = false;
        } else if (strcmp(arg, "--set") == 0 && has_value) {
            if (!skyctl_assign(a->view, argv[++i], err, sizeof err))
                return skyctl_usage_error(command, "--set %s", err);
        } else {
            return skyctl_usage_error(command, "unknown argument or missing value: %s", arg);
        }
    }
    cJSON_AddNumberToObject(a->view, "width", width);
    cJSON_AddNumberToObject(a->view, "height", height);
    if (fps > 0)
        cJSON_AddNumberToObject(a->view, "fps", fps);
    return SKYCTL_OK;
}

static bool write_file(const char *what, const char *path, const unsigned char *data, size_t len)
{
    FILE *f = fopen(path, "wb");
    if (!f) {
        fprintf(stderr, "skyctl %s: cannot write %s: %s\n", what, path, strerror(errno));
        return false;
    }
    bool ok = fwrite(data, 1, len, f) == len;
    ok = (fclose(f) == 0) && ok;
    if (!ok)
        fprintf(stderr, "skyctl %s: cannot write %s: %s\n", what, path, strerror(errno));
    return ok;
}

/* mkdir -p dir, and a check that files can be made in it. */
static int make_directory(const char *dir)
{
    char path[4096];
    if (!dir[0])
        return skyctl_usage_error("watch", "--out needs a directory");
    if (snprintf(path, sizeof path, "%s", dir) >= (int)sizeof path)
        return skyctl_usage_error("watch", "--out %s: path too long", dir);
    for (char *p = path + 1;; p++) {
        bool end = *p == '\0';
        if (*p != '/' && !end)
            continue;
        *p = '\0';
        if (mkdir(path, 0777) != 0 && errno != EEXIST) {
            fprintf(stderr, "skyctl watch: --out %s: cannot create %s: %s\n", dir, path,
                    strerror(errno));
            return SKYCTL_USAGE;
        }
        if (end)
            break;
        *p = '/';
    }
    struct stat st;
    const char *why = NULL;
    if (stat(dir, &st) != 0)
        why = strerror(errno);
    else if (!S_ISDIR(st.st_mode))
        why = "not a directory";
    else if (access(dir, W_OK | X_OK) != 0)
        why = strerror(errno);
    if (why) {
        fprintf(stderr, "skyctl watch: --out %s: %s\n", dir, why);
        return SKYCTL_USAGE;
    }
    return SKYCTL_OK;
}

static const char *format_name(enum proto_frame_format format)
{
    switch (format) {
    case PROTO_FRAME_FORMAT_PNG:
        return "png";
    case PROTO_FRAME_FORMAT_PNG16:
        return "png16";
    case PROTO_FRAME_FORMAT_JPEG:
        return "jpeg";
    }
    return "unknown";
}

/* --json line of a frame: its header, and the path it was saved to. */
static void print_frame_json(const struct proto_frame_header *h, const char *path)
{
    cJSON *out = cJSON_CreateObject();
    cJSON_AddStringToObject(out, "type", "frame");
    cJSON_AddNumberToObject(out, "frame_number", (double)h->frame_number);
    cJSON_AddNumberToObject(out, "revision", (double)h->state_revision);
    cJSON_AddNumberToObject(out, "simulation_time_s", h->simulation_time_s);
    cJSON_AddNumberToObject(out, "width", h->width);
    cJSON_AddNumberToObject(out, "height", h->height);
    cJSON_AddStringToObject(out, "format", format_name(h->format));
    cJSON_AddNumberToObject(out, "bytes", h->payload_length);
    if (path)
        cJSON_AddStringToObject(out, "path", path);
    skyctl_print_json_line(out);
    cJSON_Delete(out);
}

/* A frame file's extension; png16 frames are PNG files too, with 16 bits a channel. */
static const char *format_extension(enum proto_frame_format format)
{
    switch (format) {
    case PROTO_FRAME_FORMAT_PNG:
    case PROTO_FRAME_FORMAT_PNG16:
        return "png";
    case PROTO_FRAME_FORMAT_JPEG:
        return "jpg";
    }
    return "bin";
}

static int lost(struct skyctl_session *session, const char *what, int rc)
{
    fprintf(stderr, "skyctl %s: %s\n", what,
            rc == 1 ? "no frame in time" : sky_client_error(session->client));
    return SKYCTL_CONNECTION;
}

/* The binary message after a `frame` message: unpacked and checked against frame_number. */
static int receive_binary(struct skyctl_session *session, const char *what, double frame_number,
                          struct sky_client_message *binary, struct proto_frame_header *header)
{
    int rc;
    while ((rc = sky_client_recv(session->client, binary, session->timeout_ms)) == 0) {
        if (binary->kind == SKY_CLIENT_BINARY)
            break;
        sky_client_message_free(binary); /* an event between the two */
    }
    if (rc)
        return lost(session, what, rc);
    int status = proto_frame_header_unpack(binary->data, binary->len, header);
    if (status != PROTO_FRAME_HEADER_OK || (double)header->frame_number != frame_number) {
        fprintf(stderr, "skyctl %s: bad frame from the server (%s, frame %.0f announced)\n", what,
                proto_frame_header_status_name(status), frame_number);
        sky_client_message_free(binary);
        return SKYCTL_CONNECTION;
    }
    return SKYCTL_OK;
}

static double number_at(const cJSON *object, const char *name)
{
    const cJSON *item = cJSON_GetObjectItemCaseSensitive(object, name);
    return cJSON_IsNumber(item) ? item->valuedouble : -1;
}

static int take_snapshot(struct skyctl_session *session, const struct view_args *a)
{
    double id = (double)session->next_id++;
    cJSON *msg = cJSON_CreateObject();
    cJSON_AddStringToObject(msg, "type", "snapshot");
    cJSON_AddNumberToObject(msg, "id", id);
    cJSON_AddItemReferenceToObject(msg, "view", a->view);
    int rc = sky_client_send_json(session->client, msg, session->timeout_ms);
    cJSON_Delete(msg);
    if (rc)
        return lost(session, "snapshot", rc);
    for (;;) {
        cJSON *reply = NULL;
        char err[320];
        rc = sky_client_recv_json(session->client, NULL, session->timeout_ms, &reply, err,
                                  sizeof err);
        if (rc) {
            fprintf(stderr, "skyctl snapshot: %s\n", rc == 1 ? "no frame in time" : err);
            return SKYCTL_CONNECTION;
        }
        if (number_at(reply, "id") != id) {
            cJSON_Delete(reply);
            continue;
        }
        const cJSON *type = cJSON_GetObjectItemCaseSensitive(reply, "type");
        if (!cJSON_IsString(type) || strcmp(type->valuestring, "frame") != 0) {
            skyctl_print_error("snapshot", reply);
            cJSON_Delete(reply);
            return SKYCTL_SERVER_ERROR;
        }
        double frame_number = number_at(reply, "frame_number");
        cJSON_Delete(reply);
        struct sky_client_message binary;
        struct proto_frame_header header;
        rc = receive_binary(session, "snapshot", frame_number, &binary, &header);
        if (rc)
            return rc;
        bool ok = write_file("snapshot", a->out, binary.data + PROTO_FRAME_HEADER_SIZE,
                             header.payload_length);
        if (ok && a->json)
            print_frame_json(&header, a->out);
        else if (ok)
            printf("%s: %ux%u %s, %u bytes, state revision %llu, frame %llu\n", a->out,
                   header.width, header.height,
                   header.format == PROTO_FRAME_FORMAT_PNG16  ? "PNG16"
                   : header.format == PROTO_FRAME_FORMAT_JPEG ? "JPEG"
                                                              : "PNG",
                   header.payload_length, (unsigned long long)header.state_revision,
                   (unsigned long long)header.frame_number);
        sky_client_message_free(&binary);
        return ok ? SKYCTL_OK : SKYCTL_USAGE;
    }
}

static bool ends_with(const char *s, const char *suffix)
{
    size_t n = strlen(s), m = strlen(suffix);
    return n >= m && strcasecmp(s + n - m, suffix) == 0;
}

int skyctl_snapshot(const struct skyctl_options *options, int argc, char **argv)
{
    struct view_args a = { .frames = true, .json = options->json };
    int rc = parse_view_args("snapshot", argc, argv, &a, 640, 360);
    if (rc == SKYCTL_OK && !a.out)
        rc = skyctl_usage_error("snapshot", "needs --out FILE.png");
    /* The file's extension picks JPEG unless --set format= says otherwise. */
    if (rc == SKYCTL_OK && (ends_with(a.out, ".jpg") || ends_with(a.out, ".jpeg")) &&
        !cJSON_GetObjectItemCaseSensitive(a.view, "format"))
        cJSON_AddStringToObject(a.view, "format", "jpeg");
    struct skyctl_session session;
    if (rc == SKYCTL_OK && (rc = skyctl_connect(options, &session)) == SKYCTL_OK) {
        rc = take_snapshot(&session, &a);
        skyctl_disconnect(&session);
    }
    cJSON_Delete(a.view);
    return rc;
}

/* Saves the frame under dir when dir is set (path gets its name), then prints its line. */
static int show_frame(const char *dir, bool json, const struct proto_frame_header *h,
                      const unsigned char *payload)
{
    char path[4200] = "";
    if (dir) {
        snprintf(path, sizeof path, "%s/frame_%06llu_rev_%06llu.%s", dir,
                 (unsigned long long)h->frame_number, (unsigned long long)h->state_revision,
                 format_extension(h->format));
        if (!write_file("watch", path, payload, h->payload_length))
            return SKYCTL_USAGE;
    }
    if (json) {
        print_frame_json(h, dir ? path : NULL);
        return SKYCTL_OK;
    }
    printf("frame %llu revision %llu time %.3f s %ux%u %u bytes%s%s\n",
           (unsigned long long)h->frame_number, (unsigned long long)h->state_revision,
           h->simulation_time_s, h->width, h->height, h->payload_length, dir ? " " : "", path);
    return SKYCTL_OK;
}

/* Prints one line per frame and per event until a signal or --count frames (with
 * --no-frames: --count lines). */
static int watch_loop(struct skyctl_session *session, const struct view_args *a)
{
    double counted = 0;
    while (!interrupted && (a->count == 0 || counted < a->count)) {
        struct sky_client_message msg;
        int rc = sky_client_recv(session->client, &msg, 250);
        if (rc == 1)
            continue;
        if (rc)
            return interrupted ? SKYCTL_OK : lost(session, "watch", rc);
        if (msg.kind == SKY_CLIENT_BINARY) { /* its `frame` message went by before `subscribed` */
            sky_client_message_free(&msg);
            continue;
        }
        cJSON *json = msg.kind == SKY_CLIENT_TEXT ? cJSON_Parse((const char *)msg.data) : NULL;
        sky_client_message_free(&msg);
        if (!json)
            json = cJSON_CreateObject(); /* the server only sends JSON text */
        const cJSON *type = cJSON_GetObjectItemCaseSensitive(json, "type");
        if (cJSON_IsString(type) && strcmp(type->valuestring, "frame") == 0) {
            struct sky_client_message binary;
            struct proto_frame_header h;
            rc = receive_binary(session, "watch", number_at(json, "frame_number"), &binary, &h);
            cJSON_Delete(json);
            if (rc)
                return rc;
            rc = show_frame(a->out, a->json, &h, binary.data + PROTO_FRAME_HEADER_SIZE);
            sky_client_message_free(&binary);
            if (rc)
                return rc;
            counted++;
        } else if (a->json) { /* events and anything else, as the server sent them */
            skyctl_print_json_line(json);
            cJSON_Delete(json);
            counted += !a->frames;
        } else if (cJSON_IsString(type) && strcmp(type->valuestring, "event") == 0) {
            const cJSON *event = cJSON_GetObjectItemCaseSensitive(json, "event");
            printf("event %s revision %.0f", cJSON_IsString(event) ? event->valuestring : "?",
                   number_at(json, "revision"));
            const cJSON *changed;
            cJSON_ArrayForEach(changed, cJSON_GetObjectItemCaseSensitive(json, "changed"))
            {
                if (cJSON_IsString(changed))
                    printf(" %s", changed->valuestring);
            }
            printf("\n");
            cJSON_Delete(json);
            counted += !a->frames;
        } else {
            char *text = cJSON_PrintUnformatted(json);
            printf("message %s\n", text ? text : "?");
            free(text);
            cJSON_Delete(json);
            counted += !a->frames;
        }
        fflush(stdout);
    }
    return SKYCTL_OK;
}

int skyctl_watch(const struct skyctl_options *options, int argc, char **argv)
{
    struct view_args a = { .frames = true, .json = options->json };
    int rc = parse_view_args("watch", argc, argv, &a, 320, 180);
    if (rc == SKYCTL_OK && a.out && !a.frames)
        rc = skyctl_usage_error("watch", "--out saves frames: it does not go with --no-frames");
    if (rc == SKYCTL_OK && a.out)
        rc = make_directory(a.out);
    struct skyctl_session session;
    if (rc == SKYCTL_OK && (rc = skyctl_connect(options, &session)) == SKYCTL_OK) {
        struct sigaction action = { .sa_handler = on_signal };
        sigemptyset(&action.sa_mask);
        sigaction(SIGINT, &action, NULL);
        sigaction(SIGTERM, &action, NULL);
        if (a.frames) {
            cJSON *msg = cJSON_CreateObject();
            cJSON_AddStringToObject(msg, "type", "subscribe");
            cJSON_AddItemReferenceToObject(msg, "view", a.view);
            cJSON *reply = NULL;
            rc = skyctl_request(&session, "watch", msg, &reply);
            cJSON_Delete(msg);
            if (rc == SKYCTL_OK && a.json)
                skyctl_print_reply_json(reply);
            else if (rc == SKYCTL_OK)
                printf("subscribed %.0f\n", number_at(reply, "subscription"));
            cJSON_Delete(reply);
        }
        if (rc == SKYCTL_OK)
            rc = watch_loop(&session, &a);
        skyctl_disconnect(&session);
    }
    cJSON_Delete(a.view);
    return rc;
}
