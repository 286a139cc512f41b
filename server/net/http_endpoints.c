/* The HTTP API's endpoints: what each request becomes (http_endpoints.h). */
#include "http_endpoints.h"

#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cjson/cJSON.h>
#include <libwebsockets.h>

#include "error_text.h"
#include "json_guard.h"
#include "monotonic_clock.h"
#include "render_loop.h"
#include "service_metrics.h"
#include "session.h"
#include "utc_time.h"
#include "weather_map.h"
#include "world_state.h"

/* /healthz fails when the render thread has not ticked for this long (it ticks at least once
 * a second when idle). */
#define HEALTHY_TICK_AGE_S 5.0

void http_answer_release(struct http_answer *answer)
{
    free(answer->body);
    cJSON_Delete(answer->json);
    answer->body = NULL;
    answer->json = NULL;
}

static void answer_text(struct http_answer *out, unsigned status, const char *content_type,
                        char *body)
{
    *out = (struct http_answer){ .kind = HTTP_ANSWER_RESPONSE,
                                 .status = status,
                                 .content_type = content_type,
                                 .body = body,
                                 .body_length = body ? strlen(body) : 0 };
}

/* `json` as the response's text, or a 500 with an empty object when it cannot be printed. */
static void answer_json(struct http_answer *out, unsigned status, const cJSON *json)
{
    char *text = json ? cJSON_PrintUnformatted(json) : NULL;
    answer_text(out, text ? status : HTTP_STATUS_INTERNAL_SERVER_ERROR, "application/json", text);
}

static void answer_error(struct http_answer *out, enum proto_msg_error_code code,
                         const char *message)
{
    *out = (struct http_answer){ .kind = HTTP_ANSWER_ERROR, .code = code };
    snprintf(out->message, sizeof out->message, "%s", message);
}

/* Takes `json`. */
static void answer_submit(struct http_answer *out, cJSON *json, enum proto_msg_role role)
{
    *out = (struct http_answer){ .kind = HTTP_ANSWER_SUBMIT, .json = json, .role = role };
}

void http_endpoint_health(struct http_answer *out, struct service_metrics *metrics,
                          struct render_loop *loop, struct session_hub *hub)
{
    struct service_metrics_tick tick = service_metrics_last_tick(metrics);
    double age = monotonic_seconds() - tick.at_s;
    const char *failure = loop ? render_loop_failure(loop) : "shutting down";
    error_text reason = "";
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
    cJSON_AddNumberToObject(json, "clients", session_hub_count(hub));
    cJSON_AddNumberToObject(json, "subscriptions", (double)tick.subscriptions);
    answer_json(out, reason[0] ? HTTP_STATUS_SERVICE_UNAVAILABLE : HTTP_STATUS_OK, json);
    cJSON_Delete(json);
    json_guard_unlock();
}

void http_endpoint_metrics(struct http_answer *out, struct service_metrics *metrics,
                           struct session_hub *hub)
{
    char *text = service_metrics_exposition(metrics, session_hub_count(hub));
    if (!text)
        answer_error(out, PROTO_MSG_ERR_INTERNAL, "out of memory");
    else
        answer_text(out, HTTP_STATUS_OK, "text/plain; version=0.0.4; charset=utf-8", text);
}

void http_endpoint_schema(struct http_answer *out)
{
    json_guard_lock();
    cJSON *schema = proto_world_state_json_schema();
    if (schema)
        answer_json(out, HTTP_STATUS_OK, schema);
    cJSON_Delete(schema);
    json_guard_unlock();
    if (!schema)
        answer_error(out, PROTO_MSG_ERR_INTERNAL, "out of memory");
}

/* A time as ISO 8601 text, or null when there is none. */
static void add_time(cJSON *json, const char *name, bool known, double unix_s)
{
    char text[32];
    proto_time_format_iso8601(unix_s, text, sizeof text);
    if (known)
        cJSON_AddStringToObject(json, name, text);
    else
        cJSON_AddNullToObject(json, name);
}

