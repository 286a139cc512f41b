#include "renderer_host.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "log.h"
#include "monotonic_clock.h"
#include "probe_query.h"
#include "world_render.h"

#define LOSSES_KEPT 4
_Static_assert(RENDERER_HOST_MAX_LOSSES <= LOSSES_KEPT, "too few loss times are kept");

struct renderer_host {
    struct renderer_host_params params;
    struct sky_renderer *renderer;
    struct sky_render_lut_sizes lut_sizes;
    /* The clouds the renderer holds: the simulation moves them every tick (wind, transitions,
     * autopilot), and a frame hands them over only when they changed. */
    struct sky_render_clouds clouds;
    bool clouds_set;
    /* The client weather map the renderer holds (no texels: none), for a rebuild. */
    struct sky_weather_map map;
    /* When the last losses were, newest first. */
    double losses_s[LOSSES_KEPT];
    int loss_count;
};

static void set_amortization(struct renderer_host *h, double budget_ms)
{
    if (!h->params.amortize)
        return;
    sky_renderer_set_amortization(
        h->renderer, &(struct sky_render_amortization){
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

static int open_renderer(struct renderer_host *h, const struct sky_world_state *state,
                         const struct sky_render_atmosphere *atmosphere, bool quiet, char *err,
                         size_t errlen)
{
    struct sky_renderer_params rp = {
        .device_preference = h->params.device_preference,
        .validation = h->params.validation,
        .validation_message_counter = h->params.validation_message_counter,
        .quiet = quiet,
        .log = { .write = log_render_line },
    };
    world_to_lut_sizes(state, &rp.lut_sizes);
    h->renderer = sky_renderer_create(&rp);
    if (!h->renderer) {
        snprintf(err, errlen, "cannot create the Vulkan renderer");
        return -1;
    }
    h->lut_sizes = rp.lut_sizes;
    h->clouds_set = false;
    set_amortization(h, h->params.lut_budget_ms);
    if (atmosphere) {
        struct sky_render_atmosphere atm = *atmosphere;
        if (sky_renderer_rebuild_atmosphere(h->renderer, &atm, NULL) != 0) {
            snprintf(err, errlen, "building the atmosphere LUTs failed");
            sky_renderer_destroy(&h->renderer);
            return -1;
        }
    }
    return 0;
}

struct renderer_host *renderer_host_create(const struct renderer_host_params *params,
                                           const struct sky_world_state *state,
                                           const struct sky_render_atmosphere *atmosphere,
                                           char *err, size_t errlen)
{
    struct renderer_host *h = calloc(1, sizeof *h);
    if (!h) {
        snprintf(err, errlen, "out of memory");
        return NULL;
    }
    h->params = *params;
    if (open_renderer(h, state, atmosphere, params->quiet, err, errlen) != 0) {
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
    sky_weather_map_free(&h->map);
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

/* Hands the state's clouds over when they changed since the last time. */
static int update_clouds(struct renderer_host *h, const struct sky_world_state *state)
{
    struct sky_render_clouds clouds;
    world_to_render_clouds(state, &clouds);
    clouds.reference_spp = h->params.cloud_reference_spp;
    if (h->clouds_set && memcmp(&clouds, &h->clouds, sizeof clouds) == 0)
        return 0;
    if (sky_renderer_set_clouds(h->renderer, &clouds) != 0) {
        h->clouds_set = false;
        return -1;
    }
    h->clouds = clouds;
    h->clouds_set = true;
    return 0;
}

int renderer_host_render(struct renderer_host *h, const struct sky_world_state *state,
                         const struct sky_render_atmosphere *atmosphere,
                         const struct sky_render_view *view, bool at_once, void *pixels,
                         size_t bytes, struct sky_render_stats *stats)
{
    if (!h->renderer)
        return -1;
    struct sky_render_night night;
    world_to_render_night(state, &night);
    sky_renderer_set_night(h->renderer, &night);
    /* A frame that cannot show the state's clouds fails rather than show others. */
    if (update_clouds(h, state) != 0)
        return -1;
    struct sky_render_atmosphere atm;
    if (atmosphere)
        atm = *atmosphere;
    else
        world_to_render_atmosphere(state, &atm);
    if (at_once)
        set_amortization(h, 0.0);
    int status = sky_renderer_render(h->renderer, &atm, view, pixels, bytes, stats);
    if (at_once)
        set_amortization(h, h->params.lut_budget_ms);
    return status;
}

int renderer_host_apply_change(struct renderer_host *h, const struct sky_world_state *before,
                               const struct sky_world_state *next, char *why, size_t whylen)
{
    if (!h->renderer)
        return 0; /* the rebuild after the tick takes the whole state */
    struct sky_render_lut_sizes sizes;
    world_to_lut_sizes(next, &sizes);
    bool resized = memcmp(&sizes, &h->lut_sizes, sizeof sizes) != 0;
    struct sky_render_lut_sizes old_sizes = h->lut_sizes;
    if (resized) {
        if (sky_renderer_set_lut_sizes(h->renderer, &sizes) != 0 && !renderer_host_lost(h)) {
            /* The renderer keeps the old LUTs and sizes. */
            renderer_host_describe_failure(h, "allocating the new LUT sizes", why, whylen);
            return -1;
        }
        h->lut_sizes = sizes;
    }
    struct sky_render_clouds clouds_before, clouds_after;
    world_to_render_clouds(before, &clouds_before);
    world_to_render_clouds(next, &clouds_after);
    if (memcmp(&clouds_before, &clouds_after, sizeof clouds_before) == 0)
        return 0;
    if (sky_renderer_set_clouds(h->renderer, &clouds_after) == 0) {
        h->clouds = clouds_after; /* the renderer has them: the next frame need not */
        h->clouds_set = true;
        return 0;
    }
    h->clouds_set = false;
    if (renderer_host_lost(h))
        return 0;
    renderer_host_describe_failure(h, "generating the cloud noise", why, whylen);
    sky_renderer_set_clouds(h->renderer, &clouds_before);
    if (resized && sky_renderer_set_lut_sizes(h->renderer, &old_sizes) == 0)
        h->lut_sizes = old_sizes;
    return -1;
}

int renderer_host_rebuild_atmosphere(struct renderer_host *h,
                                     const struct sky_render_atmosphere *atmosphere)
{
    if (!h->renderer)
        return -1;
    struct sky_render_atmosphere atm = *atmosphere;
    return sky_renderer_rebuild_atmosphere(h->renderer, &atm, NULL);
}

int renderer_host_set_weather_map(struct renderer_host *h, const struct sky_weather_map *map)
{
    struct sky_weather_map copy;
    if (!sky_weather_map_copy(map, &copy))
        return -1;
    if (h->renderer &&
        sky_renderer_set_weather_map(h->renderer, copy.rgba, copy.width, copy.height) != 0 &&
        !renderer_host_lost(h)) {
        sky_weather_map_free(&copy);
        return -1;
    }
    sky_weather_map_free(&h->map);
    h->map = copy;
    return 0;
}

void renderer_host_converged_probes(struct renderer_host *h)
{
    if (h->renderer)
        sky_renderer_set_probe_multiple_scattering(h->renderer, SKY_RENDER_PROBE_MS_CONVERGED);
}

int renderer_host_probe(struct renderer_host *h, const struct sky_world_state *state,
                        const struct sky_msg_probe *query, struct sky_msg_probe_result *result)
{
    if (!h->renderer)
        return -1;
    return probe_query_run(h->renderer, state, query, result);
}

/* The CPU driver (lavapipe) compiles a shader variant at its first dispatch: a second or more
 * for each cloud pass on two cores, which stalled every stream the first time clouds showed.
 * A few small frames with clouds, by day (both halves of the reconstruction's ping-pong) and
 * by night, then one clear, dispatch those passes now, before the first client. */
static int warm_up_pipelines(struct renderer_host *h, const struct sky_world_state *state,
                             const struct sky_render_atmosphere *atmosphere)
{
    enum { WARM_W = 64, WARM_H = 36, WARM_BYTES = WARM_W * WARM_H * 4 };
    uint8_t *rgba = malloc(WARM_BYTES);
    if (!rgba)
        return -1;
    struct sky_world_state s = *state;
    s.clouds.low.coverage = fmax(s.clouds.low.coverage, 0.5);
    s.clouds.high.coverage = fmax(s.clouds.high.coverage, 0.3);
    static const double sun_elevation_deg[4] = { 30.0, 30.0, -20.0, 30.0 };
    int status = 0;
    for (int k = 0; k < 4 && status == 0; k++) {
        s.sun.elevation_deg = sun_elevation_deg[k];
        if (k == 3) /* the clear sky's composite pipelines are others */
            s.clouds.low.coverage = s.clouds.high.coverage = 0.0;
        struct sky_render_view view;
        world_to_render_view(&s, WARM_W, WARM_H, SKY_RENDER_OUTPUT_SRGB8, &view);
        view.history_key = UINT64_MAX;
        view.live = true;
        /* at once: the weather and shadow maps within the frame */
        status = renderer_host_render(h, &s, atmosphere, &view, true, rgba, WARM_BYTES, NULL);
    }
    free(rgba);
    return status;
}

int renderer_host_prepare(struct renderer_host *h, const struct sky_world_state *state,
                          const struct sky_render_atmosphere *atmosphere, char *err,
                          size_t errlen)
{
    if (!h->renderer ||
        sky_renderer_prepare_cloud_noise(h->renderer, (uint32_t)state->clouds.noise_seed) != 0) {
        snprintf(err, errlen, "generating the cloud noise failed");
        return -1;
    }
    if (warm_up_pipelines(h, state, atmosphere) != 0) {
        snprintf(err, errlen, "rendering the start-up frames failed");
        return -1;
    }
    if (update_clouds(h, state) != 0 && !renderer_host_lost(h))
        skyd_log(SKYD_LOG_ERROR, "the cloud noise could not be generated");
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

/* The new renderer, made like the first one, takes what the old one held that is not in the
 * state: the client weather map. */
static int rebuild(struct renderer_host *h, const struct sky_world_state *state,
                   const struct sky_render_atmosphere *atmosphere, char *err, size_t errlen)
{
    if (open_renderer(h, state, atmosphere, true, err, errlen) != 0)
        return -1;
    if (h->map.rgba &&
        sky_renderer_set_weather_map(h->renderer, h->map.rgba, h->map.width, h->map.height) !=
            0) {
        snprintf(err, errlen, "the new renderer could not take the client weather map");
        return -1;
    }
    return renderer_host_prepare(h, state, atmosphere, err, errlen);
}

enum renderer_host_check renderer_host_check(struct renderer_host *h,
                                             const struct sky_world_state *state,
                                             const struct sky_render_atmosphere *atmosphere,
                                             char *err, size_t errlen)
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
    char why[256];
    if (rebuild(h, state, atmosphere, why, sizeof why) != 0) {
        sky_renderer_destroy(&h->renderer);
        snprintf(err, errlen, "the Vulkan device was lost and the renderer could not be "
                 "rebuilt: %s", why);
        return RENDERER_HOST_FAILED;
    }
    skyd_log(SKYD_LOG_INFO, "renderer rebuilt on %s in %.0f ms; frames resume at revision %llu",
            sky_renderer_device_name(h->renderer), (monotonic_seconds() - start) * 1e3,
            (unsigned long long)state->revision);
    return RENDERER_HOST_REBUILT;
}

void renderer_host_describe_failure(const struct renderer_host *h, const char *what, char *out,
                                    size_t outlen)
{
    const char *detail = "";
    enum sky_render_status status =
        h->renderer ? sky_renderer_status(h->renderer, &detail) : SKY_RENDER_DEVICE_LOST;
    switch (status) {
    case SKY_RENDER_DEVICE_LOST:
        snprintf(out, outlen, "%s failed: the rendering device was lost%s%s%s; the renderer is "
                 "being rebuilt, ask again", what, *detail ? " (" : "", detail,
                 *detail ? ")" : "");
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
