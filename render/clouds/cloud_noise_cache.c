#include "cloud_noise_cache.h"

#include <dirent.h>
#include <errno.h>
#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "cloud_noise.h"
#include "vk_check.h"
#include "vk_context.h"

#include "clouds_shaders.h"

#define FILE_MAGIC "SKYDNOIS"
#define FILE_VERSION 1u
#define NAME_PREFIX "cloud-noise-"
#define NAME_SUFFIX ".bin"

struct file_header {
    char magic[8];
    uint32_t version;
    uint32_t seed;
    uint64_t key;
    uint64_t payload_bytes;
};

/* FNV-1a, 64 bits: the key and the payload's checksum. */
static uint64_t fnv1a(uint64_t h, const void *data, size_t bytes)
{
    const unsigned char *p = data;
    for (size_t i = 0; i < bytes; i++) {
        h ^= p[i];
        h *= 0x100000001b3ull;
    }
    return h;
}
#define FNV_START 0xcbf29ce484222325ull

static size_t texel_bytes(VkFormat format)
{
    switch (format) {
    case VK_FORMAT_R8G8B8A8_UNORM:
        return 4;
    case VK_FORMAT_R32G32B32A32_SFLOAT:
        return 16;
    default:
        return 0;
    }
}

#define IMAGE_COUNT 3
static void noise_images(const struct cloud_noise *n, const struct gpu_image *out[IMAGE_COUNT])
{
    out[0] = &n->base;
    out[1] = &n->detail;
    out[2] = &n->curl;
}

static size_t image_bytes(const struct gpu_image *image)
{
    return (size_t)image->width * image->height * image->depth * texel_bytes(image->format);
}

/* What a file's content depends on besides its bytes: a file made otherwise has another name. */
static uint64_t cache_key(const struct vk_context *ctx, const struct cloud_noise *n, uint32_t seed)
{
    uint64_t h = FNV_START;
    const uint32_t version = FILE_VERSION;
    h = fnv1a(h, &version, sizeof version);
    h = fnv1a(h, &seed, sizeof seed);
    const struct gpu_image *images[IMAGE_COUNT];
    noise_images(n, images);
    for (int i = 0; i < IMAGE_COUNT; i++) {
        const uint32_t shape[4] = { images[i]->width, images[i]->height, images[i]->depth,
                                    (uint32_t)images[i]->format };
        h = fnv1a(h, shape, sizeof shape);
    }
    h = fnv1a(h, cloud_noise_base_spv, sizeof cloud_noise_base_spv);
    h = fnv1a(h, cloud_noise_detail_spv, sizeof cloud_noise_detail_spv);
    h = fnv1a(h, cloud_noise_curl_spv, sizeof cloud_noise_curl_spv);
    h = fnv1a(h, ctx->properties.pipelineCacheUUID, VK_UUID_SIZE);
    return h;
}

static size_t payload_bytes(const struct cloud_noise *n)
{
    const struct gpu_image *images[IMAGE_COUNT];
    noise_images(n, images);
    size_t total = 0;
    for (int i = 0; i < IMAGE_COUNT; i++) {
        size_t bytes = image_bytes(images[i]);
        if (bytes == 0)
            return 0;
        total += bytes;
    }
    return total;
}

static bool file_path(const char *dir, uint64_t key, char *out, size_t outlen)
{
    int n = snprintf(out, outlen, "%s/" NAME_PREFIX "%016llx" NAME_SUFFIX, dir,
                     (unsigned long long)key);
    return n > 0 && (size_t)n < outlen;
}

