/* Images and buffers with their memory, made for compute passes.
 *
 * Images live in VK_IMAGE_LAYOUT_GENERAL for their whole life (storage writes and sampled
 * reads both allowed), so passes need only memory barriers. Buffers are host-visible and
 * persistently mapped: they carry uniforms, probe inputs/outputs and readbacks.
 *
 * A create that fails leaves nothing behind (out is zeroed), notes in the context what failed
 * (vk_context_note_failure: the image or buffer's name and size) and returns the result of the
 * call that failed, so that running out of memory can be told from other failures. */
#ifndef SKYD_VK_RESOURCES_H
#define SKYD_VK_RESOURCES_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <vulkan/vulkan.h>

struct vk_context;

struct gpu_image {
    VkImage image;
    VkDeviceMemory memory;
    VkImageView view;
    VkFormat format;
    uint32_t width, height, depth; /* depth > 1 makes a 3D image; gpu_image_create_view_sized's
                                      extent may be larger */
};

struct gpu_buffer {
    VkBuffer buffer;
    VkDeviceMemory memory;
    VkDeviceSize size;
    void *mapped;
};

/* Creates a 2D (depth 1) or 3D image usable as storage image, sampled image and copy source,
 * and transitions it to VK_IMAGE_LAYOUT_GENERAL. */
VkResult gpu_image_create(struct vk_context *ctx, VkFormat format, uint32_t width, uint32_t height,
                          uint32_t depth, const char *name, struct gpu_image *out);
/* A 2D image of a view's size (width x height texels used) whose extent is never a power of
 * two: the smallest one at least as large. lavapipe compiles a variant of every compute
 * pipeline for each combination of power-of-two-or-not sizes among the images it binds, so
 * images whose size follows the views' would make each new view size a hitch of several
 * compiles and grow the daemon by the code of each (up to 16 variants of a pass). Shaders read
 * such images at their size, never their extent, and never sample the texels past it. */
VkResult gpu_image_create_view_sized(struct vk_context *ctx, VkFormat format, uint32_t width,
                                     uint32_t height, const char *name, struct gpu_image *out);
/* Whether n is a power of two (lavapipe's variants above; LUT sides in sky_passes.c). */
bool gpu_is_power_of_two(uint32_t n);
void gpu_image_destroy(struct vk_context *ctx, struct gpu_image *image);

VkResult gpu_buffer_create(struct vk_context *ctx, VkDeviceSize size, VkBufferUsageFlags usage,
                           const char *name, struct gpu_buffer *out);
void gpu_buffer_destroy(struct vk_context *ctx, struct gpu_buffer *buffer);

/* A linear sampler without mipmaps: clamp-to-edge for the look-up tables, repeat for tileable
 * noise and maps. */
VkResult gpu_linear_sampler_create(struct vk_context *ctx, VkSamplerAddressMode address_mode,
                                   VkSampler *out);

/* Records a barrier making compute-shader writes visible to later compute reads/writes. */
void gpu_barrier_compute_to_compute(VkCommandBuffer cmd);
/* Records a barrier making compute-shader writes visible to transfer reads. */
void gpu_barrier_compute_to_transfer(VkCommandBuffer cmd);
/* Records a barrier making compute-shader (or transfer) writes visible to the host. */
void gpu_barrier_to_host(VkCommandBuffer cmd);

/* Records a copy of a whole 2D/3D image into a buffer (tightly packed). */
void gpu_copy_image_to_buffer(VkCommandBuffer cmd, const struct gpu_image *image,
                              const struct gpu_buffer *buffer);

#endif
