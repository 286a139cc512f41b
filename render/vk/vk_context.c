#include "vk_context.h"

#include <errno.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "fault_injection.h"
#include "vk_check.h"

#define VALIDATION_LAYER "VK_LAYER_KHRONOS_validation"
/* The passes read their parameters from storage buffers (sky_shared.h, SKY_PARAMETER_BLOCK): the
 * probe binds 6 per stage, beyond the 4 that Vulkan guarantees. */
#define MIN_STORAGE_BUFFERS_PER_STAGE 8u

const char *vk_result_name(VkResult result)
{
    /* clang-format off */
    switch (result) {
    case VK_SUCCESS: return "VK_SUCCESS";
    case VK_NOT_READY: return "VK_NOT_READY";
    case VK_TIMEOUT: return "VK_TIMEOUT";
    case VK_INCOMPLETE: return "VK_INCOMPLETE";
    case VK_ERROR_OUT_OF_HOST_MEMORY: return "VK_ERROR_OUT_OF_HOST_MEMORY";
    case VK_ERROR_OUT_OF_DEVICE_MEMORY: return "VK_ERROR_OUT_OF_DEVICE_MEMORY";
    case VK_ERROR_INITIALIZATION_FAILED: return "VK_ERROR_INITIALIZATION_FAILED";
    case VK_ERROR_DEVICE_LOST: return "VK_ERROR_DEVICE_LOST";
    case VK_ERROR_MEMORY_MAP_FAILED: return "VK_ERROR_MEMORY_MAP_FAILED";
    case VK_ERROR_LAYER_NOT_PRESENT: return "VK_ERROR_LAYER_NOT_PRESENT";
    case VK_ERROR_EXTENSION_NOT_PRESENT: return "VK_ERROR_EXTENSION_NOT_PRESENT";
    case VK_ERROR_FEATURE_NOT_PRESENT: return "VK_ERROR_FEATURE_NOT_PRESENT";
    case VK_ERROR_INCOMPATIBLE_DRIVER: return "VK_ERROR_INCOMPATIBLE_DRIVER";
    case VK_ERROR_TOO_MANY_OBJECTS: return "VK_ERROR_TOO_MANY_OBJECTS";
    case VK_ERROR_FORMAT_NOT_SUPPORTED: return "VK_ERROR_FORMAT_NOT_SUPPORTED";
    case VK_ERROR_FRAGMENTED_POOL: return "VK_ERROR_FRAGMENTED_POOL";
    case VK_ERROR_OUT_OF_POOL_MEMORY: return "VK_ERROR_OUT_OF_POOL_MEMORY";
    case VK_ERROR_UNKNOWN: return "VK_ERROR_UNKNOWN";
    default: return "VkResult(other)";
    }
    /* clang-format on */
}

static void write_line(const struct vk_context *ctx, enum vk_log_level level, const char *line)
{
    if (ctx && ctx->log.write)
        ctx->log.write(ctx->log.user, level, line);
    else
        fprintf(stderr, "skyd: %s\n", line);
}

void vk_log(const struct vk_context *ctx, enum vk_log_level level, const char *format, ...)
{
    char line[1024];
    va_list args, again;
    va_start(args, format);
    va_copy(again, args);
    int length = vsnprintf(line, sizeof line, format, args);
    /* Validation messages can run longer: those are formatted again, whole. */
    char *long_line = length >= (int)sizeof line ? malloc((size_t)length + 1) : NULL;
    if (long_line)
        vsnprintf(long_line, (size_t)length + 1, format, again);
    va_end(again);
    va_end(args);
    write_line(ctx, level, long_line ? long_line : line);
    free(long_line);
}

bool vk_log_is_stderr(const struct vk_context *ctx)
{
    return !ctx || !ctx->log.write;
}

static VKAPI_ATTR VkBool32 VKAPI_CALL on_debug_message(
    VkDebugUtilsMessageSeverityFlagBitsEXT severity, VkDebugUtilsMessageTypeFlagsEXT types,
    const VkDebugUtilsMessengerCallbackDataEXT *data, void *user)
{
    (void)types;
    struct vk_context *ctx = user;
    const char *name = "info";
    enum vk_log_level level = VK_LOG_INFO;
    if (severity & VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT) {
        ctx->validation_errors++;
        name = "error";
        level = VK_LOG_ERROR;
    } else if (severity & VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT) {
        ctx->validation_warnings++;
        name = "warning";
        level = VK_LOG_WARNING;
    }
    if (ctx->validation_message_counter &&
        (severity & (VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT |
                     VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT)))
        (*ctx->validation_message_counter)++;
    vk_log(ctx, level, "vulkan validation %s: %s", name,
           data && data->pMessage ? data->pMessage : "(no message)");
    return VK_FALSE;
}

