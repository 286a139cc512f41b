/* The clouds' path tracer (shaders/include/cloud_pathtrace.glsl) through homogeneous
 * plane-parallel decks against the Monte Carlo photon tracer of reference/cloud_mc_reference.c,
 * on the device (tests/shaders/cloud_pathtrace_selftest.comp): the reflected and diffusely
 * transmitted radiance factors per bin of the view cosine, their totals R and T, the ratio
 * tracking's transmittance against exp(-tau / mu0), energy conservation at albedo 1
 * (R + T_diffuse + T_direct = 1), and no density sample above the majorant. Both are unbiased
 * estimators of the same transport, so they agree within their noise. */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "check.h"
#include "cloud_layouts.h"
#include "cloud_mc_reference.h"
#include "cloud_pathtrace_selftest.spv.h"
#include "cloud_shared.h"
#include "compute_pass.h"
#include "test_support.h"
#include "vk_context.h"
#include "vk_resources.h"

#define PI 3.14159265358979323846
#define NBIN CLOUD_MC_BINS
#define KINDS 3 /* reflected, transmitted, transmittance */
#define SAMPLES 8192
#define RADIUS_KM 6360.0
#define THICKNESS_KM 0.2
#define MC_PHOTONS 200000

struct pt_case_gpu {
    float low[4], sun[4], phase[4], media[4];
};

struct slab {
    double tau, mu0, albedo, g0, g1, w;
};

static const struct slab slabs[] = {
    { 2.0, 1.0, 1.0, 0.8, -0.3, 0.25 }, /* the renderer's phase, no absorption */
    { 8.0, 0.5, 0.99, 0.8, -0.3, 0.25 },
    { 1.0, 0.7, 0.9, 0.0, 0.0, 0.0 }, /* isotropic */
};
#define NCASE ((int)(sizeof slabs / sizeof slabs[0]))

struct device {
    struct vk_context *ctx;
    struct compute_pass pass;
    struct gpu_buffer atmo, frame, cloud, cases, counts, results, stats;
    struct gpu_image empty2d, empty3d;
    VkSampler sampler;
};

static void device_destroy(struct device *d)
{
    compute_pass_destroy(d->ctx, &d->pass);
    struct gpu_buffer *b[] = { &d->atmo,   &d->frame,   &d->cloud, &d->cases,
                               &d->counts, &d->results, &d->stats };
    for (size_t i = 0; i < sizeof b / sizeof b[0]; i++)
        gpu_buffer_destroy(d->ctx, b[i]);
    gpu_image_destroy(d->ctx, &d->empty2d);
    gpu_image_destroy(d->ctx, &d->empty3d);
    if (d->sampler)
        vkDestroySampler(d->ctx->device, d->sampler, NULL);
}

static bool buffer(struct device *d, VkDeviceSize bytes, const char *name, struct gpu_buffer *b)
{
    return gpu_buffer_create(d->ctx, bytes, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, name, b) ==
           VK_SUCCESS;
}

