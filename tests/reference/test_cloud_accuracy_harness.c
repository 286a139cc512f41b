/* test_cloud_accuracy's device harness: the renderer's cloud march through a homogeneous deck
 * (tests/shaders/cloud_slab_selftest.comp), per case and per bin of the view cosine
 * (test_cloud_accuracy.h). */
#include "test_cloud_accuracy.h"

#include "cloud_layouts.h"
#include "cloud_params.h"
#include "cloud_shared.h"
#include "cloud_slab_selftest.spv.h"
#include "world_render.h"

/* std430 layouts of cloud_slab_selftest.comp. */
struct slab_case_gpu {
    float low[4], sun[4], phase[4], octaves[4];
};
struct slab_ray_gpu {
    float origin[4], direction[4];
};

/* ------------------------------------------------------------------ device harness */

void slab_harness_destroy(struct harness *h)
{
    if (!h->ctx)
        return;
    CHECK(vk_context_wait_idle(h->ctx) == VK_SUCCESS);
    compute_pass_destroy(h->ctx, &h->pass); /* safe on a zeroed or partly made pass */
    gpu_buffer_destroy(h->ctx, &h->atmo);
    gpu_buffer_destroy(h->ctx, &h->frame);
    gpu_buffer_destroy(h->ctx, &h->cloud);
    gpu_buffer_destroy(h->ctx, &h->cases);
    gpu_buffer_destroy(h->ctx, &h->rays);
    gpu_buffer_destroy(h->ctx, &h->results);
    gpu_image_destroy(h->ctx, &h->transmittance);
    gpu_image_destroy(h->ctx, &h->multiscattering);
    gpu_image_destroy(h->ctx, &h->irradiance);
    gpu_image_destroy(h->ctx, &h->base);
    gpu_image_destroy(h->ctx, &h->detail);
    gpu_image_destroy(h->ctx, &h->curl);
    gpu_image_destroy(h->ctx, &h->weather);
    gpu_image_destroy(h->ctx, &h->sun_depth);
    gpu_image_destroy(h->ctx, &h->skyview);
    if (h->sampler)
        vkDestroySampler(h->ctx->device, h->sampler, NULL);
    h->sampler = VK_NULL_HANDLE;
}

/* The pass, its buffers, and images that start at zero (gpu_image_create clears them): a
 * transmittance LUT of optical depth 0 (transmittance 1), empty irradiance (no sky light, and
 * ambient_scale 0 besides), multiple-scattering and sky-view LUTs, unused noise and weather. */
