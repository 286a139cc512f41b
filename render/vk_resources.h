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

#include <stddef.h>
#include <stdint.h>
#include <vulkan/vulkan.h>

struct vk_context;

struct gpu_image {
    VkImage image;
    VkDeviceMemory memory;
    VkImageView view;
    VkFormat format;
    uint32_t width, height, depth; /* depth > 1 makes a 3D image */
};

struct gpu_buffer {
    VkBuffer buffer;
    VkDeviceMemory memory;
    VkDeviceSize size;
    void *mapped;
};

/* Creates a 2D (depth 1) or 3D image usable as storage image, sampled image and copy source,
 * and transitions it to VK_IMAGE_LAYOUT_GENERAL. */
VkResult gpu_image_create(struct vk_context *ctx, VkFormat format, uint32_t width,
                          uint32_t height, uint32_t depth, const char *name,
                          struct gpu_image *out);
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
