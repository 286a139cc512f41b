#include "cloud_view.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "cloud_history.h"
#include "cloud_params.h"
#include "cloud_passes.h"
#include "cloud_reference.h"
#include "gpu_timer.h"
#include "vk_check.h"
#include "vk_context.h"

#include "clouds_shaders.h"

#define VIEW_PUSH .push_constant_bytes = sizeof(struct sky_cloud_view_push)
/* clang-format off */
#define RESOLVE_SPEC(ground)                                                               \
    .spec_count = SKY_CLOUD_RESOLVE_CONST_GROUND + 1,                                      \
    .spec_values = { [SKY_CLOUD_RESOLVE_CONST_GROUND] = ground }

/* The trace comes four times: without the moon's light, then with it, for frames the moon
 * lights; each for weather maps without towering clouds, then with them (march_variant). */
enum {
    V_TRACE,
    V_TRACE_MOONLIT,
    V_TRACE_TOWERING,
    V_TRACE_TOWERING_MOONLIT,
    V_RECONSTRUCT_0,
    V_RECONSTRUCT_1,
    V_RESOLVE,        /* rows that see no ground (GROUND false) */
    V_RESOLVE_GROUND, /* rows that may */
    V_COUNT
};

static const struct compute_pass_desc descs[V_COUNT] = {
    [V_TRACE] = { .name = "cloud_trace", SPIRV(cloud_trace_spv),
                  SKY_PASS_LAYOUT(SKY_LAYOUT_CLOUD_TRACE), VIEW_PUSH, MARCH_SPEC(0, 0) },
    [V_TRACE_MOONLIT] = { .name = "cloud_trace", SPIRV(cloud_trace_spv),
                          SKY_PASS_LAYOUT(SKY_LAYOUT_CLOUD_TRACE), VIEW_PUSH, MARCH_SPEC(1, 0) },
    [V_TRACE_TOWERING] = { .name = "cloud_trace", SPIRV(cloud_trace_spv),
                           SKY_PASS_LAYOUT(SKY_LAYOUT_CLOUD_TRACE), VIEW_PUSH, MARCH_SPEC(0, 1) },
    [V_TRACE_TOWERING_MOONLIT] = { .name = "cloud_trace", SPIRV(cloud_trace_spv),
                                   SKY_PASS_LAYOUT(SKY_LAYOUT_CLOUD_TRACE), VIEW_PUSH,
                                   MARCH_SPEC(1, 1) },
    [V_RECONSTRUCT_0] = { .name = "cloud_reconstruct", SPIRV(cloud_reconstruct_spv),
                          SKY_PASS_LAYOUT(SKY_LAYOUT_CLOUD_RECONSTRUCT), VIEW_PUSH },
    [V_RECONSTRUCT_1] = { .name = "cloud_reconstruct", SPIRV(cloud_reconstruct_spv),
                          SKY_PASS_LAYOUT(SKY_LAYOUT_CLOUD_RECONSTRUCT), VIEW_PUSH },
    [V_RESOLVE] = { .name = "cloud_resolve", SPIRV(cloud_resolve_spv),
                    SKY_PASS_LAYOUT(SKY_LAYOUT_CLOUD_RESOLVE), ROWS_PUSH, RESOLVE_SPEC(0) },
    [V_RESOLVE_GROUND] = { .name = "cloud_resolve", SPIRV(cloud_resolve_spv),
                           SKY_PASS_LAYOUT(SKY_LAYOUT_CLOUD_RESOLVE), ROWS_PUSH,
                           RESOLVE_SPEC(1) },
};
/* clang-format on */

struct cloud_views {
    struct compute_pass pass[V_COUNT];
    struct cloud_history history;
    struct cloud_reference *reference; /* created with the first reference frame */
};

struct cloud_views *cloud_views_create(struct vk_context *ctx)
{
    struct cloud_views *views = calloc(1, sizeof *views);
    if (!views)
        return NULL;
    for (int i = 0; i < V_COUNT; i++)
        VK_CHECK_GOTO(compute_pass_create(ctx, &descs[i], &views->pass[i]), destroy_partial);
    return views;
destroy_partial:
    cloud_views_destroy(ctx, &views);
    return NULL;
}

