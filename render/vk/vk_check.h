/* One VkResult check, always compiled in: it logs where the call failed, through the log of
 * the `struct vk_context *ctx` in scope (every caller has one), and jumps to a cleanup label
 * named after what that label undoes. The labels stand in reverse order of acquisition
 * (destroy_view:, free_memory:, destroy_image:), so a failure jumps to the label for the last
 * thing acquired and falls through the rest; a last report: says what failed. A create that
 * hands a partial object to its own destroy, which frees whatever is there, jumps to
 * destroy_partial:. */
#ifndef SKYD_VK_CHECK_H
#define SKYD_VK_CHECK_H

#include <vulkan/vulkan.h>

#include "vk_context.h"

const char *vk_result_name(VkResult result);

#define VK_CHECK_GOTO(call, label)                                                                 \
    do {                                                                                           \
        VkResult vk_check_result_ = (call);                                                        \
        if (vk_check_result_ != VK_SUCCESS) {                                                      \
            vk_log(ctx, VK_LOG_ERROR, "vulkan: %s failed: %s (%s:%d)", #call,                      \
                   vk_result_name(vk_check_result_), __FILE__, __LINE__);                          \
            goto label;                                                                            \
        }                                                                                          \
    } while (0)

/* The same, keeping the failed result in `result` for the cleanup to report or return. */
#define VK_CHECK_KEEP_GOTO(call, result, label)                                                    \
    do {                                                                                           \
        (result) = (call);                                                                         \
        if ((result) != VK_SUCCESS) {                                                              \
            vk_log(ctx, VK_LOG_ERROR, "vulkan: %s failed: %s (%s:%d)", #call,                      \
                   vk_result_name(result), __FILE__, __LINE__);                                    \
            goto label;                                                                            \
        }                                                                                          \
    } while (0)

/* For functions returning VkResult themselves: log and return the failure. */
#define VK_CHECK_RETURN(call)                                                                      \
    do {                                                                                           \
        VkResult vk_check_result_ = (call);                                                        \
        if (vk_check_result_ != VK_SUCCESS) {                                                      \
            vk_log(ctx, VK_LOG_ERROR, "vulkan: %s failed: %s (%s:%d)", #call,                      \
                   vk_result_name(vk_check_result_), __FILE__, __LINE__);                          \
            return vk_check_result_;                                                               \
        }                                                                                          \
    } while (0)

#endif
