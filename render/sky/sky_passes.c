#include "sky_passes_internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "composite_variants.h"
#include "compute_pass.h"
#include "gpu_timer.h"
#include "view_outputs.h"
#include "vk_check.h"
#include "vk_context.h"
#include "vk_resources.h"

#include "sky_shaders.h"

#define SPIRV(name) .spirv = name, .spirv_bytes = sizeof(name)
/* The camera inside the atmosphere, and above it (FROM_SPACE). */
/* clang-format off */
#define SHADING_PAIR(id, label, code, layout, push)                                       \
    [id] = { .name = label, SPIRV(code), SKY_PASS_LAYOUT(layout),                         \
             .push_constant_bytes = push },                                               \
    [id##_SPACE] = { .name = label, SPIRV(code), SKY_PASS_LAYOUT(layout),                 \
                     .push_constant_bytes = push, .spec_count = SKY_CONST_FROM_SPACE + 1,  \
                     .spec_values = { [SKY_CONST_FROM_SPACE] = 1 } }
#define BLEND_PASS(id, label)                                                             \
    [id] = { .name = label, SPIRV(lut_blend_spv), SKY_PASS_LAYOUT(SKY_LAYOUT_LUT_BLEND),  \
             .push_constant_bytes = sizeof(struct sky_blend_push) }

static const struct compute_pass_desc pass_descs[PASS_COUNT] = {
    [PASS_TRANSMITTANCE] = { .name = "transmittance", SPIRV(transmittance_spv),
                             SKY_PASS_LAYOUT(SKY_LAYOUT_TRANSMITTANCE),
                             .push_constant_bytes = sizeof(struct sky_rows_push) },
    [PASS_MULTISCATTERING] = { .name = "multiscattering", SPIRV(multiscattering_spv),
                               SKY_PASS_LAYOUT(SKY_LAYOUT_MULTISCATTERING),
                               .push_constant_bytes = sizeof(struct sky_rows_push) },
    [PASS_IRRADIANCE] = { .name = "irradiance", SPIRV(irradiance_spv),
                          SKY_PASS_LAYOUT(SKY_LAYOUT_IRRADIANCE) },
    [PASS_SKYVIEW] = { .name = "skyview", SPIRV(skyview_spv), SKY_PASS_LAYOUT(SKY_LAYOUT_SKYVIEW) },
    [PASS_SKYVIEW_MOON] = { .name = "moon_skyview", SPIRV(skyview_spv),
                            SKY_PASS_LAYOUT(SKY_LAYOUT_SKYVIEW),
                            .spec_count = SKY_SKYVIEW_CONST_MOON_LIGHT + 1,
                            .spec_values = { [SKY_SKYVIEW_CONST_MOON_LIGHT] = 1 } },
    [PASS_AERIAL_PERSPECTIVE] = { .name = "aerial_perspective", SPIRV(aerial_perspective_spv),
                                  SKY_PASS_LAYOUT(SKY_LAYOUT_AERIAL_PERSPECTIVE) },
    [PASS_EXPOSURE_RESOLVE] = { .name = "exposure", SPIRV(exposure_resolve_spv),
                                SKY_PASS_LAYOUT(SKY_LAYOUT_EXPOSURE_RESOLVE),
                                .push_constant_bytes = sizeof(struct sky_meter_push) },
    SHADING_PAIR(PASS_METER, "meter", meter_spv, SKY_LAYOUT_METER, sizeof(struct sky_meter_push)),
    SHADING_PAIR(PASS_PROBE, "probe", probe_spv, SKY_LAYOUT_PROBE, sizeof(struct sky_probe_push)),
    BLEND_PASS(PASS_BLEND_TRANSMITTANCE, "lut_blend"),
    BLEND_PASS(PASS_BLEND_MULTISCATTERING, "lut_blend"),
    BLEND_PASS(PASS_BLEND_IRRADIANCE, "lut_blend"),
    BLEND_PASS(PASS_SAVE_TRANSMITTANCE, "lut_save"),
    BLEND_PASS(PASS_SAVE_MULTISCATTERING, "lut_save"),
    BLEND_PASS(PASS_SAVE_IRRADIANCE, "lut_save"),
    [PASS_METER_DAY] = { .name = "meter", SPIRV(meter_spv), SKY_PASS_LAYOUT(SKY_LAYOUT_METER),
                         .push_constant_bytes = sizeof(struct sky_meter_push),
                         .spec_count = SKY_CONST_NIGHT_SKY + 1,
                         .spec_values = { [SKY_CONST_NIGHT_SKY] = 0 } },
};
/* clang-format on */

