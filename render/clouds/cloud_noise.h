/* The clouds' noise: a tileable 128^3 Perlin-Worley base-shape volume, a 32^3 Worley detail
 * volume and a 128^2 curl-noise texture (blue noise in its b channel), all generated on the
 * GPU from a seed; the 64^2 blue noise by void-and-cluster on the CPU (Ulichney 1993). */
#ifndef SKYD_CLOUD_NOISE_H
#define SKYD_CLOUD_NOISE_H

#include <stdbool.h>
#include <stdint.h>

#include "cloud_shared.h"
#include "compute_pass.h"
#include "vk_resources.h"

struct vk_context;

struct cloud_noise {
    struct gpu_image base, detail, curl;
    /* Kept for the renderer's life: a new seed must not compile them again (a compile costs
     * lavapipe tenths of a second and code memory it does not give back). */
    struct compute_pass base_pass, detail_pass, curl_pass;
    struct gpu_buffer blue; /* the curl pass's 64x64 blue-noise ranks */
    char *cache_dir;        /* cloud_noise_cache.h; NULL: none */
    uint32_t seed;
    bool generated;
};

/* Creates the images (zero until generated) and the passes that generate them; generated
 * volumes are kept in cache_dir and read from there (cloud_noise_cache.h; NULL or "": none).
 * Returns 0 or -1. */
int cloud_noise_create(struct vk_context *ctx, struct cloud_noise *noise, const char *cache_dir);
void cloud_noise_destroy(struct vk_context *ctx, struct cloud_noise *noise);

/* Reads every volume for `seed` from the cache, or else generates them now (synchronous, in
 * slabs; unless quiet, progress on stderr, or one line at the end through the context's log
 * sink) and stores them there. Returns 0 or -1. */
int cloud_noise_generate(struct vk_context *ctx, struct cloud_noise *noise, uint32_t seed,
                         bool quiet);

/* The 64x64 blue-noise ranks in [0, 1) for `seed` (void-and-cluster), row-major. Returns 0, or
 * -1 when its working memory cannot be had. */
int cloud_blue_noise(uint32_t seed, float out[64 * 64]);

#endif
