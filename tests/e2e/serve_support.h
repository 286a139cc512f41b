/* Helpers for the end-to-end daemon tests (test_serve.c): requests with ids, JSON Pointer
 * lookups, PNG inspection and scratch-directory chores. Failures print one line saying what
 * was expected and what came instead; the callers then count a failed CHECK. */
#ifndef SKYD_SERVE_SUPPORT_H
#define SKYD_SERVE_SUPPORT_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "sky_client_json.h"

struct cJSON;

#define SERVE_REPLY_MS 10000       /* a control reply (set waits for the next render tick) */
#define SERVE_FIRST_FRAME_MS 30000 /* the first frame of a run (LUTs are built at start) */

/* Connects and reads the hello; NULL (with a printed reason) on failure. *hello may be NULL. */
struct sky_client *serve_connect(const char *url, const char *origin, struct cJSON **hello);

/* Sends json_text (an object without "id") with a fresh integer id and returns the reply that
 * carries that id, dropping events and frames before it; NULL with a printed reason. */
struct cJSON *serve_request(struct sky_client *client, const char *json_text);

/* Sends text as is and waits for the next text message of `type`. */
struct cJSON *serve_send_expect(struct sky_client *client, const char *text, const char *type);

/* The next text message of `type` (others dropped); NULL with a printed reason. */
struct cJSON *serve_expect(struct sky_client *client, const char *type, int timeout_ms);

/* Subscribes with view_json and returns the subscription number, or -1. */
long serve_subscribe(struct sky_client *client, const char *view_json);

/* Sends one raw HTTP/1.1 request for `path` to 127.0.0.1:port with extra_headers (each line
 * ending in \r\n; may be "") and returns the response's status code (-1 on failure). The first
 * body bytes go to body when it is not NULL. */
int http_status(int port, const char *path, const char *extra_headers, char *body,
                size_t body_size);
#define WS_UPGRADE_HEADERS                                                                         \
    "Connection: Upgrade\r\nUpgrade: websocket\r\nSec-WebSocket-Version: 13\r\n"                   \
    "Sec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\n"

/* Value at a JSON Pointer ("/state/sun/elevation_deg", "/changed/0"): numbers (NAN when absent
 * or not a number), strings ("" when absent) and error codes of replies ("" when not an error). */
double jnum(const struct cJSON *root, const char *pointer);
const char *jstr(const struct cJSON *root, const char *pointer);
const struct cJSON *jget(const struct cJSON *root, const char *pointer);
bool jarray_has_string(const struct cJSON *array, const char *text);

/* Decodes a PNG to RGB8: its size, and whether every pixel has the same value. */
bool png_inspect(const unsigned char *png, size_t len, uint32_t *width, uint32_t *height,
                 bool *constant);

/* Creates dir (and parents) and removes the plain files in it. */
bool scratch_reset(const char *dir);
/* Plain files in dir whose names start with prefix. */
int count_files_with_prefix(const char *dir, const char *prefix);
bool write_file(const char *path, const char *text);

double now_s(void);
void sleep_s(double seconds);

#endif
