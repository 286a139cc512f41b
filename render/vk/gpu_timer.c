#include "gpu_timer.h"

#include <stdlib.h>
#include <string.h>

#include "vk_check.h"
#include "vk_context.h"

struct gpu_timer {
    VkQueryPool pool;
    int marks;
    const char *names[GPU_TIMER_MAX_PASSES];
    double period_ns;
    uint64_t mask;
};

struct gpu_timer *gpu_timer_create(struct vk_context *ctx)
{
    if (ctx->timestamp_period_ns <= 0.0f)
        return NULL;
    struct gpu_timer *timer = calloc(1, sizeof *timer);
    if (!timer)
        return NULL;
    timer->period_ns = ctx->timestamp_period_ns;
    timer->mask = ctx->timestamp_mask;
    VkQueryPoolCreateInfo info = {
        .sType = VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO,
        .queryType = VK_QUERY_TYPE_TIMESTAMP,
        .queryCount = GPU_TIMER_MAX_PASSES + 1,
    };
    VK_CHECK_GOTO(vkCreateQueryPool(ctx->device, &info, NULL, &timer->pool), free_timer);
    return timer;
free_timer:
    free(timer);
    return NULL;
}

void gpu_timer_destroy(struct vk_context *ctx, struct gpu_timer **ptimer)
{
    struct gpu_timer *timer = ptimer ? *ptimer : NULL;
    if (!timer)
        return;
    if (timer->pool)
        vkDestroyQueryPool(ctx->device, timer->pool, NULL);
    free(timer);
    *ptimer = NULL;
}

void gpu_timer_begin(struct gpu_timer *timer, VkCommandBuffer cmd)
{
    if (!timer)
        return;
    timer->marks = 0;
    vkCmdResetQueryPool(cmd, timer->pool, 0, GPU_TIMER_MAX_PASSES + 1);
    vkCmdWriteTimestamp(cmd, VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT, timer->pool, 0);
}

void gpu_timer_mark(struct gpu_timer *timer, VkCommandBuffer cmd, const char *pass_name)
{
    if (!timer || timer->marks >= GPU_TIMER_MAX_PASSES)
        return;
    timer->names[timer->marks] = pass_name;
    timer->marks++;
    vkCmdWriteTimestamp(cmd, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, timer->pool,
                        (uint32_t)timer->marks);
}

bool gpu_timer_read(struct vk_context *ctx, struct gpu_timer *timer, struct gpu_timer_result *out)
{
    memset(out, 0, sizeof *out);
    if (!timer || timer->marks == 0)
        return false;
    uint64_t stamps[GPU_TIMER_MAX_PASSES + 1];
    VkResult res = vkGetQueryPoolResults(ctx->device, timer->pool, 0, (uint32_t)timer->marks + 1,
                                         sizeof stamps, stamps, sizeof stamps[0],
                                         VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_WAIT_BIT);
    if (res != VK_SUCCESS) {
        vk_log(ctx, VK_LOG_ERROR, "vulkan: timestamps unavailable: %s", vk_result_name(res));
        vk_context_note_failure(ctx, res, "reading the timestamps");
        return false;
    }
    out->count = timer->marks;
    for (int i = 0; i < timer->marks; i++) {
        uint64_t delta = (stamps[i + 1] - stamps[i]) & timer->mask;
        out->names[i] = timer->names[i];
        out->ms[i] = (double)delta * timer->period_ns * 1e-6;
        out->total_ms += out->ms[i];
    }
    return true;
}
