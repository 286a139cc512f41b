/* skyd schema [state|config|messages]: the JSON Schema (2020-12) of the world state, of the
 * configuration file or of the client messages, generated from the field tables that validate
 * them, on stdout. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cjson/cJSON.h>

#include "commands.h"
#include "config.h"
#include "messages.h"
#include "world_state.h"

static void usage(FILE *out)
{
    fprintf(out,
            "usage: skyd schema [state|config|messages]\n"
            "Prints the JSON Schema (draft 2020-12) of the world state (the default), of\n"
            "the configuration file or of the client messages (with the default limits):\n"
            "every field's type, range, enum names, unit (x-unit), default and description.\n");
}

int skyd_cmd_schema(int argc, char **argv)
{
    bool config = argc == 1 && strcmp(argv[0], "config") == 0;
    bool messages = argc == 1 && strcmp(argv[0], "messages") == 0;
    bool state = argc == 0 || (argc == 1 && strcmp(argv[0], "state") == 0);
    if (argc == 1 && (strcmp(argv[0], "--help") == 0 || strcmp(argv[0], "-h") == 0)) {
        usage(stdout);
        return SKYD_EXIT_OK;
    }
    if (!config && !state && !messages) {
        usage(stderr);
        return SKYD_EXIT_USAGE;
    }
    struct proto_msg_limits limits;
    proto_msg_limits_default(&limits);
    cJSON *schema = config     ? skyd_config_json_schema()
                    : messages ? proto_msg_json_schema(&limits)
                               : proto_world_state_json_schema();
    char *text = schema && proto_json_exact_numbers(schema) ? cJSON_Print(schema) : NULL;
    cJSON_Delete(schema);
    if (!text) {
        fprintf(stderr, "skyd schema: out of memory\n");
        return SKYD_EXIT_FAILURE;
    }
    puts(text);
    free(text);
    return SKYD_EXIT_OK;
}
