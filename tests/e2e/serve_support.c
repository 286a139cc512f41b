#include "serve_support.h"

#include <cjson/cJSON.h>
#include <dirent.h>
#include <errno.h>
#include <math.h>
#include <netinet/in.h>
#include <png.h>
#include <poll.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

struct sky_client *serve_connect(const char *url, const char *origin, cJSON **hello)
{
    char err[320];
    if (hello)
        *hello = NULL;
    struct sky_client *client = sky_client_connect(url, origin, 10000, err, sizeof err);
    if (!client) {
        printf("connect %s (origin %s): %s\n", url, origin ? origin : "none", err);
        return NULL;
    }
    cJSON *first = serve_expect(client, NULL, SERVE_REPLY_MS);
    if (!first || strcmp(jstr(first, "/type"), "hello") != 0) {
        char *text = first ? cJSON_PrintUnformatted(first) : NULL;
        printf("connect %s: expected hello first, got %s\n", url, text ? text : "nothing");
        free(text);
        cJSON_Delete(first);
        sky_client_close(&client);
        return NULL;
    }
    if (hello)
        *hello = first;
    else
        cJSON_Delete(first);
    return client;
}

cJSON *serve_expect(struct sky_client *client, const char *type, int timeout_ms)
{
    cJSON *msg = NULL;
    char err[320];
    int rc = sky_client_recv_json(client, type, timeout_ms, &msg, err, sizeof err);
    if (rc) {
        printf("waiting for a %s message: %s (close code %d '%s')\n", type ? type : "text", err,
               sky_client_close_code(client), sky_client_close_reason(client));
        return NULL;
    }
    return msg;
}

cJSON *serve_send_expect(struct sky_client *client, const char *text, const char *type)
{
    if (sky_client_send_text(client, text, strlen(text), SERVE_REPLY_MS) != 0) {
        printf("sending %.80s: %s\n", text, sky_client_error(client));
        return NULL;
    }
    return serve_expect(client, type, SERVE_REPLY_MS);
}

cJSON *serve_request(struct sky_client *client, const char *json_text)
{
    static long next_id = 1000;
    cJSON *msg = cJSON_Parse(json_text);
    if (!msg) {
        printf("serve_request: bad JSON in the test: %s\n", json_text);
        return NULL;
    }
    long id = next_id++;
    cJSON_AddNumberToObject(msg, "id", (double)id);
    int rc = sky_client_send_json(client, msg, SERVE_REPLY_MS);
    cJSON_Delete(msg);
    if (rc) {
        printf("sending %.80s: %s\n", json_text, sky_client_error(client));
        return NULL;
    }
    double deadline = now_s() + SERVE_REPLY_MS / 1000.0;
    for (;;) {
        int left = (int)((deadline - now_s()) * 1000);
        cJSON *reply = serve_expect(client, NULL, left > 0 ? left : 0);
        if (!reply) {
            printf("  (no reply to %.80s)\n", json_text);
            return NULL;
        }
        if (jnum(reply, "/id") == (double)id)
            return reply;
        cJSON_Delete(reply);
    }
}

long serve_subscribe(struct sky_client *client, const char *view_json)
{
    char text[512];
    snprintf(text, sizeof text, "{\"type\":\"subscribe\",\"view\":%s}", view_json);
    cJSON *reply = serve_request(client, text);
    double n = jnum(reply, "/subscription");
    if (!reply || strcmp(jstr(reply, "/type"), "subscribed") != 0 || !(n >= 1)) {
        char *printed = reply ? cJSON_PrintUnformatted(reply) : NULL;
        printf("subscribe %s: got %s\n", view_json, printed ? printed : "nothing");
        free(printed);
        cJSON_Delete(reply);
        return -1;
    }
    cJSON_Delete(reply);
    return (long)n;
}

static bool response_complete(char *response, size_t used)
{
    response[used] = 0;
    const char *end = strstr(response, "\r\n\r\n");
    if (!end)
        return false;
    if (strncmp(response + 9, "101", 3) == 0)
        return true;
    size_t header_len = (size_t)(end + 4 - response);
    for (const char *p = response; p < end; p = strstr(p, "\r\n") + 2) {
        unsigned long length;
        if (strncasecmp(p, "content-length:", 15) == 0 && sscanf(p + 15, "%lu", &length) == 1)
            return used >= header_len + length;
    }
    return false;
}