/* The forecast's weather map as set_weather_map would send it, or null. */
static void add_forecast_map(cJSON *json, const struct service_metrics_forecast *f)
{
    char *data = f->map_width
                     ? proto_base64_encode(f->map_rgba, (size_t)f->map_width * f->map_height * 4)
                     : NULL;
    cJSON *map = data ? cJSON_AddObjectToObject(json, "map") : NULL;
    if (!map) {
        cJSON_AddNullToObject(json, "map");
    } else {
        cJSON_AddStringToObject(map, "format", "rgba8");
        cJSON_AddNumberToObject(map, "width", f->map_width);
        cJSON_AddNumberToObject(map, "height", f->map_height);
        cJSON_AddStringToObject(map, "data", data);
    }
    free(data);
}

void http_endpoint_forecast(struct http_answer *out, struct service_metrics *metrics)
{
    struct service_metrics_forecast f = service_metrics_last_forecast(metrics);
    json_guard_lock();
    cJSON *json = cJSON_CreateObject();
    cJSON_AddBoolToObject(json, "configured", f.configured);
    if (f.configured)
        cJSON_AddStringToObject(json, "dir", f.dir);
    else
        cJSON_AddNullToObject(json, "dir");
    cJSON_AddBoolToObject(json, "loaded", f.loaded);
    if (f.loaded)
        cJSON_AddStringToObject(json, "file", f.file);
    else
        cJSON_AddNullToObject(json, "file");
    add_time(json, "run", f.loaded, f.run_unix_s);
    cJSON_AddNumberToObject(json, "steps", f.loaded ? f.steps : 0);
    add_time(json, "first_step", f.loaded, f.first_step_unix_s);
    add_time(json, "last_step", f.loaded, f.last_step_unix_s);
    cJSON_AddBoolToObject(json, "following", f.following);
    cJSON_AddBoolToObject(json, "in_range", !f.following || f.in_range);
    if (f.error[0])
        cJSON_AddStringToObject(json, "last_error", f.error);
    else
        cJSON_AddNullToObject(json, "last_error");
    cJSON_AddNumberToObject(json, "loads", (double)f.loads);
    cJSON_AddNumberToObject(json, "refusals", (double)f.refusals);
    add_forecast_map(json, &f);
    answer_json(out, HTTP_STATUS_OK, json);
    cJSON_Delete(json);
    json_guard_unlock();
}

void http_endpoint_state(struct http_answer *out)
{
    json_guard_lock();
    cJSON *get_state = cJSON_CreateObject();
    cJSON_AddStringToObject(get_state, "type", "get_state");
    json_guard_unlock();
    answer_submit(out, get_state, PROTO_ROLE_VIEWER);
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
    { "width", NULL, "width" },
    { "height", NULL, "height" },
    { "format", NULL, "format" },
    { "quality", NULL, "quality" },
    { "projection", NULL, "projection" },
    { "yaw_deg", "camera", "yaw_deg" },
    { "pitch_deg", "camera", "pitch_deg" },
    { "fov_deg", "camera", "fov_deg" },
    { "altitude_km", "camera", "altitude_km" },
    { "exposure_mode", "exposure", "mode" },
    { "ev100", "exposure", "ev100" },
    { "compensation_ev", "exposure", "compensation_ev" },
};
#define SNAPSHOT_PARAM_COUNT (sizeof snapshot_params / sizeof snapshot_params[0])

