#include "cloud_reference.h"

#include <stdlib.h>
#include <string.h>

#include "cloud_history.h"
#include "cloud_passes.h"
#include "vk_check.h"
#include "vk_context.h"

#include "clouds_shaders.h"

/* Samples per pixel of one dispatch: each stays short even on a GPU (a sample of a storm
 * cloud follows a path of a few hundred collisions), and on lavapipe, whose loops stop once an
 * invocation's iterations reach 65535 (cloud_pathtrace.comp), each sample has that budget to
 * itself. */
#define SAMPLES_PER_DISPATCH 1

struct cloud_reference {
    struct compute_pass pass[2]; /* without, then with the moon's light */
    struct compute_pass majorant;
    struct gpu_image grid;
    struct gpu_buffer stats;
};

/* clang-format off */
#define PATHTRACE_DESC(moonlit)                                                            \
    { .name = "cloud_pathtrace", .spirv = cloud_pathtrace_spv,                             \
      .spirv_bytes = sizeof(cloud_pathtrace_spv), SKY_PASS_LAYOUT(SKY_LAYOUT_CLOUD_PATHTRACE), \
      .push_constant_bytes = sizeof(struct sky_cloud_reference_push),                      \
      .spec_count = SKY_CLOUD_CONST_MOONLIT + 1,                                            \
      .spec_values = { [SKY_CLOUD_CONST_MOONLIT] = moonlit } }

static const struct compute_pass_desc descs[2] = { PATHTRACE_DESC(0), PATHTRACE_DESC(1) };
static const struct compute_pass_desc majorant_desc = {
    .name = "cloud_majorant", .spirv = cloud_majorant_spv,
    .spirv_bytes = sizeof(cloud_majorant_spv), SKY_PASS_LAYOUT(SKY_LAYOUT_CLOUD_MAJORANT)
};
/* clang-format on */

struct cloud_reference *cloud_reference_create(struct vk_context *ctx)
{
    struct cloud_reference *ref = calloc(1, sizeof *ref);
    if (!ref)
        return NULL;
    VK_CHECK_GOTO(gpu_buffer_create(ctx, sizeof(struct sky_cloud_reference_stats),
                                    VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, "cloud_reference_stats",
                                    &ref->stats),
                  destroy_partial);
    memset(ref->stats.mapped, 0, sizeof(struct sky_cloud_reference_stats));
    for (int i = 0; i < 2; i++)
        VK_CHECK_GOTO(compute_pass_create(ctx, &descs[i], &ref->pass[i]), destroy_partial);
    VK_CHECK_GOTO(compute_pass_create(ctx, &majorant_desc, &ref->majorant), destroy_partial);
    VK_CHECK_GOTO(gpu_image_create(ctx, VK_FORMAT_R32G32B32A32_SFLOAT, SKY_CLOUD_MAJORANT_GRID_SIZE,
                                   SKY_CLOUD_MAJORANT_GRID_SIZE, 1, "cloud_majorant", &ref->grid),
                  destroy_partial);
    return ref;
destroy_partial:
    cloud_reference_destroy(ctx, &ref);
    return NULL;
}

void cloud_reference_destroy(struct vk_context *ctx, struct cloud_reference **pref)
{
    struct cloud_reference *ref = pref ? *pref : NULL;
    if (!ref)
        return;
    for (int i = 0; i < 2; i++)
        compute_pass_destroy(ctx, &ref->pass[i]);
    compute_pass_destroy(ctx, &ref->majorant);
    gpu_image_destroy(ctx, &ref->grid);
    gpu_buffer_destroy(ctx, &ref->stats);
    free(ref);
    *pref = NULL;
}

