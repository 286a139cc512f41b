/* The sky's compute passes and the resources they share: atmosphere LUTs (transmittance,
 * multi-scattering, ground irradiance), per-view LUTs (sky-view, aerial-perspective froxels),
 * exposure metering, the composite and the probe. Each record_* call follows one shape:
 * upload -> bind -> push -> dispatch (rounded up) -> barrier -> timestamp. */
#ifndef SKYD_SKY_PASSES_H
#define SKYD_SKY_PASSES_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <vulkan/vulkan.h>

#include "sky_renderer.h"
#include "sky_shared.h"

struct vk_context;
struct gpu_timer;
struct sky_passes;

/* What the composite samples of the clouds (render/clouds/cloud_renderer.h fills it). */
struct gpu_image;
struct gpu_buffer;
struct sky_cloud_bindings {
    /* The clouds' effect on each pixel (cloud_resolve.comp), over the sky and over the ground */
    const struct gpu_image *over_sky, *over_ground;
    /* Their cloud history's occupant (lru_slot.filled): images made again at the same
     * address change it, so that the composite is pointed at them again. */
    uint64_t over_filled;
    const struct gpu_image *shadow;  /* cloud shadow map (r: transmittance toward the sun) */
    VkSampler shadow_sampler;        /* repeat addressing */
    const struct gpu_buffer *params; /* sky_cloud_uniforms */
    /* The clouds' hemisphere averages (cloud_hemisphere.comp): what the air under them is lit
     * by, against a clear sky's light. */
    const struct gpu_buffer *env;
};

/* The star field the night pass draws (night/night_stars.h builds it): `words` uvec4 words,
 * uploaded once. */
struct sky_star_field {
    const uint32_t (*words)[4];
    size_t word_count;
    double brightest_lux; /* the brightest star's illuminance outside the atmosphere */
};

struct sky_passes *sky_passes_create(struct vk_context *ctx,
                                     const struct sky_render_lut_sizes *sizes,
                                     const struct sky_cloud_bindings *clouds,
                                     const struct sky_star_field *stars, bool warm_up_variants);
void sky_passes_destroy(struct vk_context *ctx, struct sky_passes **passes);

/* Recreates the LUT images at new sizes; -1 keeps the old ones (and their sizes). */
int sky_passes_resize_luts(struct vk_context *ctx, struct sky_passes *p,
                           const struct sky_render_lut_sizes *sizes);
/* Points the passes at the output image and readback buffer for this size and kind, created
 * when no view has used them in the last VIEW_OUTPUT_IDLE_S (view_outputs.h) before `now_s`
 * (a monotonic clock in seconds). */
int sky_passes_prepare_output(struct vk_context *ctx, struct sky_passes *p, uint32_t width,
                              uint32_t height, enum sky_render_output_kind kind, double now_s);
/* Grows the probe buffers to `count` and copies the inputs in. */
int sky_passes_prepare_probe(struct vk_context *ctx, struct sky_passes *p, size_t count,
                             const float (*in)[4]);

/* The atmosphere frames are shaded with (display) and the one a rebuild computes (build). */
void sky_passes_upload_atmosphere(struct sky_passes *p, const struct sky_atmosphere_uniforms *u);
void sky_passes_upload_build_atmosphere(struct sky_passes *p,
                                        const struct sky_atmosphere_uniforms *u);
void sky_passes_upload_frame(struct sky_passes *p, const struct sky_frame_uniforms *u);

/* Steps of an atmosphere rebuild into the build copy, in order; the first two in slices so a
 * rebuild can be spread over frames: blocks of 64 texels (row-major) of the transmittance LUT,
 * texels of the multiple-scattering LUT, whose texels cost most. */
enum sky_build_step {
    SKY_BUILD_TRANSMITTANCE = 0,
    SKY_BUILD_MULTISCATTERING = 1,
    SKY_BUILD_IRRADIANCE = 2,
};

/* The slices of each step: transmittance blocks of 64 texels, multiple-scattering texels. */
void sky_passes_atmosphere_slices(const struct sky_passes *p, uint32_t *transmittance_slices,
                                  uint32_t *multiscattering_slices);
