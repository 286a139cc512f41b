#include "sky_passes_internal.h"

#include <math.h>
#include <string.h>

#include "gpu_timer.h"
#include "vk_context.h"

static void record(struct sky_passes *p, VkCommandBuffer cmd, struct gpu_timer *timer,
                   enum pass_id id, const void *push, uint32_t sx, uint32_t sy, uint32_t sz,
                   uint32_t lx, uint32_t ly)
{
    const uint32_t size[3] = { sx, sy, sz };
    const uint32_t local[3] = { lx, ly, 1 };
    compute_pass_record(cmd, &p->pass[id], push, size, local);
    gpu_timer_mark(timer, cmd, p->pass[id].name);
}

void sky_passes_atmosphere_slices(const struct sky_passes *p, uint32_t *transmittance_slices,
                                  uint32_t *multiscattering_slices)
{
    *transmittance_slices =
        (p->transmittance.width * p->transmittance.height + SKY_TRANSMITTANCE_LOCAL - 1) /
        SKY_TRANSMITTANCE_LOCAL;
    *multiscattering_slices = p->multiscattering.width * p->multiscattering.height; /* texels */
}

void sky_passes_record_build(struct sky_passes *p, VkCommandBuffer cmd, struct gpu_timer *timer,
                             enum sky_build_step step, uint32_t first_slice, uint32_t slice_count)
{
    struct sky_rows_push rows = { .row_offset = first_slice };
    switch (step) {
    case SKY_BUILD_TRANSMITTANCE:
        /* a slice: a workgroup's block of SKY_TRANSMITTANCE_LOCAL texels */
        record(p, cmd, timer, PASS_TRANSMITTANCE, &rows, slice_count, 1, 1, 1, 1);
        break;
    case SKY_BUILD_MULTISCATTERING:
        /* a slice: one texel, a workgroup of SKY_MULTISCATTERING_LOCAL sphere directions */
        record(p, cmd, timer, PASS_MULTISCATTERING, &rows, slice_count, 1, 1, 1, 1);
        break;
    case SKY_BUILD_IRRADIANCE:
        /* a workgroup per texel (SKY_IRRADIANCE_DIRECTIONS lanes) */
        record(p, cmd, timer, PASS_IRRADIANCE, NULL, IRRADIANCE_SIZE, 1, 1, 1, 1);
        break;
    }
}

static void record_lut_copies(struct sky_passes *p, VkCommandBuffer cmd, struct gpu_timer *timer,
                              enum pass_id first, float weight)
{
    struct sky_blend_push push = { .weight = weight };
    const struct gpu_image *out[3] = { &p->transmittance, &p->multiscattering, &p->irradiance };
    for (int which = 0; which < 3; which++)
        record(p, cmd, timer, (enum pass_id)(first + which), &push, out[which]->width,
               out[which]->height, 1, SKY_LUT_BLEND_LOCAL, SKY_LUT_BLEND_LOCAL);
}

void sky_passes_record_save_display(struct sky_passes *p, VkCommandBuffer cmd,
                                    struct gpu_timer *timer)
{
    record_lut_copies(p, cmd, timer, PASS_SAVE_TRANSMITTANCE, 0.0f);
}

void sky_passes_record_blend(struct sky_passes *p, VkCommandBuffer cmd, struct gpu_timer *timer,
                             float weight)
{
    record_lut_copies(p, cmd, timer, PASS_BLEND_TRANSMITTANCE, weight);
}

void sky_passes_record_atmosphere(struct sky_passes *p, VkCommandBuffer cmd,
                                  struct gpu_timer *timer)
{
    uint32_t transmittance_blocks, multiscattering_texels;
    sky_passes_atmosphere_slices(p, &transmittance_blocks, &multiscattering_texels);
    sky_passes_record_build(p, cmd, timer, SKY_BUILD_TRANSMITTANCE, 0, transmittance_blocks);
    sky_passes_record_build(p, cmd, timer, SKY_BUILD_MULTISCATTERING, 0, multiscattering_texels);
    sky_passes_record_build(p, cmd, timer, SKY_BUILD_IRRADIANCE, 0, 1);
    sky_passes_record_blend(p, cmd, timer, 1.0f);
}