static bool instance_has_layer(const char *name)
{
    uint32_t count = 0;
    if (vkEnumerateInstanceLayerProperties(&count, NULL) != VK_SUCCESS)
        return false;
    VkLayerProperties *layers = calloc(count ? count : 1, sizeof *layers);
    bool found = false;
    if (layers && vkEnumerateInstanceLayerProperties(&count, layers) == VK_SUCCESS) {
        for (uint32_t i = 0; i < count && !found; i++)
            found = strcmp(layers[i].layerName, name) == 0;
    }
    free(layers);
    return found;
}

static bool instance_has_extension(const char *name)
{
    uint32_t count = 0;
    if (vkEnumerateInstanceExtensionProperties(NULL, &count, NULL) != VK_SUCCESS)
        return false;
    VkExtensionProperties *exts = calloc(count ? count : 1, sizeof *exts);
    bool found = false;
    if (exts && vkEnumerateInstanceExtensionProperties(NULL, &count, exts) == VK_SUCCESS) {
        for (uint32_t i = 0; i < count && !found; i++)
            found = strcmp(exts[i].extensionName, name) == 0;
    }
    free(exts);
    return found;
}

static int device_kind_rank(VkPhysicalDeviceType type)
{
    switch (type) {
    case VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU:
        return 4;
    case VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU:
        return 3;
    case VK_PHYSICAL_DEVICE_TYPE_VIRTUAL_GPU:
        return 2;
    case VK_PHYSICAL_DEVICE_TYPE_CPU:
        return 1;
    default:
        return 0;
    }
}

static bool find_compute_queue(VkPhysicalDevice pd, uint32_t *family, uint32_t *timestamp_bits)
{
    uint32_t count = 0;
    vkGetPhysicalDeviceQueueFamilyProperties(pd, &count, NULL);
    VkQueueFamilyProperties *props = calloc(count ? count : 1, sizeof *props);
    if (!props)
        return false;
    vkGetPhysicalDeviceQueueFamilyProperties(pd, &count, props);
    bool found = false;
    /* Prefer a family with timestamps so per-pass timing works. */
    for (int pass = 0; pass < 2 && !found; pass++) {
        for (uint32_t i = 0; i < count; i++) {
            if (!(props[i].queueFlags & VK_QUEUE_COMPUTE_BIT))
                continue;
            if (pass == 0 && props[i].timestampValidBits == 0)
                continue;
            *family = i;
            *timestamp_bits = props[i].timestampValidBits;
            found = true;
            break;
        }
    }
    free(props);
    return found;
}

static bool is_decimal(const char *s)
{
    if (!*s)
        return false;
    for (; *s; s++)
        if (*s < '0' || *s > '9')
            return false;
    return true;
}

/* Logs the devices as one line, for a preference that matched none. */
static void log_no_match(const struct vk_context *ctx, VkPhysicalDevice *devices, uint32_t count,
                         const char *preference)
{
    char list[1024] = "";
    size_t used = 0;
    for (uint32_t i = 0; i < count && used < sizeof list; i++) {
        VkPhysicalDeviceProperties p;
        vkGetPhysicalDeviceProperties(devices[i], &p);
        int n = snprintf(list + used, sizeof list - used, "%s%u: %s", i ? "; " : "", i,
                         p.deviceName);
        used += n > 0 ? (size_t)n : 0;
    }
    vk_log(ctx, VK_LOG_ERROR, "vulkan: no device with a compute queue matches \"%s\"; devices: %s",
           preference, list);
}