static bool format_supports(struct vk_context *ctx, VkFormat format, VkFormatFeatureFlags need)
{
    VkFormatProperties props;
    vkGetPhysicalDeviceFormatProperties(ctx->physical_device, format, &props);
    return (props.optimalTilingFeatures & need) == need;
}

/* The three copies of the atmosphere LUTs (display, build, previous), in that order. */
static struct gpu_image *atmosphere_lut(struct sky_passes *p, int copy, int which)
{
    struct gpu_image *sets[3][3] = {
        { &p->transmittance, &p->multiscattering, &p->irradiance },
        { &p->build_transmittance, &p->build_multiscattering, &p->build_irradiance },
        { &p->previous_transmittance, &p->previous_multiscattering, &p->previous_irradiance },
    };
    return sets[copy][which];
}

/* Every image whose size the LUT sizes set: the three copies of the atmosphere LUTs, then the
 * per-view LUTs. */
#define LUT_IMAGE_COUNT 14
static void lut_images(struct sky_passes *p, struct gpu_image *out[LUT_IMAGE_COUNT])
{
    int n = 0;
    for (int copy = 0; copy < 3; copy++)
        for (int which = 0; which < 3; which++)
            out[n++] = atmosphere_lut(p, copy, which);
    out[n++] = &p->skyview;
    out[n++] = &p->moon_skyview;
    out[n++] = &p->ap_inscatter;
    out[n++] = &p->ap_transmittance;
    out[n++] = &p->ap_shafts;
}

static void destroy_luts(struct vk_context *ctx, struct sky_passes *p)
{
    struct gpu_image *images[LUT_IMAGE_COUNT];
    lut_images(p, images);
    for (int i = 0; i < LUT_IMAGE_COUNT; i++)
        gpu_image_destroy(ctx, images[i]);
}

/* llvmpipe compiles a shader variant for each combination of whether its bound images'
 * dimensions are powers of two, and keeps the code. A power-of-two side is made two texels
 * shorter (4 becomes 6), so that no LUT size the state can ask for compiles a pipeline again.
 * Shorter: the passes run 8x8 workgroups, and 34 texels would cost a fifth row of them (the
 * aerial-perspective pass took 55 % longer at 34^3 than at 32^3). Two, not one: an odd
 * multiple-scattering side puts a texel centre on the sun's horizon, its least accurate value
 * (test_accuracy's worst sky error: 10.3 % at 30 and 32 texels, 14.6 % at 31). */
static uint32_t lut_extent(uint32_t requested)
{
    uint32_t n = requested;
    while (n >= 2 && gpu_is_power_of_two(n))
        n = n > 4 ? n - 2 : n + 2;
    return n;
}

