/* Fault injection for tests: makes the Vulkan device look lost, out of memory or stalled, on
 * demand.
 * A CPU device (lavapipe) is never lost and rarely runs out of memory, so the daemon's
 * recovery from those results could not be tested without it.
 *
 * SKYD_FAULT, read once per process when the first Vulkan context is created, holds one
 * fault:
 *
 *   device_lost:after_frames=N[:times=K][:permanent]
 *       Once N frames (successful sky_renderer_render calls, counted over the process) have
 *       been rendered, the next queue submission reports VK_ERROR_DEVICE_LOST instead of
 *       running. times=K (default 1): K losses, each N frames after the one before.
 *       permanent: the device stays lost; every later submission fails, and so does creating
 *       another device (vkCreateDevice reports VK_ERROR_DEVICE_LOST).
 *   out_of_memory:after_frames=N[:times=K]
 *       Once N frames have been rendered, the next K device memory allocations (default 1)
 *       report VK_ERROR_OUT_OF_DEVICE_MEMORY.
 *   timeout:after_frames=N[:times=K]
 *       Once N frames have been rendered, the next queue submission runs, but the wait for it
 *       gives up at once with VK_TIMEOUT, as a bounded wait does on a device still running it
 *       (a CPU device slower than the bound).
 *   stall:after_frames=N:seconds=S[:times=K]
 *       Once N frames have been rendered, the next queue submission finishes S seconds late
 *       (0 < S <= 600) and the thread that waits for it is held that long, as on a device that
 *       stalls on one frame and recovers (a GPU busy with another process, a CPU device
 *       starved by other work); the wait then succeeds. times=K: K stalls, N frames apart.
 *
 * The fault is process-wide, not per context, because a lost device outlives the renderer
 * that saw it: a renderer created after the loss must see it too. Unset (always, outside
 * tests), every hook below is one test of a flag that stays false. A malformed value is
 * reported and injects nothing. Thread-safe. Its lines are warnings through the log sink of
 * the context passed in (vk_log): the first context created says which fault is armed, and a
 * fault is said through the context it hits. */
#ifndef SKYD_FAULT_INJECTION_H
#define SKYD_FAULT_INJECTION_H

#include <stdbool.h>
#include <vulkan/vulkan.h>

struct vk_context;

/* Reads SKYD_FAULT (the first call only) and says through `ctx`, the first time, which fault
 * is armed or that the value is not understood. */
void fault_injection_init(const struct vk_context *ctx);

/* A frame was rendered. */
void fault_injection_frame_rendered(void);

/* VK_SUCCESS, or the result a queue submission must report instead of running. */
VkResult fault_injection_submit(const struct vk_context *ctx);
/* True when the wait for the submission just made must report VK_TIMEOUT at once. */
bool fault_injection_wait_times_out(const struct vk_context *ctx);
/* Seconds the submission just made is to finish late (0: on time). */
unsigned fault_injection_stall_seconds(const struct vk_context *ctx);
/* VK_SUCCESS, or the result a device memory allocation must report instead of allocating. */
VkResult fault_injection_allocate(const struct vk_context *ctx);
/* VK_SUCCESS, or the result creating a logical device must report. */
VkResult fault_injection_create_device(void);

#endif
