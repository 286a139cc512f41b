#include "cloud_noise.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cloud_layouts.h"
#include "cloud_noise_cache.h"
#include "compute_pass.h"
#include "vk_check.h"
#include "vk_context.h"

#include "clouds_shaders.h"

#define BASE_SIZE 128
#define DETAIL_SIZE 32
#define CURL_SIZE 128
#define BLUE_SIZE 64
#define SLAB 16 /* z slices of the base volume per submission */

/* ---- void-and-cluster blue noise ---- */

#define VC_N (BLUE_SIZE * BLUE_SIZE)
#define VC_RADIUS 8
#define VC_SIGMA 1.9

struct vc_state {
    unsigned char on[VC_N];
    double energy[VC_N];
    double kernel[2 * VC_RADIUS + 1][2 * VC_RADIUS + 1];
};

static void vc_splat(struct vc_state *s, int index, double sign)
{
    int x0 = index % BLUE_SIZE, y0 = index / BLUE_SIZE;
    for (int dy = -VC_RADIUS; dy <= VC_RADIUS; dy++)
        for (int dx = -VC_RADIUS; dx <= VC_RADIUS; dx++) {
            int x = (x0 + dx + BLUE_SIZE) % BLUE_SIZE, y = (y0 + dy + BLUE_SIZE) % BLUE_SIZE;
            s->energy[y * BLUE_SIZE + x] += sign * s->kernel[dy + VC_RADIUS][dx + VC_RADIUS];
        }
}

static void vc_set(struct vc_state *s, int index, bool on)
{
    s->on[index] = on;
    vc_splat(s, index, on ? 1.0 : -1.0);
}

/* The tightest cluster (highest energy among ones) or the largest void (lowest among zeros). */
static int vc_find(const struct vc_state *s, bool cluster)
{
    int best = -1;
    for (int i = 0; i < VC_N; i++) {
        if (s->on[i] != cluster)
            continue;
        if (best < 0 || (cluster ? s->energy[i] > s->energy[best] : s->energy[i] < s->energy[best]))
            best = i;
    }
    return best;
}

int cloud_blue_noise(uint32_t seed, float out[VC_N])
{
    /* The pattern and its relaxed start, each call its own (tens of kilobytes: the heap). */
    struct vc_state *work = calloc(2, sizeof *work);
    if (!work)
        return -1;
    struct vc_state *s = &work[0], *initial = &work[1];
    for (int dy = -VC_RADIUS; dy <= VC_RADIUS; dy++)
        for (int dx = -VC_RADIUS; dx <= VC_RADIUS; dx++)
            s->kernel[dy + VC_RADIUS][dx + VC_RADIUS] =
                exp(-(dx * dx + dy * dy) / (2.0 * VC_SIGMA * VC_SIGMA));
    /* A random initial pattern of a tenth of the cells (xorshift from the seed)... */
    uint32_t state = seed * 2654435761u + 0x9e3779b9u;
    int ones = 0;
    while (ones < VC_N / 10) {
        state ^= state << 13;
        state ^= state >> 17;
        state ^= state << 5;
        int i = (int)(state % VC_N);
        if (!s->on[i]) {
            vc_set(s, i, true);
            ones++;
        }
    }
    /* ...relaxed by moving the tightest cluster into the largest void until stable. */
    for (int iter = 0; iter < VC_N; iter++) {
        int c = vc_find(s, true);
        vc_set(s, c, false);
        int v = vc_find(s, false);
        vc_set(s, v, true);
        if (v == c)
            break;
    }
    *initial = *s;
    /* Ranks: remove clusters from the initial pattern downward, then fill voids upward. */
    int rank[VC_N];
    for (int r = ones - 1; r >= 0; r--) {
        int c = vc_find(s, true);
        vc_set(s, c, false);
        rank[c] = r;
    }
    *s = *initial;
    for (int r = ones; r < VC_N; r++) {
        int v = vc_find(s, false);
        vc_set(s, v, true);
        rank[v] = r;
    }
    for (int i = 0; i < VC_N; i++)
        out[i] = ((float)rank[i] + 0.5f) / VC_N;
    free(work);
    return 0;
}

/* ---- GPU generation ---- */

static int run_pass(struct vk_context *ctx, struct compute_pass *pass,
                    const struct sky_cloud_noise_push *push, const uint32_t size[3],
                    const uint32_t local[3])
{
    VkCommandBuffer cmd;
    if (vk_context_begin_commands(ctx, &cmd) != VK_SUCCESS)
        return -1;
    compute_pass_record(cmd, pass, push, size, local);
    return vk_context_submit_and_wait(ctx, &cmd) == VK_SUCCESS ? 0 : -1;
}