static int create_luts(struct vk_context *ctx, struct sky_passes *p,
                       const struct sky_render_lut_sizes *requested)
{
    struct sky_render_lut_sizes extents;
    for (int i = 0; i < 2; i++) {
        extents.transmittance[i] = lut_extent(requested->transmittance[i]);
        extents.multiscattering[i] = lut_extent(requested->multiscattering[i]);
        extents.skyview[i] = lut_extent(requested->skyview[i]);
    }
    for (int i = 0; i < 3; i++)
        extents.aerial_perspective[i] = lut_extent(requested->aerial_perspective[i]);
    const struct sky_render_lut_sizes *s = &extents;
    const uint32_t *ap = s->aerial_perspective;
    static const char *const names[3][3] = {
        { "transmittance", "multiscattering", "irradiance" },
        { "build_transmittance", "build_multiscattering", "build_irradiance" },
        { "previous_transmittance", "previous_multiscattering", "previous_irradiance" },
    };
    const uint32_t sizes[3][2] = { { s->transmittance[0], s->transmittance[1] },
                                   { s->multiscattering[0], s->multiscattering[1] },
                                   { IRRADIANCE_SIZE, 1 } };
    for (int copy = 0; copy < 3; copy++)
        for (int which = 0; which < 3; which++)
            VK_CHECK_GOTO(gpu_image_create(ctx, LUT_FORMAT, sizes[which][0], sizes[which][1], 1,
                                           names[copy][which], atmosphere_lut(p, copy, which)),
                          destroy_partial);
    VK_CHECK_GOTO(
        gpu_image_create(ctx, LUT_FORMAT, s->skyview[0], s->skyview[1], 1, "skyview", &p->skyview),
        destroy_partial);
    VK_CHECK_GOTO(gpu_image_create(ctx, LUT_FORMAT, s->skyview[0], s->skyview[1], 1, "moon_skyview",
                                   &p->moon_skyview),
                  destroy_partial);
    VK_CHECK_GOTO(
        gpu_image_create(ctx, LUT_FORMAT, ap[0], ap[1], ap[2], "ap_inscatter", &p->ap_inscatter),
        destroy_partial);
    VK_CHECK_GOTO(gpu_image_create(ctx, LUT_FORMAT, ap[0], ap[1], ap[2], "ap_transmittance",
                                   &p->ap_transmittance),
                  destroy_partial);
    VK_CHECK_GOTO(
        gpu_image_create(ctx, LUT_FORMAT, ap[0], ap[1], ap[2], "ap_shafts", &p->ap_shafts),
        destroy_partial);
    return 0;
destroy_partial:
    destroy_luts(ctx, p);
    return -1;
}

static struct compute_resource img(const struct gpu_image *image)
{
    return (struct compute_resource){ .image = image };
}

static struct compute_resource tex(const struct sky_passes *p, const struct gpu_image *image)
{
    return (struct compute_resource){ .image = image, .sampler = p->sampler };
}

static struct compute_resource buf(const struct gpu_buffer *buffer)
{
    return (struct compute_resource){ .buffer = buffer };
}

static void bind_pair(struct vk_context *ctx, struct sky_passes *p, enum pass_id inside,
                      const struct compute_resource *r)
{
    compute_pass_bind(ctx, &p->pass[inside], r);
    compute_pass_bind(ctx, &p->pass[inside + 1], r);
}

/* The aerial-perspective pass, with p->ap_clouds' shadow map and cloud block. */
void sky_passes_bind_aerial_perspective(struct vk_context *ctx, struct sky_passes *p)
{
    const struct sky_cloud_bindings *c = &p->ap_clouds;
    struct compute_resource r[SKY_LAYOUT_COUNT(SKY_LAYOUT_AERIAL_PERSPECTIVE)] = {
        [SKY_AP_ATMOSPHERE] = buf(&p->atmosphere_params),
        [SKY_AP_FRAME] = buf(&p->frame_params),
        [SKY_AP_TRANSMITTANCE] = tex(p, &p->transmittance),
        [SKY_AP_MULTISCATTERING] = tex(p, &p->multiscattering),
        [SKY_AP_INSCATTER_OUT] = img(&p->ap_inscatter),
        [SKY_AP_TRANSMITTANCE_OUT] = img(&p->ap_transmittance),
        [SKY_AP_SHAFTS_OUT] = img(&p->ap_shafts),
        [SKY_AP_CLOUD_SHADOW] = { .image = c->shadow, .sampler = c->shadow_sampler },
        [SKY_AP_CLOUD] = buf(c->params),
        [SKY_AP_CLOUD_ENV] = buf(c->env),
    };
    compute_pass_bind(ctx, &p->pass[PASS_AERIAL_PERSPECTIVE], r);
}

