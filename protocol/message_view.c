/* The parsers of the nested objects of messages: a view (camera, size, frame rate, format,
 * projection, exposure) and a client weather map. */
#include "message_parser.h"
#include "message_names.h"
#include "weather_map.h"

#include <cjson/cJSON.h>

#include <float.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static const char *const weather_map_format_names[] = {[SKY_WEATHER_MAP_RGBA8] = "rgba8",
                                                        [SKY_WEATHER_MAP_PNG] = "png"};
static const char *const view_fields[] = {"camera", "width",  "height",    "fps",
                                          "exposure", "format", "projection"};
static const char *const camera_fields[] = {"altitude_km", "yaw_deg", "pitch_deg", "fov_deg"};
static const char *const exposure_fields[] = {"mode", "ev100", "compensation_ev"};

void msg_parse_view(struct parser *p, const cJSON *object, const char *pointer,
                    struct sky_msg_view *view)
{
    if (!cJSON_IsObject(object)) {
        parser_fail(p, SKY_MSG_ERR_WRONG_TYPE, pointer, "expected an object, got %s",
                    sky_json_type_name(object));
        return;
    }
    const cJSON *found[MAX_MEMBERS];
    char at[SKY_MSG_POINTER_MAX];
    parser_collect(p, object, pointer, view_fields, COUNT_OF(view_fields), found);
    int64_t size;
    msg_child_pointer(at, pointer, "width");
    if (parser_require(p, found[1], at) &&
        parser_read_integer(p, found[1], at, 1, p->limits->max_width, &size))
        view->width = (uint32_t)size;
    msg_child_pointer(at, pointer, "height");
    if (parser_require(p, found[2], at) &&
        parser_read_integer(p, found[2], at, 1, p->limits->max_height, &size))
        view->height = (uint32_t)size;
    view->fps = p->limits->max_fps < 10 ? p->limits->max_fps : 10;
    msg_child_pointer(at, pointer, "fps");
    if (found[3] && cJSON_IsNumber(found[3]) && !(found[3]->valuedouble > 0))
        parser_fail(p, SKY_MSG_ERR_OUT_OF_RANGE, at, "must be greater than 0, got %.15g",
                    found[3]->valuedouble);
    else if (found[3])
        parser_read_number(p, found[3], at, 0, p->limits->max_fps, &view->fps);
    view->format = SKY_FRAME_FORMAT_PNG;
    msg_child_pointer(at, pointer, "format");
    if (found[5]) {
        int format = parser_read_enum(p, found[5], at, sky_msg_format_names,
                                      COUNT_OF(sky_msg_format_names));
        view->format = format > 0 ? (enum sky_frame_format)format : 0;
    }
    view->projection = SKY_VIEW_PROJECTION_PERSPECTIVE;
    msg_child_pointer(at, pointer, "projection");
    if (found[6]) {
        int projection = parser_read_enum(p, found[6], at, sky_msg_projection_names,
                                          COUNT_OF(sky_msg_projection_names));
        view->projection = projection > 0 ? (enum sky_view_projection)projection
                                          : SKY_VIEW_PROJECTION_PERSPECTIVE;
    }
    /* A panorama covers 360 x 180 degrees with square pixels. */
    if (view->projection == SKY_VIEW_PROJECTION_EQUIRECTANGULAR && view->width &&
        view->height && view->width != 2 * view->height) {
        msg_child_pointer(at, pointer, "width");
        parser_fail(p, SKY_MSG_ERR_INCONSISTENT, at,
                    "an equirectangular view is 2:1: width must be twice the height (%u), got %u",
                    view->height, view->width);
    }

