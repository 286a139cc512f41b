/* skyd schema: the world state's JSON Schema (2020-12), generated from the field table that
 * validates every `set`, on stdout. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cjson/cJSON.h>

#include "commands.h"
#include "world_state.h"

int skyd_cmd_schema(int argc, char **argv)
{
    if (argc > 0) {
        bool help = strcmp(argv[0], "--help") == 0 || strcmp(argv[0], "-h") == 0;
        fprintf(help ? stdout : stderr,
                "usage: skyd schema\n"
                "Prints the world state's JSON Schema (draft 2020-12): every field's type, range,\n"
                "enum names, unit (x-unit), default and description.\n");
        return help ? SKYD_EXIT_OK : SKYD_EXIT_USAGE;
    }
    cJSON *schema = sky_world_state_json_schema();
    char *text = schema ? cJSON_Print(schema) : NULL;
    cJSON_Delete(schema);
    if (!text) {
        fprintf(stderr, "skyd schema: out of memory\n");
        return SKYD_EXIT_FAILURE;
    }
    puts(text);
    free(text);
    return SKYD_EXIT_OK;
}