void cloud_views_destroy(struct vk_context *ctx, struct cloud_views **pviews)
{
    struct cloud_views *views = pviews ? *pviews : NULL;
    if (!views)
        return;
    for (int i = 0; i < V_COUNT; i++)
        compute_pass_destroy(ctx, &views->pass[i]);
    cloud_history_destroy(ctx, &views->history);
    cloud_reference_destroy(ctx, &views->reference);
    free(views);
    *pviews = NULL;
}

int cloud_views_reference_stats(const struct cloud_views *views,
                                struct sky_render_reference_stats *out)
{
    if (!views->reference)
        return -1;
    cloud_reference_stats(views->reference, out);
    return 0;
}

/* ---- per-view trace and reconstruction ---- */

/* Order in which the pixels of a block are traced: a 4x4 Bayer matrix (and its 2x2 corner),
 * so that consecutive frames land far apart. */
static void block_offset(int block, uint32_t frame, int *x, int *y)
{
    static const int bayer4[16] = { 0, 10, 2, 8, 5, 15, 7, 13, 1, 11, 3, 9, 4, 14, 6, 12 };
    static const int bayer2[4] = { 0, 3, 1, 2 };
    int count = block * block;
    int i = block == 4 ? bayer4[frame % 16] : block == 2 ? bayer2[frame % 4] : 0;
    (void)count;
    *x = i % block;
    *y = i / block;
}

static void copy4(float dst[4], sky_vec4 v)
{
    dst[0] = v.x, dst[1] = v.y, dst[2] = v.z, dst[3] = v.w;
}

static sky_vec4 vec4_of(const float v[4])
{
    return (sky_vec4){ v[0], v[1], v[2], v[3] };
}

/* Internal frames a new history accumulates before its first image is shown, so that one-off
 * renders come out converged: about two samples per pixel (four for the half-size image),
 * at least four frames. */
static int frames_for_new_history(enum sky_render_cloud_resolution resolution)
{
    switch (resolution) {
    case SKY_RENDER_CLOUDS_FULL:
        return 4;
    case SKY_RENDER_CLOUDS_QUARTER:
        return 8;
    case SKY_RENDER_CLOUDS_SIXTEENTH:
        return 32;
    default:
        return 64;
    }
}

/* Rows [first, end) of the cloud image that the output's ground rows sample (bilinear: two
 * taps per output row); left as they are when there are none. */
static void cloud_ground_rows(const struct cloud_frame *f, uint32_t cloud_height, uint32_t rows[2])
{
    if (!f->ground_rows)
        return;
    double scale = (double)cloud_height / f->height;
    double first = floor((f->ground_rows[0] + 0.5) * scale - 0.5);
    double last = floor((f->ground_rows[1] - 0.5) * scale - 0.5) + 1.0;
    first = fmax(first, 0.0);
    last = fmin(last, cloud_height - 1.0);
    if (last < first)
        return;
    rows[0] = (uint32_t)first;
    rows[1] = (uint32_t)last + 1;
}

static void record_resolve_rows(VkCommandBuffer cmd, struct compute_pass *pass, uint32_t width,
                                uint32_t height, uint32_t first, uint32_t end)
{
    if (end <= first)
        return;
    struct sky_cloud_rows_push push = { .row_offset = first,
                                        .size = { (float)width, (float)height, 0.0f, 0.0f } };
    const uint32_t size[3] = { width, end - first, 1 };
    compute_pass_record(cmd, pass, &push, size, local_2d);
}

/* The clouds' effect on the final image from the latest reconstruction (cloud_resolve.comp):
 * the rows that may see the ground with the ground's part, the rest without it. */
