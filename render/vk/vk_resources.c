#include "vk_resources.h"

#include <string.h>

#include "fault_injection.h"
#include "vk_check.h"
#include "vk_context.h"

static VkResult bind_new_memory(struct vk_context *ctx, VkMemoryRequirements req,
                                VkMemoryPropertyFlags preferred, VkMemoryPropertyFlags required,
                                VkDeviceMemory *out)
{
    uint32_t type = vk_context_find_memory_type(ctx, req.memoryTypeBits, preferred);
    if (type == UINT32_MAX)
        type = vk_context_find_memory_type(ctx, req.memoryTypeBits, required);
    if (type == UINT32_MAX) {
        vk_log(ctx, VK_LOG_ERROR, "vulkan: no memory type for %#x", (unsigned)required);
        return VK_ERROR_OUT_OF_DEVICE_MEMORY;
    }
    VkMemoryAllocateInfo info = {
        .sType = VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO,
        .allocationSize = req.size,
        .memoryTypeIndex = type,
    };
    VkResult injected = fault_injection_allocate(ctx);
    if (injected != VK_SUCCESS)
        return injected;
    return vkAllocateMemory(ctx->device, &info, NULL, out);
}

/* Moves a new image to the general layout, cleared to zero so that a table read before its
 * first build is black, never garbage. */
static VkResult clear_image(struct vk_context *ctx, const struct gpu_image *image)
{
    VkCommandBuffer cmd;
    VK_CHECK_RETURN(vk_context_begin_commands(ctx, &cmd));
    VkImageMemoryBarrier barrier = {
        .sType = VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER,
        .srcAccessMask = 0,
        .dstAccessMask = VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT,
        .oldLayout = VK_IMAGE_LAYOUT_UNDEFINED,
        .newLayout = VK_IMAGE_LAYOUT_GENERAL,
        .srcQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED,
        .dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED,
        .image = image->image,
        .subresourceRange = { VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1 },
    };
    vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT,
                         VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, 0, 0, NULL, 0, NULL, 1, &barrier);
    VkClearColorValue zero = { .float32 = { 0, 0, 0, 0 } };
    vkCmdClearColorImage(cmd, image->image, VK_IMAGE_LAYOUT_GENERAL, &zero, 1,
                         &barrier.subresourceRange);
    gpu_barrier_compute_to_compute(cmd);
    VK_CHECK_RETURN(vk_context_submit_and_wait(ctx, &cmd));
    return VK_SUCCESS;
}