/* Copies between the images and one buffer holding them back to back, in either direction. */
static int copy_images(struct vk_context *ctx, const struct cloud_noise *n,
                       const struct gpu_buffer *buffer, bool to_images)
{
    const struct gpu_image *images[IMAGE_COUNT];
    noise_images(n, images);
    VkCommandBuffer cmd;
    if (vk_context_begin_commands(ctx, &cmd) != VK_SUCCESS)
        return -1;
    /* Frames sampling the images, or the passes that generated them, come first. */
    VkMemoryBarrier before = {
        .sType = VK_STRUCTURE_TYPE_MEMORY_BARRIER,
        .srcAccessMask = VK_ACCESS_SHADER_WRITE_BIT,
        .dstAccessMask = to_images ? VK_ACCESS_TRANSFER_WRITE_BIT : VK_ACCESS_TRANSFER_READ_BIT,
    };
    vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT,
                         0, 1, &before, 0, NULL, 0, NULL);
    VkDeviceSize offset = 0;
    for (int i = 0; i < IMAGE_COUNT; i++) {
        VkBufferImageCopy region = {
            .bufferOffset = offset,
            .imageSubresource = { VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1 },
            .imageExtent = { images[i]->width, images[i]->height, images[i]->depth },
        };
        if (to_images)
            vkCmdCopyBufferToImage(cmd, buffer->buffer, images[i]->image, VK_IMAGE_LAYOUT_GENERAL,
                                   1, &region);
        else
            vkCmdCopyImageToBuffer(cmd, images[i]->image, VK_IMAGE_LAYOUT_GENERAL, buffer->buffer,
                                   1, &region);
        offset += image_bytes(images[i]);
    }
    if (to_images)
        gpu_barrier_compute_to_compute(cmd); /* transfer writes before the passes' reads */
    else
        gpu_barrier_to_host(cmd);
    return vk_context_submit_and_wait(ctx, &cmd) == VK_SUCCESS ? 0 : -1;
}

static bool read_exact(FILE *f, void *data, size_t bytes)
{
    return fread(data, 1, bytes, f) == bytes;
}

int cloud_noise_cache_load(struct vk_context *ctx, struct cloud_noise *n, const char *dir,
                           uint32_t seed)
{
    size_t bytes = payload_bytes(n);
    uint64_t key = cache_key(ctx, n, seed);
    char path[PATH_MAX];
    if (!dir || !dir[0] || bytes == 0 || !file_path(dir, key, path, sizeof path))
        return -1;
    FILE *f = fopen(path, "rb");
    if (!f)
        return -1; /* none yet: not worth a line */
    struct gpu_buffer staging = { 0 };
    const char *damage = NULL;
    struct file_header header;
    uint64_t checksum = 0;
    if (!read_exact(f, &header, sizeof header) || memcmp(header.magic, FILE_MAGIC, 8) != 0 ||
        header.version != FILE_VERSION || header.seed != seed || header.key != key ||
        header.payload_bytes != bytes)
        damage = "its header does not match";
    else if (gpu_buffer_create(ctx, bytes, VK_BUFFER_USAGE_TRANSFER_SRC_BIT, "cloud_noise_load",
                               &staging) != VK_SUCCESS)
        damage = "no staging memory";
    else if (!read_exact(f, staging.mapped, bytes) || !read_exact(f, &checksum, sizeof checksum))
        damage = "it is short";
    else if (fgetc(f) != EOF)
        damage = "it is too long";
    else if (fnv1a(FNV_START, staging.mapped, bytes) != checksum)
        damage = "its checksum does not match";
    fclose(f);
    int rc = -1;
    if (damage)
        vk_log(ctx, VK_LOG_WARNING, "cloud noise cache %s: %s; generating the noise", path, damage);
    else if (copy_images(ctx, n, &staging, true) == 0)
        rc = 0;
    gpu_buffer_destroy(ctx, &staging);
    return rc;
}

/* Makes dir and any missing parent (mode 0700, as a cache under $HOME should be). */
static int make_directories(const char *dir)
{
    char path[PATH_MAX];
    int n = snprintf(path, sizeof path, "%s", dir);
    if (n <= 0 || (size_t)n >= sizeof path)
        return -1;
    for (char *p = path + 1; *p; p++) {
        if (*p != '/')
            continue;
        *p = '\0';
        if (mkdir(path, 0700) != 0 && errno != EEXIST)
            return -1;
        *p = '/';
    }
    return mkdir(path, 0700) == 0 || errno == EEXIST ? 0 : -1;
}