/* Bindings 0-7 of the passes that shade view directions. */
static void shading_resources(struct sky_passes *p, struct compute_resource *r)
{
    r[SKY_SHADING_ATMOSPHERE] = buf(&p->atmosphere_params);
    r[SKY_SHADING_FRAME] = buf(&p->frame_params);
    r[SKY_SHADING_TRANSMITTANCE] = tex(p, &p->transmittance);
    r[SKY_SHADING_MULTISCATTERING] = tex(p, &p->multiscattering);
    r[SKY_SHADING_SKYVIEW] = tex(p, &p->skyview);
    r[SKY_SHADING_IRRADIANCE] = tex(p, &p->irradiance);
    r[SKY_SHADING_STARS] = buf(&p->stars);
    r[SKY_SHADING_MOON_SKYVIEW] = tex(p, &p->moon_skyview);
}

/* The composite passes alone: the clouds they sample change from view to view, while the
 * passes recorded before them in a frame must keep their bindings. */
void sky_passes_bind_composite(struct sky_passes *p)
{
    if (!p->out)
        return;
    struct compute_resource r[COMPOSITE_BINDING_COUNT];
    shading_resources(p, r);
    r[SKY_COMPOSITE_EXPOSURE] = buf(&p->exposure);
    r[SKY_COMPOSITE_OUT] = img(&p->out->image);
    r[SKY_COMPOSITE_CLOUDS_OVER_SKY] = tex(p, p->clouds.over_sky);
    r[SKY_COMPOSITE_CLOUDS_OVER_GROUND] = tex(p, p->clouds.over_ground);
    composite_variants_bind(p->composite, r);
}

