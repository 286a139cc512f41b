#include "renderer_host.h"

#include <limits.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cache_dir.h"
#include "error_text.h"
#include "log.h"
#include "monotonic_clock.h"
#include "probe_query.h"
#include "world_render.h"

#define LOSSES_KEPT 4
_Static_assert(RENDERER_HOST_MAX_LOSSES <= LOSSES_KEPT, "too few loss times are kept");

struct renderer_host {
    struct renderer_host_params params;
    char cache_dir[PATH_MAX]; /* cache_dir.h; "": none */
    struct sky_renderer *renderer;
    struct sky_render_lut_sizes lut_sizes;
    /* The clouds the renderer holds: the simulation moves them every tick (wind, transitions,
     * autopilot), and an input hands them over only when they changed. */
    struct sky_render_clouds clouds;
    bool clouds_set;
    /* The client weather map the renderer holds (no texels: none) and the input's generation
     * it came with (0: none taken since the renderer was made). */
    struct proto_weather_map map;
    uint64_t map_generation;
    /* The atmosphere of the last frame or at-once build; built: its LUTs are complete. */
    struct sky_render_atmosphere atmosphere;
    bool built;
    /* When the last losses were, newest first. */
    double losses_s[LOSSES_KEPT];
    int loss_count;
};

static void set_amortization(struct renderer_host *h, double budget_ms)
{
    if (!h->params.amortize)
        return;
    sky_renderer_set_amortization(h->renderer, &(struct sky_render_amortization){
                                                   .budget_ms = budget_ms,
                                                   .budget_fraction = h->params.lut_budget_fraction,
                                                   .blend_frames = h->params.lut_blend_frames });
}

_Static_assert(SKY_RENDER_LOG_ERROR == (int)SKYD_LOG_ERROR &&
                   SKY_RENDER_LOG_WARNING == (int)SKYD_LOG_WARNING &&
                   SKY_RENDER_LOG_INFO == (int)SKYD_LOG_INFO &&
                   SKY_RENDER_LOG_DEBUG == (int)SKYD_LOG_DEBUG,
               "the renderer's log levels are the daemon's");

/* The renderer's lines join the daemon's log, so --log-level governs them too. */
static void log_render_line(void *user, enum sky_render_log_level level, const char *line)
{
    (void)user;
    skyd_log((enum skyd_log_level)level, "%s", line);
}

static int open_renderer(struct renderer_host *h, const struct render_input *input,
                         bool build_atmosphere, bool quiet, char *err, size_t errlen)
{
    struct sky_renderer_params rp = {
        .device_preference = h->params.device_preference,
        .validation = h->params.validation,
        .validation_message_counter = h->params.validation_message_counter,
        .quiet = quiet,
        .log = { .write = log_render_line },
        .lut_sizes = input->lut_sizes,
        .warm_up_variants = h->params.warm_up_variants,
        .cache_dir = h->cache_dir,
    };
    h->renderer = sky_renderer_create(&rp);
    if (!h->renderer) {
        snprintf(err, errlen, "cannot create the Vulkan renderer");
        return -1;
    }
    h->lut_sizes = rp.lut_sizes;
    h->clouds_set = false;
    h->map_generation = 0;
    h->built = false;
    set_amortization(h, h->params.lut_budget_ms);
    sky_renderer_set_frame_budget(h->renderer, h->params.frame_budget_ms);
    if (build_atmosphere) {
        struct sky_render_atmosphere atm = input->frame_atmosphere;
        if (sky_renderer_rebuild_atmosphere(h->renderer, &atm, NULL) != 0) {
            snprintf(err, errlen, "building the atmosphere LUTs failed");
            sky_renderer_destroy(&h->renderer);
            return -1;
        }
        h->atmosphere = input->frame_atmosphere;
        h->built = true;
    }
    return 0;
}

