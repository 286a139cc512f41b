/* The renderer host: the renderer (render/), and the one path from a render input
 * (render_input.h) to a frame. The daemon's frames and its start-up warm-up, `skyd render`,
 * `skyd probe` and the protocol's probes all render through it: an input's client weather
 * map, LUT sizes, clouds, night and atmosphere are handed to the renderer here, and nowhere
 * else. It owns the renderer, the device it was made on (made again the same way when that
 * device is lost), and copies of what the renderer holds. One thread uses it. */
#ifndef SKYD_RENDERER_HOST_H
#define SKYD_RENDERER_HOST_H

#include <stdbool.h>
#include <stddef.h>

#include "messages.h"
#include "render_input.h"
#include "sky_renderer.h"
#include "weather_map.h"
#include "world_state.h"

/* Losses this close together mean the device will not stay usable: the daemon stops. */
#define RENDERER_HOST_MAX_LOSSES 3
#define RENDERER_HOST_LOSS_WINDOW_S 60.0

struct renderer_host_params {
    const char *device_preference; /* NULL: the first usable device */
    bool validation;
    unsigned *validation_message_counter; /* counted through the destruction; may be NULL */
    bool quiet;                           /* the device is not logged */
    /* The LUT and cloud-map amortization (config lut_budget_*); amortize false leaves the
     * renderer's default. */
    bool amortize;
    double lut_budget_ms, lut_budget_fraction;
    int lut_blend_frames;
    double frame_budget_ms; /* config render.frame_budget_ms: clouds at resolution auto */
    /* Path-traced reference clouds with this many samples per pixel (0: the real-time ones). */
    uint32_t cloud_reference_spp;
    /* Every composite pipeline made and dispatched in the first frames (sky_renderer_params). */
    bool warm_up_variants;
};

struct renderer_host;

/* Makes the renderer with the input's LUT sizes; its frame atmosphere's LUTs are built at
 * once when input->atmosphere_at_once (else on the first frame). NULL with err filled when no
 * renderer can be made. */
struct renderer_host *renderer_host_create(const struct renderer_host_params *params,
                                           const struct render_input *input, char *err,
                                           size_t errlen);
void renderer_host_destroy(struct renderer_host **host);

/* Generates the cloud noise, dispatches every pipeline once with a few small frames and takes
 * the input: after it no client waits for a shader to compile. 0 or -1 (err). */
int renderer_host_prepare(struct renderer_host *host, const struct render_input *input, char *err,
                          size_t errlen);

/* Takes what changed in the input since the last one, all or nothing: the client weather map,
 * the LUT sizes and the clouds; then, when input->atmosphere_at_once, builds the frame
 * atmosphere's LUTs unless they are built. 0, or -1 with `why` filled and the renderer holding
 * what it held. A lost device counts as success: the rebuild after the tick takes the input. */
int renderer_host_take(struct renderer_host *host, const struct render_input *input, char *why,
                       size_t whylen);

/* The one world-to-frame path: takes the input (renderer_host_take), hands over its night,
 * then renders `view` under its frame atmosphere. at_once: rebuild the cloud maps within this
 * frame instead of amortized (a snapshot nobody streams). 0, or -1
 * (renderer_host_describe_failure says why), also when the input could not be taken: a frame
 * never shows other clouds than the input's. */
int renderer_host_render(struct renderer_host *host, const struct render_input *input,
                         const struct sky_render_view *view, bool at_once, void *pixels,
                         size_t bytes, struct sky_render_stats *stats);

/* Probes from now on build and answer with the converged multiple scattering (skyd probe). */
void renderer_host_converged_probes(struct renderer_host *host);
/* A physical query (protocol probe, skyd probe) under the input's state. 0 or -1. */
int renderer_host_probe(struct renderer_host *host, const struct render_input *input,
                        const struct proto_msg_probe *query, struct proto_msg_probe_result *result);

enum renderer_host_check {
    RENDERER_HOST_OK,      /* the renderer is usable */
    RENDERER_HOST_REBUILT, /* its device was lost; a new renderer shows the same state */
    RENDERER_HOST_FAILED,  /* lost, and no usable renderer could be made: see err */
};
/* After work that used the renderer: when it reports its device lost, says so in the log and
 * makes it again (renderer_host_create's way with the frame atmosphere built at once, then
 * renderer_host_prepare with the input). FAILED when that fails, or at the
 * RENDERER_HOST_MAX_LOSSES-th loss within RENDERER_HOST_LOSS_WINDOW_S: the host then has no
 * renderer and every call fails. */
enum renderer_host_check renderer_host_check(struct renderer_host *host,
                                             const struct render_input *input, char *err,
                                             size_t errlen);

bool renderer_host_lost(const struct renderer_host *host);
const char *renderer_host_device_name(const struct renderer_host *host);

/* A message for a client whose request failed in the renderer: `what` ("rendering the 64x36
 * view") failed, and why as the renderer tells it (a lost device, out of memory and what
 * could not be allocated, another Vulkan failure). */
void renderer_host_describe_failure(const struct renderer_host *host, const char *what, char *out,
                                    size_t outlen);

#endif
