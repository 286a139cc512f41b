/* Headless Vulkan context: instance (validation optional), physical device choice, one
 * compute queue, a command pool and a fence for synchronous submission.
 *
 * Not thread-safe: one thread (the render thread) owns a context and everything made from it. */
#ifndef SKYD_VK_CONTEXT_H
#define SKYD_VK_CONTEXT_H

#include <stdbool.h>
#include <stdint.h>
#include <vulkan/vulkan.h>

struct vk_context_params {
    /* Device choice: NULL or "" picks a GPU when present (discrete, then integrated, then
     * virtual), else a CPU device (lavapipe). "cpu"/"gpu" force a kind; a decimal number picks
     * that enumeration index; any other text picks the first device whose name contains it. */
    const char *device_preference;
    bool validation; /* enable VK_LAYER_KHRONOS_validation and count its messages */
    bool quiet;      /* do not log the chosen device */
    /* Optional counter of validation warnings + errors that outlives the context, so that
     * messages raised while destroying it (objects still alive) are counted too. */
    unsigned *validation_message_counter;
};

struct vk_context {
    VkInstance instance;
    VkDebugUtilsMessengerEXT messenger;
    VkPhysicalDevice physical_device;
    VkPhysicalDeviceProperties properties;
    VkPhysicalDeviceMemoryProperties memory_properties;
    VkDevice device;
    uint32_t queue_family;
    VkQueue queue;
    VkCommandPool command_pool;
    VkFence fence;
    float timestamp_period_ns;     /* 0 when the queue has no timestamps */
    uint64_t timestamp_mask;       /* valid bits of a timestamp */
    bool validation_enabled;
    /* Validation messages of warning or error severity seen so far (written by the
     * messenger callback, which runs on the thread that made the offending call). */
    unsigned validation_warnings;
    unsigned validation_errors;
    unsigned *validation_message_counter; /* from the params, may be NULL */
};

/* Returns NULL on failure after logging why. */
struct vk_context *vk_context_create(const struct vk_context_params *params);
void vk_context_destroy(struct vk_context **ctx);

/* Waits until the device is idle (before destroying what it may use); logs a failure. */
VkResult vk_context_wait_idle(struct vk_context *ctx);

/* Allocates a primary command buffer and begins it for one-time submission. */
VkResult vk_context_begin_commands(struct vk_context *ctx, VkCommandBuffer *out);
/* Ends, submits, waits for completion and frees the command buffer (always freed). */
VkResult vk_context_submit_and_wait(struct vk_context *ctx, VkCommandBuffer *cmd);

/* Finds a memory type allowed by type_bits with all `required` flags; UINT32_MAX if none. */
uint32_t vk_context_find_memory_type(const struct vk_context *ctx, uint32_t type_bits,
                                     VkMemoryPropertyFlags required);

/* Gives a Vulkan object a debug name (no-op without debug utils). */
void vk_context_name_object(const struct vk_context *ctx, VkObjectType type, uint64_t handle,
                            const char *name);

#endif