/* Points every pass whose resources exist at them; called after any resource changes. */
static void bind_passes(struct vk_context *ctx, struct sky_passes *p)
{
    /* Rebuilds write the build copy from the build atmosphere. */
    struct compute_resource transmittance[SKY_LAYOUT_COUNT(SKY_LAYOUT_TRANSMITTANCE)] = {
        [SKY_TRANSMITTANCE_ATMOSPHERE] = buf(&p->build_atmosphere_params),
        [SKY_TRANSMITTANCE_OUT] = img(&p->build_transmittance),
    };
    compute_pass_bind(ctx, &p->pass[PASS_TRANSMITTANCE], transmittance);
    struct compute_resource multiscattering[SKY_LAYOUT_COUNT(SKY_LAYOUT_MULTISCATTERING)] = {
        [SKY_MULTISCATTERING_ATMOSPHERE] = buf(&p->build_atmosphere_params),
        [SKY_MULTISCATTERING_TRANSMITTANCE] = tex(p, &p->build_transmittance),
        [SKY_MULTISCATTERING_OUT] = img(&p->build_multiscattering),
    };
    compute_pass_bind(ctx, &p->pass[PASS_MULTISCATTERING], multiscattering);
    struct compute_resource irradiance[SKY_LAYOUT_COUNT(SKY_LAYOUT_IRRADIANCE)] = {
        [SKY_IRRADIANCE_ATMOSPHERE] = buf(&p->build_atmosphere_params),
        [SKY_IRRADIANCE_TRANSMITTANCE] = tex(p, &p->build_transmittance),
        [SKY_IRRADIANCE_MULTISCATTERING] = tex(p, &p->build_multiscattering),
        [SKY_IRRADIANCE_OUT] = img(&p->build_irradiance),
    };
    compute_pass_bind(ctx, &p->pass[PASS_IRRADIANCE], irradiance);
    for (int which = 0; which < 3; which++) {
        struct compute_resource blend[SKY_LAYOUT_COUNT(SKY_LAYOUT_LUT_BLEND)] = {
            [SKY_LUT_BLEND_FROM] = img(atmosphere_lut(p, 2, which)),
            [SKY_LUT_BLEND_TO] = img(atmosphere_lut(p, 1, which)),
            [SKY_LUT_BLEND_OUT] = img(atmosphere_lut(p, 0, which)),
        };
        compute_pass_bind(ctx, &p->pass[PASS_BLEND_TRANSMITTANCE + which], blend);
        struct compute_resource save[SKY_LAYOUT_COUNT(SKY_LAYOUT_LUT_BLEND)] = {
            [SKY_LUT_BLEND_FROM] = img(atmosphere_lut(p, 0, which)),
            [SKY_LUT_BLEND_TO] = img(atmosphere_lut(p, 0, which)),
            [SKY_LUT_BLEND_OUT] = img(atmosphere_lut(p, 2, which)),
        };
        compute_pass_bind(ctx, &p->pass[PASS_SAVE_TRANSMITTANCE + which], save);
    }

    /* Frames read the display copy; so does the converged multiple scattering. */
    ms_refine_bind(ctx, p->ms, &p->atmosphere_params, &p->transmittance, p->sampler);
    sky_passes_bind_aerial_perspective(ctx, p);
    struct compute_resource skyview[SKY_LAYOUT_COUNT(SKY_LAYOUT_SKYVIEW)] = {
        [SKY_SKYVIEW_ATMOSPHERE] = buf(&p->atmosphere_params),
        [SKY_SKYVIEW_FRAME] = buf(&p->frame_params),
        [SKY_SKYVIEW_TRANSMITTANCE] = tex(p, &p->transmittance),
        [SKY_SKYVIEW_MULTISCATTERING] = tex(p, &p->multiscattering),
        [SKY_SKYVIEW_IRRADIANCE] = tex(p, &p->irradiance),
        [SKY_SKYVIEW_OUT] = img(&p->skyview),
        [SKY_SKYVIEW_MS_SUM] = tex(p, ms_refine_table(p->ms)),
    };
    compute_pass_bind(ctx, &p->pass[PASS_SKYVIEW], skyview);
    skyview[SKY_SKYVIEW_OUT] = img(&p->moon_skyview);
    compute_pass_bind(ctx, &p->pass[PASS_SKYVIEW_MOON], skyview);

    struct compute_resource r[COMPUTE_PASS_MAX_BINDINGS];
    shading_resources(p, r);
    r[SKY_METER_PARTIALS] = buf(&p->meter_partials);
    bind_pair(ctx, p, PASS_METER, r);
    compute_pass_bind(ctx, &p->pass[PASS_METER_DAY], r);
    sky_passes_bind_composite(p);
    if (p->probe_in.buffer) {
        shading_resources(p, r);
        r[SKY_PROBE_IN] = buf(&p->probe_in);
        r[SKY_PROBE_OUT] = buf(&p->probe_out);
        bind_pair(ctx, p, PASS_PROBE, r);
    }

    struct compute_resource resolve[SKY_LAYOUT_COUNT(SKY_LAYOUT_EXPOSURE_RESOLVE)] = {
        [SKY_EXPOSURE_FRAME] = buf(&p->frame_params),
        [SKY_EXPOSURE_PARTIALS] = buf(&p->meter_partials),
        [SKY_EXPOSURE_OUT] = buf(&p->exposure),
    };
    compute_pass_bind(ctx, &p->pass[PASS_EXPOSURE_RESOLVE], resolve);
}

/* The star field never changes: uploaded once. */
static int create_stars(struct vk_context *ctx, struct sky_passes *p,
                        const struct sky_star_field *stars)
{
    VkResult result = gpu_buffer_create(ctx, stars->word_count * sizeof *stars->words,
                                        VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, "stars", &p->stars);
    if (result != VK_SUCCESS) {
        vk_log(ctx, VK_LOG_ERROR, "render: cannot create the star buffer: %s",
               vk_result_name(result));
        return -1;
    }
    memcpy(p->stars.mapped, stars->words, stars->word_count * sizeof *stars->words);
    p->brightest_star_lux = stars->brightest_lux;
    return 0;
}

