/* libFuzzer target: a configuration file's text through the loader's parser and validator
 * (server/host/config.c), initial_state included. */
#include "config.h"
#include "field_errors.h"

#include <stdint.h>
#include <stdlib.h>

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    struct skyd_config config;
    struct proto_field_errors errors;
    char msg[512];
    if (skyd_config_parse((const char *)data, size, "fuzz.json", &config, &errors, msg,
                          sizeof msg)) {
        struct proto_msg_limits limits;
        skyd_config_limits(&config, &limits);
    } else {
        char text[4096];
        proto_field_errors_format(&errors, text, sizeof text);
    }
    return 0;
}