struct renderer_host *renderer_host_create(const struct renderer_host_params *params,
                                           const struct render_input *input, char *err,
                                           size_t errlen)
{
    struct renderer_host *h = calloc(1, sizeof *h);
    if (!h) {
        snprintf(err, errlen, "out of memory");
        return NULL;
    }
    h->params = *params;
    skyd_cache_dir(h->cache_dir, sizeof h->cache_dir);
    if (open_renderer(h, input, input->atmosphere_at_once, params->quiet, err, errlen) != 0) {
        free(h);
        return NULL;
    }
    return h;
}

void renderer_host_destroy(struct renderer_host **host)
{
    struct renderer_host *h = host ? *host : NULL;
    if (!h)
        return;
    sky_renderer_destroy(&h->renderer);
    proto_weather_map_free(&h->map);
    free(h);
    *host = NULL;
}

bool renderer_host_lost(const struct renderer_host *h)
{
    return !h->renderer || sky_renderer_status(h->renderer, NULL) == SKY_RENDER_DEVICE_LOST;
}

const char *renderer_host_device_name(const struct renderer_host *h)
{
    return h->renderer ? sky_renderer_device_name(h->renderer) : "(no device)";
}

/* Hands the input's client weather map over when it is another; old: the one it replaced,
 * which the caller frees or puts back (restore_map). */
static int take_map(struct renderer_host *h, const struct render_input *input,
                    struct proto_weather_map *old, char *why, size_t whylen)
{
    struct proto_weather_map copy;
    if (!proto_weather_map_copy(input->client_map, &copy)) {
        snprintf(why, whylen, "out of memory for the weather map");
        return -1;
    }
    if (sky_renderer_set_weather_map(h->renderer, copy.rgba, copy.width, copy.height) != 0 &&
        !renderer_host_lost(h)) {
        renderer_host_describe_failure(h, "uploading the weather map", why, whylen);
        proto_weather_map_free(&copy);
        return -1;
    }
    *old = h->map;
    h->map = copy;
    h->map_generation = input->map_generation;
    return 0;
}

static void restore_map(struct renderer_host *h, struct proto_weather_map *old, uint64_t generation)
{
    sky_renderer_set_weather_map(h->renderer, old->rgba, old->width, old->height);
    proto_weather_map_free(&h->map);
    h->map = *old;
    h->map_generation = generation;
    memset(old, 0, sizeof *old);
}

/* New LUT sizes; *resized: they changed. The renderer keeps the old ones when it fails. */
static int take_lut_sizes(struct renderer_host *h, const struct render_input *input, bool *resized,
                          char *why, size_t whylen)
{
    *resized = memcmp(&input->lut_sizes, &h->lut_sizes, sizeof h->lut_sizes) != 0;
    if (!*resized)
        return 0;
    struct sky_render_lut_sizes sizes = input->lut_sizes;
    if (sky_renderer_set_lut_sizes(h->renderer, &sizes) != 0 && !renderer_host_lost(h)) {
        renderer_host_describe_failure(h, "allocating the new LUT sizes", why, whylen);
        *resized = false;
        return -1;
    }
    h->lut_sizes = sizes;
    return 0;
}

/* The input's clouds when they are not those the renderer holds; on failure the renderer gets
 * its old clouds back. */
static int take_clouds(struct renderer_host *h, const struct render_input *input, char *why,
                       size_t whylen)
{
    struct sky_render_clouds clouds = input->clouds;
    clouds.reference_spp = h->params.cloud_reference_spp;
    if (h->clouds_set && memcmp(&clouds, &h->clouds, sizeof clouds) == 0)
        return 0;
    if (sky_renderer_set_clouds(h->renderer, &clouds) == 0) {
        h->clouds = clouds;
        h->clouds_set = true;
        return 0;
    }
    if (renderer_host_lost(h)) {
        h->clouds_set = false;
        return 0;
    }
    renderer_host_describe_failure(h, "generating the cloud noise", why, whylen);
    if (h->clouds_set && sky_renderer_set_clouds(h->renderer, &h->clouds) != 0)
        h->clouds_set = false;
    return -1;
}

