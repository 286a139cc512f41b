/* skyd metar "TEXT": decodes a METAR or SPECI report (protocol/metar.h) and prints it as JSON
 * on stdout, with a one-line summary on stderr. A refused report is a bad command-line value:
 * the error names the offending group, and the exit status is 2. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cjson/cJSON.h>

#include "commands.h"
#include "messages.h"
#include "metar.h"

static void usage(FILE *out)
{
    fprintf(out, "usage: skyd metar \"METAR EGLL 281250Z 24015G28KT 9999 -SHRA FEW012 BKN025CB "
                 "12/08 Q1002 NOSIG=\"\n"
                 "Decodes one METAR or SPECI report (WMO No. 306 FM 15, ICAO Annex 3): prints it\n"
                 "as JSON on stdout (clouds with coverage and base in metres, visibility and its\n"
                 "extinction, weather, wind in m/s, relative humidity) and a summary on stderr.\n"
                 "Several arguments are joined by blanks. Exit status 2 when the report is\n"
                 "refused; the message names the offending group and its offset.\n");
}

int skyd_cmd_metar(int argc, char **argv)
{
    if (argc == 1 && (strcmp(argv[0], "--help") == 0 || strcmp(argv[0], "-h") == 0)) {
        usage(stdout);
        return SKYD_EXIT_OK;
    }
    if (argc < 1) {
        usage(stderr);
        return SKYD_EXIT_USAGE;
    }
    /* The report may come as one argument or as its groups unquoted. */
    char text[PROTO_METAR_MAX_LENGTH + 2];
    size_t length = 0;
    for (int i = 0; i < argc; i++) {
        size_t n = strlen(argv[i]);
        if (length + n + 1 > sizeof text - 1) {
            fprintf(stderr, "skyd metar: the report is longer than %d characters\n",
                    PROTO_METAR_MAX_LENGTH);
            return SKYD_EXIT_USAGE;
        }
        if (i)
            text[length++] = ' ';
        memcpy(text + length, argv[i], n);
        length += n;
    }
    text[length] = '\0';
    struct proto_metar_report report;
    struct proto_metar_error error;
    if (!proto_metar_decode(text, length, &report, &error)) {
        fprintf(stderr, "skyd metar: %s\n", error.message);
        return SKYD_EXIT_USAGE;
    }
    cJSON *json = proto_metar_to_json(&report);
    char *printed = json && proto_json_exact_numbers(json) ? cJSON_Print(json) : NULL;
    cJSON_Delete(json);
    if (!printed) {
        fprintf(stderr, "skyd metar: out of memory\n");
        return SKYD_EXIT_FAILURE;
    }
    puts(printed);
    free(printed);
    char summary[512];
    proto_metar_summary(&report, summary, sizeof summary);
    fprintf(stderr, "%s\n", summary);
    return SKYD_EXIT_OK;
}