int http_status(int port, const char *path, const char *extra_headers, char *body, size_t body_size)
{
    int fd = socket(AF_INET, SOCK_STREAM, 0);
    struct sockaddr_in addr = { .sin_family = AF_INET,
                                .sin_port = htons((uint16_t)port),
                                .sin_addr.s_addr = htonl(INADDR_LOOPBACK) };
    if (fd < 0 || connect(fd, (struct sockaddr *)&addr, sizeof addr) != 0) {
        printf("http: cannot connect to port %d: %s\n", port, strerror(errno));
        if (fd >= 0)
            close(fd);
        return -1;
    }
    char request[1024], response[8192];
    int n = snprintf(request, sizeof request, "GET %s HTTP/1.1\r\nHost: 127.0.0.1:%d\r\n%s\r\n",
                     path, port, extra_headers);
    size_t used = 0;
    if (write(fd, request, (size_t)n) != n)
        used = sizeof response; /* skip reading */
    /* Read until the peer closes, the buffer is full, the headers and Content-Length bytes
     * have come (a 101 has no body and keeps the connection open), or 2 s pass in silence. */
    while (used < sizeof response - 1 && !response_complete(response, used)) {
        struct pollfd pfd = { fd, POLLIN, 0 };
        if (poll(&pfd, 1, 2000) <= 0)
            break;
        ssize_t got = read(fd, response + used, sizeof response - 1 - used);
        if (got <= 0)
            break;
        used += (size_t)got;
    }
    close(fd);
    if (used >= sizeof response)
        return -1;
    response[used] = 0;
    int status = -1;
    if (sscanf(response, "HTTP/1.%*d %d", &status) != 1)
        printf("http: no status line in '%.80s'\n", response);
    if (body && body_size) {
        const char *start = strstr(response, "\r\n\r\n");
        snprintf(body, body_size, "%s", start ? start + 4 : "");
    }
    return status;
}

const cJSON *jget(const cJSON *root, const char *pointer)
{
    const cJSON *node = root;
    const char *p = pointer;
    while (node && *p == '/') {
        char token[128];
        size_t n = strcspn(p + 1, "/");
        if (n >= sizeof token)
            return NULL;
        memcpy(token, p + 1, n);
        token[n] = 0;
        p += 1 + n;
        if (cJSON_IsArray(node)) {
            char *end;
            long index = strtol(token, &end, 10);
            node = *end || index < 0 ? NULL : cJSON_GetArrayItem(node, (int)index);
        } else {
            node = cJSON_GetObjectItemCaseSensitive(node, token);
        }
    }
    return *p ? NULL : node;
}

double jnum(const cJSON *root, const char *pointer)
{
    const cJSON *node = jget(root, pointer);
    return cJSON_IsNumber(node) ? node->valuedouble : NAN;
}

const char *jstr(const cJSON *root, const char *pointer)
{
    const cJSON *node = jget(root, pointer);
    return cJSON_IsString(node) ? node->valuestring : "";
}

bool jarray_has_string(const cJSON *array, const char *text)
{
    const cJSON *item;
    cJSON_ArrayForEach(item, array)
    {
        if (cJSON_IsString(item) && strcmp(item->valuestring, text) == 0)
            return true;
    }
    return false;
}

bool png_inspect(const unsigned char *png, size_t len, uint32_t *width, uint32_t *height,
                 bool *constant)
{
    png_image image;
    memset(&image, 0, sizeof image);
    image.version = PNG_IMAGE_VERSION;
    if (!png_image_begin_read_from_memory(&image, png, len)) {
        printf("png: %s\n", image.message);
        return false;
    }
    image.format = PNG_FORMAT_RGB;
    size_t size = PNG_IMAGE_SIZE(image);
    unsigned char *pixels = malloc(size);
    if (!pixels || !png_image_finish_read(&image, NULL, pixels, 0, NULL)) {
        printf("png: %s\n", pixels ? image.message : "out of memory");
        free(pixels);
        png_image_free(&image);
        return false;
    }
    *width = image.width;
    *height = image.height;
    *constant = true;
    for (size_t i = 3; i < size && *constant; i++)
        *constant = pixels[i] == pixels[i % 3];
    free(pixels);
    return true;
}

bool scratch_reset(const char *dir)
{
    char path[1024];
    snprintf(path, sizeof path, "%s", dir);
    for (char *p = path + 1; *p; p++) {
        if (*p == '/') {
            *p = 0;
            mkdir(path, 0755);
            *p = '/';
        }
    }
    if (mkdir(path, 0755) != 0 && errno != EEXIST) {
        printf("mkdir %s: %s\n", path, strerror(errno));
        return false;
    }
    DIR *d = opendir(dir);
    if (!d)
        return false;
    struct dirent *e;
    while ((e = readdir(d))) {
        char file[2048];
        struct stat st;
        snprintf(file, sizeof file, "%s/%s", dir, e->d_name);
        if (stat(file, &st) == 0 && S_ISREG(st.st_mode))
            remove(file);
    }
    closedir(d);
    return true;
}

int count_files_with_prefix(const char *dir, const char *prefix)
{
    DIR *d = opendir(dir);
    if (!d)
        return 0;
    int count = 0;
    struct dirent *e;
    while ((e = readdir(d)))
        count += strncmp(e->d_name, prefix, strlen(prefix)) == 0;
    closedir(d);
    return count;
}

bool write_file(const char *path, const char *text)
{
    FILE *f = fopen(path, "w");
    if (!f) {
        printf("cannot write %s: %s\n", path, strerror(errno));
        return false;
    }
    fputs(text, f);
    return fclose(f) == 0;
}

double now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + ts.tv_nsec * 1e-9;
}

void sleep_s(double seconds)
{
    struct timespec ts = { (time_t)seconds, (long)((seconds - (double)(time_t)seconds) * 1e9) };
    nanosleep(&ts, NULL);
}