/* Runs every sample; results[] then holds one value per sample (case, kind, bin, sample). */
static bool device_run(struct device *d)
{
    const struct compute_pass_desc desc = {
        .name = "cloud_pathtrace_selftest",
        .spirv = cloud_pathtrace_selftest_spv,
        .spirv_bytes = sizeof cloud_pathtrace_selftest_spv,
        SKY_PASS_LAYOUT(SKY_LAYOUT_CLOUD_PT_SLAB),
        .spec_count = SKY_CLOUD_CONST_MOONLIT + 1,
        .spec_values = { [SKY_CLOUD_CONST_MOONLIT] = 0 },
    };
    const uint32_t count = NCASE * KINDS * NBIN * SAMPLES;
    const VkFormat f = VK_FORMAT_R32G32B32A32_SFLOAT;
    /* Zeroed images: transmittance LUT of optical depth 0, no sky, no noise. */
    bool ok = compute_pass_create(d->ctx, &desc, &d->pass) == VK_SUCCESS &&
              buffer(d, sizeof(struct sky_atmosphere_uniforms), "pt_atmo", &d->atmo) &&
              buffer(d, sizeof(struct sky_frame_uniforms), "pt_frame", &d->frame) &&
              buffer(d, sizeof(struct sky_cloud_uniforms), "pt_cloud", &d->cloud) &&
              buffer(d, NCASE * sizeof(struct pt_case_gpu), "pt_cases", &d->cases) &&
              buffer(d, 16, "pt_counts", &d->counts) &&
              buffer(d, count * sizeof(float), "pt_results", &d->results) &&
              buffer(d, sizeof(struct sky_cloud_reference_stats), "pt_stats", &d->stats) &&
              gpu_image_create(d->ctx, f, 8, 8, 1, "pt_empty2d", &d->empty2d) == VK_SUCCESS &&
              gpu_image_create(d->ctx, f, 4, 4, 4, "pt_empty3d", &d->empty3d) == VK_SUCCESS &&
              gpu_linear_sampler_create(d->ctx, VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE,
                                        &d->sampler) == VK_SUCCESS;
    CHECK(ok);
    if (!ok)
        return false;
    struct compute_resource t2 = { .image = &d->empty2d, .sampler = d->sampler };
    struct compute_resource t3 = { .image = &d->empty3d, .sampler = d->sampler };
    struct compute_resource res[SKY_LAYOUT_COUNT(SKY_LAYOUT_CLOUD_PT_SLAB)] = {
        [SKY_CLOUD_MARCH_ATMOSPHERE] = { .buffer = &d->atmo },
        [SKY_CLOUD_MARCH_FRAME] = { .buffer = &d->frame },
        [SKY_CLOUD_MARCH_TRANSMITTANCE] = t2,
        [SKY_CLOUD_MARCH_MULTISCATTERING] = t2,
        [SKY_CLOUD_MARCH_IRRADIANCE] = t2,
        [SKY_CLOUD_MARCH_CLOUD] = { .buffer = &d->cloud },
        [SKY_CLOUD_MARCH_BASE_NOISE] = t3,
        [SKY_CLOUD_MARCH_DETAIL_NOISE] = t3,
        [SKY_CLOUD_MARCH_CURL_NOISE] = t2,
        [SKY_CLOUD_MARCH_WEATHER] = t2,
        [SKY_CLOUD_MARCH_SKYVIEW] = t2,
        [SKY_CLOUD_MARCH_SUN_DEPTH] = t3,
        [SKY_CLOUD_MARCH_SUN_COLUMNS] = t2, /* unread: slab_sun_depth.glsl */
        [SKY_CLOUD_SLAB_CASES] = { .buffer = &d->cases },
        [SKY_CLOUD_SLAB_RAYS] = { .buffer = &d->counts },
        [SKY_CLOUD_SLAB_RESULTS] = { .buffer = &d->results },
        [SKY_CLOUD_PT_SLAB_STATS] = { .buffer = &d->stats },
    };
    compute_pass_bind(d->ctx, &d->pass, res);

    /* An atmosphere of nothing (radii only), a black ground; a sun of unit illuminance. */
    struct sky_atmosphere_uniforms *a = d->atmo.mapped;
    memset(a, 0, sizeof *a);
    a->radii = (sky_vec4){ (float)RADIUS_KM, (float)(RADIUS_KM + 100.0), 8.0f, 1.2f };
    struct sky_frame_uniforms *fr = d->frame.mapped;
    memset(fr, 0, sizeof *fr);
    fr->sun_illuminance = (sky_vec4){ 1.0f, 1.0f, 1.0f, 0.0f };
    struct sky_cloud_uniforms *cu = d->cloud.mapped;
    memset(cu, 0, sizeof *cu);
    memset(d->stats.mapped, 0, sizeof(struct sky_cloud_reference_stats));
    struct pt_case_gpu *cases = d->cases.mapped;
    for (int c = 0; c < NCASE; c++) {
        const struct slab *s = &slabs[c];
        double bottom = RADIUS_KM + 1.0;
        cases[c] = (struct pt_case_gpu){
            .low = { (float)bottom, (float)(bottom + THICKNESS_KM), (float)(s->tau / THICKNESS_KM),
                     1.0f },
            .sun = { (float)sqrt(1.0 - s->mu0 * s->mu0), 0.0f, (float)s->mu0, 0.0f },
            .phase = { (float)s->g0, (float)s->g1, (float)s->w, 0.0f },
            .media = { (float)s->albedo, 0.0f, 0.0f, 0.0f },
        };
    }
    uint32_t *counts = d->counts.mapped;
    counts[0] = NCASE, counts[1] = KINDS, counts[2] = NBIN, counts[3] = SAMPLES;
    VkCommandBuffer cmd;
    if (vk_context_begin_commands(d->ctx, &cmd) != VK_SUCCESS)
        return false;
    const uint32_t size[3] = { count, 1, 1 }, local[3] = { SKY_CLOUD_SLAB_LOCAL, 1, 1 };
    compute_pass_record(cmd, &d->pass, NULL, size, local);
    gpu_barrier_to_host(cmd);
    VkResult r = vk_context_submit_and_wait(d->ctx, &cmd);
    CHECK(r == VK_SUCCESS);
    return r == VK_SUCCESS;
}

/* Mean and standard error of n samples. */
static void mean_se(const float *x, int n, double *mean, double *se)
{
    double s = 0.0, s2 = 0.0;
    for (int i = 0; i < n; i++) {
        s += x[i];
        s2 += (double)x[i] * x[i];
    }
    *mean = s / n;
    *se = sqrt(fmax(s2 / n - *mean * *mean, 0.0) / (n - 1));
}