    char group[SKY_MSG_POINTER_MAX];
    const cJSON *members[MAX_MEMBERS];
    msg_child_pointer(group, pointer, "camera");
    if (found[0] && !cJSON_IsObject(found[0])) {
        parser_fail(p, SKY_MSG_ERR_WRONG_TYPE, group, "expected an object, got %s",
                    sky_json_type_name(found[0]));
    } else if (found[0]) {
        parser_collect(p, found[0], group, camera_fields, COUNT_OF(camera_fields), members);
        bool *has[] = {&view->has_altitude_km, &view->has_yaw_deg, &view->has_pitch_deg,
                       &view->has_fov_deg};
        double *value[] = {&view->altitude_km, &view->yaw_deg, &view->pitch_deg, &view->fov_deg};
        for (size_t i = 0; i < COUNT_OF(camera_fields); i++) {
            char schema_path[64];
            snprintf(schema_path, sizeof schema_path, "camera.%s", camera_fields[i]);
            msg_child_pointer(at, group, camera_fields[i]);
            parser_read_schema_number(p, members[i], at, schema_path, has[i], value[i]);
        }
    }
    msg_child_pointer(group, pointer, "exposure");
    if (found[4] && !cJSON_IsObject(found[4])) {
        parser_fail(p, SKY_MSG_ERR_WRONG_TYPE, group, "expected an object, got %s",
                    sky_json_type_name(found[4]));
    } else if (found[4]) {
        parser_collect(p, found[4], group, exposure_fields, COUNT_OF(exposure_fields), members);
        const struct sky_field_desc *mode = sky_world_state_find_field("exposure.mode");
        msg_child_pointer(at, group, "mode");
        if (members[0] && mode) {
            int index = parser_read_enum(p, members[0], at, mode->enum_names,
                                         (size_t)mode->enum_count);
            view->has_exposure_mode = index >= 0;
            view->exposure_mode = index >= 0 ? (enum sky_exposure_mode)index : 0;
        }
        msg_child_pointer(at, group, "ev100");
        parser_read_schema_number(p, members[1], at, "exposure.ev100", &view->has_ev100,
                                  &view->ev100);
        msg_child_pointer(at, group, "compensation_ev");
        parser_read_schema_number(p, members[2], at, "exposure.compensation_ev",
                                  &view->has_compensation_ev, &view->compensation_ev);
    }
}

/* format, data (base64), and width and height (required for rgba8, checked for png). */
void msg_parse_weather_map(struct parser *p, const cJSON **found, struct sky_weather_map *map)
{
    int format = -1;
    if (parser_require(p, found[0], "/format"))
        format = parser_read_enum(p, found[0], "/format", weather_map_format_names,
                                  COUNT_OF(weather_map_format_names));
    int64_t side[2] = {0, 0};
    const char *side_pointers[2] = {"/width", "/height"};
    for (int i = 0; i < 2; i++) {
        const cJSON *item = found[2 + i];
        if (format == SKY_WEATHER_MAP_RGBA8 && !parser_require(p, item, side_pointers[i]))
            continue;
        if (item)
            parser_read_integer(p, item, side_pointers[i], 1, SKY_WEATHER_MAP_MAX_SIDE, &side[i]);
    }
    if (!parser_require(p, found[1], "/data"))
        return;
    if (!cJSON_IsString(found[1])) {
        parser_fail(p, SKY_MSG_ERR_WRONG_TYPE, "/data", "expected a base64 string, got %s",
                    sky_json_type_name(found[1]));
        return;
    }
    if (p->error->fields.total > 0 || format < 0)
        return;
    char reason[REASON_MAX];
    uint8_t *bytes;
    size_t length;
    if (!sky_base64_decode(found[1]->valuestring, strlen(found[1]->valuestring), &bytes, &length,
                           reason, sizeof reason)) {
        parser_fail(p, SKY_MSG_ERR_BAD_VALUE, "/data", "%s", reason);
        return;
    }
    if (!sky_weather_map_decode((enum sky_weather_map_format)format, bytes, length,
                                (uint32_t)side[0], (uint32_t)side[1], map, reason, sizeof reason))
        parser_fail(p, SKY_MSG_ERR_BAD_VALUE, "/data", "%s", reason);
    free(bytes);
}
