/* skyd render: frames through the daemon's render path, written to PNG files; one frame, or a
 * time-lapse that advances the whole world simulation (clock, sun and moon, weather
 * transitions, autopilot, wind) between frames. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "cli_args.h"
#include "cli_observation.h"
#include "commands.h"
#include "field_errors.h"
#include "forecast.h"
#include "messages.h"
#include "jpeg_write.h"
#include "png_write.h"
#include "presets.h"
#include "world_files.h"
#include "world_render.h"
#include "world_sim.h"

#define MAX_DIMENSION 8192
#define MAX_FRAMES 100000
#define MAX_STEP_S 31557600.0 /* a year of simulated time between frames */
#define DEFAULT_REFERENCE_SPP 256
#define MAX_REFERENCE_SPP 65536

/* The time-lapse: frame count, simulated seconds between frames, and a weather transition
 * that starts with the first frame. */
struct lapse_args {
    unsigned frames;
    double step_s;
    bool has_step;
    const char *weather_to;
    double transition_s;
    bool has_transition;
};

static void usage(FILE *out)
{
    fprintf(out,
            "usage: skyd render --width W --height H --out FILE.png|FILE.jpg [options]\n"
            "  --preset NAME          apply atmosphere/NAME.json (earth, mars, ...)\n"
            "  --set PATH=VALUE       set a world-state field, e.g. sun.elevation_deg=5\n"
            "  --sun-azimuth DEG      shorthand for --set sun.azimuth_deg=DEG\n"
            "  --sun-elevation DEG    shorthand for --set sun.elevation_deg=DEG\n"
            "  --time ISO8601         simulated UTC time (2026-06-21T05:00:00Z); with --lat and\n"
            "  --lat DEG, --lon DEG   --lon the sun and moon follow the ephemeris (sky_bodies)\n"
            "  --weather NAME         apply weather/NAME.json (clear, storm, ...)\n"
            "  --projection NAME      perspective (default) or equirectangular: the whole sky,\n"
            "                         2:1, camera.yaw_deg at the centre (an environment map)\n"
            "  --format NAME          png (8-bit sRGB, default) or png16 (16-bit linear light;\n"
            "                         tEXt \"" PNG_LINEAR16_FULL_SCALE_KEY "\" = L of 65535)\n"
            "                         or jpeg (8-bit sRGB; the default for --out *.jpg, *.jpeg)\n"
            "  --quality N            JPEG quality 1..100 (default 85), with jpeg only\n"
            "  --weather-map FILE     a client weather map (PNG: r low coverage, g high coverage,\n"
            "                         b cloud type, a precipitation; sets weather.map_source)\n"
            "  --metar \"TEXT\"         the sky of a METAR or SPECI report, applied where it\n"
            "                         stands among the options (sets weather.source metar)\n"
            "  --forecast FILE        the sky of a GRIB2 forecast at the final location and\n"
            "                         clock; a time-lapse follows it from step to step\n"
            "  --frames N             a time-lapse of N frames; --out then holds one %%d or %%0Nd\n"
            "                         for the frame number (e.g. frames/f-%%03d.png)\n"
            "  --step-s S             simulated seconds between frames (default 60)\n"
            "  --weather-to NAME      a weather transition from the first frame to NAME ...\n"
            "  --transition-s S       ... over S simulated seconds (default: the whole lapse)\n"
            "  --config FILE          read render.device, render.validation and presets_dir\n"
            "                         from a skyd.json\n"
            "  --config-dir DIR       where presets live ($SKYD_CONFIG_DIR; default: the\n"
            "                         installed presets, else the source tree's config/)\n"
            "  --device NAME          cpu, gpu, an index or part of a device name\n"
            "  --validation           enable the Vulkan validation layer (exit 3 on messages)\n"
            "  --stats                print per-pass GPU times as JSON on stdout\n"
            "  --reference            path trace the clouds (the unbiased reference of the\n"
            "                         real-time clouds: slow, minutes per frame on a CPU)\n"
            "  --spp N                the reference's samples per pixel, 1..65536 (default 256)\n");
}

