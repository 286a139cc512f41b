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
#include "error_text.h"
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

/* The widest %0Nd split_pattern takes: its digit loop stops at a value of 2 or more. */
#define FRAME_NUMBER_MAX_WIDTH 19

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
        snprintf(out, capacity, "%s%0*u%s", prefix,
                 width < FRAME_NUMBER_MAX_WIDTH ? width : FRAME_NUMBER_MAX_WIDTH, frame, suffix);
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
    error_text msg;
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
    error_text msg;
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

/* Everything the command line settles before the first frame. */
struct render_args {
    struct cli_common common;
    struct lapse_args lapse;
    unsigned width, height, spp, quality;
    const char *out_path, *weather_map_path, *forecast_path, *format;
    bool stats_json, linear16, reference, help;
    enum sky_render_projection projection;
};

/* One of `skyd render`'s own options: 0 taken, -1 after a message. */
struct render_option {
    const char *name;
    bool takes_value;
    int (*take)(struct render_args *a, const char *opt, const char *value);
};

static int take_help(struct render_args *a, const char *opt, const char *value)
{
    (void)opt, (void)value;
    a->help = true;
    return 0;
}

static int take_stats(struct render_args *a, const char *opt, const char *value)
{
    (void)opt, (void)value;
    a->stats_json = true;
    return 0;
}

static int take_reference(struct render_args *a, const char *opt, const char *value)
{
    (void)opt, (void)value;
    a->reference = true;
    return 0;
}

static int take_spp(struct render_args *a, const char *opt, const char *value)
{
    return cli_parse_uint(opt, value, 1, MAX_REFERENCE_SPP, &a->spp) ? 0 : -1;
}

static int take_size(struct render_args *a, const char *opt, const char *value)
{
    unsigned *size = opt[2] == 'w' ? &a->width : &a->height;
    return cli_parse_uint(opt, value, 1, MAX_DIMENSION, size) ? 0 : -1;
}

static int take_projection(struct render_args *a, const char *opt, const char *value)
{
    (void)opt;
    if (strcmp(value, "perspective") != 0 && strcmp(value, "equirectangular") != 0) {
        fprintf(stderr,
                "skyd render: --projection: expected perspective or equirectangular, got "
                "\"%s\"\n",
                value);
        return -1;
    }
    a->projection = value[0] == 'e' ? SKY_RENDER_PROJECTION_EQUIRECTANGULAR
                                    : SKY_RENDER_PROJECTION_PERSPECTIVE;
    return 0;
}

static int take_format(struct render_args *a, const char *opt, const char *value)
{
    (void)opt;
    if (strcmp(value, "png") != 0 && strcmp(value, "png16") != 0 && strcmp(value, "jpeg") != 0) {
        fprintf(stderr, "skyd render: --format: expected png, png16 or jpeg, got \"%s\"\n", value);
        return -1;
    }
    a->format = value;
    a->linear16 = strcmp(value, "png16") == 0;
    return 0;
}

static int take_quality(struct render_args *a, const char *opt, const char *value)
{
    return cli_parse_uint(opt, value, JPEG_QUALITY_MIN, JPEG_QUALITY_MAX, &a->quality) ? 0 : -1;
}

static int take_path(struct render_args *a, const char *opt, const char *value)
{
    const char **slot = strcmp(opt, "--out") == 0        ? &a->out_path
                        : strcmp(opt, "--forecast") == 0 ? &a->forecast_path
                                                         : &a->weather_map_path;
    *slot = value;
    return 0;
}

/* Applied where it stands among the options, as --set is. */
static int take_metar(struct render_args *a, const char *opt, const char *value)
{
    (void)opt;
    return cli_apply_metar(&a->common.state, value) ? 0 : -1;
}

static int take_sun_angle(struct render_args *a, const char *opt, const char *value)
{
    const char *path = opt[6] == 'a' ? "sun.azimuth_deg" : "sun.elevation_deg";
    struct proto_field_errors errors;
    if (proto_world_state_set_path(&a->common.state, path, value, &errors))
        return 0;
    char buf[1024];
    proto_field_errors_format(&errors, buf, sizeof buf);
    fprintf(stderr, "skyd: %s: %s\n", opt, buf);
    return -1;
}

static const struct render_option render_options[] = {
    { "--help", false, take_help },
    { "-h", false, take_help },
    { "--stats", false, take_stats },
    { "--reference", false, take_reference },
    { "--spp", true, take_spp },
    { "--width", true, take_size },
    { "--height", true, take_size },
    { "--projection", true, take_projection },
    { "--format", true, take_format },
    { "--quality", true, take_quality },
    { "--weather-map", true, take_path },
    { "--forecast", true, take_path },
    { "--out", true, take_path },
    { "--metar", true, take_metar },
    { "--sun-azimuth", true, take_sun_angle },
    { "--sun-elevation", true, take_sun_angle },
};