bool slab_harness_create(struct vk_context *ctx, const struct options *o, struct harness *h)
{
    memset(h, 0, sizeof *h);
    h->ctx = ctx;
    struct compute_pass_desc desc = {
        .name = "cloud_slab_selftest",
        .spirv = cloud_slab_selftest_spv,
        .spirv_bytes = sizeof cloud_slab_selftest_spv,
        SKY_PASS_LAYOUT(SKY_LAYOUT_CLOUD_SLAB),
        .spec_count = SKY_CLOUD_CONST_MOONLIT + 1,
        .spec_values = { [SKY_CLOUD_CONST_MOONLIT] = 0 }, /* no moon */
    };
    const VkFormat f = VK_FORMAT_R32G32B32A32_SFLOAT;
    h->ray_count = NCASE * rays_per_case(o);
    bool ok = compute_pass_create(ctx, &desc, &h->pass) == VK_SUCCESS;
    ok = ok &&
         gpu_buffer_create(ctx, sizeof(struct sky_atmosphere_uniforms),
                           VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, "slab_atmo", &h->atmo) == VK_SUCCESS;
    ok = ok && gpu_buffer_create(ctx, sizeof(struct sky_frame_uniforms),
                                 VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, "slab_frame",
                                 &h->frame) == VK_SUCCESS;
    ok = ok && gpu_buffer_create(ctx, sizeof(struct sky_cloud_uniforms),
                                 VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, "slab_cloud",
                                 &h->cloud) == VK_SUCCESS;
    ok = ok && gpu_buffer_create(ctx, NCASE * sizeof(struct slab_case_gpu),
                                 VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, "slab_cases",
                                 &h->cases) == VK_SUCCESS;
    ok = ok &&
         gpu_buffer_create(ctx, 16 + (VkDeviceSize)h->ray_count * sizeof(struct slab_ray_gpu),
                           VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, "slab_rays", &h->rays) == VK_SUCCESS;
    ok = ok && gpu_buffer_create(ctx, (VkDeviceSize)h->ray_count * sizeof(float),
                                 VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, "slab_results",
                                 &h->results) == VK_SUCCESS;
    ok = ok &&
         gpu_image_create(ctx, f, 8, 8, 1, "slab_transmittance", &h->transmittance) == VK_SUCCESS;
    ok = ok && gpu_image_create(ctx, f, 8, 8, 1, "slab_multiscattering", &h->multiscattering) ==
                   VK_SUCCESS;
    ok = ok && gpu_image_create(ctx, f, 8, 2, 1, "slab_irradiance", &h->irradiance) == VK_SUCCESS;
    ok = ok && gpu_image_create(ctx, f, 4, 4, 4, "slab_base", &h->base) == VK_SUCCESS;
    ok = ok && gpu_image_create(ctx, f, 4, 4, 4, "slab_detail", &h->detail) == VK_SUCCESS;
    ok = ok && gpu_image_create(ctx, f, 4, 4, 1, "slab_curl", &h->curl) == VK_SUCCESS;
    ok = ok && gpu_image_create(ctx, f, 4, 4, 1, "slab_weather", &h->weather) == VK_SUCCESS;
    ok = ok && gpu_image_create(ctx, f, 8, 8, 1, "slab_skyview", &h->skyview) == VK_SUCCESS;
    ok = ok && gpu_image_create(ctx, f, 4, 4, 4, "slab_sun_depth", &h->sun_depth) == VK_SUCCESS;
    ok = ok && gpu_linear_sampler_create(ctx, VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE, &h->sampler) ==
                   VK_SUCCESS;
    CHECK(ok);
    if (!ok)
        return false;
    VkSampler smp = h->sampler;
    struct compute_resource res[SKY_LAYOUT_COUNT(SKY_LAYOUT_CLOUD_SLAB)] = {
        [SKY_CLOUD_MARCH_ATMOSPHERE] = { .buffer = &h->atmo },
        [SKY_CLOUD_MARCH_FRAME] = { .buffer = &h->frame },
        [SKY_CLOUD_MARCH_TRANSMITTANCE] = { .image = &h->transmittance, .sampler = smp },
        [SKY_CLOUD_MARCH_MULTISCATTERING] = { .image = &h->multiscattering, .sampler = smp },
        [SKY_CLOUD_MARCH_IRRADIANCE] = { .image = &h->irradiance, .sampler = smp },
        [SKY_CLOUD_MARCH_CLOUD] = { .buffer = &h->cloud },
        [SKY_CLOUD_MARCH_BASE_NOISE] = { .image = &h->base, .sampler = smp },
        [SKY_CLOUD_MARCH_DETAIL_NOISE] = { .image = &h->detail, .sampler = smp },
        [SKY_CLOUD_MARCH_CURL_NOISE] = { .image = &h->curl, .sampler = smp },
        [SKY_CLOUD_MARCH_WEATHER] = { .image = &h->weather, .sampler = smp },
        [SKY_CLOUD_MARCH_SKYVIEW] = { .image = &h->skyview, .sampler = smp },
        [SKY_CLOUD_MARCH_SUN_DEPTH] = { .image = &h->sun_depth, .sampler = smp },
        /* Unread: slab_sun_depth.glsl gives the deck's columns. */
        [SKY_CLOUD_MARCH_SUN_COLUMNS] = { .image = &h->weather, .sampler = smp },
        [SKY_CLOUD_SLAB_CASES] = { .buffer = &h->cases },
        [SKY_CLOUD_SLAB_RAYS] = { .buffer = &h->rays },
        [SKY_CLOUD_SLAB_RESULTS] = { .buffer = &h->results },
    };
    compute_pass_bind(ctx, &h->pass, res);

    /* An atmosphere of nothing (radii only), a black ground. */
    struct sky_atmosphere_uniforms *a = h->atmo.mapped;
    memset(a, 0, sizeof *a);
    a->radii = (sky_vec4){ (float)o->radius_km, (float)(o->radius_km + 100.0), 8.0f, 1.2f };
    /* The sun: unit illuminance outside the atmosphere; no moon, no airglow. */
    struct sky_frame_uniforms *fr = h->frame.mapped;
    memset(fr, 0, sizeof *fr);
    fr->sun_illuminance = (sky_vec4){ 1.0f, 1.0f, 1.0f, 0.0f };
    fr->sun_direction = (sky_vec4){ 0.0f, 0.0f, 1.0f, 0.99999f };
    return true;
}

