/* The daemon's renderer (render/) for the world state: made at start-up ready for the first
 * client (atmosphere LUTs built, cloud noise generated, every pipeline dispatched once), and
 * made again the same way when its device is lost, so that frames resume from the same world
 * state. Only the render thread calls these. */
#ifndef SKYD_RENDER_DEVICE_H
#define SKYD_RENDER_DEVICE_H

#include <stdbool.h>
#include <stddef.h>

#include "render_commands.h"

/* Losses this close together mean the device will not stay usable: the daemon stops. */
#define RENDER_DEVICE_MAX_LOSSES 3
#define RENDER_DEVICE_LOSS_WINDOW_S 60.0

/* Creates ctx->renderer on ctx->device_preference with the state's LUT sizes, sets the
 * amortization and builds the atmosphere LUTs for ctx->atmosphere. quiet: the device is not
 * logged. Returns 0, or -1 with err filled and ctx->renderer NULL. */
int render_device_open(struct render_context *ctx, bool quiet, char *err, size_t errlen);
/* Generates the cloud noise, dispatches every pipeline once with a few small frames and hands
 * the state's clouds over: after it no client waits for a shader to compile. 0 or -1 (err). */
int render_device_prepare(struct render_context *ctx, char *err, size_t errlen);

/* The renderer's amortization budget (0: rebuild LUTs and maps at once). */
void render_device_set_amortization(struct render_context *ctx, double budget_ms);
/* Hands the state's clouds to the renderer when they changed since the last time. */
void render_device_update_clouds(struct render_context *ctx);

/* Whether the renderer's device is lost: the rebuild after the tick takes the whole state,
 * so a change need not reach the lost renderer first. */
bool render_device_lost(const struct render_context *ctx);

enum render_device_check {
    RENDER_DEVICE_OK,      /* the renderer is usable */
    RENDER_DEVICE_REBUILT, /* its device was lost; a new renderer shows the same state */
    RENDER_DEVICE_FAILED,  /* lost, and no usable renderer could be made: see err */
};
/* After work that used the renderer: when it reports its device lost, says so on stderr and
 * rebuilds it (render_device_open, the client weather map in ctx->client_map, then
 * render_device_prepare). FAILED when that fails, or when this is the
 * RENDER_DEVICE_MAX_LOSSES-th loss within RENDER_DEVICE_LOSS_WINDOW_S; ctx->renderer is then
 * NULL and the daemon cannot render any more. */
enum render_device_check render_device_check(struct render_context *ctx, char *err,
                                             size_t errlen);

/* A message for a client whose request failed in the renderer: `what` ("rendering the 64x36
 * view") failed, and why as the renderer tells it (a lost device, out of memory and what
 * could not be allocated, another Vulkan failure). */
void render_device_describe_failure(const struct render_context *ctx, const char *what,
                                    char *out, size_t outlen);

#endif
