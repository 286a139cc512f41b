/* libFuzzer target: one client text message through the protocol parser and validator, and
 * for a valid set its patch onto a live state (the daemon's path), then the replies built
 * from what was parsed. Any crash or sanitizer report is a failure. */
#include "field_errors.h"
#include "messages.h"
#include "world_state.h"

#include <cjson/cJSON.h>

#include <stdint.h>
#include <stdlib.h>

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    struct sky_msg_limits limits;
    sky_msg_limits_default(&limits);
    struct sky_client_msg msg;
    struct sky_msg_parse_error error;
    enum sky_msg_error_code code = sky_msg_parse((const char *)data, size, &limits, &msg, &error);
    char *reply = NULL;
    if (code != SKY_MSG_OK) {
        reply = sky_msg_build_parse_error(&msg, &error);
    } else if (msg.type == SKY_MSG_SET) {
        struct sky_world_state state;
        struct sky_field_errors errors;
        sky_world_state_defaults(&state);
        struct sky_world_state before = state;
        if (sky_world_state_apply_patch(&state, msg.set.patch, &errors)) {
            char changed[64][SKY_MSG_POINTER_MAX];
            size_t count = sky_msg_state_diff(&before, &state, changed, 64);
            (void)count;
            reply = sky_msg_build_state(&msg.id, &state);
        } else {
            reply = sky_msg_build_error(&msg.id, SKY_MSG_ERR_BAD_VALUE, "rejected", &errors);
        }
    } else if (msg.type == SKY_MSG_SUBSCRIBE || msg.type == SKY_MSG_SNAPSHOT) {
        reply = sky_msg_build_subscribed(&msg.id, 1, &msg.view);
        struct sky_world_state state;
        sky_world_state_defaults(&state);
        struct sky_camera_state camera;
        struct sky_exposure_state exposure;
        sky_msg_view_resolve(&msg.view, &state, &camera, &exposure);
    } else {
        reply = sky_msg_build_ack(&msg.id, 1, SKY_ROLE_NONE);
    }
    if (reply) {
        cJSON *parsed = cJSON_Parse(reply); /* every reply is valid JSON */
        if (!parsed)
            abort();
        cJSON_Delete(parsed);
    }
    free(reply);
    sky_client_msg_free(&msg);
    return 0;
}