/* The deck of a case: bottom radius, thickness and extinction giving optical depth tau. */
static void deck(const struct proto_world_state *state, const struct options *o, double tau,
                 double *bottom, double *thickness, double *extinction)
{
    const struct proto_cloud_state *c = &state->clouds;
    *bottom = o->radius_km + c->low.bottom_km;
    double sigma = c->extinction_per_km * c->low.density;
    *thickness = o->thickness_km > 0.0 ? o->thickness_km : tau / sigma;
    *extinction = tau / *thickness;
}

/* Marches every ray of every case for one phase and octave set; answers per case. */
bool slab_harness_run(struct harness *h, const struct proto_world_state *state,
                      const struct options *o, const struct phase_set *ph,
                      const struct octave_set *os, struct slab_answer out[NCASE])
{
    /* The cloud block as the renderer fills it (cloud_params_fill: a <= b, albedo, steps). */
    struct sky_render_clouds rc;
    world_to_render_clouds(state, &rc);
    rc.low.coverage = 1.0;
    rc.high.coverage = 0.0;
    rc.albedo = o->albedo;
    rc.precipitation = 0.0;
    rc.ambient_scale = 0.0;
    rc.phase_g0 = ph->g0;
    rc.phase_g1 = ph->g1;
    rc.phase_w = ph->w;
    rc.multiscatter_a = os->a;
    rc.multiscatter_b = os->b;
    rc.multiscatter_c = os->c;
    rc.multiscatter_octaves = os->octaves;
    rc.multiscatter_powder = os->powder;
    rc.primary_steps = o->primary_steps;
    rc.light_steps = o->light_steps;
    rc.use_client_map = false;
    struct sky_cloud_uniforms *u = h->cloud.mapped;
    cloud_params_fill(&rc, o->radius_km, u);
    u->shadow_sun = (sky_vec4){ 0, 0, 1, 0 };

    const int G = o->nodes, P = o->azimuths, J = o->jitters;
    double mu_node[NBIN][MAX_NODES], mu_weight[NBIN][MAX_NODES];
    for (int b = 0; b < NBIN; b++) {
        double lo, hi;
        cloud_mc_bin_edges(b, &lo, &hi);
        cloud_gauss_legendre(G, lo, hi, mu_node[b], mu_weight[b]);
    }
    struct slab_case_gpu *cases = h->cases.mapped;
    uint32_t *header = h->rays.mapped;
    header[0] = h->ray_count;
    header[1] = header[2] = header[3] = 0;
    struct slab_ray_gpu *rays = (struct slab_ray_gpu *)((char *)h->rays.mapped + 16);
    uint32_t i = 0;
    for (int ci = 0; ci < NCASE; ci++) {
        double tau = slab_taus[ci / NMU0], mu0 = slab_mu0s[ci % NMU0];
        double bottom, thickness, sigma;
        deck(state, o, tau, &bottom, &thickness, &sigma);
        double top = bottom + thickness;
        double sun_sin = sqrt(fmax(0.0, 1.0 - mu0 * mu0));
        cases[ci] = (struct slab_case_gpu){
            .low = { (float)bottom, (float)top, (float)sigma, 1.0f },
            .sun = { (float)sun_sin, 0.0f, (float)mu0, u->march.x },
            .phase = { u->phase.x, u->phase.y, u->phase.z, u->phase.w },
            .octaves = { u->octaves.x, u->octaves.y, u->octaves.z, u->octaves.w },
        };
        /* 1 m above the top (looking down), 1 m below the bottom (looking up). */
        const double eps = 1e-3;
        for (int side = 0; side < 2; side++) {
            double z0 = side == 0 ? top + eps : bottom - eps, sz = side == 0 ? -1.0 : 1.0;
            for (int b = 0; b < NBIN; b++)
                for (int g = 0; g < G; g++) {
                    double mu = mu_node[b][g], s = sqrt(fmax(0.0, 1.0 - mu * mu));
                    for (int k = 0; k < P; k++) {
                        /* Midpoints over [0, pi]: the radiance is symmetric about the sun's
                         * vertical plane. */
                        double phi = PI * (k + 0.5) / P;
                        for (int j = 0; j < J; j++, i++) {
                            rays[i] = (struct slab_ray_gpu){
                                .origin = { 0.0f, 0.0f, (float)z0, (float)ci },
                                .direction = { (float)(s * cos(phi)), (float)(s * sin(phi)),
                                               (float)(sz * mu), (float)((j + 0.5) / J) },
                            };
                        }
                    }
                }
        }
    }
    if (i != h->ray_count) {
        CHECK(i == h->ray_count);
        return false;
    }
    VkCommandBuffer cmd;
    VkResult r = vk_context_begin_commands(h->ctx, &cmd);
    CHECK(r == VK_SUCCESS);
    if (r != VK_SUCCESS)
        return false;
    const uint32_t size[3] = { h->ray_count, 1, 1 }, local[3] = { SKY_CLOUD_SLAB_LOCAL, 1, 1 };
    compute_pass_record(cmd, &h->pass, NULL, size, local);
    gpu_barrier_to_host(cmd);
    r = vk_context_submit_and_wait(h->ctx, &cmd);
    CHECK(r == VK_SUCCESS);
    if (r != VK_SUCCESS)
        return false;

    /* R = (2 pi / mu0) int L mu dmu; a bin's factor = (pi / mu0) int_bin L mu dmu / int_bin mu
     * dmu (the tracer's rho = pi L / (E mu0), mu-weighted bin mean). */
    const float *L = h->results.mapped;
    bool finite = true;
    i = 0;
    for (int ci = 0; ci < NCASE; ci++) {
        double mu0 = slab_mu0s[ci % NMU0];
        struct slab_answer *a = &out[ci];
        memset(a, 0, sizeof *a);
        for (int side = 0; side < 2; side++)
            for (int b = 0; b < NBIN; b++) {
                double lo, hi, sum = 0.0;
                cloud_mc_bin_edges(b, &lo, &hi);
                for (int g = 0; g < G; g++) {
                    double mean = 0.0;
                    for (int k = 0; k < P * J; k++, i++) {
                        finite &= isfinite(L[i]) != 0;
                        mean += L[i];
                    }
                    mean /= P * J;
                    sum += mu_weight[b][g] * mu_node[b][g] * mean;
                }
                double factor = PI / mu0 * sum / (0.5 * (hi * hi - lo * lo));
                if (side == 0) {
                    a->reflect[b] = factor;
                    a->R += factor * (hi * hi - lo * lo);
                } else {
                    a->transmit[b] = factor;
                    a->T += factor * (hi * hi - lo * lo);
                }
            }
    }
    CHECK(finite);
    return finite;
}