/* Returns the index of the chosen device or -1; logs why nothing matched. */
static int choose_device(const struct vk_context *ctx, VkPhysicalDevice *devices, uint32_t count,
                         const char *preference)
{
    const char *pref = preference ? preference : "";
    int best = -1, best_rank = -1;
    for (uint32_t i = 0; i < count; i++) {
        VkPhysicalDeviceProperties p;
        vkGetPhysicalDeviceProperties(devices[i], &p);
        uint32_t family, bits;
        if (!find_compute_queue(devices[i], &family, &bits))
            continue;
        if (p.limits.maxPerStageDescriptorStorageBuffers < MIN_STORAGE_BUFFERS_PER_STAGE) {
            vk_log(ctx, VK_LOG_WARNING,
                   "vulkan: %s skipped: %u storage buffers per stage, %u needed", p.deviceName,
                   p.limits.maxPerStageDescriptorStorageBuffers, MIN_STORAGE_BUFFERS_PER_STAGE);
            continue;
        }
        int rank = device_kind_rank(p.deviceType);
        bool ok;
        if (!*pref)
            ok = true;
        else if (strcmp(pref, "cpu") == 0)
            ok = p.deviceType == VK_PHYSICAL_DEVICE_TYPE_CPU;
        else if (strcmp(pref, "gpu") == 0)
            ok = p.deviceType != VK_PHYSICAL_DEVICE_TYPE_CPU;
        else if (is_decimal(pref))
            ok = (uint32_t)strtoul(pref, NULL, 10) == i;
        else
            ok = strstr(p.deviceName, pref) != NULL;
        if (ok && rank > best_rank) {
            best = (int)i;
            best_rank = rank;
        }
    }
    if (best < 0)
        log_no_match(ctx, devices, count, pref);
    return best;
}

static VkResult create_instance(struct vk_context *ctx, bool validation)
{
    const char *layers[1];
    uint32_t layer_count = 0;
    if (validation) {
        if (!instance_has_layer(VALIDATION_LAYER)) {
            vk_log(ctx, VK_LOG_ERROR, "vulkan: validation requested but %s is not installed",
                   VALIDATION_LAYER);
            return VK_ERROR_LAYER_NOT_PRESENT;
        }
        layers[layer_count++] = VALIDATION_LAYER;
    }
    const char *extensions[1];
    uint32_t extension_count = 0;
    bool debug_utils = instance_has_extension(VK_EXT_DEBUG_UTILS_EXTENSION_NAME);
    if (debug_utils)
        extensions[extension_count++] = VK_EXT_DEBUG_UTILS_EXTENSION_NAME;
    else if (validation) {
        vk_log(ctx, VK_LOG_ERROR, "vulkan: validation needs %s", VK_EXT_DEBUG_UTILS_EXTENSION_NAME);
        return VK_ERROR_EXTENSION_NOT_PRESENT;
    }

    VkApplicationInfo app = {
        .sType = VK_STRUCTURE_TYPE_APPLICATION_INFO,
        .pApplicationName = "skyd",
        .applicationVersion = VK_MAKE_VERSION(0, 1, 0),
        .pEngineName = "skyd",
        .engineVersion = VK_MAKE_VERSION(0, 1, 0),
        .apiVersion = VK_API_VERSION_1_2,
    };
    VkDebugUtilsMessengerCreateInfoEXT messenger_info = {
        .sType = VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT,
        .messageSeverity = VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT |
                           VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT,
        .messageType = VK_DEBUG_UTILS_MESSAGE_TYPE_GENERAL_BIT_EXT |
                       VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT,
        .pfnUserCallback = on_debug_message,
        .pUserData = ctx,
    };
    VkInstanceCreateInfo info = {
        .sType = VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO,
        /* Chained so instance creation and destruction are validated too. */
        .pNext = validation ? &messenger_info : NULL,
        .pApplicationInfo = &app,
        .enabledLayerCount = layer_count,
        .ppEnabledLayerNames = layers,
        .enabledExtensionCount = extension_count,
        .ppEnabledExtensionNames = extensions,
    };
    VK_CHECK_RETURN(vkCreateInstance(&info, NULL, &ctx->instance));

    if (validation) {
        PFN_vkCreateDebugUtilsMessengerEXT create_messenger = (PFN_vkCreateDebugUtilsMessengerEXT)
            vkGetInstanceProcAddr(ctx->instance, "vkCreateDebugUtilsMessengerEXT");
        if (!create_messenger)
            return VK_ERROR_EXTENSION_NOT_PRESENT;
        VK_CHECK_RETURN(create_messenger(ctx->instance, &messenger_info, NULL, &ctx->messenger));
        ctx->validation_enabled = true;
    }
    return VK_SUCCESS;
}

