/* Headless Vulkan context: instance (validation optional), physical device choice, one
 * compute queue, a command pool and a fence for synchronous submission.
 *
 * Failures that say something about the device are noted here (vk_context_note_failure):
 * VK_ERROR_DEVICE_LOST, or a submission that has not finished after
 * VK_CONTEXT_SUBMIT_TIMEOUT_S, makes the device lost for good: nothing is submitted to it any
 * more, waits return at once, and the owner must destroy the context and create another.
 * Other failures (out of memory above all) leave the context usable.
 *
 * Not thread-safe: one thread (the render thread) owns a context and everything made from it. */
#ifndef SKYD_VK_CONTEXT_H
#define SKYD_VK_CONTEXT_H

#include <stdbool.h>
#include <stdint.h>
#include <vulkan/vulkan.h>

enum vk_log_level {
    VK_LOG_ERROR = 0,
    VK_LOG_WARNING = 1,
    VK_LOG_INFO = 2,
    VK_LOG_DEBUG = 3,
};

/* Where a context's lines go: one line per call, without the "skyd: " prefix or a newline,
 * on the thread that made the call (the render thread). No `write`: stderr, prefixed. */
struct vk_log_sink {
    void (*write)(void *user, enum vk_log_level level, const char *line);
    void *user;
};

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
    struct vk_log_sink log;
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
    float timestamp_period_ns; /* 0 when the queue has no timestamps */
    uint64_t timestamp_mask;   /* valid bits of a timestamp */
    bool validation_enabled;
    /* Lost for good (see above): every submission and wait fails at once. */
    bool device_lost;
    /* The first failure noted since vk_context_clear_failure (a loss replaces any other), and
     * what failed: VK_SUCCESS and "" when none. */
    VkResult failure;
    char failure_what[224];
    /* Validation messages of warning or error severity seen so far (written by the
     * messenger callback, which runs on the thread that made the offending call). */
    unsigned validation_warnings;
    unsigned validation_errors;
    unsigned *validation_message_counter; /* from the params, may be NULL */
    struct vk_log_sink log;
    /* The next submission may run for VK_CONTEXT_LONG_SUBMIT_TIMEOUT_S
     * (vk_context_expect_long_submission). */
    bool long_submission;
};

/* A submission not finished after this long is taken for a hung device: waits are bounded. A
 * path-traced reference frame, which takes minutes on a CPU device, may take up to a day. */
#define VK_CONTEXT_SUBMIT_TIMEOUT_S 300
#define VK_CONTEXT_LONG_SUBMIT_TIMEOUT_S 86400

/* Writes one line through the context's sink (ctx NULL or no sink: stderr). */
#if defined(__GNUC__)
__attribute__((format(printf, 3, 4)))
#endif
void vk_log(const struct vk_context *ctx, enum vk_log_level level, const char *format, ...);
/* Whether the context's lines go to stderr (no sink), where a progress indicator may
 * rewrite its own line. */
bool vk_log_is_stderr(const struct vk_context *ctx);

/* Lets the next vk_context_submit_and_wait wait up to VK_CONTEXT_LONG_SUBMIT_TIMEOUT_S. */
void vk_context_expect_long_submission(struct vk_context *ctx);

/* Returns NULL on failure after logging why. */
struct vk_context *vk_context_create(const struct vk_context_params *params);
void vk_context_destroy(struct vk_context **ctx);

/* Notes that `what` (printf format) failed with `result`: VK_ERROR_DEVICE_LOST and VK_TIMEOUT
 * (only a bounded wait reports it) make the device lost for good. */
#if defined(__GNUC__)
__attribute__((format(printf, 3, 4)))
#endif
void vk_context_note_failure(struct vk_context *ctx, VkResult result, const char *what, ...);
/* Forgets the failure noted (a lost device stays lost). */
void vk_context_clear_failure(struct vk_context *ctx);
/* VK_ERROR_OUT_OF_HOST_MEMORY or VK_ERROR_OUT_OF_DEVICE_MEMORY. */
bool vk_result_is_out_of_memory(VkResult result);

/* Waits until the device is idle (before destroying what it may use); logs a failure. A lost
 * device is not waited for: nothing runs on it any more. */
VkResult vk_context_wait_idle(struct vk_context *ctx);

/* Allocates a primary command buffer and begins it for one-time submission. */
VkResult vk_context_begin_commands(struct vk_context *ctx, VkCommandBuffer *out);
/* Ends, submits, waits for completion (at most VK_CONTEXT_SUBMIT_TIMEOUT_S, or the long bound
 * once) and frees the command buffer (always freed). On a lost device nothing is submitted:
 * VK_ERROR_DEVICE_LOST. A submission still running at the bound makes the device lost, and is
 * waited for without a bound before its command buffer is freed: freeing it while it runs (a CPU
 * device keeps running it) would pull its commands from under the driver. */
VkResult vk_context_submit_and_wait(struct vk_context *ctx, VkCommandBuffer *cmd);

/* Finds a memory type allowed by type_bits with all `required` flags; UINT32_MAX if none. */
uint32_t vk_context_find_memory_type(const struct vk_context *ctx, uint32_t type_bits,
                                     VkMemoryPropertyFlags required);

/* Gives a Vulkan object a debug name (no-op without debug utils). */
void vk_context_name_object(const struct vk_context *ctx, VkObjectType type, uint64_t handle,
                            const char *name);

#endif