void sky_passes_record_view_luts(struct sky_passes *p, VkCommandBuffer cmd, struct gpu_timer *timer,
                                 bool skyview, bool moonlit_sky)
{
    if (skyview)
        record(p, cmd, timer, PASS_SKYVIEW, NULL, p->skyview.width, p->skyview.height, 1,
               SKY_SKYVIEW_LOCAL, SKY_SKYVIEW_LOCAL);
    if (skyview && moonlit_sky)
        record(p, cmd, timer, PASS_SKYVIEW_MOON, NULL, p->moon_skyview.width,
               p->moon_skyview.height, 1, SKY_SKYVIEW_LOCAL, SKY_SKYVIEW_LOCAL);
}

void sky_passes_record_aerial_perspective(struct vk_context *ctx, struct sky_passes *p,
                                          VkCommandBuffer cmd, struct gpu_timer *timer,
                                          const struct sky_cloud_bindings *clouds)
{
    /* Nothing of this command buffer uses the AP pass's set yet: it may follow the clouds.
     * Only the shadow map and the block matter to it, not the view's cloud image. */
    if (p->ap_clouds.shadow != clouds->shadow ||
        p->ap_clouds.shadow_sampler != clouds->shadow_sampler ||
        p->ap_clouds.params != clouds->params || p->ap_clouds.env != clouds->env) {
        p->ap_clouds = *clouds;
        sky_passes_bind_aerial_perspective(ctx, p);
    }
    record(p, cmd, timer, PASS_AERIAL_PERSPECTIVE, NULL, p->ap_inscatter.width,
           p->ap_inscatter.height, 1, SKY_AP_LOCAL, SKY_AP_LOCAL);
}

void sky_passes_record_metering(struct sky_passes *p, VkCommandBuffer cmd, struct gpu_timer *timer,
                                uint32_t width, uint32_t height, bool from_space, bool night_sky)
{
    /* About one sample per 16x16 pixels (a log average of a smooth sky needs few), at most
     * METER_MAX_GRID^2 so the partials fit. */
    uint32_t gw = (width + 15) / 16, gh = (height + 15) / 16;
    if (gw > METER_MAX_GRID)
        gw = METER_MAX_GRID;
    if (gh > METER_MAX_GRID)
        gh = METER_MAX_GRID;
    p->meter = (struct sky_meter_push){
        .grid_width = gw,
        .grid_height = gh,
        .group_count = ((gw + SKY_METER_LOCAL - 1) / SKY_METER_LOCAL) *
                       ((gh + SKY_METER_LOCAL - 1) / SKY_METER_LOCAL),
    };
    enum pass_id meter = night_sky || from_space ? sky_pass_variant(PASS_METER, from_space)
                                                 : PASS_METER_DAY;
    record(p, cmd, timer, meter, &p->meter, gw, gh, 1, SKY_METER_LOCAL, SKY_METER_LOCAL);
    record(p, cmd, timer, PASS_EXPOSURE_RESOLVE, &p->meter, 1, 1, 1, 1, 1);
}

/* One composite dispatch over `rect` (x0, y0, w, h); false when its pipeline is missing. */
static bool record_region(struct vk_context *ctx, struct sky_passes *p, VkCommandBuffer cmd,
                          unsigned flags, const int32_t rect[4])
{
    const struct compute_pass *pass = composite_variants_get(ctx, p->composite, flags);
    if (!pass)
        return false;
    const struct gpu_image *clouds = p->clouds.over_sky;
    struct sky_region_push push = {
        .rect = { rect[0], rect[1], rect[2], rect[3] },
        .clouds = { clouds ? (float)clouds->width : 1.0f, clouds ? (float)clouds->height : 1.0f,
                    0.0f, 0.0f },
    };
    const uint32_t size[3] = { (uint32_t)rect[2], (uint32_t)rect[3], 1 };
    const uint32_t local[3] = { SKY_COMPOSITE_LOCAL, SKY_COMPOSITE_LOCAL, 1 };
    compute_pass_record(cmd, pass, &push, size, local);
    return true;
}

