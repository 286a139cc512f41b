#include "fault_injection.h"

#include "vk_context.h"

#include <pthread.h>
#include <stdbool.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

enum fault_kind { FAULT_DEVICE_LOST, FAULT_OUT_OF_MEMORY, FAULT_TIMEOUT, FAULT_STALL };

#define MAX_TIMES 1000u
#define MAX_AFTER_FRAMES 1000000u
#define MAX_STALL_SECONDS 600u

/* The one fault of the process (see the header for why it is not per context). `active` is
 * written once, under pthread_once, before any hook can read it; the rest under `lock`. */
static struct {
    bool active;
    enum fault_kind kind;
    unsigned after_frames, times;
    unsigned stall_seconds;
    bool permanent;
    pthread_mutex_t lock;
    uint64_t frames;    /* frames rendered so far */
    uint64_t due_frame; /* the next fault fires once `frames` reaches this */
    unsigned injected;  /* faults injected so far */
    bool lost_for_good; /* a permanent loss happened */
    const char *spec;   /* SKYD_FAULT when set, understood or not */
    bool announced;     /* the first context has said what `spec` arms */
} fault = { .lock = PTHREAD_MUTEX_INITIALIZER };

static pthread_once_t fault_once = PTHREAD_ONCE_INIT;

static bool parse_count(const char *text, size_t length, unsigned max, unsigned *out)
{
    if (length == 0 || length > 9)
        return false;
    unsigned value = 0;
    for (size_t i = 0; i < length; i++) {
        if (text[i] < '0' || text[i] > '9')
            return false;
        value = value * 10 + (unsigned)(text[i] - '0');
    }
    if (value > max)
        return false;
    *out = value;
    return true;
}

/* Parses "kind:key=value:..." into `fault`; false when anything is not understood. */
static bool parse(const char *spec)
{
    const char *colon = strchr(spec, ':');
    size_t kind_length = colon ? (size_t)(colon - spec) : strlen(spec);
    if (kind_length == strlen("device_lost") && strncmp(spec, "device_lost", kind_length) == 0)
        fault.kind = FAULT_DEVICE_LOST;
    else if (kind_length == strlen("out_of_memory") &&
             strncmp(spec, "out_of_memory", kind_length) == 0)
        fault.kind = FAULT_OUT_OF_MEMORY;
    else if (kind_length == strlen("timeout") && strncmp(spec, "timeout", kind_length) == 0)
        fault.kind = FAULT_TIMEOUT;
    else if (kind_length == strlen("stall") && strncmp(spec, "stall", kind_length) == 0)
        fault.kind = FAULT_STALL;
    else
        return false;
    fault.times = 1;
    bool have_after = false;
    for (const char *item = colon; item; item = strchr(item + 1, ':')) {
        const char *start = item + 1;
        const char *end = strchr(start, ':');
        size_t length = end ? (size_t)(end - start) : strlen(start);
        const char *equals = memchr(start, '=', length);
        size_t key_length = equals ? (size_t)(equals - start) : length;
        const char *value = equals ? equals + 1 : NULL;
        size_t value_length = equals ? length - key_length - 1 : 0;
        if (key_length == 12 && strncmp(start, "after_frames", 12) == 0 && value) {
            if (!parse_count(value, value_length, MAX_AFTER_FRAMES, &fault.after_frames))
                return false;
            have_after = true;
        } else if (key_length == 5 && strncmp(start, "times", 5) == 0 && value) {
            if (!parse_count(value, value_length, MAX_TIMES, &fault.times) || fault.times == 0)
                return false;
        } else if (key_length == 7 && strncmp(start, "seconds", 7) == 0 && value &&
                   fault.kind == FAULT_STALL) {
            if (!parse_count(value, value_length, MAX_STALL_SECONDS, &fault.stall_seconds) ||
                fault.stall_seconds == 0)
                return false;
        } else if (length == 9 && strncmp(start, "permanent", 9) == 0 &&
                   fault.kind == FAULT_DEVICE_LOST) {
            fault.permanent = true;
        } else {
            return false;
        }
    }
    return have_after && (fault.kind != FAULT_STALL || fault.stall_seconds > 0);
}

