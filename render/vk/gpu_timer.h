/* Per-pass GPU timing with timestamp queries: a timestamp before the first pass and after
 * each marked pass; after the submission completes, each pass's duration in milliseconds. */
#ifndef SKYD_GPU_TIMER_H
#define SKYD_GPU_TIMER_H

#include <stdbool.h>
#include <stdint.h>
#include <vulkan/vulkan.h>

struct vk_context;

#define GPU_TIMER_MAX_PASSES 32 /* a full LUT rebuild with clouds and the moon marks about 20 */

struct gpu_timer_result {
    int count;
    const char *names[GPU_TIMER_MAX_PASSES];
    double ms[GPU_TIMER_MAX_PASSES];
    double total_ms;
};

struct gpu_timer;

/* Returns NULL when the queue has no timestamps (timing is then simply unavailable) or on
 * failure. */
struct gpu_timer *gpu_timer_create(struct vk_context *ctx);
void gpu_timer_destroy(struct vk_context *ctx, struct gpu_timer **timer);

/* All three accept a NULL timer and then do nothing. */
void gpu_timer_begin(struct gpu_timer *timer, VkCommandBuffer cmd);
void gpu_timer_mark(struct gpu_timer *timer, VkCommandBuffer cmd, const char *pass_name);
/* Reads the results of the last completed submission; false when none are available. */
bool gpu_timer_read(struct vk_context *ctx, struct gpu_timer *timer, struct gpu_timer_result *out);

#endif
