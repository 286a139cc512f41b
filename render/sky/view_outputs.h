/* The image a view is rendered into and the host-visible buffer its pixels are read back
 * through, one pair per (size, format) in recent use. Views of different sizes rendered in
 * turn (a daemon's subscriptions, snapshots) each find their pair instead of replacing a
 * single one at every frame, which cost two allocations of the view's size, a submission to
 * set the new image's layout and new bindings for every pass. A pair no view has used for
 * VIEW_OUTPUT_IDLE_S is released. */
#ifndef SKYD_VIEW_OUTPUTS_H
#define SKYD_VIEW_OUTPUTS_H

#include <stdbool.h>
#include <stdint.h>

#include "lru_slots.h"
#include "vk_resources.h"

struct vk_context;

/* As many as cloud histories (cloud_history.h): one per view of a busy daemon. */
#define VIEW_OUTPUTS_MAX 32
#define VIEW_OUTPUT_IDLE_S 5.0

struct view_output {
    struct lru_slot use; /* first: the slot's place in lru_slots */
    struct gpu_image image;
    struct gpu_buffer readback; /* width x height texels of the image's format */
};

struct view_outputs {
    struct view_output slot[VIEW_OUTPUTS_MAX];
    uint64_t clock;
};

/* The pair for (width, height, format), created when there is none (replacing the least
 * recently used when all are taken; *created tells, since a new pair may take the slot, and
 * so the address, of the one it replaced); NULL on failure. `now_s` is any monotonic clock in
 * seconds; pairs idle for more than VIEW_OUTPUT_IDLE_S before it are released first. */
struct view_output *view_outputs_acquire(struct vk_context *ctx, struct view_outputs *o,
                                         uint32_t width, uint32_t height, VkFormat format,
                                         VkDeviceSize texel_bytes, double now_s, bool *created);
/* Pairs holding an image. */
int view_outputs_in_use(const struct view_outputs *o);
void view_outputs_destroy(struct vk_context *ctx, struct view_outputs *o);

#endif