/* One option at argv[*i] (its value too): 1 taken, -1 after a message. */
static int take_option(int argc, char **argv, int *i, struct render_args *a)
{
    int rc = cli_parse_common(argc, argv, i, &a->common);
    if (rc == 0)
        rc = cli_parse_sim_option(argc, argv, i, &a->common);
    if (rc == 0)
        rc = parse_lapse_option(argc, argv, i, &a->lapse);
    if (rc != 0)
        return rc;
    const char *opt = argv[*i];
    for (size_t k = 0; k < sizeof render_options / sizeof render_options[0]; k++) {
        const struct render_option *o = &render_options[k];
        if (strcmp(opt, o->name) != 0)
            continue;
        const char *value = o->takes_value ? cli_take_value(argc, argv, i) : NULL;
        if (o->takes_value && !value)
            return -1;
        return o->take(a, opt, value) == 0 ? 1 : -1;
    }
    fprintf(stderr, "skyd render: unknown option \"%s\"\n", opt);
    usage(stderr);
    return -1;
}

/* The options that only make sense together; false after a message. */
static bool check_args(struct render_args *a)
{
    if (!a->width || !a->height || !a->out_path) {
        fprintf(stderr, "skyd render: --width, --height and --out are required\n");
        usage(stderr);
        return false;
    }
    if (a->spp && !a->reference) {
        fprintf(stderr, "skyd render: --spp is for the path-traced reference: give --reference\n");
        return false;
    }
    if (a->reference)
        a->common.reference_spp = a->spp ? a->spp : DEFAULT_REFERENCE_SPP;
    if (!a->format && (has_suffix(a->out_path, ".jpg") || has_suffix(a->out_path, ".jpeg")))
        a->format = "jpeg";
    bool jpeg = a->format && strcmp(a->format, "jpeg") == 0;
    if (a->quality && !jpeg) {
        fprintf(stderr, "skyd render: --quality is for JPEG: give --format jpeg or --out "
                        "FILE.jpg\n");
        return false;
    }
    if (jpeg && !a->quality)
        a->quality = JPEG_QUALITY_DEFAULT;
    if (a->projection == SKY_RENDER_PROJECTION_EQUIRECTANGULAR && a->width != 2 * a->height) {
        fprintf(stderr,
                "skyd render: an equirectangular image is 2:1: --width must be twice "
                "--height (%u), got %u\n",
                a->height, a->width);
        return false;
    }
    if (a->lapse.has_transition && !a->lapse.weather_to) {
        fprintf(stderr, "skyd render: --transition-s needs --weather-to\n");
        return false;
    }
    return true;
}

/* The weather sources the frames read besides the state: a forecast, a client map. */
struct render_maps {
    struct forecast *forecast;
    struct proto_weather_map forecast_map, weather_map;
};

static void render_maps_free(struct render_maps *m)
{
    forecast_free(m->forecast);
    proto_weather_map_free(&m->forecast_map);
    proto_weather_map_free(&m->weather_map);
}

/* The forecast at the location and clock the options settled on, the lapse's transition and
 * the client map, in that order (as the daemon would take them); false after a message. */
static bool open_maps(struct render_args *a, struct render_maps *m)
{
    struct proto_world_state *state = &a->common.state;
    if (a->forecast_path) {
        m->forecast = cli_open_forecast(state, a->forecast_path);
        if (!m->forecast || !cli_apply_forecast(state, m->forecast, false, false, &m->forecast_map))
            return false;
        /* the forecast's cover over the map's square, as the daemon follows it */
        state->weather.map_source = PROTO_WEATHER_MAP_FORECAST;
    }
    if (!start_lapse_transition(&a->common, &a->lapse))
        return false;
    if (a->weather_map_path) {
        if (!load_weather_map(a->weather_map_path, &m->weather_map))
            return false;
        state->weather.map_source = PROTO_WEATHER_MAP_CLIENT;
    }
    return true;
}

/* Pixel buffers of one frame: RGBA (8-bit, or 32-bit float for png16) and png16's RGB. */
struct render_buffers {
    void *pixels;
    size_t bytes;
    uint16_t *rgb16;
    struct render_input *input;
};

static bool render_buffers_alloc(const struct render_args *a, struct render_buffers *b)
{
    size_t texels = (size_t)a->width * a->height;
    b->bytes = texels * (a->linear16 ? 16 : 4);
    b->pixels = malloc(b->bytes);
    b->rgb16 = a->linear16 ? malloc(texels * 3 * sizeof *b->rgb16) : NULL;
    b->input = malloc(sizeof *b->input);
    return b->pixels && b->input && (b->rgb16 || !a->linear16);
}

static void render_buffers_free(struct render_buffers *b)
{
    free(b->pixels);
    free(b->rgb16);
    free(b->input);
}

/* One frame of the lapse through the daemon's path (world_render_input, renderer_host_render),
 * written to its file. */
