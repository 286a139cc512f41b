#include "cli_args.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "commands.h"
#include "config.h"
#include "error_text.h"
#include "field_errors.h"
#include "install_paths.h"
#include "presets.h"
#include "world_render.h"

void cli_common_init(struct cli_common *c)
{
    memset(c, 0, sizeof *c);
    proto_world_state_defaults(&c->state);
    const char *dir = getenv("SKYD_CONFIG_DIR");
    c->config_dir = dir && *dir ? dir : NULL;
    const char *device = getenv("SKYD_DEVICE");
    c->device = device && *device ? device : NULL;
    c->device_given = c->device != NULL;
    const char *validation = getenv("SKYD_VALIDATION");
    c->validation = validation && strcmp(validation, "1") == 0;
}

const char *cli_presets_dir(struct cli_common *c)
{
    if (c->config_dir)
        return c->config_dir;
    if (c->config_presets_dir[0])
        return c->config_presets_dir;
    if (!c->found_presets_dir[0]) /* found or not, a place to name */
        install_paths_find(INSTALL_PRESETS, c->found_presets_dir, sizeof c->found_presets_dir);
    return c->found_presets_dir;
}

const char *cli_take_value(int argc, char **argv, int *i)
{
    if (*i + 1 >= argc) {
        fprintf(stderr, "skyd: %s needs a value\n", argv[*i]);
        return NULL;
    }
    *i += 1;
    return argv[*i];
}

static void print_field_errors(const char *context, const struct proto_field_errors *errors)
{
    char buf[4096];
    proto_field_errors_format(errors, buf, sizeof buf);
    fprintf(stderr, "skyd: %s:\n%s\n", context, buf);
}

static int apply_set(struct cli_common *c, const char *assignment)
{
    const char *eq = strchr(assignment, '=');
    if (!eq || eq == assignment) {
        fprintf(stderr, "skyd: --set expects PATH=VALUE, got \"%s\"\n", assignment);
        return -1;
    }
    char path[256];
    size_t len = (size_t)(eq - assignment);
    if (len >= sizeof path) {
        fprintf(stderr, "skyd: --set: path too long\n");
        return -1;
    }
    memcpy(path, assignment, len);
    path[len] = '\0';
    struct proto_field_errors errors;
    if (!proto_world_state_set_path(&c->state, path, eq + 1, &errors)) {
        char context[300];
        snprintf(context, sizeof context, "--set %s rejected", path);
        print_field_errors(context, &errors);
        return -1;
    }
    return 0;
}

static int apply_preset(struct cli_common *c, const char *name)
{
    struct proto_field_errors errors = { 0 };
    error_text msg = "";
    if (!world_preset_apply(cli_presets_dir(c), "atmosphere", name, &c->state, &errors, msg,
                            sizeof msg)) {
        fprintf(stderr, "skyd: --preset %s: %s\n", name, msg);
        if (errors.count > 0)
            print_field_errors("preset fields", &errors);
        return -1;
    }
    return 0;
}

static int set_field(struct cli_common *c, const char *option, const char *path, const char *value)
{
    struct proto_field_errors errors;
    if (!proto_world_state_set_path(&c->state, path, value, &errors)) {
        char context[160];
        snprintf(context, sizeof context, "%s \"%s\" rejected", option, value);
        print_field_errors(context, &errors);
        return -1;
    }
    return 0;
}

int cli_parse_sim_option(int argc, char **argv, int *i, struct cli_common *c)
{
    static const struct {
        const char *option, *path;
    } fields[] = {
        { "--time", "clock.utc" },
        { "--lat", "location.latitude_deg" },
        { "--lon", "location.longitude_deg" },
    };
    const char *opt = argv[*i];
    const char *value;
    if (strcmp(opt, "--weather") == 0) {
        if (!(value = cli_take_value(argc, argv, i)))
            return -1;
        struct proto_field_errors errors = { 0 };
        error_text msg = "";
        if (!world_preset_apply(cli_presets_dir(c), "weather", value, &c->state, &errors, msg,
                                sizeof msg)) {
            fprintf(stderr, "skyd: --weather %s: %s\n", value, msg);
            return -1;
        }
        return 1;
    }
    for (size_t k = 0; k < sizeof fields / sizeof fields[0]; k++) {
        if (strcmp(opt, fields[k].option) != 0)
            continue;
        if (!(value = cli_take_value(argc, argv, i)) ||
            set_field(c, opt, fields[k].path, value) != 0)
            return -1;
        c->state.clock.sky_bodies = PROTO_BODIES_EPHEMERIS;
        return 1;
    }
    return 0;
}