int renderer_host_take(struct renderer_host *h, const struct render_input *input, char *why,
                       size_t whylen)
{
    if (!h->renderer)
        return 0; /* the rebuild after the tick takes the input */
    struct proto_weather_map old_map = { 0 };
    uint64_t old_generation = h->map_generation;
    bool new_map = input->map_generation != h->map_generation;
    if (new_map && take_map(h, input, &old_map, why, whylen) != 0)
        return -1;
    struct sky_render_lut_sizes old_sizes = h->lut_sizes;
    bool resized = false;
    if (take_lut_sizes(h, input, &resized, why, whylen) != 0 ||
        take_clouds(h, input, why, whylen) != 0) {
        if (resized && sky_renderer_set_lut_sizes(h->renderer, &old_sizes) == 0)
            h->lut_sizes = old_sizes;
        if (new_map)
            restore_map(h, &old_map, old_generation);
        return -1;
    }
    proto_weather_map_free(&old_map);
    bool built = h->built &&
                 memcmp(&h->atmosphere, &input->frame_atmosphere, sizeof h->atmosphere) == 0;
    if (input->atmosphere_at_once && !built) {
        struct sky_render_atmosphere atm = input->frame_atmosphere;
        if (sky_renderer_rebuild_atmosphere(h->renderer, &atm, NULL) == 0) {
            h->atmosphere = input->frame_atmosphere;
            h->built = true;
        }
    }
    return 0;
}

int renderer_host_render(struct renderer_host *h, const struct render_input *input,
                         const struct sky_render_view *view, bool at_once, void *pixels,
                         size_t bytes, struct sky_render_stats *stats)
{
    error_text why;
    /* A frame that cannot show the input's clouds fails rather than show others. */
    if (!h->renderer || renderer_host_take(h, input, why, sizeof why) != 0)
        return -1;
    sky_renderer_set_night(h->renderer, &input->night);
    struct sky_render_atmosphere atm = input->frame_atmosphere;
    if (at_once)
        set_amortization(h, 0.0);
    int status = sky_renderer_render(h->renderer, &atm, view, pixels, bytes, stats);
    if (at_once)
        set_amortization(h, h->params.lut_budget_ms);
    if (status != 0)
        return status;
    struct sky_render_reference_stats reference;
    if (h->params.cloud_reference_spp > 0 &&
        sky_renderer_cloud_reference_stats(h->renderer, &reference) == 0 && reference.truncated > 0)
        skyd_log(SKYD_LOG_WARNING,
                 "the path-traced reference lost light: the device's loop limit (lavapipe's) cut "
                 "%u of its samples short, so its clouds are darker than the truth",
                 reference.truncated);
    bool settled = stats && stats->atmosphere_settled;
    if (memcmp(&h->atmosphere, &input->frame_atmosphere, sizeof h->atmosphere) != 0) {
        h->atmosphere = input->frame_atmosphere;
        h->built = settled;
    } else {
        h->built = h->built || settled;
    }
    return 0;
}

void renderer_host_converged_probes(struct renderer_host *h)
{
    if (h->renderer)
        sky_renderer_set_probe_multiple_scattering(h->renderer, SKY_RENDER_PROBE_MS_CONVERGED);
}

int renderer_host_probe(struct renderer_host *h, const struct render_input *input,
                        const struct proto_msg_probe *query, struct proto_msg_probe_result *result)
{
    if (!h->renderer)
        return -1;
    return probe_query_run(h->renderer, input, query, result);
}

/* The CPU driver (lavapipe) compiles a shader variant at its first dispatch: a second or more
 * for each cloud pass on two cores, which stalled every stream the first time clouds showed.
 * llvmpipe also compiles a pipeline again for each new kind of image bound to it, so each kind
 * of view is drawn once: with clouds by day (both halves of the reconstruction's ping-pong)
 * and by night, a clear sky, linear output (PNG16), a panorama and a camera in space. So is
 * each kind of light and map the clouds' passes are compiled for: the moon lighting them (under
 * another sun than the night before, so that the passes the sun's direction drives, such as
 * the hemisphere's, run again), a client's weather map of a power-of-two size, of another
 * and of one of each on either axis (a repeating texture is sampled by other code for each axis
 * whose size is not a power of two: a client's 7x512 map compiled the weather pass again six
 * minutes into a cluster soak), and towering clouds in the weather map, with and without the
 * moon (the marches' TOWERING variants). A probe dispatches its own pass. That compiles every
 * variant a client can ask for now, before the first one: a variant first compiled for a
 * client stalled its stream, and the memory each keeps grew a long-running daemon for hours. */
