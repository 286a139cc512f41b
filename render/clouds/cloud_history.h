/* Per-view cloud histories for temporal reprojection: a least-recently-used set keyed by the
 * view's history_key, size and trace block. Each entry owns its trace images (the
 * block-resolution samples of one frame), two cloud-image-sized history pairs (colour with
 * opacity; depth and sample count) used alternately, and the resolved clouds' effect on the
 * final image (over the sky, over the ground). */
#ifndef SKYD_CLOUD_HISTORY_H
#define SKYD_CLOUD_HISTORY_H

#include <stdbool.h>
#include <stdint.h>

#include "lru_slots.h"
#include "vk_resources.h"

struct vk_context;

/* Room for every view of a busy daemon (8 clients with 4 subscriptions each): a view that
 * finds none free replaces the least recently used, and when more views than entries are
 * rendered in turn, every frame of each creates its six images again and its clouds never
 * converge. Idle entries hold no images, so the room costs nothing while unused. */
#define CLOUD_HISTORY_ENTRIES 32
/* An entry no view has used for this long is released: views come and go (a client's views,
 * snapshots), and an entry is up to six float images of its view's size. */
#define CLOUD_HISTORY_IDLE_S 5.0

struct cloud_history_entry {
    struct lru_slot use; /* first: the entry's place in lru_slots */
    uint64_t key;
    uint32_t width, height;
    int block;
    struct gpu_image trace_color, trace_depth;
    struct gpu_image color[2], aux[2];
    struct gpu_image over_sky, over_ground; /* cloud_resolve.comp's outputs */
    int latest;                             /* index of the pair holding the last result */
    bool valid;                             /* latest holds a frame of this view */
    uint32_t frame;                         /* frames rendered into this history */
    float prev_forward[4], prev_right[4], prev_up[4]; /* camera of the latest frame */
    double prev_wind[2];                              /* wind displacement of the latest frame */
    uint32_t look; /* the cloud renderer's parameter and map generations it shows */
};

struct cloud_history {
    struct cloud_history_entry entries[CLOUD_HISTORY_ENTRIES];
    uint64_t clock;
};

/* The entry for (key, size, block), created (replacing the least recently used) when new;
 * NULL on failure. Entries idle for more than CLOUD_HISTORY_IDLE_S before `now_s` (any
 * monotonic clock in seconds) are released first. */
struct cloud_history_entry *cloud_history_acquire(struct vk_context *ctx, struct cloud_history *h,
                                                  uint64_t key, uint32_t width, uint32_t height,
                                                  int block, double now_s);
/* Entries holding images. */
int cloud_history_entries_in_use(const struct cloud_history *h);
void cloud_history_destroy(struct vk_context *ctx, struct cloud_history *h);

#endif
