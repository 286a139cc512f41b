#include "trivial_write.h"

#include <stdlib.h>

#include "compute_pass.h"
#include "gpu_timer.h"
#include "trivial_write.spv.h"
#include "vk_context.h"
#include "vk_resources.h"

static int compare_doubles(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

double trivial_write_ms(const char *device_preference, uint32_t width, uint32_t height, int runs)
{
    struct vk_context_params params = { .device_preference = device_preference, .quiet = true };
    struct vk_context *ctx = vk_context_create(&params);
    if (!ctx)
        return -1.0;
    struct gpu_timer *timer = gpu_timer_create(ctx);
    struct gpu_image image = { 0 };
    struct compute_pass pass = { 0 };
    struct compute_pass_desc desc = {
        .name = "trivial_write",
        .spirv = trivial_write_spv,
        .spirv_bytes = sizeof trivial_write_spv,
        .binding_count = 1,
        .bindings = { VK_DESCRIPTOR_TYPE_STORAGE_IMAGE },
    };
    double *ms = calloc((size_t)runs, sizeof *ms);
    double result = -1.0;
    if (!timer || !ms ||
        gpu_image_create(ctx, VK_FORMAT_R8G8B8A8_UNORM, width, height, 1, "trivial", &image) !=
            VK_SUCCESS ||
        compute_pass_create(ctx, &desc, &pass) != VK_SUCCESS)
        goto done;
    struct compute_resource resource = { .image = &image };
    compute_pass_bind(ctx, &pass, &resource);
    const uint32_t size[3] = { width, height, 1 }, local[3] = { 8, 8, 1 };
    for (int i = 0; i < runs; i++) {
        VkCommandBuffer cmd;
        if (vk_context_begin_commands(ctx, &cmd) != VK_SUCCESS)
            goto done;
        gpu_timer_begin(timer, cmd);
        compute_pass_record(cmd, &pass, NULL, size, local);
        gpu_timer_mark(timer, cmd, "trivial_write");
        struct gpu_timer_result t;
        if (vk_context_submit_and_wait(ctx, &cmd) != VK_SUCCESS || !gpu_timer_read(ctx, timer, &t))
            goto done;
        ms[i] = t.total_ms;
    }
    qsort(ms, (size_t)runs, sizeof *ms, compare_doubles);
    result = ms[runs / 2];
done:
    free(ms);
    compute_pass_destroy(ctx, &pass);
    gpu_image_destroy(ctx, &image);
    gpu_timer_destroy(ctx, &timer);
    vk_context_destroy(&ctx);
    return result;
}