#define SPIRV(name) .spirv = name, .spirv_bytes = sizeof(name)
#define NOISE_PUSH .push_constant_bytes = sizeof(struct sky_cloud_noise_push)

static VkResult create_passes(struct vk_context *ctx, struct cloud_noise *n)
{
    /* clang-format off */
    const struct compute_pass_desc descs[3] = {
        { .name = "cloud_noise_base", SPIRV(cloud_noise_base_spv),
          SKY_PASS_LAYOUT(SKY_LAYOUT_CLOUD_NOISE_VOLUME), NOISE_PUSH },
        { .name = "cloud_noise_detail", SPIRV(cloud_noise_detail_spv),
          SKY_PASS_LAYOUT(SKY_LAYOUT_CLOUD_NOISE_VOLUME), NOISE_PUSH },
        { .name = "cloud_noise_curl", SPIRV(cloud_noise_curl_spv),
          SKY_PASS_LAYOUT(SKY_LAYOUT_CLOUD_NOISE_CURL), NOISE_PUSH },
    };
    /* clang-format on */
    struct compute_pass *passes[3] = { &n->base_pass, &n->detail_pass, &n->curl_pass };
    for (int i = 0; i < 3; i++)
        VK_CHECK_RETURN(compute_pass_create(ctx, &descs[i], passes[i]));
    struct compute_resource base[SKY_LAYOUT_COUNT(SKY_LAYOUT_CLOUD_NOISE_VOLUME)] = {
        [SKY_CLOUD_NOISE_VOLUME_OUT] = { .image = &n->base },
    };
    struct compute_resource detail[SKY_LAYOUT_COUNT(SKY_LAYOUT_CLOUD_NOISE_VOLUME)] = {
        [SKY_CLOUD_NOISE_VOLUME_OUT] = { .image = &n->detail },
    };
    struct compute_resource curl[SKY_LAYOUT_COUNT(SKY_LAYOUT_CLOUD_NOISE_CURL)] = {
        [SKY_CLOUD_NOISE_CURL_BLUE] = { .buffer = &n->blue },
        [SKY_CLOUD_NOISE_CURL_OUT] = { .image = &n->curl },
    };
    compute_pass_bind(ctx, &n->base_pass, base);
    compute_pass_bind(ctx, &n->detail_pass, detail);
    compute_pass_bind(ctx, &n->curl_pass, curl);
    return VK_SUCCESS;
}

/* The progress rewrites one line of stderr; a sink takes whole lines, so it hears only the
 * end. */
static void progress_show(const struct vk_context *ctx, uint32_t percent)
{
    if (vk_log_is_stderr(ctx))
        fprintf(stderr, "\rskyd: cloud noise %3u%%", percent);
}

static void progress_end(const struct vk_context *ctx, bool done)
{
    if (vk_log_is_stderr(ctx))
        fputc('\n', stderr);
    else if (done)
        vk_log(ctx, VK_LOG_INFO, "cloud noise 100%%");
}

static int generate_volumes(struct vk_context *ctx, struct cloud_noise *n, uint32_t seed,
                            bool quiet)
{
    struct compute_pass *passes[2] = { &n->base_pass, &n->detail_pass };
    const struct gpu_image *images[2] = { &n->base, &n->detail };
    int rc = 0;
    for (int v = 0; v < 2 && rc == 0; v++) {
        uint32_t depth = images[v]->depth;
        for (uint32_t z = 0; z < depth && rc == 0; z += SLAB) {
            struct sky_cloud_noise_push push = { .seed = seed, .z_offset = z };
            uint32_t slab = depth - z < SLAB ? depth - z : SLAB;
            const uint32_t size[3] = { images[v]->width, images[v]->height, slab };
            const uint32_t local[3] = { SKY_CLOUD_NOISE_VOLUME_LOCAL, SKY_CLOUD_NOISE_VOLUME_LOCAL,
                                        SKY_CLOUD_NOISE_VOLUME_LOCAL };
            rc = run_pass(ctx, passes[v], &push, size, local);
            if (!quiet && v == 0)
                progress_show(ctx, (z + slab) * 100 / depth);
        }
    }
    if (!quiet)
        progress_end(ctx, rc == 0);
    return rc;
}

static int generate_curl(struct vk_context *ctx, struct cloud_noise *n, uint32_t seed)
{
    if (cloud_blue_noise(seed, n->blue.mapped) != 0)
        return -1;
    struct sky_cloud_noise_push push = { .seed = seed };
    const uint32_t size[3] = { CURL_SIZE, CURL_SIZE, 1 };
    const uint32_t local[3] = { SKY_CLOUD_LOCAL, SKY_CLOUD_LOCAL, 1 };
    return run_pass(ctx, &n->curl_pass, &push, size, local);
}