/* Splits an --out pattern at its one %d or %0Nd; false when it has none, another conversion,
 * or more than one. A lone frame may have no conversion at all. */
static bool split_pattern(const char *pattern, bool need_number, char *prefix, size_t capacity,
                          int *width, const char **suffix)
{
    const char *percent = strchr(pattern, '%');
    *width = -1;
    *suffix = "";
    if (!percent) {
        snprintf(prefix, capacity, "%s", pattern);
        return !need_number;
    }
    const char *p = percent + 1;
    int digits = 0;
    if (*p == '0') {
        p++;
        while (*p >= '0' && *p <= '9' && digits < 2)
            digits = digits * 10 + (*p++ - '0');
    }
    if (*p != 'd' || strchr(p + 1, '%') || (size_t)(percent - pattern) >= capacity)
        return false;
    memcpy(prefix, pattern, (size_t)(percent - pattern));
    prefix[percent - pattern] = '\0';
    *width = digits;
    *suffix = p + 1;
    return true;
}

static void frame_path(const char *prefix, int width, const char *suffix, unsigned frame, char *out,
                       size_t capacity)
{
    if (width < 0)
        snprintf(out, capacity, "%s", prefix);
    else
        snprintf(out, capacity, "%s%0*u%s", prefix, width, frame, suffix);
}

static int parse_lapse_option(int argc, char **argv, int *i, struct lapse_args *a)
{
    const char *opt = argv[*i];
    const char *value;
    if (strcmp(opt, "--frames") == 0) {
        if (!(value = cli_take_value(argc, argv, i)) ||
            !cli_parse_uint(opt, value, 1, MAX_FRAMES, &a->frames))
            return -1;
        return 1;
    }
    if (strcmp(opt, "--weather-to") == 0) {
        if (!(a->weather_to = cli_take_value(argc, argv, i)))
            return -1;
        if (!world_preset_name_is_valid(a->weather_to)) {
            fprintf(stderr, "skyd: --weather-to: \"%s\" is not a preset name\n", a->weather_to);
            return -1;
        }
        return 1;
    }
    static const struct cli_number_option options[] = {
        { "--step-s", 0.0, MAX_STEP_S, offsetof(struct lapse_args, step_s),
          offsetof(struct lapse_args, has_step) },
        { "--transition-s", 0.0, PROTO_MSG_MAX_TRANSITION_S,
          offsetof(struct lapse_args, transition_s), offsetof(struct lapse_args, has_transition) },
    };
    return cli_parse_number_option(argc, argv, i, options, sizeof options / sizeof options[0], a);
}

/* Starts the --weather-to transition on the parsed state. */
static bool start_lapse_transition(struct cli_common *common, const struct lapse_args *a)
{
    if (!a->weather_to)
        return true;
    struct proto_world_state target = common->state;
    char msg[1024];
    if (!world_preset_apply(cli_presets_dir(common), "weather", a->weather_to, &target, NULL, msg,
                            sizeof msg)) {
        fprintf(stderr, "skyd: --weather-to %s: %s\n", a->weather_to, msg);
        return false;
    }
    struct proto_weather_params goal;
    proto_weather_params_get(&target, &goal);
    double duration = a->has_transition ? a->transition_s : a->step_s * (a->frames - 1);
    common->state.weather.autopilot = PROTO_SWITCH_OFF;
    world_sim_start_transition(&common->state, &goal, duration);
    return true;
}

/* --weather-map: the PNG a client would send in set_weather_map. */
static bool load_weather_map(const char *path, struct proto_weather_map *map)
{
    char msg[640];
    if (world_files_read_weather_map(path, 16u << 20, map, msg, sizeof msg))
        return true;
    fprintf(stderr, "skyd render: --weather-map: %s\n", msg);
    return false;
}

static bool has_suffix(const char *s, const char *suffix)
{
    size_t n = strlen(s), m = strlen(suffix);
    return n >= m && strcasecmp(s + n - m, suffix) == 0;
}

/* An 8-bit PNG, a JPEG when quality is 1..100, or a 16-bit linear PNG when rgb16 (its buffer)
 * is given. */
