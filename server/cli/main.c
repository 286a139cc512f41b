/* skyd: sky and cloud weather simulator. Subcommand dispatch. */
#include <stdio.h>
#include <string.h>

#include "commands.h"

static void usage(FILE *out)
{
    fprintf(out,
            "skyd %s - physically based sky and weather simulator service\n"
            "usage: skyd [<command>] [options]\n"
            "  serve    the daemon (the default)       (skyd serve --help)\n"
            "  render   render one frame to a PNG      (skyd render --help)\n"
            "  probe    print physical quantities      (skyd probe --help)\n"
            "  schema   print the world state's JSON Schema\n"
            "  metar    decode a METAR or SPECI report (skyd metar --help)\n"
            "  version  print the version\n",
            SKYD_VERSION);
}

int main(int argc, char **argv)
{
    if (argc >= 2 && (strcmp(argv[1], "--help") == 0 || strcmp(argv[1], "-h") == 0 ||
                      strcmp(argv[1], "help") == 0)) {
        usage(stdout);
        return SKYD_EXIT_OK;
    }
    /* No command, or options straight away: the daemon. */
    if (argc < 2 || argv[1][0] == '-')
        return skyd_cmd_serve(argc - 1, argv + 1);
    if (strcmp(argv[1], "serve") == 0)
        return skyd_cmd_serve(argc - 2, argv + 2);
    if (strcmp(argv[1], "render") == 0)
        return skyd_cmd_render(argc - 2, argv + 2);
    if (strcmp(argv[1], "probe") == 0)
        return skyd_cmd_probe(argc - 2, argv + 2);
    if (strcmp(argv[1], "schema") == 0)
        return skyd_cmd_schema(argc - 2, argv + 2);
    if (strcmp(argv[1], "metar") == 0)
        return skyd_cmd_metar(argc - 2, argv + 2);
    if (strcmp(argv[1], "version") == 0 || strcmp(argv[1], "--version") == 0) {
        printf("skyd %s\n", SKYD_VERSION);
        return SKYD_EXIT_OK;
    }
    fprintf(stderr, "skyd: unknown command \"%s\"\n", argv[1]);
    usage(stderr);
    return SKYD_EXIT_USAGE;
}
