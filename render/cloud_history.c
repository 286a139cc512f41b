#include "cloud_history.h"

#include <string.h>

#include "vk_check.h"
#include "vk_context.h"

#define FORMAT VK_FORMAT_R32G32B32A32_SFLOAT

static void entry_destroy(struct vk_context *ctx, struct cloud_history_entry *e)
{
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

static int entry_create(struct vk_context *ctx, struct cloud_history_entry *e, uint64_t key,
                        uint32_t w, uint32_t h, int block)
{
    memset(e, 0, sizeof *e);
    uint32_t tw = (w + (uint32_t)block - 1) / (uint32_t)block;
    uint32_t th = (h + (uint32_t)block - 1) / (uint32_t)block;
    VK_CHECK_GOTO(gpu_image_create(ctx, FORMAT, tw, th, 1, "cloud_trace", &e->trace_color), fail);
    VK_CHECK_GOTO(gpu_image_create(ctx, FORMAT, tw, th, 1, "cloud_trace_depth", &e->trace_depth),
                  fail);
    for (int i = 0; i < 2; i++) {
        VK_CHECK_GOTO(gpu_image_create(ctx, FORMAT, w, h, 1, "cloud_history", &e->color[i]), fail);
        VK_CHECK_GOTO(gpu_image_create(ctx, FORMAT, w, h, 1, "cloud_history_aux", &e->aux[i]),
                      fail);
    }
    VK_CHECK_GOTO(gpu_image_create(ctx, FORMAT, w, h, 1, "clouds_over_sky", &e->over_sky), fail);
    VK_CHECK_GOTO(gpu_image_create(ctx, FORMAT, w, h, 1, "clouds_over_ground", &e->over_ground),
                  fail);
    e->in_use = true;
    e->key = key;
    e->width = w;
    e->height = h;
    e->block = block;
    return 0;
fail:
    entry_destroy(ctx, e);
    return -1;
}

struct cloud_history_entry *cloud_history_acquire(struct vk_context *ctx, struct cloud_history *h,
                                                  uint64_t key, uint32_t width, uint32_t height,
                                                  int block, double now_s)
{
    h->clock++;
    struct cloud_history_entry *victim = &h->entries[0];
    for (int i = 0; i < CLOUD_HISTORY_ENTRIES; i++) {
        struct cloud_history_entry *e = &h->entries[i];
        if (e->in_use && e->key == key && e->width == width && e->height == height &&
            e->block == block) {
            e->last_used = h->clock;
            e->last_used_s = now_s;
            return e;
        }
        if (e->in_use && now_s - e->last_used_s > CLOUD_HISTORY_IDLE_S)
            entry_destroy(ctx, e);
        if (!e->in_use || (victim->in_use && e->last_used < victim->last_used))
            victim = e;
    }
    entry_destroy(ctx, victim);
    if (entry_create(ctx, victim, key, width, height, block) != 0)
        return NULL;
    victim->last_used = h->clock;
    victim->last_used_s = now_s;
    return victim;
}

int cloud_history_entries_in_use(const struct cloud_history *h)
{
    int n = 0;
    for (int i = 0; i < CLOUD_HISTORY_ENTRIES; i++)
        n += h->entries[i].in_use;
    return n;
}

void cloud_history_destroy(struct vk_context *ctx, struct cloud_history *h)
{
    for (int i = 0; i < CLOUD_HISTORY_ENTRIES; i++)
        entry_destroy(ctx, &h->entries[i]);
}
