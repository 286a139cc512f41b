#include "sky_client_json.h"

#include <cjson/cJSON.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

static int64_t now_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (int64_t)ts.tv_sec * 1000 + ts.tv_nsec / 1000000;
}

static int remaining_ms(int64_t deadline)
{
    int64_t left = deadline - now_ms();
    return left < 0 ? 0 : left > INT32_MAX ? INT32_MAX : (int)left;
}

int sky_client_send_json(struct sky_client *client, const cJSON *msg, int timeout_ms)
{
    char *text = cJSON_PrintUnformatted(msg);
    if (!text)
        return -1;
    int rc = sky_client_send_text(client, text, strlen(text), timeout_ms);
    free(text);
    return rc;
}

int sky_client_recv_json(struct sky_client *client, const char *type, int timeout_ms, cJSON **out,
                         char *err, size_t errlen)
{
    *out = NULL;
    int64_t deadline = now_ms() + timeout_ms;
    for (;;) {
        struct sky_client_message msg;
        int rc = sky_client_recv(client, &msg, remaining_ms(deadline));
        if (rc) {
            snprintf(err, errlen, "%s", rc > 0 ? "timed out" : sky_client_error(client));
            return rc;
        }
        if (msg.kind != SKY_CLIENT_TEXT) {
            sky_client_message_free(&msg);
            continue;
        }
        cJSON *json = cJSON_ParseWithLength((const char *)msg.data, msg.len);
        const cJSON *t = cJSON_GetObjectItemCaseSensitive(json, "type");
        if (!cJSON_IsObject(json) || !cJSON_IsString(t)) {
            snprintf(err, errlen,
                     "server sent a text message that is not a typed JSON object: %.200s",
                     (const char *)msg.data);
            cJSON_Delete(json);
            sky_client_message_free(&msg);
            return SKY_CLIENT_BAD;
        }
        sky_client_message_free(&msg);
        if (!type || strcmp(t->valuestring, type) == 0) {
            *out = json;
            return 0;
        }
        cJSON_Delete(json);
    }
}

int sky_client_recv_frame(struct sky_client *client, int timeout_ms, struct sky_client_frame *out,
                          char *err, size_t errlen)
{
    memset(out, 0, sizeof *out);
    int64_t deadline = now_ms() + timeout_ms;
    int rc = sky_client_recv_json(client, "frame", timeout_ms, &out->announce, err, errlen);
    if (rc)
        return rc;
    rc = sky_client_recv(client, &out->binary, remaining_ms(deadline));
    if (rc) {
        snprintf(err, errlen, "no binary message after a frame message: %s",
                 rc > 0 ? "timed out" : sky_client_error(client));
        sky_client_frame_free(out);
        return rc;
    }
    const cJSON *number = cJSON_GetObjectItemCaseSensitive(out->announce, "frame_number");
    enum proto_frame_header_status status = PROTO_FRAME_HEADER_OK;
    if (out->binary.kind != SKY_CLIENT_BINARY) {
        snprintf(err, errlen, "a text message follows a frame message: %.200s",
                 (const char *)out->binary.data);
    } else if ((status = proto_frame_header_unpack(out->binary.data, out->binary.len,
                                                   &out->header)) != PROTO_FRAME_HEADER_OK) {
        snprintf(err, errlen, "bad frame header: %s", proto_frame_header_status_name(status));
    } else if (!cJSON_IsNumber(number) || number->valuedouble != (double)out->header.frame_number) {
        snprintf(err, errlen, "frame message announces frame_number %g, header has %llu",
                 cJSON_IsNumber(number) ? number->valuedouble : -1.0,
                 (unsigned long long)out->header.frame_number);
    } else {
        out->payload = out->binary.data + PROTO_FRAME_HEADER_SIZE;
        return 0;
    }
    sky_client_frame_free(out);
    return SKY_CLIENT_BAD;
}

void sky_client_frame_free(struct sky_client_frame *frame)
{
    if (!frame)
        return;
    cJSON_Delete(frame->announce);
    sky_client_message_free(&frame->binary);
    memset(frame, 0, sizeof *frame);
}