struct sky_passes *sky_passes_create(struct vk_context *ctx,
                                     const struct sky_render_lut_sizes *sizes,
                                     const struct sky_cloud_bindings *clouds,
                                     const struct sky_star_field *stars, bool warm_up_variants)
{
    if (!format_supports(ctx, LUT_FORMAT,
                         VK_FORMAT_FEATURE_STORAGE_IMAGE_BIT |
                             VK_FORMAT_FEATURE_SAMPLED_IMAGE_FILTER_LINEAR_BIT) ||
        !format_supports(ctx, VK_FORMAT_R8G8B8A8_UNORM, VK_FORMAT_FEATURE_STORAGE_IMAGE_BIT)) {
        vk_log(ctx, VK_LOG_ERROR, "render: device lacks filtered RGBA32F storage images");
        return NULL;
    }
    struct sky_passes *p = calloc(1, sizeof *p);
    if (!p)
        return NULL;
    p->metered_ev100 = NAN;
    p->clouds = p->ap_clouds = *clouds;
    VK_CHECK_GOTO(
        gpu_linear_sampler_create(ctx, VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE, &p->sampler),
        destroy_partial);
    for (int i = 0; i < PASS_COUNT; i++)
        VK_CHECK_GOTO(compute_pass_create(ctx, &pass_descs[i], &p->pass[i]), destroy_partial);
    p->composite = composite_variants_create(warm_up_variants);
    if (!p->composite)
        goto destroy_partial;
    VkBufferUsageFlags params = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT;
    VkBufferUsageFlags storage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT;
    VK_CHECK_GOTO(gpu_buffer_create(ctx, sizeof(struct sky_atmosphere_uniforms), params,
                                    "atmosphere_params", &p->atmosphere_params),
                  destroy_partial);
    VK_CHECK_GOTO(gpu_buffer_create(ctx, sizeof(struct sky_atmosphere_uniforms), params,
                                    "build_atmosphere_params", &p->build_atmosphere_params),
                  destroy_partial);
    VK_CHECK_GOTO(gpu_buffer_create(ctx, sizeof(struct sky_frame_uniforms), params, "frame_params",
                                    &p->frame_params),
                  destroy_partial);
    VK_CHECK_GOTO(gpu_buffer_create(ctx, 4 * sizeof(float), storage, "exposure", &p->exposure),
                  destroy_partial);
    VK_CHECK_GOTO(gpu_buffer_create(ctx, SKY_METER_MAX_GROUPS * 2 * sizeof(float), storage,
                                    "meter_partials", &p->meter_partials),
                  destroy_partial);
    memset(p->exposure.mapped, 0, 4 * sizeof(float));
    if (create_stars(ctx, p, stars) != 0)
        goto destroy_partial;
    if (create_luts(ctx, p, sizes) != 0)
        goto destroy_partial;
    p->ms = ms_refine_create(ctx);
    if (!p->ms)
        goto destroy_partial;
    bind_passes(ctx, p);
    return p;
destroy_partial:
    sky_passes_destroy(ctx, &p);
    return NULL;
}