static VkResult pick_physical_device(struct vk_context *ctx, const struct vk_context_params *p)
{
    uint32_t count = 0;
    VK_CHECK_RETURN(vkEnumeratePhysicalDevices(ctx->instance, &count, NULL));
    if (count == 0) {
        vk_log(ctx, VK_LOG_ERROR, "vulkan: no physical device (is mesa-vulkan-drivers installed?)");
        return VK_ERROR_INITIALIZATION_FAILED;
    }
    VkPhysicalDevice *devices = calloc(count, sizeof *devices);
    if (!devices)
        return VK_ERROR_OUT_OF_HOST_MEMORY;
    VkResult res = vkEnumeratePhysicalDevices(ctx->instance, &count, devices);
    if (res != VK_SUCCESS && res != VK_INCOMPLETE) {
        free(devices);
        return res;
    }
    int chosen = choose_device(ctx, devices, count, p->device_preference);
    if (chosen >= 0)
        ctx->physical_device = devices[chosen];
    free(devices);
    if (chosen < 0)
        return VK_ERROR_INITIALIZATION_FAILED;

    vkGetPhysicalDeviceProperties(ctx->physical_device, &ctx->properties);
    vkGetPhysicalDeviceMemoryProperties(ctx->physical_device, &ctx->memory_properties);
    uint32_t timestamp_bits = 0;
    find_compute_queue(ctx->physical_device, &ctx->queue_family, &timestamp_bits);
    ctx->timestamp_period_ns = timestamp_bits ? ctx->properties.limits.timestampPeriod : 0.0f;
    ctx->timestamp_mask = timestamp_bits >= 64 ? UINT64_MAX : ((1ull << timestamp_bits) - 1ull);
    if (!p->quiet) {
        vk_log(ctx, VK_LOG_INFO, "vulkan device: %s (%s, Vulkan %u.%u.%u)%s",
               ctx->properties.deviceName,
               ctx->properties.deviceType == VK_PHYSICAL_DEVICE_TYPE_CPU ? "cpu" : "gpu",
               VK_API_VERSION_MAJOR(ctx->properties.apiVersion),
               VK_API_VERSION_MINOR(ctx->properties.apiVersion),
               VK_API_VERSION_PATCH(ctx->properties.apiVersion),
               ctx->validation_enabled ? ", validation on" : "");
    }
    return VK_SUCCESS;
}

struct vk_context *vk_context_create(const struct vk_context_params *params)
{
    struct vk_context_params defaults = { 0 };
    const struct vk_context_params *p = params ? params : &defaults;
    struct vk_context *ctx = calloc(1, sizeof *ctx);
    if (!ctx)
        return NULL;
    ctx->validation_message_counter = p->validation_message_counter;
    ctx->log = p->log;
    fault_injection_init(ctx);

    VK_CHECK_GOTO(create_instance(ctx, p->validation), destroy_partial);
    VK_CHECK_GOTO(pick_physical_device(ctx, p), destroy_partial);

    float priority = 1.0f;
    VkDeviceQueueCreateInfo queue_info = {
        .sType = VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO,
        .queueFamilyIndex = ctx->queue_family,
        .queueCount = 1,
        .pQueuePriorities = &priority,
    };
    VkDeviceCreateInfo device_info = {
        .sType = VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO,
        .queueCreateInfoCount = 1,
        .pQueueCreateInfos = &queue_info,
    };
    VkResult injected = fault_injection_create_device();
    VK_CHECK_GOTO(injected != VK_SUCCESS
                      ? injected
                      : vkCreateDevice(ctx->physical_device, &device_info, NULL, &ctx->device),
                  destroy_partial);
    vkGetDeviceQueue(ctx->device, ctx->queue_family, 0, &ctx->queue);

