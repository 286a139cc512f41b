/* skyd subcommands; each takes the arguments after its name and returns the exit status. */
#ifndef SKYD_COMMANDS_H
#define SKYD_COMMANDS_H

int skyd_cmd_serve(int argc, char **argv);
int skyd_cmd_render(int argc, char **argv);
int skyd_cmd_probe(int argc, char **argv);
int skyd_cmd_schema(int argc, char **argv);
int skyd_cmd_metar(int argc, char **argv);

/* Exit statuses scripts can rely on. */
#define SKYD_EXIT_OK 0
#define SKYD_EXIT_FAILURE 1    /* rendering or I/O failed */
#define SKYD_EXIT_USAGE 2      /* bad command line: unknown option, bad value, bad --set */
#define SKYD_EXIT_VALIDATION 3 /* finished, but the Vulkan validation layer reported problems */

#endif