void sky_passes_destroy(struct vk_context *ctx, struct sky_passes **pp)
{
    struct sky_passes *p = pp ? *pp : NULL;
    if (!p)
        return;
    destroy_luts(ctx, p);
    ms_refine_destroy(ctx, &p->ms);
    view_outputs_destroy(ctx, &p->outputs);
    gpu_buffer_destroy(ctx, &p->probe_in);
    gpu_buffer_destroy(ctx, &p->probe_out);
    gpu_buffer_destroy(ctx, &p->atmosphere_params);
    gpu_buffer_destroy(ctx, &p->build_atmosphere_params);
    gpu_buffer_destroy(ctx, &p->frame_params);
    gpu_buffer_destroy(ctx, &p->exposure);
    gpu_buffer_destroy(ctx, &p->meter_partials);
    gpu_buffer_destroy(ctx, &p->stars);
    for (int i = 0; i < PASS_COUNT; i++)
        compute_pass_destroy(ctx, &p->pass[i]);
    composite_variants_destroy(ctx, &p->composite);
    if (p->sampler)
        vkDestroySampler(ctx->device, p->sampler, NULL);
    free(p);
    *pp = NULL;
}

/* The new images are made beside the old ones, which stay in place when that fails (out of
 * memory, say): the passes never point at destroyed images. */
int sky_passes_resize_luts(struct vk_context *ctx, struct sky_passes *p,
                           const struct sky_render_lut_sizes *sizes)
{
    struct gpu_image *images[LUT_IMAGE_COUNT];
    struct gpu_image kept[LUT_IMAGE_COUNT];
    lut_images(p, images);
    for (int i = 0; i < LUT_IMAGE_COUNT; i++) {
        kept[i] = *images[i];
        memset(images[i], 0, sizeof *images[i]);
    }
    bool created = create_luts(ctx, p, sizes) == 0; /* leaves none behind when it fails */
    for (int i = 0; i < LUT_IMAGE_COUNT; i++) {
        if (created)
            gpu_image_destroy(ctx, &kept[i]);
        else
            *images[i] = kept[i];
    }
    if (!created)
        return -1;
    bind_passes(ctx, p);
    return 0;
}

int sky_passes_prepare_output(struct vk_context *ctx, struct sky_passes *p, uint32_t width,
                              uint32_t height, enum sky_render_output_kind kind, double now_s)
{
    bool linear = kind == SKY_RENDER_OUTPUT_LINEAR, created;
    struct view_output *out = view_outputs_acquire(ctx, &p->outputs, width, height,
                                                   linear ? LUT_FORMAT : VK_FORMAT_R8G8B8A8_UNORM,
                                                   linear ? 16 : 4, now_s, &created);
    if (out != p->out || created) {
        p->out = out;
        sky_passes_bind_composite(p); /* the only passes that use the output */
    }
    return out ? 0 : -1;
}

int sky_passes_prepare_probe(struct vk_context *ctx, struct sky_passes *p, size_t count,
                             const float (*in)[4])
{
    if (count == 0)
        count = 1;
    if (count > p->probe_capacity) {
        gpu_buffer_destroy(ctx, &p->probe_in);
        gpu_buffer_destroy(ctx, &p->probe_out);
        VkDeviceSize bytes = (VkDeviceSize)count * 4 * sizeof(float);
        VkBufferUsageFlags storage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT;
        VK_CHECK_GOTO(gpu_buffer_create(ctx, bytes, storage, "probe_in", &p->probe_in),
                      forget_probes);
        VK_CHECK_GOTO(gpu_buffer_create(ctx, bytes, storage, "probe_out", &p->probe_out),
                      destroy_probe_in);
        p->probe_capacity = count;
        bind_passes(ctx, p);
    }
    memcpy(p->probe_in.mapped, in, count * 4 * sizeof(float));
    return 0;
destroy_probe_in:
    gpu_buffer_destroy(ctx, &p->probe_in);
forget_probes: /* the old pair is already gone */
    p->probe_capacity = 0;
    return -1;
}

void sky_passes_upload_atmosphere(struct sky_passes *p, const struct sky_atmosphere_uniforms *u)
{
    memcpy(p->atmosphere_params.mapped, u, sizeof *u);
}

void sky_passes_upload_build_atmosphere(struct sky_passes *p,
                                        const struct sky_atmosphere_uniforms *u)
{
    memcpy(p->build_atmosphere_params.mapped, u, sizeof *u);
}