static void read_environment(void)
{
    const char *spec = getenv("SKYD_FAULT");
    if (!spec || !*spec)
        return;
    fault.spec = spec;
    if (!parse(spec))
        return;
    fault.due_frame = fault.after_frames;
    fault.active = true;
}

void fault_injection_init(const struct vk_context *ctx)
{
    pthread_once(&fault_once, read_environment);
    if (!fault.spec)
        return;
    pthread_mutex_lock(&fault.lock);
    bool announce = !fault.announced;
    fault.announced = true;
    pthread_mutex_unlock(&fault.lock);
    if (!announce)
        return;
    if (fault.active)
        vk_log(ctx, VK_LOG_WARNING, "fault injection armed (tests only): SKYD_FAULT=%s",
               fault.spec);
    else
        vk_log(ctx, VK_LOG_WARNING,
               "SKYD_FAULT=\"%s\" is not understood; no fault is injected "
               "(render/vk/fault_injection.h describes the forms)",
               fault.spec);
}

void fault_injection_frame_rendered(void)
{
    if (!fault.active)
        return;
    pthread_mutex_lock(&fault.lock);
    fault.frames++;
    pthread_mutex_unlock(&fault.lock);
}

static const char *kind_text(enum fault_kind kind)
{
    switch (kind) {
    case FAULT_DEVICE_LOST:
        return "the device is lost";
    case FAULT_TIMEOUT:
        return "the wait for a submission times out";
    case FAULT_STALL:
        return "a submission stalls";
    case FAULT_OUT_OF_MEMORY:
        return "out of device memory";
    }
    return "?";
}

/* Whether a fault of `kind` fires now; counts it and says so through `ctx` when it does. */
static bool fire(const struct vk_context *ctx, enum fault_kind kind)
{
    if (!fault.active || fault.kind != kind)
        return false;
    pthread_mutex_lock(&fault.lock);
    bool fires = fault.lost_for_good;
    bool fresh = false;
    unsigned injected = 0;
    uint64_t frames = 0;
    if (!fires && fault.injected < fault.times && fault.frames >= fault.due_frame) {
        fires = fresh = true;
        injected = ++fault.injected;
        frames = fault.frames;
        /* The next loss comes after_frames later; allocations fail back to back. */
        if (kind != FAULT_OUT_OF_MEMORY)
            fault.due_frame = fault.frames + fault.after_frames;
        fault.lost_for_good = fault.permanent;
    }
    pthread_mutex_unlock(&fault.lock);
    if (fresh)
        vk_log(ctx, VK_LOG_WARNING, "fault injection: %s (%u of %u, after %llu frames)",
               kind_text(kind), injected, fault.times, (unsigned long long)frames);
    return fires;
}

VkResult fault_injection_submit(const struct vk_context *ctx)
{
    return fire(ctx, FAULT_DEVICE_LOST) ? VK_ERROR_DEVICE_LOST : VK_SUCCESS;
}

bool fault_injection_wait_times_out(const struct vk_context *ctx)
{
    return fire(ctx, FAULT_TIMEOUT);
}

unsigned fault_injection_stall_seconds(const struct vk_context *ctx)
{
    return fire(ctx, FAULT_STALL) ? fault.stall_seconds : 0;
}

VkResult fault_injection_allocate(const struct vk_context *ctx)
{
    return fire(ctx, FAULT_OUT_OF_MEMORY) ? VK_ERROR_OUT_OF_DEVICE_MEMORY : VK_SUCCESS;
}

VkResult fault_injection_create_device(void)
{
    if (!fault.active)
        return VK_SUCCESS;
    pthread_mutex_lock(&fault.lock);
    bool lost = fault.lost_for_good;
    pthread_mutex_unlock(&fault.lock);
    return lost ? VK_ERROR_DEVICE_LOST : VK_SUCCESS;
}