static int write_frame(const char *path, const void *pixels, uint16_t *rgb16, int quality,
                       uint32_t width, uint32_t height, double exposure, char *err, size_t errlen)
{
    if (quality > 0)
        return jpeg_write_rgba8_file(path, pixels, width, height, quality, err, errlen);
    if (!rgb16)
        return png_write_rgba8_file(path, pixels, width, height, err, errlen);
    double full_scale = png_linear16_full_scale(exposure);
    png_linear16_quantize(pixels, (size_t)width * height, full_scale, rgb16);
    return png_write_linear16_file(path, rgb16, width, height, full_scale, err, errlen);
}

static void print_stats(const struct sky_render_stats *s)
{
    /* The exposure too, so that another render (a reference) can be exposed alike. */
    printf("{\"gpu_ms\":%.3f,\"wall_ms\":%.3f,\"exposure\":%.9g,\"metered_ev100\":%.4f,"
           "\"passes\":{",
           s->gpu_ms, s->wall_ms, s->exposure, s->metered_ev100);
    for (int i = 0; i < s->pass_count; i++)
        printf("%s\"%s\":%.3f", i ? "," : "", s->pass_names[i], s->pass_ms[i]);
    printf("}}\n");
}

int skyd_cmd_render(int argc, char **argv)
{
    struct cli_common common;
    cli_common_init(&common);
    unsigned width = 0, height = 0;
    const char *out_path = NULL, *weather_map_path = NULL, *forecast_path = NULL;
    bool stats_json = false, linear16 = false, reference = false;
    unsigned spp = 0;
    const char *format = NULL;
    unsigned quality = 0;
    enum sky_render_projection projection = SKY_RENDER_PROJECTION_PERSPECTIVE;
    struct lapse_args lapse = { .frames = 1, .step_s = 60.0 };
    for (int i = 0; i < argc; i++) {
        int rc = cli_parse_common(argc, argv, &i, &common);
        if (rc == 0)
            rc = cli_parse_sim_option(argc, argv, &i, &common);
        if (rc == 0)
            rc = parse_lapse_option(argc, argv, &i, &lapse);
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
        } else if (strcmp(opt, "--reference") == 0) {
            reference = true;
        } else if (strcmp(opt, "--spp") == 0) {
            if (!(value = cli_take_value(argc, argv, &i)) ||
                !cli_parse_uint(opt, value, 1, MAX_REFERENCE_SPP, &spp))
                return SKYD_EXIT_USAGE;
        } else if (strcmp(opt, "--width") == 0 || strcmp(opt, "--height") == 0) {
            if (!(value = cli_take_value(argc, argv, &i)) ||
                !cli_parse_uint(opt, value, 1, MAX_DIMENSION, opt[2] == 'w' ? &width : &height))
                return SKYD_EXIT_USAGE;
        } else if (strcmp(opt, "--projection") == 0) {
            if (!(value = cli_take_value(argc, argv, &i)))
                return SKYD_EXIT_USAGE;
            if (strcmp(value, "perspective") != 0 && strcmp(value, "equirectangular") != 0) {
                fprintf(stderr,
                        "skyd render: --projection: expected perspective or "
                        "equirectangular, got \"%s\"\n",
                        value);
                return SKYD_EXIT_USAGE;
            }
            projection = value[0] == 'e' ? SKY_RENDER_PROJECTION_EQUIRECTANGULAR
                                         : SKY_RENDER_PROJECTION_PERSPECTIVE;
        } else if (strcmp(opt, "--format") == 0) {
            if (!(value = cli_take_value(argc, argv, &i)))
                return SKYD_EXIT_USAGE;
            if (strcmp(value, "png") != 0 && strcmp(value, "png16") != 0 &&
                strcmp(value, "jpeg") != 0) {
                fprintf(stderr,
                        "skyd render: --format: expected png, png16 or jpeg, got "
                        "\"%s\"\n",
                        value);
                return SKYD_EXIT_USAGE;
            }
            format = value;
            linear16 = strcmp(value, "png16") == 0;
        } else if (strcmp(opt, "--quality") == 0) {
            if (!(value = cli_take_value(argc, argv, &i)) ||
                !cli_parse_uint(opt, value, JPEG_QUALITY_MIN, JPEG_QUALITY_MAX, &quality))
                return SKYD_EXIT_USAGE;
        } else if (strcmp(opt, "--weather-map") == 0) {
            if (!(weather_map_path = cli_take_value(argc, argv, &i)))
                return SKYD_EXIT_USAGE;
        } else if (strcmp(opt, "--metar") == 0) {
            if (!(value = cli_take_value(argc, argv, &i)) || !cli_apply_metar(&common.state, value))
                return SKYD_EXIT_USAGE;
        } else if (strcmp(opt, "--forecast") == 0) {
            if (!(forecast_path = cli_take_value(argc, argv, &i)))
                return SKYD_EXIT_USAGE;
        } else if (strcmp(opt, "--out") == 0) {
            if (!(out_path = cli_take_value(argc, argv, &i)))
                return SKYD_EXIT_USAGE;
        } else if (strcmp(opt, "--sun-azimuth") == 0 || strcmp(opt, "--sun-elevation") == 0) {
            if (!(value = cli_take_value(argc, argv, &i)))
                return SKYD_EXIT_USAGE;
            const char *path = opt[6] == 'a' ? "sun.azimuth_deg" : "sun.elevation_deg";
            struct proto_field_errors errors;
            if (!proto_world_state_set_path(&common.state, path, value, &errors)) {
                char buf[1024];
                proto_field_errors_format(&errors, buf, sizeof buf);
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

    if (spp && !reference) {
        fprintf(stderr, "skyd render: --spp is for the path-traced reference: give --reference\n");
        return SKYD_EXIT_USAGE;
    }
    if (reference)
        common.reference_spp = spp ? spp : DEFAULT_REFERENCE_SPP;

    if (!format && (has_suffix(out_path, ".jpg") || has_suffix(out_path, ".jpeg")))
        format = "jpeg";
    bool jpeg = format && strcmp(format, "jpeg") == 0;
    if (quality && !jpeg) {
        fprintf(stderr, "skyd render: --quality is for JPEG: give --format jpeg or --out "
                        "FILE.jpg\n");
        return SKYD_EXIT_USAGE;
    }
    if (jpeg && !quality)
        quality = JPEG_QUALITY_DEFAULT;
    if (projection == SKY_RENDER_PROJECTION_EQUIRECTANGULAR && width != 2 * height) {
        fprintf(stderr,
                "skyd render: an equirectangular image is 2:1: --width must be twice "
                "--height (%u), got %u\n",
                height, width);
        return SKYD_EXIT_USAGE;
    }
    if (lapse.has_transition && !lapse.weather_to) {
        fprintf(stderr, "skyd render: --transition-s needs --weather-to\n");
        return SKYD_EXIT_USAGE;
    }
    char prefix[1024];
    const char *suffix;
    int number_width;
    if (!split_pattern(out_path, lapse.frames > 1, prefix, sizeof prefix, &number_width, &suffix)) {
        fprintf(stderr, "skyd render: --out \"%s\": %s\n", out_path,
                lapse.frames > 1 ? "a time-lapse needs one %d or %0Nd for the frame number"
                                 : "only one %d or %0Nd may appear");
        return SKYD_EXIT_USAGE;
    }
    /* The forecast at the location and clock the options settled on. */
    struct forecast *forecast = forecast_path ? cli_open_forecast(&common.state, forecast_path)
                                              : NULL;
    struct proto_weather_map forecast_map = { 0 };
    if (forecast_path &&
        (!forecast || !cli_apply_forecast(&common.state, forecast, false, false, &forecast_map))) {
        forecast_free(forecast);
        proto_weather_map_free(&forecast_map);
        return SKYD_EXIT_USAGE;
    }
    if (forecast) /* the forecast's cover over the map's square, as the daemon follows it */
        common.state.weather.map_source = PROTO_WEATHER_MAP_FORECAST;
    if (!start_lapse_transition(&common, &lapse)) {
        forecast_free(forecast);
        proto_weather_map_free(&forecast_map);
        return SKYD_EXIT_USAGE;
    }
    struct proto_weather_map weather_map = { 0 };
    if (weather_map_path) {
        if (!load_weather_map(weather_map_path, &weather_map)) {
            forecast_free(forecast);
            proto_weather_map_free(&forecast_map);
            return SKYD_EXIT_USAGE;
        }
        common.state.weather.map_source = PROTO_WEATHER_MAP_CLIENT;
    }
    world_sim_settle(&common.state);

    size_t texels = (size_t)width * height;
    size_t bytes = texels * (linear16 ? 16 : 4);
    void *pixels = malloc(bytes);
    uint16_t *rgb16 = linear16 ? malloc(texels * 3 * sizeof *rgb16) : NULL;
    if (linear16 && !rgb16) {
        free(pixels);
        pixels = NULL;
    }
    struct renderer_host *renderer = pixels ? cli_create_renderer(&common) : NULL;
    struct render_input *input = malloc(sizeof *input);
    if (!input)
        cli_finish(&common, &renderer, SKYD_EXIT_FAILURE);
    if (!renderer) {
        forecast_free(forecast);
        free(input);
        proto_weather_map_free(&weather_map);
        proto_weather_map_free(&forecast_map);
        free(pixels);
        free(rgb16);
        return SKYD_EXIT_FAILURE;
    }
    struct sky_render_view view;
    struct sky_render_stats stats;
    int status = SKYD_EXIT_OK;
    char err[512], path[1200];
    world_sim_anchor_wind(&common.state); /* the lapse's wind runs from the state as given */
    const struct proto_msg_view asked = {
        .width = width,
        .height = height,
        .format = linear16 ? PROTO_FRAME_FORMAT_PNG16 : PROTO_FRAME_FORMAT_PNG,
        .projection = projection == SKY_RENDER_PROJECTION_EQUIRECTANGULAR
                          ? PROTO_VIEW_PROJECTION_EQUIRECTANGULAR
                          : PROTO_VIEW_PROJECTION_PERSPECTIVE,
    };
    for (unsigned frame = 0; frame < lapse.frames && status == SKYD_EXIT_OK; frame++) {
        if (frame > 0) {
            world_sim_advance(&common.state, lapse.step_s);
            /* The weather follows the forecast, held at its last step beyond it. */
            if (forecast &&
                !cli_apply_forecast(&common.state, forecast, true, true, &forecast_map)) {
                status = SKYD_EXIT_FAILURE;
                break;
            }
        }
        world_render_input(&common.state, input);
        bool forecast_selected = common.state.weather.map_source == PROTO_WEATHER_MAP_FORECAST;
        input->client_map = forecast_selected ? &forecast_map : &weather_map;
        input->map_generation = forecast_selected ? 2 + frame : weather_map.rgba ? 1 : 0;
        world_render_view(input, &asked, &view);
        frame_path(prefix, number_width, suffix, frame, path, sizeof path);
        if (renderer_host_render(renderer, input, &view, false, pixels, bytes, &stats) != 0) {
            fprintf(stderr, "skyd render: rendering failed\n");
            status = SKYD_EXIT_FAILURE;
        } else if (write_frame(path, pixels, rgb16, (int)quality, width, height, stats.exposure,
                               err, sizeof err) != 0) {
            fprintf(stderr, "skyd render: %s\n", err);
            status = SKYD_EXIT_FAILURE;
        } else {
            if (stats_json)
                print_stats(&stats);
            else
                printf("%s\n", path);
            fprintf(stderr, "skyd render: %ux%u in %.1f ms (GPU %.1f ms), sun at %.2f deg\n", width,
                    height, stats.wall_ms, stats.gpu_ms, common.state.sun.elevation_deg);
        }
    }
    status = cli_finish(&common, &renderer, status);
    forecast_free(forecast);
    free(input);
    proto_weather_map_free(&weather_map);
    proto_weather_map_free(&forecast_map);
    free(pixels);
    free(rgb16);
    return status;
}