    VkCommandPoolCreateInfo pool_info = {
        .sType = VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO,
        .flags = VK_COMMAND_POOL_CREATE_TRANSIENT_BIT,
        .queueFamilyIndex = ctx->queue_family,
    };
    VK_CHECK_GOTO(vkCreateCommandPool(ctx->device, &pool_info, NULL, &ctx->command_pool),
                  destroy_partial);
    VkFenceCreateInfo fence_info = { .sType = VK_STRUCTURE_TYPE_FENCE_CREATE_INFO };
    VK_CHECK_GOTO(vkCreateFence(ctx->device, &fence_info, NULL, &ctx->fence), destroy_partial);
    return ctx;

destroy_partial:
    vk_context_destroy(&ctx);
    return NULL;
}

void vk_context_destroy(struct vk_context **pctx)
{
    struct vk_context *ctx = pctx ? *pctx : NULL;
    if (!ctx)
        return;
    if (ctx->device) {
        vk_context_wait_idle(ctx);
        if (ctx->fence)
            vkDestroyFence(ctx->device, ctx->fence, NULL);
        if (ctx->command_pool)
            vkDestroyCommandPool(ctx->device, ctx->command_pool, NULL);
        vkDestroyDevice(ctx->device, NULL);
    }
    if (ctx->messenger) {
        PFN_vkDestroyDebugUtilsMessengerEXT destroy_messenger =
            (PFN_vkDestroyDebugUtilsMessengerEXT)vkGetInstanceProcAddr(
                ctx->instance, "vkDestroyDebugUtilsMessengerEXT");
        if (destroy_messenger)
            destroy_messenger(ctx->instance, ctx->messenger, NULL);
    }
    if (ctx->instance)
        vkDestroyInstance(ctx->instance, NULL);
    free(ctx);
    *pctx = NULL;
}

void vk_context_note_failure(struct vk_context *ctx, VkResult result, const char *what, ...)
{
    bool loses_device = result == VK_ERROR_DEVICE_LOST || result == VK_TIMEOUT;
    if (ctx->device_lost || (ctx->failure != VK_SUCCESS && !loses_device))
        return; /* the first failure is the cause; a loss outranks everything */
    /* What failed, then the result's name (which a long description may cut short). */
    char *out = ctx->failure_what;
    size_t room = sizeof ctx->failure_what;
    va_list args;
    va_start(args, what);
    vsnprintf(out, room, what, args);
    va_end(args);
    size_t used = strlen(out);
    snprintf(out + used, room - used, ": %s", vk_result_name(result));
    ctx->failure = result;
    ctx->device_lost = loses_device;
}

void vk_context_clear_failure(struct vk_context *ctx)
{
    if (ctx->device_lost)
        return;
    ctx->failure = VK_SUCCESS;
    ctx->failure_what[0] = '\0';
}

bool vk_result_is_out_of_memory(VkResult result)
{
    return result == VK_ERROR_OUT_OF_HOST_MEMORY || result == VK_ERROR_OUT_OF_DEVICE_MEMORY;
}

VkResult vk_context_wait_idle(struct vk_context *ctx)
{
    if (ctx->device_lost)
        return VK_ERROR_DEVICE_LOST;
    VkResult res = vkDeviceWaitIdle(ctx->device);
    if (res != VK_SUCCESS) {
        vk_log(ctx, VK_LOG_ERROR, "vulkan: vkDeviceWaitIdle failed: %s", vk_result_name(res));
        vk_context_note_failure(ctx, res, "waiting for the device to be idle");
    }
    return res;
}

VkResult vk_context_begin_commands(struct vk_context *ctx, VkCommandBuffer *out)
{
    VkCommandBufferAllocateInfo alloc = {
        .sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO,
        .commandPool = ctx->command_pool,
        .level = VK_COMMAND_BUFFER_LEVEL_PRIMARY,
        .commandBufferCount = 1,
    };
    VkResult res = vkAllocateCommandBuffers(ctx->device, &alloc, out);
    if (res != VK_SUCCESS) {
        vk_log(ctx, VK_LOG_ERROR, "vulkan: vkAllocateCommandBuffers failed: %s",
               vk_result_name(res));
        vk_context_note_failure(ctx, res, "allocating a command buffer");
        *out = VK_NULL_HANDLE;
        return res;
    }
    VkCommandBufferBeginInfo begin = {
        .sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO,
        .flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT,
    };
    res = vkBeginCommandBuffer(*out, &begin);
    if (res != VK_SUCCESS) {
        vk_context_note_failure(ctx, res, "beginning a command buffer");
        vkFreeCommandBuffers(ctx->device, ctx->command_pool, 1, out);
        *out = VK_NULL_HANDLE;
    }
    return res;
}