int cloud_reference_record(struct vk_context *ctx, struct cloud_reference *ref,
                           const struct compute_resource *march, VkCommandBuffer cmd,
                           const struct cloud_frame *f, struct cloud_history_entry *e, uint32_t spp,
                           uint32_t seed, float precipitation_ceiling)
{
    if (spp == 0 || e->block != 1)
        return -1;
    struct compute_pass *pass = &ref->pass[moonlit(f)];
    struct compute_resource r[SKY_LAYOUT_COUNT(SKY_LAYOUT_CLOUD_PATHTRACE)];
    cloud_march_copy(march, r);
    struct compute_resource g[SKY_LAYOUT_COUNT(SKY_LAYOUT_CLOUD_MAJORANT)] = {
        [SKY_CLOUD_MAJORANT_WEATHER] = r[SKY_CLOUD_MARCH_WEATHER],
        [SKY_CLOUD_MAJORANT_OUT] = img(&ref->grid),
        [SKY_CLOUD_MAJORANT_CLOUD] = r[SKY_CLOUD_MARCH_CLOUD],
    };
    compute_pass_bind(ctx, &ref->majorant, g);
    const uint32_t grid_size[3] = { SKY_CLOUD_MAJORANT_GRID_SIZE, SKY_CLOUD_MAJORANT_GRID_SIZE, 1 };
    compute_pass_record(cmd, &ref->majorant, NULL, grid_size, local_2d);
    r[SKY_CLOUD_PATHTRACE_SUM] = img(&e->trace_color);
    r[SKY_CLOUD_PATHTRACE_DEPTH_SUM] = img(&e->trace_depth);
    r[SKY_CLOUD_PATHTRACE_COLOR_OUT] = img(&e->color[e->latest]);
    r[SKY_CLOUD_PATHTRACE_AP_INSCATTER] = tex(f->sky.ap_inscatter, f->sky.sampler);
    r[SKY_CLOUD_PATHTRACE_AP_TRANSMITTANCE] = tex(f->sky.ap_transmittance, f->sky.sampler);
    r[SKY_CLOUD_PATHTRACE_STATS] = buf(&ref->stats);
    r[SKY_CLOUD_PATHTRACE_GRID] = tex(&ref->grid, f->sky.sampler);
    compute_pass_bind(ctx, pass, r);
    /* The frame is recorded after the last one completed: nothing reads the counters now. */
    memset(ref->stats.mapped, 0, sizeof(struct sky_cloud_reference_stats));
    const uint32_t size[3] = { e->width, e->height, 1 };
    for (uint32_t done = 0; done < spp; done += SAMPLES_PER_DISPATCH) {
        uint32_t n = spp - done < SAMPLES_PER_DISPATCH ? spp - done : SAMPLES_PER_DISPATCH;
        struct sky_cloud_reference_push push = {
            .samples = { (int32_t)done, (int32_t)n, (int32_t)seed, 0 },
            .target = { (int32_t)e->width, (int32_t)e->height, 0, 0 },
            .media = { precipitation_ceiling, 0, 0, 0 },
        };
        compute_pass_record(cmd, pass, &push, size, local_2d);
    }
    /* The image from the sums, in a dispatch of its own: its aerial perspective's march needs
     * loops that no path has used up. */
    struct sky_cloud_reference_push last = {
        .samples = { (int32_t)spp, 0, (int32_t)seed, 0 },
        .target = { (int32_t)e->width, (int32_t)e->height, 0, 1 },
        .media = { precipitation_ceiling, 0, 0, 0 },
    };
    compute_pass_record(cmd, pass, &last, size, local_2d);
    return 0;
}

void cloud_reference_stats(const struct cloud_reference *ref,
                           struct sky_render_reference_stats *out)
{
    struct sky_cloud_reference_stats s;
    memcpy(&s, ref->stats.mapped, sizeof s);
    float max_ratio;
    memcpy(&max_ratio, &s.max_ratio_bits, sizeof max_ratio);
    *out = (struct sky_render_reference_stats){
        .density_samples = 1e3 * s.kilo_samples,
        .bound_violations = s.violations,
        .max_bound_ratio = s.violations ? max_ratio : 0.0,
        .overflows = s.overflows,
        .truncated = s.truncated,
    };
}