static void record_resolve(struct vk_context *ctx, struct cloud_views *views, VkCommandBuffer cmd,
                           struct gpu_timer *timer, const struct cloud_frame *f,
                           const struct cloud_view_inputs *in, struct cloud_history_entry *e)
{
    const struct sky_pass_resources *s = &f->sky;
    struct compute_resource r[SKY_LAYOUT_COUNT(SKY_LAYOUT_CLOUD_RESOLVE)] = {
        [SKY_CLOUD_RESOLVE_ATMOSPHERE] = buf(s->atmosphere_params),
        [SKY_CLOUD_RESOLVE_FRAME] = buf(s->frame_params),
        [SKY_CLOUD_RESOLVE_TRANSMITTANCE] = tex(s->transmittance, s->sampler),
        [SKY_CLOUD_RESOLVE_IRRADIANCE] = tex(s->irradiance, s->sampler),
        [SKY_CLOUD_RESOLVE_CLOUD] = buf(in->params),
        [SKY_CLOUD_RESOLVE_ENV] = buf(in->env),
        [SKY_CLOUD_RESOLVE_SHADOW] = tex(in->shadow, in->repeat),
        [SKY_CLOUD_RESOLVE_AP_SHAFTS] = tex(s->ap_shafts, s->sampler),
        [SKY_CLOUD_RESOLVE_CLOUD_COLOR] = tex(&e->color[e->latest], s->sampler),
        [SKY_CLOUD_RESOLVE_SKY_OUT] = img(&e->over_sky),
        [SKY_CLOUD_RESOLVE_GROUND_OUT] = img(&e->over_ground),
    };
    compute_pass_bind(ctx, &views->pass[V_RESOLVE], r);
    compute_pass_bind(ctx, &views->pass[V_RESOLVE_GROUND], r);
    uint32_t w = e->over_sky.width, h = e->over_sky.height, ground[2] = { h, h };
    cloud_ground_rows(f, h, ground);
    record_resolve_rows(cmd, &views->pass[V_RESOLVE], w, h, 0, ground[0]);
    record_resolve_rows(cmd, &views->pass[V_RESOLVE_GROUND], w, h, ground[0], ground[1]);
    record_resolve_rows(cmd, &views->pass[V_RESOLVE], w, h, ground[1], h);
    gpu_timer_mark(timer, cmd, views->pass[V_RESOLVE].name);
}

/* The reference's history entries: apart from the views' own. */
#define REFERENCE_KEY_BIT (UINT64_C(1) << 63)

/* The path-traced reference in place of trace and reconstruction, at the output's size, then
 * the same resolve. */
static int record_reference(struct vk_context *ctx, struct cloud_views *views, VkCommandBuffer cmd,
                            struct gpu_timer *timer, const struct cloud_frame *f,
                            const struct cloud_view_inputs *in, struct sky_cloud_bindings *out)
{
    const struct sky_render_clouds *c = in->clouds;
    struct cloud_history_entry *e = cloud_history_acquire(
        ctx, &views->history, f->history_key ^ REFERENCE_KEY_BIT, f->width, f->height, 1, f->now_s);
    if (!e)
        return -1;
    if (!views->reference && !(views->reference = cloud_reference_create(ctx)))
        return -1;
    if (cloud_reference_record(ctx, views->reference, in->march, cmd, f, e, c->reference_spp,
                               c->reference_seed, in->precipitation_ceiling) != 0)
        return -1;
    /* The path trace takes minutes on a CPU device: its frame may be waited for that long. */
    vk_context_expect_long_submission(ctx);
    gpu_timer_mark(timer, cmd, "cloud_pathtrace");
    e->valid = false;
    record_resolve(ctx, views, cmd, timer, f, in, e);
    out->over_sky = &e->over_sky;
    out->over_ground = &e->over_ground;
    out->over_filled = e->use.filled;
    return 0;
}

/* Within about a degree: reprojection keeps nearly all of a history. */
static bool same_direction(const float a[4], const sky_vec4 b)
{
    return a[0] * b.x + a[1] * b.y + a[2] * b.z > 0.99985f;
}