/* After a read from the cache: one workgroup of each pass, rewriting texels with the values
 * they hold (the blue noise made as generation makes it), so that lavapipe compiles the
 * passes' variants now, at start-up, and not at the first new seed a client sets: a compile
 * then would stall its frames and keep its code for the daemon's life. */
static int dispatch_one_group_each(struct vk_context *ctx, struct cloud_noise *n, uint32_t seed)
{
    if (cloud_blue_noise(seed, n->blue.mapped) != 0)
        return -1;
    VkCommandBuffer cmd;
    if (vk_context_begin_commands(ctx, &cmd) != VK_SUCCESS)
        return -1;
    const struct sky_cloud_noise_push push = { .seed = seed, .z_offset = 0 };
    const uint32_t volume[3] = { SKY_CLOUD_NOISE_VOLUME_LOCAL, SKY_CLOUD_NOISE_VOLUME_LOCAL,
                                 SKY_CLOUD_NOISE_VOLUME_LOCAL };
    const uint32_t plane[3] = { SKY_CLOUD_LOCAL, SKY_CLOUD_LOCAL, 1 };
    compute_pass_record(cmd, &n->base_pass, &push, volume, volume);
    compute_pass_record(cmd, &n->detail_pass, &push, volume, volume);
    compute_pass_record(cmd, &n->curl_pass, &push, plane, plane);
    gpu_barrier_compute_to_compute(cmd);
    return vk_context_submit_and_wait(ctx, &cmd) == VK_SUCCESS ? 0 : -1;
}

int cloud_noise_create(struct vk_context *ctx, struct cloud_noise *n, const char *cache_dir)
{
    memset(n, 0, sizeof *n);
    if (cache_dir && cache_dir[0] && !(n->cache_dir = strdup(cache_dir)))
        return -1;
    VK_CHECK_GOTO(gpu_image_create(ctx, VK_FORMAT_R8G8B8A8_UNORM, BASE_SIZE, BASE_SIZE, BASE_SIZE,
                                   "cloud_base_noise", &n->base),
                  destroy_partial);
    VK_CHECK_GOTO(gpu_image_create(ctx, VK_FORMAT_R8G8B8A8_UNORM, DETAIL_SIZE, DETAIL_SIZE,
                                   DETAIL_SIZE, "cloud_detail_noise", &n->detail),
                  destroy_partial);
    VK_CHECK_GOTO(gpu_image_create(ctx, VK_FORMAT_R32G32B32A32_SFLOAT, CURL_SIZE, CURL_SIZE, 1,
                                   "cloud_curl_noise", &n->curl),
                  destroy_partial);
    VK_CHECK_GOTO(gpu_buffer_create(ctx, VC_N * sizeof(float), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT,
                                    "cloud_blue_noise", &n->blue),
                  destroy_partial);
    if (create_passes(ctx, n) != VK_SUCCESS)
        goto destroy_partial;
    return 0;
destroy_partial:
    cloud_noise_destroy(ctx, n);
    return -1;
}

void cloud_noise_destroy(struct vk_context *ctx, struct cloud_noise *n)
{
    compute_pass_destroy(ctx, &n->base_pass);
    compute_pass_destroy(ctx, &n->detail_pass);
    compute_pass_destroy(ctx, &n->curl_pass);
    gpu_buffer_destroy(ctx, &n->blue);
    gpu_image_destroy(ctx, &n->base);
    gpu_image_destroy(ctx, &n->detail);
    gpu_image_destroy(ctx, &n->curl);
    free(n->cache_dir);
    n->cache_dir = NULL;
    n->generated = false;
}

int cloud_noise_generate(struct vk_context *ctx, struct cloud_noise *n, uint32_t seed, bool quiet)
{
    n->generated = false;
    if (cloud_noise_cache_load(ctx, n, n->cache_dir, seed) == 0) {
        if (dispatch_one_group_each(ctx, n, seed) != 0) {
            vk_log(ctx, VK_LOG_ERROR, "render: cloud noise passes failed");
            return -1;
        }
        if (!quiet)
            vk_log(ctx, VK_LOG_INFO, "cloud noise read from the cache in %s", n->cache_dir);
    } else if (generate_volumes(ctx, n, seed, quiet) != 0 || generate_curl(ctx, n, seed) != 0) {
        vk_log(ctx, VK_LOG_ERROR, "render: cloud noise generation failed");
        return -1;
    } else {
        cloud_noise_cache_store(ctx, n, n->cache_dir, seed);
    }
    n->seed = seed;
    n->generated = true;
    return 0;
}
