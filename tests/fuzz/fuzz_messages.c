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
    struct proto_msg_limits limits;
    proto_msg_limits_default(&limits);
    struct proto_client_msg msg;
    struct proto_msg_parse_error error;
    enum proto_msg_error_code code = proto_msg_parse((const char *)data, size, &limits, &msg,
                                                     &error);
    char *reply = NULL;
    if (code != PROTO_MSG_OK) {
        reply = proto_msg_build_parse_error(&msg, &error);
    } else if (msg.type == PROTO_MSG_SET) {
        struct proto_world_state state;
        struct proto_field_errors errors;
        proto_world_state_defaults(&state);
        struct proto_world_state before = state;
        if (proto_world_state_apply_patch(&state, msg.set.patch, &errors)) {
            char changed[64][PROTO_MSG_POINTER_MAX];
            size_t count = proto_msg_state_diff(&before, &state, changed, 64);
            (void)count;
            reply = proto_msg_build_state(&msg.id, &state);
        } else {
            reply = proto_msg_build_error(&msg.id, PROTO_MSG_ERR_BAD_VALUE, "rejected", &errors);
        }
    } else if (msg.type == PROTO_MSG_SUBSCRIBE || msg.type == PROTO_MSG_SNAPSHOT) {
        reply = proto_msg_build_subscribed(&msg.id, 1, &msg.view);
        struct proto_world_state state;
        proto_world_state_defaults(&state);
        struct proto_camera_state camera;
        struct proto_exposure_state exposure;
        proto_msg_view_resolve(&msg.view, &state, &camera, &exposure);
    } else {
        reply = proto_msg_build_ack(&msg.id, 1, PROTO_ROLE_NONE);
    }
    if (reply) {
        cJSON *parsed = cJSON_Parse(reply); /* every reply is valid JSON */
        if (!parsed)
            abort();
        cJSON_Delete(parsed);
    }
    free(reply);
    proto_client_msg_free(&msg);
    return 0;
}