enum warm_up_map {
    WARM_MAP_STATE,
    WARM_MAP_POWER_OF_TWO,
    WARM_MAP_OTHER,
    WARM_MAP_OTHER_WIDTH, /* only the width not a power of two */
    WARM_MAP_OTHER_HEIGHT,
};
struct warm_up_frame {
    double sun_elevation_deg;
    bool clouds;
    enum proto_frame_format format;
    enum proto_view_projection projection;
    double altitude_km; /* 0: the state's */
    bool moonlit;
    enum warm_up_map map;
    bool towering; /* a weather map with towering clouds (false: none, whatever the state's) */
};

#define PNG8 PROTO_FRAME_FORMAT_PNG
#define PERSPECTIVE PROTO_VIEW_PROJECTION_PERSPECTIVE
/* Ordered so that the maps are built again as seldom as possible: the day's views under one
 * sun, then the night's (a shadow map for a sun below the horizon is cheap), and the client
 * maps last, by night, since each builds the weather map again and the world's own map is
 * built again after them anyway. A shadow map under a high sun costs a second on two cores,
 * a weather map most of one: 2.9 s of warm-up in this order, 5.3 s day and night mixed. */
static const struct warm_up_frame warm_up_frames[] = {
    { 30.0, true, PNG8, PERSPECTIVE, 0.0, false, WARM_MAP_STATE, false },
    { 30.0, true, PNG8, PERSPECTIVE, 0.0, false, WARM_MAP_STATE, false },
    { 30.0, true, PROTO_FRAME_FORMAT_PNG16, PERSPECTIVE, 0.0, false, WARM_MAP_STATE, false },
    { 30.0, true, PROTO_FRAME_FORMAT_PNG16, PROTO_VIEW_PROJECTION_EQUIRECTANGULAR, 0.0, false,
      WARM_MAP_STATE, false },
    { 30.0, true, PNG8, PERSPECTIVE, 150.0, false, WARM_MAP_STATE, false },
    { 30.0, false, PNG8, PERSPECTIVE, 0.0, false, WARM_MAP_STATE, false },
    { -20.0, true, PNG8, PERSPECTIVE, 0.0, false, WARM_MAP_STATE, false },
    { -25.0, true, PNG8, PERSPECTIVE, 0.0, true, WARM_MAP_STATE, false },
    /* the client maps: towering clouds, by the sun alone, then with the moon */
    { -20.0, true, PNG8, PERSPECTIVE, 0.0, false, WARM_MAP_POWER_OF_TWO, true },
    { -25.0, true, PNG8, PERSPECTIVE, 0.0, true, WARM_MAP_OTHER, true },
    { -25.0, true, PNG8, PERSPECTIVE, 0.0, true, WARM_MAP_OTHER_WIDTH, true },
    { -25.0, true, PNG8, PERSPECTIVE, 0.0, true, WARM_MAP_OTHER_HEIGHT, true },
};
#undef PNG8
#undef PERSPECTIVE
#define WARM_UP_FRAME_COUNT (sizeof warm_up_frames / sizeof warm_up_frames[0])

/* A client weather map of 2 or 3 texels a side (as kind asks), half covered by cumulus or
 * cumulonimbus (towering); its generation is one no world's map has (renderer_host_take then
 * hands the world's own over after the warm-up). */
