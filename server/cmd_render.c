/* skyd render: one frame through the daemon's render path, written to a PNG. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli_args.h"
#include "commands.h"
#include "png_write.h"
#include "world_render.h"

#define MAX_DIMENSION 8192

static void usage(FILE *out)
{
    fprintf(out,
            "usage: skyd render --width W --height H --out FILE.png [options]\n"
            "  --preset NAME          apply config/atmosphere/NAME.json (earth, mars, ...)\n"
            "  --set PATH=VALUE       set a world-state field, e.g. sun.elevation_deg=5\n"
            "  --sun-azimuth DEG      shorthand for --set sun.azimuth_deg=DEG\n"
            "  --sun-elevation DEG    shorthand for --set sun.elevation_deg=DEG\n"
            "  --config FILE          read render.device and render.validation from a skyd.json\n"
            "  --config-dir DIR       where presets live (default: the source tree's config/)\n"
            "  --device NAME          cpu, gpu, an index or part of a device name\n"
            "  --validation           enable the Vulkan validation layer (exit 3 on messages)\n"
            "  --stats                print per-pass GPU times as JSON on stdout\n");
}

static void print_stats(const struct sky_render_stats *s)
{
    printf("{\"gpu_ms\":%.3f,\"wall_ms\":%.3f,\"passes\":{", s->gpu_ms, s->wall_ms);
    for (int i = 0; i < s->pass_count; i++)
        printf("%s\"%s\":%.3f", i ? "," : "", s->pass_names[i], s->pass_ms[i]);
    printf("}}\n");
}

int skyd_cmd_render(int argc, char **argv)
{
    struct cli_common common;
    cli_common_init(&common);
    unsigned width = 0, height = 0;
    const char *out_path = NULL;
    bool stats_json = false;
    for (int i = 0; i < argc; i++) {
        int rc = cli_parse_common(argc, argv, &i, &common);
        if (rc < 0)
            return SKYD_EXIT_USAGE;
        if (rc > 0)
            continue;
        const char *opt = argv[i];
        const char *value = NULL;
        if (strcmp(opt, "--help") == 0 || strcmp(opt, "-h") == 0) {
            usage(stdout);
            return SKYD_EXIT_OK;
        } else if (strcmp(opt, "--stats") == 0) {
            stats_json = true;
        } else if (strcmp(opt, "--width") == 0 || strcmp(opt, "--height") == 0) {
            if (!(value = cli_take_value(argc, argv, &i)) ||
                !cli_parse_uint(opt, value, 1, MAX_DIMENSION, opt[2] == 'w' ? &width : &height))
                return SKYD_EXIT_USAGE;
        } else if (strcmp(opt, "--out") == 0) {
            if (!(out_path = cli_take_value(argc, argv, &i)))
                return SKYD_EXIT_USAGE;
        } else if (strcmp(opt, "--sun-azimuth") == 0 || strcmp(opt, "--sun-elevation") == 0) {
            if (!(value = cli_take_value(argc, argv, &i)))
                return SKYD_EXIT_USAGE;
            const char *path = opt[6] == 'a' ? "sun.azimuth_deg" : "sun.elevation_deg";
            struct sky_field_errors errors;
            if (!sky_world_state_set_path(&common.state, path, value, &errors)) {
                char buf[1024];
                sky_field_errors_format(&errors, buf, sizeof buf);
                fprintf(stderr, "skyd: %s: %s\n", opt, buf);
                return SKYD_EXIT_USAGE;
            }
        } else {
            fprintf(stderr, "skyd render: unknown option \"%s\"\n", opt);
            usage(stderr);
            return SKYD_EXIT_USAGE;
        }
    }
    if (!width || !height || !out_path) {
        fprintf(stderr, "skyd render: --width, --height and --out are required\n");
        usage(stderr);
        return SKYD_EXIT_USAGE;
    }

    size_t bytes = (size_t)width * height * 4;
    uint8_t *pixels = malloc(bytes);
    if (!pixels)
        return SKYD_EXIT_FAILURE;
    struct sky_renderer *renderer = cli_create_renderer(&common);
    if (!renderer) {
        free(pixels);
        return SKYD_EXIT_FAILURE;
    }
    struct sky_render_atmosphere atmosphere;
    struct sky_render_view view;
    struct sky_render_stats stats;
    world_to_render_atmosphere(&common.state, &atmosphere);
    world_to_render_view(&common.state, width, height, SKY_RENDER_OUTPUT_SRGB8, &view);
    struct sky_render_night night;
    world_to_render_night(&common.state, &night);
    sky_renderer_set_night(renderer, &night);
    int status = SKYD_EXIT_OK;
    char err[512];
    if (sky_renderer_render(renderer, &atmosphere, &view, pixels, bytes, &stats) != 0) {
        fprintf(stderr, "skyd render: rendering failed\n");
        status = SKYD_EXIT_FAILURE;
    } else if (png_write_rgba8_file(out_path, pixels, width, height, err, sizeof err) != 0) {
        fprintf(stderr, "skyd render: %s\n", err);
        status = SKYD_EXIT_FAILURE;
    } else {
        if (stats_json)
            print_stats(&stats);
        else
            printf("%s\n", out_path);
        fprintf(stderr, "skyd render: %ux%u in %.1f ms (GPU %.1f ms)\n", width, height,
                stats.wall_ms, stats.gpu_ms);
    }
    status = cli_finish(&common, &renderer, status);
    free(pixels);
    return status;
}
