/* The reuse policy of the renderer's per-view caches (cloud_history, view_outputs): a fixed
 * array of slots, each found again by its key while in use, released once idle for longer
 * than its kind's limit, and, when all are taken, the least recently used replaced. */
#ifndef SKYD_LRU_SLOTS_H
#define SKYD_LRU_SLOTS_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

struct vk_context;

/* The first member of every slot; all zero is a free slot. */
struct lru_slot {
    bool in_use;
    uint64_t last_used; /* the set's clock at its last acquisition */
    double last_used_s; /* the `now_s` of its last acquisition */
    /* The set's clock when the slot was last given out to fill: a new occupant at the same
     * address has a new value, so that what was bound to the old one can tell. */
    uint64_t filled;
};

struct lru_slots_kind {
    int count;
    size_t stride; /* bytes from one slot to the next */
    double idle_s;
    bool (*matches)(const void *slot, const void *key);
    void (*release)(struct vk_context *ctx, void *slot); /* frees what it holds, zeroes it */
};

/* The in-use slot matching `key` (*found true), or else a released slot to fill (*found
 * false): a free one, or the least recently used. Either way it is stamped as used at `now_s`
 * (any monotonic clock in seconds); the caller fills a new one and sets its in_use. Every
 * other slot idle for more than kind->idle_s before now_s is released first: all are looked
 * at, past a match too, or an idle slot behind the one a lone view keeps using would never
 * be released. */
void *lru_slots_acquire(struct vk_context *ctx, const struct lru_slots_kind *kind, void *slots,
                        uint64_t *clock, const void *key, double now_s, bool *found);
/* Slots in use. */
int lru_slots_in_use(const struct lru_slots_kind *kind, const void *slots);
void lru_slots_release_all(struct vk_context *ctx, const struct lru_slots_kind *kind, void *slots);

#endif