void vk_context_expect_long_submission(struct vk_context *ctx)
{
    ctx->long_submission = true;
}

/* A submission that finishes late (fault_injection.h, "stall"): the waiting thread is held. */
static void stall(unsigned seconds)
{
    struct timespec left = { .tv_sec = (time_t)seconds };
    while (seconds > 0 && nanosleep(&left, &left) != 0 && errno == EINTR) {
    }
}

VkResult vk_context_submit_and_wait(struct vk_context *ctx, VkCommandBuffer *cmd)
{
    if (ctx->device_lost) { /* said when it was lost; the commands are dropped */
        vkFreeCommandBuffers(ctx->device, ctx->command_pool, 1, cmd);
        *cmd = VK_NULL_HANDLE;
        return VK_ERROR_DEVICE_LOST;
    }
    const char *step = "ending a command buffer";
    VkResult res = vkEndCommandBuffer(*cmd);
    if (res == VK_SUCCESS) {
        step = "resetting the fence";
        res = vkResetFences(ctx->device, 1, &ctx->fence);
    }
    if (res == VK_SUCCESS) {
        VkSubmitInfo submit = {
            .sType = VK_STRUCTURE_TYPE_SUBMIT_INFO,
            .commandBufferCount = 1,
            .pCommandBuffers = cmd,
        };
        step = "submitting to the queue";
        res = fault_injection_submit(ctx);
        if (res == VK_SUCCESS)
            res = vkQueueSubmit(ctx->queue, 1, &submit, ctx->fence);
    }
    unsigned timeout_s = ctx->long_submission ? VK_CONTEXT_LONG_SUBMIT_TIMEOUT_S
                                              : VK_CONTEXT_SUBMIT_TIMEOUT_S;
    ctx->long_submission = false;
    char waiting[64];
    if (res == VK_SUCCESS) {
        snprintf(waiting, sizeof waiting, "waiting for the queue (at most %u s)", timeout_s);
        step = waiting;
        stall(fault_injection_stall_seconds(ctx));
        res = fault_injection_wait_times_out(ctx)
                  ? VK_TIMEOUT
                  : vkWaitForFences(ctx->device, 1, &ctx->fence, VK_TRUE,
                                    (uint64_t)timeout_s * 1000000000ull);
    }
    if (res != VK_SUCCESS) {
        vk_log(ctx, VK_LOG_ERROR, "vulkan: %s failed: %s", step, vk_result_name(res));
        vk_context_note_failure(ctx, res, "%s", step);
    }
    if (res == VK_TIMEOUT) {
        vk_log(ctx, VK_LOG_ERROR,
               "vulkan: the device is taken as lost; waiting for the "
               "submission to end before its commands are freed");
        vkQueueWaitIdle(ctx->queue);
    }
    vkFreeCommandBuffers(ctx->device, ctx->command_pool, 1, cmd);
    *cmd = VK_NULL_HANDLE;
    return res;
}

uint32_t vk_context_find_memory_type(const struct vk_context *ctx, uint32_t type_bits,
                                     VkMemoryPropertyFlags required)
{
    for (uint32_t i = 0; i < ctx->memory_properties.memoryTypeCount; i++) {
        if ((type_bits & (1u << i)) &&
            (ctx->memory_properties.memoryTypes[i].propertyFlags & required) == required)
            return i;
    }
    return UINT32_MAX;
}

void vk_context_name_object(const struct vk_context *ctx, VkObjectType type, uint64_t handle,
                            const char *name)
{
    if (!ctx->validation_enabled || !handle || !name)
        return;
    PFN_vkSetDebugUtilsObjectNameEXT set_name =
        (PFN_vkSetDebugUtilsObjectNameEXT)vkGetInstanceProcAddr(ctx->instance,
                                                                "vkSetDebugUtilsObjectNameEXT");
    if (!set_name)
        return;
    VkDebugUtilsObjectNameInfoEXT info = {
        .sType = VK_STRUCTURE_TYPE_DEBUG_UTILS_OBJECT_NAME_INFO_EXT,
        .objectType = type,
        .objectHandle = handle,
        .pObjectName = name,
    };
    set_name(ctx->device, &info);
}
