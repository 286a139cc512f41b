#include "cloud_history.h"

#include <string.h>

#include "vk_check.h"
#include "vk_context.h"

#define FORMAT VK_FORMAT_R32G32B32A32_SFLOAT

struct entry_key {
    uint64_t key;
    uint32_t width, height;
    int block;
};

static bool entry_matches(const void *slot, const void *key)
{
    const struct cloud_history_entry *e = slot;
    const struct entry_key *k = key;
    return e->key == k->key && e->width == k->width && e->height == k->height &&
           e->block == k->block;
}

static void entry_destroy(struct vk_context *ctx, void *slot)
{
    struct cloud_history_entry *e = slot;
    gpu_image_destroy(ctx, &e->trace_color);
    gpu_image_destroy(ctx, &e->trace_depth);
    for (int i = 0; i < 2; i++) {
        gpu_image_destroy(ctx, &e->color[i]);
        gpu_image_destroy(ctx, &e->aux[i]);
    }
    gpu_image_destroy(ctx, &e->over_sky);
    gpu_image_destroy(ctx, &e->over_ground);
    memset(e, 0, sizeof *e);
}

static const struct lru_slots_kind kind = {
    .count = CLOUD_HISTORY_ENTRIES,
    .stride = sizeof(struct cloud_history_entry),
    .idle_s = CLOUD_HISTORY_IDLE_S,
    .matches = entry_matches,
    .release = entry_destroy,
};

static VkResult image(struct vk_context *ctx, uint32_t w, uint32_t h, const char *name,
                      struct gpu_image *out)
{
    return gpu_image_create_view_sized(ctx, FORMAT, w, h, name, out);
}

/* Fills `e`, a released slot. */
static int entry_create(struct vk_context *ctx, struct cloud_history_entry *e, uint64_t key,
                        uint32_t w, uint32_t h, int block)
{
    uint32_t tw = (w + (uint32_t)block - 1) / (uint32_t)block;
    uint32_t th = (h + (uint32_t)block - 1) / (uint32_t)block;
    VK_CHECK_GOTO(image(ctx, tw, th, "cloud_trace", &e->trace_color), destroy_partial);
    VK_CHECK_GOTO(image(ctx, tw, th, "cloud_trace_depth", &e->trace_depth), destroy_partial);
    for (int i = 0; i < 2; i++) {
        VK_CHECK_GOTO(image(ctx, w, h, "cloud_history", &e->color[i]), destroy_partial);
        VK_CHECK_GOTO(image(ctx, w, h, "cloud_history_aux", &e->aux[i]), destroy_partial);
    }
    VK_CHECK_GOTO(image(ctx, w, h, "clouds_over_sky", &e->over_sky), destroy_partial);
    VK_CHECK_GOTO(image(ctx, w, h, "clouds_over_ground", &e->over_ground), destroy_partial);
    e->use.in_use = true;
    e->key = key;
    e->width = w;
    e->height = h;
    e->block = block;
    return 0;
destroy_partial:
    entry_destroy(ctx, e);
    return -1;
}

struct cloud_history_entry *cloud_history_acquire(struct vk_context *ctx, struct cloud_history *h,
                                                  uint64_t key, uint32_t width, uint32_t height,
                                                  int block, double now_s)
{
    const struct entry_key k = { key, width, height, block };
    bool found;
    struct cloud_history_entry *e = lru_slots_acquire(ctx, &kind, h->entries, &h->clock, &k, now_s,
                                                      &found);
    if (!found && entry_create(ctx, e, key, width, height, block) != 0)
        return NULL;
    return e;
}

int cloud_history_entries_in_use(const struct cloud_history *h)
{
    return lru_slots_in_use(&kind, h->entries);
}

void cloud_history_destroy(struct vk_context *ctx, struct cloud_history *h)
{
    lru_slots_release_all(ctx, &kind, h->entries);
}
