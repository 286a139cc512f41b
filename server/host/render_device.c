#include "render_device.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "monotonic_clock.h"
#include "world_render.h"

_Static_assert(RENDER_DEVICE_MAX_LOSSES <= RENDER_CONTEXT_LOSSES_KEPT,
               "render_context keeps too few loss times");

void render_device_set_amortization(struct render_context *ctx, double budget_ms)
{
    sky_renderer_set_amortization(
        ctx->renderer, &(struct sky_render_amortization){
                           .budget_ms = budget_ms,
                           .budget_fraction = ctx->config->lut_budget_fraction,
                           .blend_frames = ctx->config->lut_blend_frames });
}

bool render_device_lost(const struct render_context *ctx)
{
    return !ctx->renderer || sky_renderer_status(ctx->renderer, NULL) == SKY_RENDER_DEVICE_LOST;
}

/* The weather and shadow maps then rebuild amortized over the next frames. */
void render_device_update_clouds(struct render_context *ctx)
{
    struct sky_render_clouds clouds;
    world_to_render_clouds(&ctx->state, &clouds);
    if (ctx->clouds_set && memcmp(&clouds, &ctx->clouds, sizeof clouds) == 0)
        return;
    if (sky_renderer_set_clouds(ctx->renderer, &clouds) == 0) {
        ctx->clouds = clouds;
        ctx->clouds_set = true;
    } else if (!render_device_lost(ctx)) { /* a loss is reported once, by the check */
        fprintf(stderr, "skyd: the cloud noise could not be generated\n");
    }
}

int render_device_open(struct render_context *ctx, bool quiet, char *err, size_t errlen)
{
    struct sky_renderer_params rp = { .device_preference = ctx->device_preference,
                                      .validation = ctx->validation,
                                      .quiet = quiet };
    world_to_lut_sizes(&ctx->state, &rp.lut_sizes);
    ctx->renderer = sky_renderer_create(&rp);
    if (!ctx->renderer) {
        snprintf(err, errlen, "cannot create the Vulkan renderer");
        return -1;
    }
    ctx->lut_sizes = rp.lut_sizes;
    render_device_set_amortization(ctx, ctx->config->lut_budget_ms);
    struct sky_render_atmosphere atm = ctx->atmosphere;
    if (sky_renderer_rebuild_atmosphere(ctx->renderer, &atm, NULL) != 0) {
        snprintf(err, errlen, "building the atmosphere LUTs failed");
        sky_renderer_destroy(&ctx->renderer);
        return -1;
    }
    return 0;
}

/* The CPU driver (lavapipe) compiles a shader variant at its first dispatch: a second or more
 * for each cloud pass on two cores, which stalled every stream the first time clouds showed.
 * A few small frames with clouds, by day (both halves of the reconstruction's ping-pong) and
 * by night, then one clear, dispatch those passes now, before the first client. The caller
 * then sets the state's own clouds. */
static int warm_up_pipelines(struct render_context *ctx)
{
    enum { WARM_W = 64, WARM_H = 36 };
    static uint8_t rgba[WARM_W * WARM_H * 4];
    struct sky_world_state s = ctx->state;
    s.clouds.low.coverage = fmax(s.clouds.low.coverage, 0.5);
    s.clouds.high.coverage = fmax(s.clouds.high.coverage, 0.3);
    struct sky_render_clouds clouds;
    world_to_render_clouds(&s, &clouds);
    if (sky_renderer_set_clouds(ctx->renderer, &clouds) != 0)
        return -1;
    ctx->clouds_set = false;
    render_device_set_amortization(ctx, 0.0); /* the weather and shadow maps at once */
    static const double sun_elevation_deg[4] = { 30.0, 30.0, -20.0, 30.0 };
    int status = 0;
    for (int k = 0; k < 4 && status == 0; k++) {
        s.sun.elevation_deg = sun_elevation_deg[k];
        if (k == 3) { /* the clear sky's composite pipelines are others */
            s.clouds.low.coverage = s.clouds.high.coverage = 0.0;
            world_to_render_clouds(&s, &clouds);
            if (sky_renderer_set_clouds(ctx->renderer, &clouds) != 0)
                return -1;
        }
        struct sky_render_night night;
        world_to_render_night(&s, &night);
        sky_renderer_set_night(ctx->renderer, &night);
        struct sky_render_view view;
        world_to_render_view(&s, WARM_W, WARM_H, SKY_RENDER_OUTPUT_SRGB8, &view);
        view.history_key = UINT64_MAX;
        view.live = true;
        struct sky_render_atmosphere atm = ctx->atmosphere;
        status = sky_renderer_render(ctx->renderer, &atm, &view, rgba, sizeof rgba, NULL);
    }
    render_device_set_amortization(ctx, ctx->config->lut_budget_ms);
    return status;
}