static void compare_case(int c, const float *results)
{
    const struct slab *s = &slabs[c];
    struct cloud_mc_slab in = { .tau = s->tau,
                                .omega = s->albedo,
                                .mu0 = s->mu0,
                                .g0 = s->g0,
                                .g1 = s->g1,
                                .w = s->w,
                                .photons = MC_PHOTONS,
                                .seed = 7 + c,
                                .threads = 2 };
    struct cloud_mc_result mc;
    CHECK(cloud_mc_slab_run(&in, &mc) == 0);
    printf("deck tau %g, mu0 %g, albedo %g, phase (%g, %g, %g):\n", s->tau, s->mu0, s->albedo,
           s->g0, s->g1, s->w);
    double total[2] = { 0.0, 0.0 }, total_var[2] = { 0.0, 0.0 };
    for (int kind = 0; kind < 2; kind++) {
        const double *ref = kind == 0 ? mc.reflect_factor : mc.transmit_factor;
        const double *ref_se = kind == 0 ? mc.reflect_factor_stderr : mc.transmit_factor_stderr;
        printf("  %s factor per mu bin (path tracer / Monte Carlo):", kind ? "T" : "R");
        for (int b = 0; b < NBIN; b++) {
            const float *x = results + (((size_t)c * KINDS + kind) * NBIN + b) * SAMPLES;
            double m, se, lo, hi;
            mean_se(x, SAMPLES, &m, &se);
            double f = PI * m / s->mu0, f_se = PI * se / s->mu0;
            cloud_mc_bin_edges(b, &lo, &hi);
            total[kind] += f * (hi * hi - lo * lo);
            total_var[kind] += pow(f_se * (hi * hi - lo * lo), 2.0);
            printf(" %.3f/%.3f", f, ref[b]);
            double allowed = 0.03 * ref[b] + 4.0 * hypot(f_se, ref_se[b]) + 1e-3;
            CHECK_MSG(fabs(f - ref[b]) <= allowed, "tau %g mu0 %g %s bin %d: %.4f vs %.4f (+-%.4f)",
                      s->tau, s->mu0, kind ? "T" : "R", b, f, ref[b], allowed);
        }
        printf("\n");
    }
    double R_se = sqrt(total_var[0]), T_se = sqrt(total_var[1]);
    printf("  R %.4f +- %.4f (MC %.4f +- %.4f), T_diffuse %.4f +- %.4f (MC %.4f +- %.4f)\n",
           total[0], R_se, mc.R, mc.R_stderr, total[1], T_se, mc.T_diffuse, mc.T_stderr);
    CHECK_MSG(fabs(total[0] - mc.R) <= 0.01 * mc.R + 4.0 * hypot(R_se, mc.R_stderr),
              "tau %g: R %.4f vs %.4f", s->tau, total[0], mc.R);
    CHECK_MSG(fabs(total[1] - mc.T_diffuse) <= 0.01 * mc.T_diffuse + 4.0 * hypot(T_se, mc.T_stderr),
              "tau %g: T %.4f vs %.4f", s->tau, total[1], mc.T_diffuse);
    /* Ratio tracking's transmittance along the sun's ray: exp(-tau / mu0). */
    const float *tr = results + ((size_t)c * KINDS + 2) * NBIN * SAMPLES;
    double t, t_se;
    mean_se(tr, NBIN * SAMPLES, &t, &t_se);
    double exact = exp(-s->tau / s->mu0);
    printf("  transmittance %.5f +- %.5f, exp(-tau/mu0) %.5f\n", t, t_se, exact);
    CHECK_MSG(fabs(t - exact) <= 4.0 * t_se + 2e-4, "tau %g: transmittance %.5f vs %.5f", s->tau, t,
              exact);
    if (s->albedo == 1.0) {
        double sum = total[0] + total[1] + exact;
        printf("  energy: R + T_diffuse + T_direct = %.4f +- %.4f\n", sum, hypot(R_se, T_se));
        CHECK_MSG(fabs(sum - 1.0) <= 4.0 * hypot(R_se, T_se) + 0.005, "energy %.4f", sum);
    }
}

int main(void)
{
    unsigned validation_messages = 0;
    struct vk_context_params params = { .validation = test_validation_requested(),
                                        .quiet = true,
                                        .validation_message_counter = &validation_messages };
    struct device d = { .ctx = vk_context_create(&params) };
    CHECK(d.ctx != NULL);
    if (!d.ctx)
        return check_summary();
    if (device_run(&d)) {
        const struct sky_cloud_reference_stats *st = d.stats.mapped;
        printf("density samples above the majorant %u, segments cut short %u, paths cut short by "
               "the device's loop limit %u\n",
               st->violations, st->overflows, st->truncated);
        /* No path cut short by lavapipe's loop limit: about 1 % were while a path that set off
         * downward from on the shell's base crossed under it, through the planet (before
         * cloud_shell.glsl's descending exit). */
        CHECK(st->violations == 0 && st->overflows == 0 && st->truncated == 0);
        for (int c = 0; c < NCASE; c++)
            compare_case(c, d.results.mapped);
    }
    CHECK(vk_context_wait_idle(d.ctx) == VK_SUCCESS);
    device_destroy(&d);
    vk_context_destroy(&d.ctx);
    CHECK(validation_messages == 0);
    return check_summary();
}
