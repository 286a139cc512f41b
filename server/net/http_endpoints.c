/* The HTTP API's endpoints: what each request becomes (http_api_internal.h). */
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cjson/cJSON.h>

#include "http_api_internal.h"
#include "json_guard.h"
#include "monotonic_clock.h"
#include "world_state.h"

void answer_health(struct http_api *api, struct http_request *r)
{
    struct service_metrics_tick tick = service_metrics_last_tick(api->metrics);
    double age = monotonic_seconds() - tick.at_s;
    const char *failure = api->loop ? render_loop_failure(api->loop) : "shutting down";
    char reason[448] = "";
    if (failure)
        snprintf(reason, sizeof reason, "rendering stopped: %s", failure);
    else if (tick.at_s <= 0 || age > HEALTHY_TICK_AGE_S)
        snprintf(reason, sizeof reason, "the render thread has not ticked for %.1f s", age);
    json_guard_lock();
    cJSON *json = cJSON_CreateObject();
    cJSON_AddStringToObject(json, "status", reason[0] ? "unavailable" : "ok");
    if (reason[0])
        cJSON_AddStringToObject(json, "reason", reason);
    cJSON_AddNumberToObject(json, "revision", (double)tick.state_revision);
    cJSON_AddNumberToObject(json, "last_tick_age_s", age);
    cJSON_AddNumberToObject(json, "clients", session_hub_count(api->hub));
    cJSON_AddNumberToObject(json, "subscriptions", (double)tick.subscriptions);
    respond_json(r, reason[0] ? HTTP_STATUS_SERVICE_UNAVAILABLE : HTTP_STATUS_OK, json);
    cJSON_Delete(json);
    json_guard_unlock();
}

void answer_metrics(struct http_api *api, struct http_request *r)
{
    char *text = service_metrics_exposition(api->metrics, session_hub_count(api->hub));
    if (!text) {
        respond_error(api, r, 0, SKY_MSG_ERR_INTERNAL, "out of memory", NULL);
        return;
    }
    respond(r, HTTP_STATUS_OK, "text/plain; version=0.0.4; charset=utf-8", text, strlen(text));
    free(text);
}

void answer_schema(struct http_api *api, struct http_request *r)
{
    json_guard_lock();
    cJSON *schema = sky_world_state_json_schema();
    if (schema)
        respond_json(r, HTTP_STATUS_OK, schema);
    cJSON_Delete(schema);
    json_guard_unlock();
    if (!schema)
        respond_error(api, r, 0, SKY_MSG_ERR_INTERNAL, "out of memory", NULL);
}

/* A query parameter's value as JSON: a number when it reads as one, else the text (which the
 * message parser then refuses by type where a number belongs). */
static cJSON *query_value(const char *text)
{
    char *end = NULL;
    double number = strtod(text, &end);
    if (text[0] && end && *end == '\0')
        return cJSON_CreateNumber(number);
    return cJSON_CreateString(text);
}

/* Where each snapshot parameter goes in the message's view. */
static const struct {
    const char *name, *group, *member;
} snapshot_params[] = {
    { "width", NULL, "width" },           { "height", NULL, "height" },
    { "format", NULL, "format" },         { "quality", NULL, "quality" },
    { "projection", NULL, "projection" },
    { "yaw_deg", "camera", "yaw_deg" },   { "pitch_deg", "camera", "pitch_deg" },
    { "fov_deg", "camera", "fov_deg" },   { "altitude_km", "camera", "altitude_km" },
    { "exposure_mode", "exposure", "mode" }, { "ev100", "exposure", "ev100" },
    { "compensation_ev", "exposure", "compensation_ev" },
};
#define SNAPSHOT_PARAM_COUNT (sizeof snapshot_params / sizeof snapshot_params[0])

void answer_snapshot(struct http_api *api, struct http_request *r)
{
    json_guard_lock();
    cJSON *message = cJSON_CreateObject();
    cJSON_AddStringToObject(message, "type", "snapshot");
    cJSON *view = cJSON_AddObjectToObject(message, "view");
    char fragment[256], problem[320] = "";
    for (int n = 0; !problem[0] &&
                    lws_hdr_copy_fragment(r->wsi, fragment, sizeof fragment,
                                          WSI_TOKEN_HTTP_URI_ARGS, n) > 0; n++) {
        char *equals = strchr(fragment, '=');
        const char *value = equals ? equals + 1 : "";
        if (equals)
            *equals = '\0';
        size_t i = 0;
        while (i < SNAPSHOT_PARAM_COUNT && strcmp(snapshot_params[i].name, fragment) != 0)
            i++;
        if (i == SNAPSHOT_PARAM_COUNT) {
            snprintf(problem, sizeof problem, "unknown query parameter '%.64s'; expected: width, "
                     "height, format, quality, projection, yaw_deg, pitch_deg, fov_deg, altitude_km, "
                     "exposure_mode, ev100, compensation_ev", fragment);
            break;
        }
        cJSON *parent = view;
        if (snapshot_params[i].group) {
            parent = cJSON_GetObjectItemCaseSensitive(view, snapshot_params[i].group);
            if (!parent)
                parent = cJSON_AddObjectToObject(view, snapshot_params[i].group);
        }
        if (cJSON_GetObjectItemCaseSensitive(parent, snapshot_params[i].member)) {
            snprintf(problem, sizeof problem, "query parameter '%s' is given twice", fragment);
            break;
        }
        cJSON_AddItemToObject(parent, snapshot_params[i].member, query_value(value));
    }
    json_guard_unlock();
    if (problem[0])
        respond_error(api, r, 0, SKY_MSG_ERR_UNKNOWN_FIELD, problem, NULL);
    else
        submit_json(api, r, message, SKY_ROLE_VIEWER);
    cJSON_Delete(message);
}

void answer_patch(struct http_api *api, struct http_request *r)
{
    char message[160];
    if (r->body_too_large) {
        snprintf(message, sizeof message, "the body is larger than max_message_bytes (%zu)",
                 api->limits->max_message_bytes);
        respond_error(api, r, 0, SKY_MSG_ERR_MESSAGE_TOO_LARGE, message, NULL);
        return;
    }
    const char *text = r->body ? r->body : "";
    if (memchr(text, '\0', r->body_length)) {
        respond_error(api, r, 0, SKY_MSG_ERR_MALFORMED_JSON, "NUL byte in the body", NULL);
        return;
    }
    json_guard_lock();
    const char *end = NULL;
    cJSON *patch = cJSON_ParseWithLengthOpts(text, r->body_length, &end, false);
    size_t offset = end ? (size_t)(end - text) : 0;
    while (patch && offset < r->body_length && strchr(" \t\r\n", text[offset]))
        offset++;
    cJSON *set = NULL;
    if (patch && offset == r->body_length) {
        set = cJSON_CreateObject();
        cJSON_AddStringToObject(set, "type", "set");
        cJSON_AddItemToObject(set, "patch", patch);
    } else {
        cJSON_Delete(patch);
    }
    json_guard_unlock();
    if (!set) {
        snprintf(message, sizeof message, "the body is not JSON (at offset %zu)", offset);
        respond_error(api, r, 0, SKY_MSG_ERR_MALFORMED_JSON, message, NULL);
        return;
    }
    submit_json(api, r, set, SKY_ROLE_CONTROLLER);
    cJSON_Delete(set);
}