void sky_passes_upload_frame(struct sky_passes *p, const struct sky_frame_uniforms *u)
{
    memcpy(p->frame_params.mapped, u, sizeof *u);
}

void sky_passes_copy_output(const struct sky_passes *p, void *pixels, size_t bytes)
{
    memcpy(pixels, p->out->readback.mapped, bytes);
}

void sky_passes_read_probe(const struct sky_passes *p, size_t count, double (*out)[3])
{
    const float *values = p->probe_out.mapped;
    for (size_t i = 0; i < count; i++)
        for (int c = 0; c < 3; c++)
            out[i][c] = values[i * 4 + (size_t)c];
}

double sky_passes_brightest_star_lux(const struct sky_passes *p)
{
    return p->brightest_star_lux;
}

double sky_passes_metered_ev100(const struct sky_passes *p)
{
    if (p->meter.group_count == 0)
        return NAN;
    const float *metered = p->exposure.mapped;
    return metered[1];
}

float *sky_passes_read_lut(struct vk_context *ctx, struct sky_passes *p, const char *name,
                           uint32_t size[3])
{
    const struct gpu_image *image = NULL;
    if (strcmp(name, "transmittance") == 0)
        image = &p->transmittance;
    else if (strcmp(name, "multiscattering") == 0)
        image = &p->multiscattering;
    else if (strcmp(name, "skyview") == 0)
        image = &p->skyview;
    else if (strcmp(name, "moon_skyview") == 0)
        image = &p->moon_skyview;
    else if (strcmp(name, "irradiance") == 0)
        image = &p->irradiance;
    else if (strcmp(name, "ap_inscatter") == 0)
        image = &p->ap_inscatter;
    else if (strcmp(name, "ap_transmittance") == 0)
        image = &p->ap_transmittance;
    else if (strcmp(name, "ap_shafts") == 0)
        image = &p->ap_shafts;
    else
        image = ms_refine_image(p->ms, name);
    if (!image)
        return NULL;
    size_t bytes = (size_t)image->width * image->height * image->depth * 16;
    struct gpu_buffer staging;
    if (gpu_buffer_create(ctx, bytes, VK_BUFFER_USAGE_TRANSFER_DST_BIT, "lut_readback", &staging) !=
        VK_SUCCESS)
        return NULL;
    float *out = NULL;
    VkCommandBuffer cmd;
    if (vk_context_begin_commands(ctx, &cmd) == VK_SUCCESS) {
        gpu_barrier_compute_to_transfer(cmd);
        gpu_copy_image_to_buffer(cmd, image, &staging);
        gpu_barrier_to_host(cmd);
        if (vk_context_submit_and_wait(ctx, &cmd) == VK_SUCCESS) {
            out = malloc(bytes);
            if (out) {
                memcpy(out, staging.mapped, bytes);
                size[0] = image->width;
                size[1] = image->height;
                size[2] = image->depth;
            }
        }
    }
    gpu_buffer_destroy(ctx, &staging);
    return out;
}

void sky_passes_resources(const struct sky_passes *p, struct sky_pass_resources *out)
{
    out->atmosphere_params = &p->atmosphere_params;
    out->frame_params = &p->frame_params;
    out->transmittance = &p->transmittance;
    out->multiscattering = &p->multiscattering;
    out->skyview = &p->skyview;
    out->irradiance = &p->irradiance;
    out->ap_inscatter = &p->ap_inscatter;
    out->ap_transmittance = &p->ap_transmittance;
    out->ap_shafts = &p->ap_shafts;
    out->sampler = p->sampler;
}

void sky_passes_bind_clouds(struct sky_passes *p, const struct sky_cloud_bindings *clouds)
{
    if (memcmp(&p->clouds, clouds, sizeof *clouds) == 0)
        return;
    p->clouds = *clouds;
    sky_passes_bind_composite(p);
}

struct ms_refine *sky_passes_ms_refine(struct sky_passes *p)
{
    return p->ms;
}
