#include "view_outputs.h"

#include <string.h>

#include "vk_check.h"
#include "vk_context.h"

struct output_key {
    uint32_t width, height;
    VkFormat format;
};

static bool matches(const void *slot, const void *key)
{
    const struct view_output *s = slot;
    const struct output_key *k = key;
    return s->image.width == k->width && s->image.height == k->height &&
           s->image.format == k->format;
}

static void release(struct vk_context *ctx, void *slot)
{
    struct view_output *s = slot;
    gpu_image_destroy(ctx, &s->image);
    gpu_buffer_destroy(ctx, &s->readback);
    memset(s, 0, sizeof *s);
}

static const struct lru_slots_kind kind = {
    .count = VIEW_OUTPUTS_MAX,
    .stride = sizeof(struct view_output),
    .idle_s = VIEW_OUTPUT_IDLE_S,
    .matches = matches,
    .release = release,
};

struct view_output *view_outputs_acquire(struct vk_context *ctx, struct view_outputs *o,
                                         uint32_t width, uint32_t height, VkFormat format,
                                         VkDeviceSize texel_bytes, double now_s, bool *created)
{
    const struct output_key key = { width, height, format };
    bool found;
    struct view_output *s = lru_slots_acquire(ctx, &kind, o->slot, &o->clock, &key, now_s, &found);
    *created = false;
    if (found)
        return s;
    VK_CHECK_GOTO(gpu_image_create_view_sized(ctx, format, width, height, "output", &s->image),
                  destroy_partial);
    VK_CHECK_GOTO(gpu_buffer_create(ctx, (VkDeviceSize)width * height * texel_bytes,
                                    VK_BUFFER_USAGE_TRANSFER_DST_BIT, "readback", &s->readback),
                  destroy_partial);
    s->use.in_use = true;
    *created = true;
    return s;
destroy_partial:
    release(ctx, s);
    return NULL;
}

int view_outputs_in_use(const struct view_outputs *o)
{
    return lru_slots_in_use(&kind, o->slot);
}

void view_outputs_destroy(struct vk_context *ctx, struct view_outputs *o)
{
    lru_slots_release_all(ctx, &kind, o->slot);
}