void sky_passes_record_build(struct sky_passes *p, VkCommandBuffer cmd, struct gpu_timer *timer,
                             enum sky_build_step step, uint32_t first_slice, uint32_t slice_count);
/* previous = display, before a rebuild whose result the display will blend toward. */
void sky_passes_record_save_display(struct sky_passes *p, VkCommandBuffer cmd,
                                    struct gpu_timer *timer);
/* display = mix(previous, build, weight). */
void sky_passes_record_blend(struct sky_passes *p, VkCommandBuffer cmd, struct gpu_timer *timer,
                             float weight);
/* The whole rebuild at once, then display = build. */
void sky_passes_record_atmosphere(struct sky_passes *p, VkCommandBuffer cmd,
                                  struct gpu_timer *timer);
/* The sky-view LUTs (skyview false: they still hold this view's, nothing is recorded);
 * moonlit_sky: also the one lit by the moon (night sky). */
void sky_passes_record_view_luts(struct sky_passes *p, VkCommandBuffer cmd, struct gpu_timer *timer,
                                 bool skyview, bool moonlit_sky);
/* The view's aerial-perspective volume, shadowed by `clouds`' shadow map (light shafts). */
void sky_passes_record_aerial_perspective(struct vk_context *ctx, struct sky_passes *p,
                                          VkCommandBuffer cmd, struct gpu_timer *timer,
                                          const struct sky_cloud_bindings *clouds);
/* from_space: the camera is above the atmosphere (selects the specialized pipelines);
 * night_sky false: pipelines without the night sky (night_sky_visible). */
void sky_passes_record_metering(struct sky_passes *p, VkCommandBuffer cmd, struct gpu_timer *timer,
                                uint32_t width, uint32_t height, bool from_space, bool night_sky);
/* What a frame's composite needs. */
struct sky_composite_job {
    enum sky_render_output_kind kind;
    bool from_space;             /* the camera above the atmosphere */
    bool night_sky;              /* night_sky_visible */
    bool clouds;                 /* a cloud layer is shown */
    const uint32_t *ground_rows; /* rows that may see the ground [first, end), or NULL: none */
    const int32_t *sun_rect, *moon_rect; /* x0, y0, w, h of each disc's box, or NULL */
};
/* Composite into the output image (then the sun-disk pass over the sun's and the moon's boxes),
 * then copy it into the readback buffer; -1 when a pipeline cannot be created. */
int sky_passes_record_composite(struct vk_context *ctx, struct sky_passes *p, VkCommandBuffer cmd,
                                struct gpu_timer *timer, const struct sky_composite_job *job);
void sky_passes_record_probe(struct sky_passes *p, VkCommandBuffer cmd, struct gpu_timer *timer,
                             uint32_t mode, uint32_t count, bool from_space);

void sky_passes_copy_output(const struct sky_passes *p, void *pixels, size_t bytes);
void sky_passes_read_probe(const struct sky_passes *p, size_t count, double (*out)[3]);
/* Illuminance of the brightest star of the uploaded field (lux, outside the atmosphere). */
double sky_passes_brightest_star_lux(const struct sky_passes *p);
/* EV100 of the last metering (NAN when none ran). */
double sky_passes_metered_ev100(const struct sky_passes *p);
float *sky_passes_read_lut(struct vk_context *ctx, struct sky_passes *p, const char *name,
                           uint32_t size[3]);

/* The converged multiple scattering (ms_refine.h) the sky-view reads. */
struct ms_refine *sky_passes_ms_refine(struct sky_passes *p);

/* The resources the cloud passes share with the sky's. */
struct sky_pass_resources {
    const struct gpu_buffer *atmosphere_params, *frame_params;
    const struct gpu_image *transmittance, *multiscattering, *irradiance, *skyview;
    const struct gpu_image *ap_inscatter, *ap_transmittance; /* this view's froxel volume */
    const struct gpu_image *ap_shafts; /* in-scattering the cloud shadows take (light shafts) */
    VkSampler sampler;                 /* linear, clamp to edge */
};
void sky_passes_resources(const struct sky_passes *p, struct sky_pass_resources *out);
/* Points the composite at the clouds (rebinding only when they change). */
void sky_passes_bind_clouds(struct sky_passes *p, const struct sky_cloud_bindings *clouds);

#endif