/* Every pipeline of the output kind, each dispatched on pixel (0, 0), which the frame's own
 * regions then write again. lavapipe compiles a pipeline's code at its first dispatch and keeps
 * it: had each combination (sun in view, night, camera in space...) waited for a view that
 * needs it, a stream would stall at that frame, and a daemon's memory would keep growing for
 * hours as new ones came (heaptrack on the cluster soak's node A). */
static bool warm_up_variants(struct vk_context *ctx, struct sky_passes *p, VkCommandBuffer cmd,
                             unsigned kind)
{
    static const int32_t first_pixel[4] = { 0, 0, 1, 1 };
    unsigned flags[COMPOSITE_VARIANT_COUNT];
    int count = composite_variants_of_kind(kind, flags);
    for (int i = 0; i < count; i++)
        if (!record_region(ctx, p, cmd, flags[i], first_pixel))
            return false;
    return true;
}

int sky_passes_record_composite(struct vk_context *ctx, struct sky_passes *p, VkCommandBuffer cmd,
                                struct gpu_timer *timer, const struct sky_composite_job *job)
{
    unsigned kind = job->kind == SKY_RENDER_OUTPUT_LINEAR ? COMPOSITE_LINEAR : 0;
    unsigned base = kind | (job->clouds ? COMPOSITE_CLOUDS : 0);
    unsigned main_flags = base | (job->night_sky ? COMPOSITE_NIGHT_SKY : 0);
    int32_t w = (int32_t)p->out->image.width, h = (int32_t)p->out->image.height;
    bool ok = true;
    if (composite_variants_claim_warm_up(p->composite, kind))
        ok = warm_up_variants(ctx, p, cmd, kind);
    if (job->from_space) {
        const int32_t full[4] = { 0, 0, w, h };
        ok = ok && record_region(ctx, p, cmd, main_flags | COMPOSITE_FROM_SPACE, full);
    } else {
        /* The rows that may see the ground get the ground's work; the rest go without it. */
        int32_t g0 = h, g1 = h;
        if (job->ground_rows)
            g0 = (int32_t)job->ground_rows[0], g1 = (int32_t)job->ground_rows[1];
        const int32_t above[4] = { 0, 0, w, g0 }, ground[4] = { 0, g0, w, g1 - g0 };
        const int32_t below[4] = { 0, g1, w, h - g1 };
        if (above[3] > 0)
            ok = ok && record_region(ctx, p, cmd, main_flags, above);
        if (ground[3] > 0)
            ok = ok && record_region(ctx, p, cmd, main_flags | COMPOSITE_GROUND, ground);
        if (below[3] > 0)
            ok = ok && record_region(ctx, p, cmd, main_flags, below);
    }
    gpu_timer_mark(timer, cmd, "composite");
    /* The sun's box is rewritten with the sun included, so the main pass never carries the
     * disk's cost; the moon's likewise (always with the night sky: the moon shows by day). */
    unsigned disc = base | COMPOSITE_SUN_REGION | COMPOSITE_GROUND;
    if (!job->from_space && job->sun_rect) {
        ok = ok && record_region(ctx, p, cmd, disc | (job->night_sky ? COMPOSITE_NIGHT_SKY : 0),
                                 job->sun_rect);
        gpu_timer_mark(timer, cmd, "sun_disk");
    }
    if (!job->from_space && job->moon_rect) {
        ok = ok && record_region(ctx, p, cmd, disc | COMPOSITE_NIGHT_SKY, job->moon_rect);
        gpu_timer_mark(timer, cmd, "moon_disk");
    }
    gpu_barrier_compute_to_transfer(cmd);
    gpu_copy_image_to_buffer(cmd, &p->out->image, &p->out->readback);
    gpu_barrier_to_host(cmd);
    gpu_timer_mark(timer, cmd, "readback");
    return ok ? 0 : -1;
}

void sky_passes_record_probe(struct sky_passes *p, VkCommandBuffer cmd, struct gpu_timer *timer,
                             uint32_t mode, uint32_t count, bool from_space)
{
    struct sky_probe_push push = { .count = count, .mode = mode };
    record(p, cmd, timer, sky_pass_variant(PASS_PROBE, from_space), &push, count, 1, 1,
           SKY_PROBE_LOCAL, 1);
    gpu_barrier_to_host(cmd);
}