enum { WARM_MAP_MAX_SIDE = 3 };
static void warm_up_map(enum warm_up_map kind, bool towering, struct render_input *warm,
                        uint8_t texels[WARM_MAP_MAX_SIDE * WARM_MAP_MAX_SIDE * 4],
                        struct proto_weather_map *map)
{
    uint32_t width = kind == WARM_MAP_POWER_OF_TWO || kind == WARM_MAP_OTHER_HEIGHT
                         ? 2
                         : WARM_MAP_MAX_SIDE;
    uint32_t height = kind == WARM_MAP_POWER_OF_TWO || kind == WARM_MAP_OTHER_WIDTH
                          ? 2
                          : WARM_MAP_MAX_SIDE;
    for (uint32_t i = 0; i < width * height; i++) {
        uint8_t *t = texels + 4 * i;
        t[0] = i % 2 ? 200 : 0;      /* low coverage */
        t[1] = 0;                    /* high coverage */
        t[2] = towering ? 255 : 170; /* cumulonimbus or cumulus */
        t[3] = 0;                    /* no rain */
    }
    *map = (struct proto_weather_map){ .width = width, .height = height, .rgba = texels };
    warm->client_map = map;
    warm->map_generation = UINT64_MAX - (uint64_t)kind;
    warm->clouds.use_client_map = true;
    warm->clouds.client_map_drives_procedural = false;
}

static int warm_up_probe(struct renderer_host *h, const struct render_input *input)
{
    const struct proto_msg_probe luminance = {
        .quantity = PROTO_PROBE_LUMINANCE,
        .altitude_km = 1.0,
        .view_zenith_deg = 40.0,
        .sun_zenith_deg = 50.0,
    };
    struct proto_msg_probe_result result;
    return renderer_host_probe(h, input, &luminance, &result);
}

static int warm_up_pipelines(struct renderer_host *h, const struct render_input *input)
{
    enum { WARM_W = 64, WARM_H = 36, WARM_BYTES = WARM_W * WARM_H * 16 }; /* RGBA float */
    uint8_t *rgba = malloc(WARM_BYTES);
    struct render_input *warm = malloc(sizeof *warm);
    if (!rgba || !warm) {
        free(rgba);
        free(warm);
        return -1;
    }
    int status = 0;
    for (size_t k = 0; k < WARM_UP_FRAME_COUNT && status == 0; k++) {
        const struct warm_up_frame *f = &warm_up_frames[k];
        *warm = *input;
        warm->clouds.low.coverage = f->clouds ? fmax(input->clouds.low.coverage, 0.5) : 0.0;
        warm->clouds.high.coverage = f->clouds ? fmax(input->clouds.high.coverage, 0.3) : 0.0;
        struct proto_weather_map map;
        uint8_t texels[WARM_MAP_MAX_SIDE * WARM_MAP_MAX_SIDE * 4];
        warm->clouds.low.type = f->towering
                                    ? 1.0
                                    : fmin(input->clouds.low.type, sky_renderer_plain_cloud_type());
        if (f->map != WARM_MAP_STATE)
            warm_up_map(f->map, f->towering, warm, texels, &map);
        if (f->moonlit) {
            warm->night.moon_elevation_deg = 40.0;
            warm->night.moon_illuminance_lux = fmax(input->night.moon_illuminance_lux, 0.25);
            warm->night.moon_angular_diameter_deg = fmax(input->night.moon_angular_diameter_deg,
                                                         0.5);
        }
        const struct proto_msg_view small = {
            .width = WARM_W,
            .height = WARM_H,
            .format = f->format,
            .projection = f->projection,
            .has_altitude_km = f->altitude_km > 0.0,
            .altitude_km = f->altitude_km,
        };
        struct sky_render_view view;
        world_render_view(warm, &small, &view);
        view.sun_elevation_deg = f->sun_elevation_deg;
        view.history_key = UINT64_MAX;
        view.live = true;
        /* at once: the weather and shadow maps within the frame */
        status = renderer_host_render(h, warm, &view, true, rgba, WARM_BYTES, NULL);
    }
    if (status == 0)
        status = warm_up_probe(h, input);
    free(warm);
    free(rgba);
    return status;
}