/* The renderer's settings from a configuration file; flags and environment keep priority. */
static int apply_config_file(struct cli_common *c, const char *path)
{
    struct skyd_config config;
    struct proto_field_errors errors;
    error_text msg;
    if (!skyd_config_load(path, &config, &errors, msg, sizeof msg)) {
        fprintf(stderr, "skyd: --config: %s\n", msg);
        if (errors.count > 0)
            print_field_errors("configuration fields", &errors);
        return -1;
    }
    if (!c->device_given && config.render_device[0]) {
        snprintf(c->config_device, sizeof c->config_device, "%s", config.render_device);
        c->device = c->config_device;
    }
    c->validation = c->validation || config.render_validation;
    snprintf(c->config_presets_dir, sizeof c->config_presets_dir, "%s", config.presets_dir);
    return 0;
}

int cli_parse_common(int argc, char **argv, int *i, struct cli_common *c)
{
    const char *opt = argv[*i];
    const char *value;
    if (strcmp(opt, "--validation") == 0) {
        c->validation = true;
        return 1;
    }
    if (strcmp(opt, "--preset") == 0) {
        if (!(value = cli_take_value(argc, argv, i)))
            return -1;
        return apply_preset(c, value) == 0 ? 1 : -1;
    }
    if (strcmp(opt, "--set") == 0) {
        if (!(value = cli_take_value(argc, argv, i)))
            return -1;
        return apply_set(c, value) == 0 ? 1 : -1;
    }
    if (strcmp(opt, "--config") == 0) {
        if (!(value = cli_take_value(argc, argv, i)))
            return -1;
        return apply_config_file(c, value) == 0 ? 1 : -1;
    }
    if (strcmp(opt, "--config-dir") == 0) {
        if (!(value = cli_take_value(argc, argv, i)))
            return -1;
        c->config_dir = value;
        return 1;
    }
    if (strcmp(opt, "--device") == 0) {
        if (!(value = cli_take_value(argc, argv, i)))
            return -1;
        c->device = value;
        c->device_given = true;
        return 1;
    }
    return 0;
}

bool cli_parse_double(const char *option, const char *text, double min, double max, double *out)
{
    char *end = NULL;
    errno = 0;
    double v = strtod(text, &end);
    if (end == text || *end != '\0' || errno == ERANGE || !isfinite(v)) {
        fprintf(stderr, "skyd: %s: \"%s\" is not a finite number\n", option, text);
        return false;
    }
    if (v < min || v > max) {
        fprintf(stderr, "skyd: %s: %g is out of range [%g, %g]\n", option, v, min, max);
        return false;
    }
    *out = v;
    return true;
}

bool cli_parse_uint(const char *option, const char *text, unsigned min, unsigned max, unsigned *out)
{
    char *end = NULL;
    errno = 0;
    unsigned long v = strtoul(text, &end, 10);
    if (end == text || *end != '\0' || errno == ERANGE || text[0] == '-') {
        fprintf(stderr, "skyd: %s: \"%s\" is not a whole number\n", option, text);
        return false;
    }
    if (v < min || v > max) {
        fprintf(stderr, "skyd: %s: %lu is out of range [%u, %u]\n", option, v, min, max);
        return false;
    }
    *out = (unsigned)v;
    return true;
}

struct renderer_host *cli_create_renderer(struct cli_common *c)
{
    struct renderer_host_params params = {
        .device_preference = c->device,
        .validation = c->validation,
        .validation_message_counter = &c->validation_messages,
        .cloud_reference_spp = c->reference_spp,
    };
    error_text err;
    struct render_input input;
    world_render_input(&c->state, &input);
    struct renderer_host *r = renderer_host_create(&params, &input, err, sizeof err);
    if (!r)
        fprintf(stderr, "skyd: cannot start the Vulkan renderer\n");
    return r;
}

int cli_finish(struct cli_common *c, struct renderer_host **renderer, int status)
{
    renderer_host_destroy(renderer);
    if (c->validation && c->validation_messages > 0) {
        fprintf(stderr, "skyd: %u Vulkan validation messages\n", c->validation_messages);
        if (status == SKYD_EXIT_OK)
            status = SKYD_EXIT_VALIDATION;
    }
    return status;
}

int cli_parse_number_option(int argc, char **argv, int *i, const struct cli_number_option *options,
                            size_t count, void *target)
{
    for (size_t k = 0; k < count; k++) {
        if (strcmp(argv[*i], options[k].name) != 0)
            continue;
        const char *value = cli_take_value(argc, argv, i);
        double *number = (double *)((char *)target + options[k].value_offset);
        if (!value ||
            !cli_parse_double(options[k].name, value, options[k].min, options[k].max, number))
            return -1;
        *(bool *)((char *)target + options[k].flag_offset) = true;
        return 1;
    }
    return 0;
}
