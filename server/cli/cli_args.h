/* Command-line options shared by `skyd render` and `skyd probe`: the world state built from
 * presets and --set assignments in command-line order, and the renderer's device options. */
#ifndef SKYD_CLI_ARGS_H
#define SKYD_CLI_ARGS_H

#include <stdbool.h>
#include <stddef.h>

#include "renderer_host.h"
#include "sky_renderer.h"
#include "world_state.h"

struct cli_common {
    /* The presets' folder (atmosphere/, weather/): --config-dir or $SKYD_CONFIG_DIR, else the
     * presets_dir of a --config given before, else install_paths.h's. Use cli_presets_dir. */
    const char *config_dir;
    char config_presets_dir[4096];
    char found_presets_dir[4096];
    /* Device: --device, else $SKYD_DEVICE, else the config file's render.device (--config). */
    const char *device;
    bool device_given; /* by --device or the environment: a config file does not override */
    char config_device[64];
    bool validation;              /* --validation, $SKYD_VALIDATION=1 */
    unsigned validation_messages; /* counted by the renderer, through its destruction */
    struct proto_world_state state;
    unsigned reference_spp; /* skyd render --reference: path-traced clouds (0: off) */
};

void cli_common_init(struct cli_common *c);

/* The folder presets are read from now (see config_dir above); where it is looked up and
 * nothing is found, the installed folder, so that a missing preset's message names it. */
const char *cli_presets_dir(struct cli_common *c);

/* Tries the option at argv[*i] (--preset, --set, --config, --config-dir, --device,
 * --validation),
 * advancing *i past its value. Returns 1 when consumed, 0 when not a common option, -1 after
 * printing an error that names the problem. */
int cli_parse_common(int argc, char **argv, int *i, struct cli_common *c);

/* Tries the world-simulation options of `skyd render`: --time ISO8601 (clock.utc), --lat DEG,
 * --lon DEG (location); each switches clock.sky_bodies to ephemeris. --weather NAME applies
 * config/weather/NAME.json at once. Same return values as cli_parse_common. */
int cli_parse_sim_option(int argc, char **argv, int *i, struct cli_common *c);

/* Takes the value of option argv[*i] (advancing *i), or prints "OPTION needs a value". */
const char *cli_take_value(int argc, char **argv, int *i);

/* Parses a finite number within [min, max]; prints "OPTION: ..." and returns false if not. */
bool cli_parse_double(const char *option, const char *text, double min, double max, double *out);
bool cli_parse_uint(const char *option, const char *text, unsigned min, unsigned max,
                    unsigned *out);

/* A numeric option stored into a struct: its value at value_offset (a double), a bool set at
 * flag_offset when given. */
struct cli_number_option {
    const char *name;
    double min, max;
    size_t value_offset, flag_offset;
};

/* Tries argv[*i] against a table of numeric options writing into *target; 1 consumed, 0 not
 * one of them, -1 after printing an error that names the option. */
int cli_parse_number_option(int argc, char **argv, int *i, const struct cli_number_option *options,
                            size_t count, void *target);

/* Creates the renderer for these options with the state's LUT sizes; NULL after a message. */
struct renderer_host *cli_create_renderer(struct cli_common *c);

/* Destroys the renderer; with validation on, reports its messages and turns a successful
 * status into SKYD_EXIT_VALIDATION (3) when there were any. Returns the final status. */
int cli_finish(struct cli_common *c, struct renderer_host **renderer, int status);

#endif
