/* What the rows of message_fields.c leave to code: a view object (its rows run here, with the
 * limits, then its aspect is checked) and a client weather map's data. */
#include "field_errors.h"
#include "field_schema.h"
#include "message_parser.h"
#include "message_names.h"
#include "weather_map.h"

#include <cjson/cJSON.h>

#include <stdlib.h>
#include <string.h>

void msg_parse_view(struct parser *p, const cJSON *object, const char *pointer,
                    struct proto_msg_view *view)
{
    struct msg_view_schema schema;
    msg_view_schema(p->limits, &schema);
    view->fps = p->limits->max_fps < 10 ? p->limits->max_fps : 10;
    view->format = PROTO_FRAME_FORMAT_PNG;
    view->projection = PROTO_VIEW_PROJECTION_PERSPECTIVE;
    bool named[MSG_VIEW_ROWS] = { false };
    proto_schema_apply_json(&schema.schema, view, object, pointer, &p->error->fields, named);
    view->has_altitude_km = named[MSG_VIEW_ALTITUDE];
    view->has_yaw_deg = named[MSG_VIEW_YAW];
    view->has_pitch_deg = named[MSG_VIEW_PITCH];
    view->has_fov_deg = named[MSG_VIEW_FOV];
    view->has_exposure_mode = named[MSG_VIEW_EXPOSURE_MODE];
    view->has_ev100 = named[MSG_VIEW_EV100];
    view->has_compensation_ev = named[MSG_VIEW_COMPENSATION];
    if (view->format == PROTO_FRAME_FORMAT_JPEG && !named[MSG_VIEW_QUALITY])
        view->quality = PROTO_MSG_JPEG_QUALITY_DEFAULT;
    if (view->format != PROTO_FRAME_FORMAT_JPEG && named[MSG_VIEW_QUALITY]) {
        char at[PROTO_MSG_POINTER_MAX];
        msg_child_pointer(at, pointer, "quality");
        parser_fail(p, PROTO_MSG_ERR_INCONSISTENT, at, "quality is for format jpeg only");
    }
    /* A panorama covers 360 x 180 degrees with square pixels. */
    if (view->projection == PROTO_VIEW_PROJECTION_EQUIRECTANGULAR && view->width && view->height &&
        view->width != 2 * view->height) {
        char at[PROTO_MSG_POINTER_MAX];
        msg_child_pointer(at, pointer, "width");
        parser_fail(p, PROTO_MSG_ERR_INCONSISTENT, at,
                    "an equirectangular view is 2:1: width must be twice the height (%u), got %u",
                    view->height, view->width);
    }
}

/* data (base64), once the rows took format, width and height (required for rgba8, checked
 * against the file for png). */
void msg_parse_weather_map(struct parser *p, struct proto_client_msg *msg)
{
    const cJSON *data = cJSON_GetObjectItemCaseSensitive(p->root, "data");
    if (!parser_require(p, data, "/data"))
        return;
    if (!cJSON_IsString(data)) {
        parser_fail(p, PROTO_MSG_ERR_WRONG_TYPE, "/data", "expected a base64 string, got %s",
                    proto_json_type_name(data));
        return;
    }
    if (p->error->fields.total > 0)
        return;
    char reason[REASON_MAX];
    uint8_t *bytes;
    size_t length;
    if (!proto_base64_decode(data->valuestring, strlen(data->valuestring), &bytes, &length, reason,
                             sizeof reason)) {
        parser_fail(p, PROTO_MSG_ERR_BAD_VALUE, "/data", "%s", reason);
        return;
    }
    if (!proto_weather_map_decode(
            msg->weather_map_format, bytes, length, (uint32_t)msg->weather_map_width,
            (uint32_t)msg->weather_map_height, &msg->weather_map, reason, sizeof reason))
        parser_fail(p, PROTO_MSG_ERR_BAD_VALUE, "/data", "%s", reason);
    free(bytes);
}