static bool is_cache_file(const char *name)
{
    size_t len = strlen(name), prefix = strlen(NAME_PREFIX), suffix = strlen(NAME_SUFFIX);
    return len > prefix + suffix && strncmp(name, NAME_PREFIX, prefix) == 0 &&
           strcmp(name + len - suffix, NAME_SUFFIX) == 0;
}

/* Removes the oldest cache files (by modification time) past CLOUD_NOISE_CACHE_FILES. */
static void remove_oldest(const char *dir)
{
    for (;;) {
        DIR *d = opendir(dir);
        if (!d)
            return;
        int count = 0;
        char oldest[PATH_MAX] = "";
        struct timespec oldest_time = { 0 };
        struct dirent *e;
        while ((e = readdir(d))) {
            char path[PATH_MAX];
            struct stat st;
            int len = snprintf(path, sizeof path, "%s/%s", dir, e->d_name);
            if (!is_cache_file(e->d_name) || len <= 0 || (size_t)len >= sizeof path ||
                stat(path, &st) != 0 || !S_ISREG(st.st_mode))
                continue;
            count++;
            if (!oldest[0] || st.st_mtim.tv_sec < oldest_time.tv_sec ||
                (st.st_mtim.tv_sec == oldest_time.tv_sec &&
                 st.st_mtim.tv_nsec < oldest_time.tv_nsec)) {
                oldest_time = st.st_mtim;
                memcpy(oldest, path, sizeof oldest);
            }
        }
        closedir(d);
        if (count <= CLOUD_NOISE_CACHE_FILES || unlink(oldest) != 0)
            return;
    }
}

static int write_file(const char *path, const struct file_header *header, const void *payload,
                      uint64_t checksum)
{
    char temporary[PATH_MAX];
    int n = snprintf(temporary, sizeof temporary, "%s.%ld.tmp", path, (long)getpid());
    if (n <= 0 || (size_t)n >= sizeof temporary)
        return -1;
    FILE *f = fopen(temporary, "wb");
    if (!f)
        return -1;
    bool ok = fwrite(header, sizeof *header, 1, f) == 1 &&
              fwrite(payload, 1, header->payload_bytes, f) == header->payload_bytes &&
              fwrite(&checksum, sizeof checksum, 1, f) == 1;
    ok = fclose(f) == 0 && ok;
    if (!ok || rename(temporary, path) != 0) {
        int why = errno;
        unlink(temporary);
        errno = why;
        return -1;
    }
    return 0;
}

void cloud_noise_cache_store(struct vk_context *ctx, const struct cloud_noise *n, const char *dir,
                             uint32_t seed)
{
    size_t bytes = payload_bytes(n);
    uint64_t key = cache_key(ctx, n, seed);
    char path[PATH_MAX];
    if (!dir || !dir[0] || bytes == 0 || !file_path(dir, key, path, sizeof path))
        return;
    if (make_directories(dir) != 0) {
        vk_log(ctx, VK_LOG_WARNING, "cloud noise cache: cannot make %s: %s", dir, strerror(errno));
        return;
    }
    struct gpu_buffer staging;
    if (gpu_buffer_create(ctx, bytes, VK_BUFFER_USAGE_TRANSFER_DST_BIT, "cloud_noise_store",
                          &staging) != VK_SUCCESS)
        return;
    if (copy_images(ctx, n, &staging, false) == 0) {
        struct file_header header = {
            .version = FILE_VERSION, .seed = seed, .key = key, .payload_bytes = bytes
        };
        memcpy(header.magic, FILE_MAGIC, 8);
        uint64_t checksum = fnv1a(FNV_START, staging.mapped, bytes);
        if (write_file(path, &header, staging.mapped, checksum) != 0)
            vk_log(ctx, VK_LOG_WARNING, "cloud noise cache: cannot write %s: %s", path,
                   strerror(errno));
        else
            remove_oldest(dir);
    }
    gpu_buffer_destroy(ctx, &staging);
}