static int render_frame(struct render_args *a, struct render_maps *m, struct renderer_host *host,
                        struct render_buffers *b, unsigned frame, const char *path)
{
    struct proto_world_state *state = &a->common.state;
    const struct proto_msg_view asked = {
        .width = a->width,
        .height = a->height,
        .format = a->linear16 ? PROTO_FRAME_FORMAT_PNG16 : PROTO_FRAME_FORMAT_PNG,
        .projection = a->projection == SKY_RENDER_PROJECTION_EQUIRECTANGULAR
                          ? PROTO_VIEW_PROJECTION_EQUIRECTANGULAR
                          : PROTO_VIEW_PROJECTION_PERSPECTIVE,
    };
    world_render_input(state, b->input);
    bool forecast_selected = state->weather.map_source == PROTO_WEATHER_MAP_FORECAST;
    b->input->client_map = forecast_selected ? &m->forecast_map : &m->weather_map;
    b->input->map_generation = forecast_selected ? 2 + frame : m->weather_map.rgba ? 1 : 0;
    struct sky_render_view view;
    struct sky_render_stats stats;
    world_render_view(b->input, &asked, &view);
    if (renderer_host_render(host, b->input, &view, false, b->pixels, b->bytes, &stats) != 0) {
        fprintf(stderr, "skyd render: rendering failed\n");
        return SKYD_EXIT_FAILURE;
    }
    error_text err;
    if (write_frame(path, b->pixels, b->rgb16, (int)a->quality, a->width, a->height, stats.exposure,
                    err, sizeof err) != 0) {
        fprintf(stderr, "skyd render: %s\n", err);
        return SKYD_EXIT_FAILURE;
    }
    if (a->stats_json)
        print_stats(&stats);
    else
        printf("%s\n", path);
    fprintf(stderr, "skyd render: %ux%u in %.1f ms (GPU %.1f ms), sun at %.2f deg\n", a->width,
            a->height, stats.wall_ms, stats.gpu_ms, state->sun.elevation_deg);
    return SKYD_EXIT_OK;
}

/* The frames: the world advances by the lapse's step between them, the weather following the
 * forecast (held at its last step beyond it). */
static int render_lapse(struct render_args *a, struct render_maps *m, struct renderer_host *host,
                        struct render_buffers *b, const char *prefix, int number_width,
                        const char *suffix)
{
    world_sim_anchor_wind(&a->common.state); /* the lapse's wind runs from the state as given */
    for (unsigned frame = 0; frame < a->lapse.frames; frame++) {
        if (frame > 0) {
            world_sim_advance(&a->common.state, a->lapse.step_s);
            if (m->forecast &&
                !cli_apply_forecast(&a->common.state, m->forecast, true, true, &m->forecast_map))
                return SKYD_EXIT_FAILURE;
        }
        char path[1200];
        frame_path(prefix, number_width, suffix, frame, path, sizeof path);
        int status = render_frame(a, m, host, b, frame, path);
        if (status != SKYD_EXIT_OK)
            return status;
    }
    return SKYD_EXIT_OK;
}

int skyd_cmd_render(int argc, char **argv)
{
    struct render_args a = {
        .lapse = { .frames = 1, .step_s = 60.0 },
        .projection = SKY_RENDER_PROJECTION_PERSPECTIVE,
    };
    cli_common_init(&a.common);
    for (int i = 0; i < argc; i++) {
        if (take_option(argc, argv, &i, &a) < 0)
            return SKYD_EXIT_USAGE;
        if (a.help) {
            usage(stdout);
            return SKYD_EXIT_OK;
        }
    }
    if (!check_args(&a))
        return SKYD_EXIT_USAGE;
    char prefix[1024];
    const char *suffix;
    int number_width;
    if (!split_pattern(a.out_path, a.lapse.frames > 1, prefix, sizeof prefix, &number_width,
                       &suffix)) {
        fprintf(stderr, "skyd render: --out \"%s\": %s\n", a.out_path,
                a.lapse.frames > 1 ? "a time-lapse needs one %d or %0Nd for the frame number"
                                   : "only one %d or %0Nd may appear");
        return SKYD_EXIT_USAGE;
    }
    struct render_maps maps = { 0 };
    if (!open_maps(&a, &maps)) {
        render_maps_free(&maps);
        return SKYD_EXIT_USAGE;
    }
    world_sim_settle(&a.common.state);
    struct render_buffers buffers = { 0 };
    struct renderer_host *host = render_buffers_alloc(&a, &buffers) ? cli_create_renderer(&a.common)
                                                                    : NULL;
    int status = SKYD_EXIT_FAILURE;
    if (host)
        status = render_lapse(&a, &maps, host, &buffers, prefix, number_width, suffix);
    status = host ? cli_finish(&a.common, &host, status) : SKYD_EXIT_FAILURE;
    render_maps_free(&maps);
    render_buffers_free(&buffers);
    return status;
}
