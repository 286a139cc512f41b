#include "lru_slots.h"

static struct lru_slot *slot_at(const struct lru_slots_kind *kind, void *slots, int i)
{
    return (struct lru_slot *)((char *)slots + (size_t)i * kind->stride);
}

void *lru_slots_acquire(struct vk_context *ctx, const struct lru_slots_kind *kind, void *slots,
                        uint64_t *clock, const void *key, double now_s, bool *found)
{
    ++*clock;
    struct lru_slot *match = NULL, *victim = slot_at(kind, slots, 0);
    for (int i = 0; i < kind->count; i++) {
        struct lru_slot *s = slot_at(kind, slots, i);
        if (s->in_use && kind->matches(s, key))
            match = s;
        else if (s->in_use && now_s - s->last_used_s > kind->idle_s)
            kind->release(ctx, s);
        if (!s->in_use || (victim->in_use && s->last_used < victim->last_used))
            victim = s;
    }
    *found = match != NULL;
    struct lru_slot *s = match;
    if (!s) {
        s = victim;
        kind->release(ctx, s);
        s->filled = *clock;
    }
    s->last_used = *clock;
    s->last_used_s = now_s;
    return s;
}

int lru_slots_in_use(const struct lru_slots_kind *kind, const void *slots)
{
    int n = 0;
    for (int i = 0; i < kind->count; i++)
        n += ((const struct lru_slot *)((const char *)slots + (size_t)i * kind->stride))->in_use;
    return n;
}

void lru_slots_release_all(struct vk_context *ctx, const struct lru_slots_kind *kind, void *slots)
{
    for (int i = 0; i < kind->count; i++)
        kind->release(ctx, slot_at(kind, slots, i));
}