void http_endpoint_snapshot(struct http_answer *out, struct lws *wsi)
{
    json_guard_lock();
    cJSON *message = cJSON_CreateObject();
    cJSON_AddStringToObject(message, "type", "snapshot");
    cJSON *view = cJSON_AddObjectToObject(message, "view");
    char fragment[256];
    error_text problem = "";
    for (int n = 0; !problem[0] && lws_hdr_copy_fragment(wsi, fragment, sizeof fragment,
                                                         WSI_TOKEN_HTTP_URI_ARGS, n) > 0;
         n++) {
        char *equals = strchr(fragment, '=');
        const char *value = equals ? equals + 1 : "";
        if (equals)
            *equals = '\0';
        size_t i = 0;
        while (i < SNAPSHOT_PARAM_COUNT && strcmp(snapshot_params[i].name, fragment) != 0)
            i++;
        if (i == SNAPSHOT_PARAM_COUNT) {
            snprintf(
                problem, sizeof problem,
                "unknown query parameter '%.64s'; expected: width, "
                "height, format, quality, projection, yaw_deg, pitch_deg, fov_deg, altitude_km, "
                "exposure_mode, ev100, compensation_ev",
                fragment);
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
    if (problem[0]) {
        answer_error(out, PROTO_MSG_ERR_UNKNOWN_FIELD, problem);
        cJSON_Delete(message);
    } else {
        answer_submit(out, message, PROTO_ROLE_VIEWER);
    }
}

/* A request body the endpoints can read as text, or NULL once the refusal (too large, a NUL
 * byte) is answered. */
static const char *body_text(struct http_answer *out, const char *body, size_t length,
                             bool too_large, size_t max_message_bytes)
{
    if (too_large) {
        error_text message;
        snprintf(message, sizeof message, "the body is larger than max_message_bytes (%zu)",
                 max_message_bytes);
        answer_error(out, PROTO_MSG_ERR_MESSAGE_TOO_LARGE, message);
        return NULL;
    }
    const char *text = body ? body : "";
    if (memchr(text, '\0', length)) {
        answer_error(out, PROTO_MSG_ERR_MALFORMED_JSON, "NUL byte in the body");
        return NULL;
    }
    return text;
}

void http_endpoint_metar(struct http_answer *out, const char *body, size_t length, bool too_large,
                         size_t max_message_bytes)
{
    const char *text = body_text(out, body, length, too_large, max_message_bytes);
    if (!text)
        return;
    error_text message;
    size_t start = 0;
    while (start < length && strchr(" \t\r\n", text[start]))
        start++;
    while (length > start && strchr(" \t\r\n", text[length - 1]))
        length--;
    cJSON *observation = NULL;
    json_guard_lock();
    if (start < length && text[start] == '{') {
        /* {"metar": "..."}: the object is the message, less its type. */
        const char *end = NULL;
        observation = cJSON_ParseWithLengthOpts(text + start, length - start, &end, false);
        if (!observation || end != text + length || !cJSON_IsObject(observation)) {
            size_t offset = end ? (size_t)(end - text) : start;
            cJSON_Delete(observation);
            json_guard_unlock();
            snprintf(message, sizeof message, "the body is not JSON (at offset %zu)", offset);
            answer_error(out, PROTO_MSG_ERR_MALFORMED_JSON, message);
            return;
        }
        if (cJSON_GetObjectItemCaseSensitive(observation, "type") ||
            cJSON_GetObjectItemCaseSensitive(observation, "id")) {
            cJSON_Delete(observation);
            json_guard_unlock();
            answer_error(out, PROTO_MSG_ERR_BAD_VALUE,
                         "the body's object holds \"metar\" only (no \"type\" or \"id\")");
            return;
        }
    } else {
        /* The report's text itself. */
        char *report = malloc(length - start + 1);
        observation = report ? cJSON_CreateObject() : NULL;
        if (report) {
            memcpy(report, text + start, length - start);
            report[length - start] = '\0';
            if (!cJSON_AddStringToObject(observation, "metar", report)) {
                cJSON_Delete(observation);
                observation = NULL;
            }
        }
        free(report);
    }
    if (observation && !cJSON_AddStringToObject(observation, "type", "apply_observation")) {
        cJSON_Delete(observation);
        observation = NULL;
    }
    json_guard_unlock();
    if (!observation) {
        answer_error(out, PROTO_MSG_ERR_INTERNAL, "out of memory");
        return;
    }
    answer_submit(out, observation, PROTO_ROLE_CONTROLLER);
}

void http_endpoint_patch(struct http_answer *out, const char *body, size_t length, bool too_large,
                         size_t max_message_bytes)
{
    const char *text = body_text(out, body, length, too_large, max_message_bytes);
    if (!text)
        return;
    error_text message;
    json_guard_lock();
    const char *end = NULL;
    cJSON *patch = cJSON_ParseWithLengthOpts(text, length, &end, false);
    size_t offset = end ? (size_t)(end - text) : 0;
    while (patch && offset < length && strchr(" \t\r\n", text[offset]))
        offset++;
    cJSON *set = NULL;
    if (patch && offset == length) {
        set = cJSON_CreateObject();
        cJSON_AddStringToObject(set, "type", "set");
        cJSON_AddItemToObject(set, "patch", patch);
    } else {
        cJSON_Delete(patch);
    }
    json_guard_unlock();
    if (!set) {
        snprintf(message, sizeof message, "the body is not JSON (at offset %zu)", offset);
        answer_error(out, PROTO_MSG_ERR_MALFORMED_JSON, message);
        return;
    }
    answer_submit(out, set, PROTO_ROLE_CONTROLLER);
}