int renderer_host_prepare(struct renderer_host *h, const struct render_input *input, char *err,
                          size_t errlen)
{
    if (!h->renderer ||
        sky_renderer_prepare_cloud_noise(h->renderer, input->clouds.noise_seed) != 0) {
        snprintf(err, errlen, "generating the cloud noise failed");
        return -1;
    }
    double start = monotonic_seconds();
    if (warm_up_pipelines(h, input) != 0) {
        snprintf(err, errlen, "rendering the start-up frames failed");
        return -1;
    }
    skyd_log(SKYD_LOG_INFO, "start-up frames: %zu and a probe in %.1f s", WARM_UP_FRAME_COUNT,
             monotonic_seconds() - start);
    error_text why;
    if (renderer_host_take(h, input, why, sizeof why) != 0 && !renderer_host_lost(h))
        skyd_log(SKYD_LOG_ERROR, "%s", why);
    return 0;
}

/* Remembers a loss at `now`; returns how many of the remembered ones fall within the window. */
static int count_recent_losses(struct renderer_host *h, double now)
{
    memmove(&h->losses_s[1], &h->losses_s[0], sizeof h->losses_s[0] * (LOSSES_KEPT - 1));
    h->losses_s[0] = now;
    if (h->loss_count < LOSSES_KEPT)
        h->loss_count++;
    int recent = 0;
    for (int i = 0; i < h->loss_count; i++)
        recent += now - h->losses_s[i] <= RENDERER_HOST_LOSS_WINDOW_S;
    return recent;
}

enum renderer_host_check renderer_host_check(struct renderer_host *h,
                                             const struct render_input *input, char *err,
                                             size_t errlen)
{
    const char *detail = "";
    if (!h->renderer || sky_renderer_status(h->renderer, &detail) != SKY_RENDER_DEVICE_LOST)
        return RENDERER_HOST_OK;
    double start = monotonic_seconds();
    int recent = count_recent_losses(h, start);
    skyd_log(SKYD_LOG_ERROR, "the Vulkan device was lost (%s)%s", detail,
             recent < RENDERER_HOST_MAX_LOSSES ? "; rebuilding the renderer" : "");
    sky_renderer_destroy(&h->renderer);
    if (recent >= RENDERER_HOST_MAX_LOSSES) {
        snprintf(err, errlen, "the Vulkan device was lost %d times within %.0f s", recent,
                 RENDERER_HOST_LOSS_WINDOW_S);
        return RENDERER_HOST_FAILED;
    }
    /* The new renderer, made like the first one, takes the whole input, its client weather
     * map included. */
    error_text why;
    if (open_renderer(h, input, true, true, why, sizeof why) != 0 ||
        renderer_host_prepare(h, input, why, sizeof why) != 0) {
        sky_renderer_destroy(&h->renderer);
        snprintf(err, errlen,
                 "the Vulkan device was lost and the renderer could not be "
                 "rebuilt: %s",
                 why);
        return RENDERER_HOST_FAILED;
    }
    skyd_log(SKYD_LOG_INFO, "renderer rebuilt on %s in %.0f ms; frames resume at revision %llu",
             sky_renderer_device_name(h->renderer), (monotonic_seconds() - start) * 1e3,
             (unsigned long long)input->state.revision);
    return RENDERER_HOST_REBUILT;
}

void renderer_host_describe_failure(const struct renderer_host *h, const char *what, char *out,
                                    size_t outlen)
{
    const char *detail = "";
    enum sky_render_status status = h->renderer ? sky_renderer_status(h->renderer, &detail)
                                                : SKY_RENDER_DEVICE_LOST;
    switch (status) {
    case SKY_RENDER_DEVICE_LOST:
        snprintf(out, outlen,
                 "%s failed: the rendering device was lost%s%s%s; the renderer is "
                 "being rebuilt, ask again",
                 what, *detail ? " (" : "", detail, *detail ? ")" : "");
        break;
    case SKY_RENDER_OUT_OF_MEMORY:
        snprintf(out, outlen, "%s failed: out of memory (%s)", what, detail);
        break;
    case SKY_RENDER_FAILED:
        snprintf(out, outlen, "%s failed (%s)", what, detail);
        break;
    case SKY_RENDER_OK:
        snprintf(out, outlen, "%s failed", what);
        break;
    }
}