int cloud_views_record(struct vk_context *ctx, struct cloud_views *views, VkCommandBuffer cmd,
                       struct gpu_timer *timer, const struct cloud_frame *f,
                       const struct cloud_view_inputs *in, struct sky_cloud_bindings *out)
{
    const struct sky_render_clouds *c = in->clouds;
    if (c->reference_spp > 0)
        return record_reference(ctx, views, cmd, timer, f, in, out);
    int block = cloud_params_block(c->resolution);
    uint32_t scale = (uint32_t)cloud_params_downscale(c->resolution);
    uint32_t width = (f->width + scale - 1) / scale, height = (f->height + scale - 1) / scale;
    struct cloud_history_entry *e = cloud_history_acquire(ctx, &views->history, f->history_key,
                                                          width, height, block, f->now_s);
    if (!e)
        return -1;
    struct compute_pass *trace = &views->pass[V_TRACE + in->march_variant];
    struct compute_resource tr[SKY_LAYOUT_COUNT(SKY_LAYOUT_CLOUD_TRACE)];
    cloud_march_copy(in->march, tr);
    tr[SKY_CLOUD_TRACE_COLOR_OUT] = img(&e->trace_color);
    tr[SKY_CLOUD_TRACE_DEPTH_OUT] = img(&e->trace_depth);
    tr[SKY_CLOUD_TRACE_AP_INSCATTER] = tex(f->sky.ap_inscatter, f->sky.sampler);
    tr[SKY_CLOUD_TRACE_AP_TRANSMITTANCE] = tex(f->sky.ap_transmittance, f->sky.sampler);
    compute_pass_bind(ctx, trace, tr);
    for (int i = 0; i < 2; i++) {
        VkSampler smp = f->sky.sampler;
        struct compute_resource r[SKY_LAYOUT_COUNT(SKY_LAYOUT_CLOUD_RECONSTRUCT)] = {
            [SKY_CLOUD_RECONSTRUCT_FRAME] = buf(f->sky.frame_params),
            [SKY_CLOUD_RECONSTRUCT_TRACE_COLOR] = tex(&e->trace_color, smp),
            [SKY_CLOUD_RECONSTRUCT_TRACE_DEPTH] = tex(&e->trace_depth, smp),
            [SKY_CLOUD_RECONSTRUCT_HISTORY_COLOR] = tex(&e->color[i], smp),
            [SKY_CLOUD_RECONSTRUCT_HISTORY_AUX] = tex(&e->aux[i], smp),
            [SKY_CLOUD_RECONSTRUCT_COLOR_OUT] = img(&e->color[1 - i]),
            [SKY_CLOUD_RECONSTRUCT_AUX_OUT] = img(&e->aux[1 - i]),
        };
        compute_pass_bind(ctx, &views->pass[V_RECONSTRUCT_0 + i], r);
    }
    /* A one-off view comes out converged: it starts over when its history shows other clouds
     * than it would now (a history shared by views at different times, such as snapshots). */
    if (!f->live && e->valid &&
        (e->look != in->look || e->prev_up[3] != f->frame->camera_up.w ||
         !same_direction(e->prev_forward, f->frame->camera_forward)))
        e->valid = false;
    e->look = in->look;
    int frames = (!e->valid && c->temporal && !f->live) ? frames_for_new_history(c->resolution) : 1;
    static const float min_weight[5] = { 0, 0.08f, 0.15f, 0, 0.25f };
    const uint32_t tsize[3] = { e->trace_color.width, e->trace_color.height, 1 };
    const uint32_t size[3] = { width, height, 1 };
    for (int k = 0; k < frames; k++) {
        struct sky_cloud_view_push push;
        memset(&push, 0, sizeof push);
        int ox, oy;
        block_offset(block, e->frame, &ox, &oy);
        push.frame = (sky_ivec4){ (int32_t)e->frame, block, ox, oy };
        push.target = (sky_ivec4){ (int32_t)width, (int32_t)height, (int32_t)e->prev_up[3], 0 };
        if (e->valid) {
            push.prev_forward = vec4_of(e->prev_forward);
            push.prev_right = vec4_of(e->prev_right);
            push.prev_up = vec4_of(e->prev_up);
            push.prev_up.w = 1.0f;
            push.motion.x = (float)(c->wind_offset_east_km - e->prev_wind[0]);
            push.motion.y = (float)(c->wind_offset_north_km - e->prev_wind[1]);
        }
        push.motion.z = min_weight[block];
        push.motion.w = c->temporal ? 1.0f : 0.0f;
        compute_pass_record(cmd, trace, &push, tsize, local_2d);
        if (frames == 1)
            gpu_timer_mark(timer, cmd, "cloud_trace");
        compute_pass_record(cmd, &views->pass[V_RECONSTRUCT_0 + e->latest], &push, size, local_2d);
        if (frames == 1)
            gpu_timer_mark(timer, cmd, "cloud_reconstruct");
        e->latest = 1 - e->latest;
        e->valid = true;
        e->frame++;
        copy4(e->prev_forward, f->frame->camera_forward);
        copy4(e->prev_right, f->frame->camera_right);
        copy4(e->prev_up, f->frame->camera_up);
        e->prev_wind[0] = c->wind_offset_east_km;
        e->prev_wind[1] = c->wind_offset_north_km;
    }
    if (frames > 1)
        gpu_timer_mark(timer, cmd, "cloud_accumulate");
    record_resolve(ctx, views, cmd, timer, f, in, e);
    out->over_sky = &e->over_sky;
    out->over_ground = &e->over_ground;
    out->over_filled = e->use.filled;
    return 0;
}