int render_device_prepare(struct render_context *ctx, char *err, size_t errlen)
{
    if (sky_renderer_prepare_cloud_noise(ctx->renderer, (uint32_t)ctx->state.clouds.noise_seed) !=
        0) {
        snprintf(err, errlen, "generating the cloud noise failed");
        return -1;
    }
    if (warm_up_pipelines(ctx) != 0) {
        snprintf(err, errlen, "rendering the start-up frames failed");
        return -1;
    }
    render_device_update_clouds(ctx);
    return 0;
}

/* Remembers a loss at `now`; returns how many of the remembered ones fall within the window. */
static int count_recent_losses(struct render_context *ctx, double now)
{
    memmove(&ctx->device_losses_s[1], &ctx->device_losses_s[0],
            sizeof ctx->device_losses_s[0] * (RENDER_CONTEXT_LOSSES_KEPT - 1));
    ctx->device_losses_s[0] = now;
    if (ctx->device_loss_count < RENDER_CONTEXT_LOSSES_KEPT)
        ctx->device_loss_count++;
    int recent = 0;
    for (int i = 0; i < ctx->device_loss_count; i++)
        recent += now - ctx->device_losses_s[i] <= RENDER_DEVICE_LOSS_WINDOW_S;
    return recent;
}

/* The new renderer, made like the first one, takes what the old one held that is not in the
 * state: the client weather map. */
static int rebuild(struct render_context *ctx, char *err, size_t errlen)
{
    if (render_device_open(ctx, true, err, errlen) != 0)
        return -1;
    const struct sky_weather_map *map = &ctx->client_map;
    if (map->rgba &&
        sky_renderer_set_weather_map(ctx->renderer, map->rgba, map->width, map->height) != 0) {
        snprintf(err, errlen, "the new renderer could not take the client weather map");
        return -1;
    }
    ctx->clouds_set = false;
    return render_device_prepare(ctx, err, errlen);
}

enum render_device_check render_device_check(struct render_context *ctx, char *err,
                                             size_t errlen)
{
    const char *detail = "";
    if (!ctx->renderer || sky_renderer_status(ctx->renderer, &detail) != SKY_RENDER_DEVICE_LOST)
        return RENDER_DEVICE_OK;
    double start = monotonic_seconds();
    int recent = count_recent_losses(ctx, start);
    fprintf(stderr, "skyd: error: the Vulkan device was lost (%s)%s\n", detail,
            recent < RENDER_DEVICE_MAX_LOSSES ? "; rebuilding the renderer" : "");
    sky_renderer_destroy(&ctx->renderer);
    if (recent >= RENDER_DEVICE_MAX_LOSSES) {
        snprintf(err, errlen, "the Vulkan device was lost %d times within %.0f s", recent,
                 RENDER_DEVICE_LOSS_WINDOW_S);
        return RENDER_DEVICE_FAILED;
    }
    char why[256];
    if (rebuild(ctx, why, sizeof why) != 0) {
        sky_renderer_destroy(&ctx->renderer);
        snprintf(err, errlen, "the Vulkan device was lost and the renderer could not be "
                 "rebuilt: %s", why);
        return RENDER_DEVICE_FAILED;
    }
    /* The LUTs were built at once for the atmosphere frames are asked to show. */
    ctx->atmosphere_pending = false;
    ctx->settled_revision = ctx->state.revision;
    fprintf(stderr, "skyd: renderer rebuilt on %s in %.0f ms; frames resume at revision %llu\n",
            sky_renderer_device_name(ctx->renderer), (monotonic_seconds() - start) * 1e3,
            (unsigned long long)ctx->state.revision);
    return RENDER_DEVICE_REBUILT;
}

void render_device_describe_failure(const struct render_context *ctx, const char *what,
                                    char *out, size_t outlen)
{
    const char *detail = "";
    enum sky_render_status status =
        ctx->renderer ? sky_renderer_status(ctx->renderer, &detail) : SKY_RENDER_DEVICE_LOST;
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