static VkResult image_create(struct vk_context *ctx, VkFormat format, uint32_t width,
                             uint32_t height, uint32_t depth, uint32_t extent_width,
                             uint32_t extent_height, const char *name, struct gpu_image *out)
{
    memset(out, 0, sizeof *out);
    out->format = format;
    out->width = width;
    out->height = height;
    out->depth = depth ? depth : 1;
    VkImageType type = out->depth > 1 ? VK_IMAGE_TYPE_3D : VK_IMAGE_TYPE_2D;
    VkImageCreateInfo info = {
        .sType = VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO,
        .imageType = type,
        .format = format,
        .extent = { extent_width, extent_height, out->depth },
        .mipLevels = 1,
        .arrayLayers = 1,
        .samples = VK_SAMPLE_COUNT_1_BIT,
        .tiling = VK_IMAGE_TILING_OPTIMAL,
        .usage = VK_IMAGE_USAGE_STORAGE_BIT | VK_IMAGE_USAGE_SAMPLED_BIT |
                 VK_IMAGE_USAGE_TRANSFER_SRC_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT,
        .sharingMode = VK_SHARING_MODE_EXCLUSIVE,
        .initialLayout = VK_IMAGE_LAYOUT_UNDEFINED,
    };
    VkResult result;
    VK_CHECK_KEEP_GOTO(vkCreateImage(ctx->device, &info, NULL, &out->image), result, report);
    vk_context_name_object(ctx, VK_OBJECT_TYPE_IMAGE, (uint64_t)out->image, name);
    VkMemoryRequirements req;
    vkGetImageMemoryRequirements(ctx->device, out->image, &req);
    VK_CHECK_KEEP_GOTO(
        bind_new_memory(ctx, req, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT, 0, &out->memory), result,
        destroy_image);
    VK_CHECK_KEEP_GOTO(vkBindImageMemory(ctx->device, out->image, out->memory, 0), result,
                       free_memory);

    VkImageViewCreateInfo view = {
        .sType = VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO,
        .image = out->image,
        .viewType = out->depth > 1 ? VK_IMAGE_VIEW_TYPE_3D : VK_IMAGE_VIEW_TYPE_2D,
        .format = format,
        .subresourceRange = { VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1 },
    };
    VK_CHECK_KEEP_GOTO(vkCreateImageView(ctx->device, &view, NULL, &out->view), result,
                       free_memory);
    result = clear_image(ctx, out);
    if (result != VK_SUCCESS)
        goto destroy_view;
    return VK_SUCCESS;

destroy_view:
    vkDestroyImageView(ctx->device, out->view, NULL);
free_memory:
    vkFreeMemory(ctx->device, out->memory, NULL);
destroy_image:
    vkDestroyImage(ctx->device, out->image, NULL);
report:
    vk_context_note_failure(ctx, result, "creating image \"%s\" (%ux%ux%u)", name ? name : "",
                            width, height, out->depth);
    memset(out, 0, sizeof *out);
    return result;
}

VkResult gpu_image_create(struct vk_context *ctx, VkFormat format, uint32_t width, uint32_t height,
                          uint32_t depth, const char *name, struct gpu_image *out)
{
    return image_create(ctx, format, width, height, depth, width, height, name, out);
}

bool gpu_is_power_of_two(uint32_t n)
{
    return n != 0 && (n & (n - 1)) == 0;
}

/* The smallest n' >= n that is not a power of two (n >= 1). */
static uint32_t extent_not_power_of_two(uint32_t n)
{
    if (n <= 1)
        return 3;
    return gpu_is_power_of_two(n) ? n + 1 : n;
}

VkResult gpu_image_create_view_sized(struct vk_context *ctx, VkFormat format, uint32_t width,
                                     uint32_t height, const char *name, struct gpu_image *out)
{
    return image_create(ctx, format, width, height, 1, extent_not_power_of_two(width),
                        extent_not_power_of_two(height), name, out);
}

void gpu_image_destroy(struct vk_context *ctx, struct gpu_image *image)
{
    if (!ctx || !image)
        return;
    if (image->view)
        vkDestroyImageView(ctx->device, image->view, NULL);
    if (image->image)
        vkDestroyImage(ctx->device, image->image, NULL);
    if (image->memory)
        vkFreeMemory(ctx->device, image->memory, NULL);
    memset(image, 0, sizeof *image);
}

VkResult gpu_buffer_create(struct vk_context *ctx, VkDeviceSize size, VkBufferUsageFlags usage,
                           const char *name, struct gpu_buffer *out)
{
    memset(out, 0, sizeof *out);
    out->size = size;
    VkBufferCreateInfo info = {
        .sType = VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO,
        .size = size,
        .usage = usage,
        .sharingMode = VK_SHARING_MODE_EXCLUSIVE,
    };
    VkResult result;
    VK_CHECK_KEEP_GOTO(vkCreateBuffer(ctx->device, &info, NULL, &out->buffer), result, report);
    vk_context_name_object(ctx, VK_OBJECT_TYPE_BUFFER, (uint64_t)out->buffer, name);
    VkMemoryRequirements req;
    vkGetBufferMemoryRequirements(ctx->device, out->buffer, &req);
    VkMemoryPropertyFlags host = VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT |
                                 VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;
    VK_CHECK_KEEP_GOTO(
        bind_new_memory(ctx, req, host | VK_MEMORY_PROPERTY_HOST_CACHED_BIT, host, &out->memory),
        result, destroy_buffer);
    VK_CHECK_KEEP_GOTO(vkBindBufferMemory(ctx->device, out->buffer, out->memory, 0), result,
                       free_memory);
    VK_CHECK_KEEP_GOTO(vkMapMemory(ctx->device, out->memory, 0, VK_WHOLE_SIZE, 0, &out->mapped),
                       result, free_memory);
    return VK_SUCCESS;

free_memory:
    vkFreeMemory(ctx->device, out->memory, NULL);
destroy_buffer:
    vkDestroyBuffer(ctx->device, out->buffer, NULL);
report:
    vk_context_note_failure(ctx, result, "creating buffer \"%s\" (%llu bytes)", name ? name : "",
                            (unsigned long long)size);
    memset(out, 0, sizeof *out);
    return result;
}

void gpu_buffer_destroy(struct vk_context *ctx, struct gpu_buffer *buffer)
{
    if (!ctx || !buffer)
        return;
    if (buffer->mapped)
        vkUnmapMemory(ctx->device, buffer->memory);
    if (buffer->buffer)
        vkDestroyBuffer(ctx->device, buffer->buffer, NULL);
    if (buffer->memory)
        vkFreeMemory(ctx->device, buffer->memory, NULL);
    memset(buffer, 0, sizeof *buffer);
}

VkResult gpu_linear_sampler_create(struct vk_context *ctx, VkSamplerAddressMode address_mode,
                                   VkSampler *out)
{
    VkSamplerCreateInfo info = {
        .sType = VK_STRUCTURE_TYPE_SAMPLER_CREATE_INFO,
        .magFilter = VK_FILTER_LINEAR,
        .minFilter = VK_FILTER_LINEAR,
        .mipmapMode = VK_SAMPLER_MIPMAP_MODE_NEAREST,
        .addressModeU = address_mode,
        .addressModeV = address_mode,
        .addressModeW = address_mode,
        .maxLod = 0.0f,
    };
    return vkCreateSampler(ctx->device, &info, NULL, out);
}

static void memory_barrier(VkCommandBuffer cmd, VkPipelineStageFlags src_stage, VkAccessFlags src,
                           VkPipelineStageFlags dst_stage, VkAccessFlags dst)
{
    VkMemoryBarrier barrier = {
        .sType = VK_STRUCTURE_TYPE_MEMORY_BARRIER,
        .srcAccessMask = src,
        .dstAccessMask = dst,
    };
    vkCmdPipelineBarrier(cmd, src_stage, dst_stage, 0, 1, &barrier, 0, NULL, 0, NULL);
}

void gpu_barrier_compute_to_compute(VkCommandBuffer cmd)
{
    memory_barrier(cmd, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT,
                   VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_WRITE_BIT,
                   VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT,
                   VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT);
}

void gpu_barrier_compute_to_transfer(VkCommandBuffer cmd)
{
    memory_barrier(cmd, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_WRITE_BIT,
                   VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_READ_BIT);
}

void gpu_barrier_to_host(VkCommandBuffer cmd)
{
    memory_barrier(cmd, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT,
                   VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_WRITE_BIT,
                   VK_PIPELINE_STAGE_HOST_BIT, VK_ACCESS_HOST_READ_BIT);
}

void gpu_copy_image_to_buffer(VkCommandBuffer cmd, const struct gpu_image *image,
                              const struct gpu_buffer *buffer)
{
    VkBufferImageCopy region = {
        .bufferOffset = 0,
        .imageSubresource = { VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1 },
        .imageExtent = { image->width, image->height, image->depth },
    };
    vkCmdCopyImageToBuffer(cmd, image->image, VK_IMAGE_LAYOUT_GENERAL, buffer->buffer, 1, &region);
}
