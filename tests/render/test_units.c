/* Unit tests: photometric conversions (C) and the renderer's GLSL functions run on the
 * device (LUT parameterization round trips, phase functions integrating to 1). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "cloud_history.h"
#include "compute_pass.h"
#include "ground_transfer.h"
#include "lut_selftest.spv.h"
#include "sky_photometry.h"
#include "sky_uniforms.h"
#include "test_support.h"
#include "view_outputs.h"
#include "vk_context.h"
#include "vk_resources.h"

/* A 100 km atmosphere with Earth's scale heights and no medium: each test adds its species. */
static struct sky_render_atmosphere empty_atmosphere(double bottom_radius_km)
{
    struct sky_render_atmosphere a;
    memset(&a, 0, sizeof a);
    a.bottom_radius_km = bottom_radius_km;
    a.top_radius_km = bottom_radius_km + 100.0;
    a.rayleigh_scale_height_km = 8;
    a.mie_scale_height_km = 1.2;
    a.fog_scale_height_km = 1;
    a.ozone_width_km = 30;
    return a;
}

static void test_photometry(void)
{
    /* Seed 001, 4.1: 0.545 deg -> 0.0000711 sr; 120000 lx -> 1.69e9 cd/m2. */
    CHECK_NEAR(sky_disk_solid_angle(0.545), 7.11e-5, 0.01e-5);
    CHECK_NEAR(sky_sun_disk_luminance(120000.0, 0.545) / 1.69e9, 1.0, 0.01);
    /* Moon, seed 001 4.2: 0.26 lx over 0.568 deg... quoted 3658 cd/m2 for 7.11e-5 sr. */
    CHECK_NEAR(0.26 / 7.11e-5, 3658.0, 5.0);
    CHECK_NEAR(sky_ev100_to_exposure(0.0), 1.0 / 1.2, 1e-12);
    CHECK_NEAR(sky_ev100_to_exposure(15.0) * pow(2.0, 15.0) * 1.2, 1.0, 1e-12);
    CHECK_NEAR(sky_luminance_to_ev100(12.5 / 100.0 * pow(2.0, 15.0)), 15.0, 1e-12);
    const double white[3] = { 1, 1, 1 };
    CHECK_NEAR(sky_rgb_to_luminance(white), 1.0, 1e-12);

    /* Zenith transmittance of a single exponential species: exp(-sigma H (1 - e^(-D/H))). */
    struct sky_render_atmosphere a = empty_atmosphere(6360);
    a.rayleigh_scattering[0] = 0.01;
    a.mie_scattering[1] = 0.02;
    a.mie_absorption[1] = 0.005;
    a.ozone_absorption[2] = 0.002;
    a.ozone_peak_km = 25;
    double t[3];
    sky_zenith_transmittance(&a, t);
    CHECK_NEAR(t[0], exp(-0.01 * 8 * (1 - exp(-100.0 / 8))), 1e-7);
    CHECK_NEAR(t[1], exp(-0.025 * 1.2 * (1 - exp(-100.0 / 1.2))), 1e-7);
    /* Tent of full width 30 km entirely inside: area 15 km. */
    CHECK_NEAR(t[2], exp(-0.002 * 15.0), 1e-7);
    double e[3];
    sky_sun_illuminance_top(&a, 1000.0, e);
    CHECK_NEAR(e[0] * t[0], 1000.0, 1e-6);
}

/* E_3(x), the third exponential integral, from E_1's series (x small): E_{n+1} = (e^-x - x E_n)/n. */
static double exponential_integral_3(double x)
{
    double e1 = -0.57721566490153286 - log(x), term = 1.0;
    for (int k = 1; k < 60; k++) {
        term *= -x / k;
        e1 -= term / k;
    }
    double e2 = exp(-x) - x * e1;
    return 0.5 * (exp(-x) - x * e2);
}

/* The ground transfer of a pure scatterer over a planet so large that the atmosphere is plane
 * parallel: F(mu) = 1 - exp(-tau / mu) along each ray, so A = 2 int_0^1 F mu dmu = 1 - 2 E_3(tau). */
static void test_ground_transfer(void)
{
    struct sky_render_atmosphere a = empty_atmosphere(1e7);
    a.rayleigh_scattering[0] = 0.002;
    a.rayleigh_scattering[1] = 0.0135;
    a.rayleigh_scattering[2] = 0.08;
    double transfer[3];
    sky_ground_transfer(&a, transfer);
    for (int c = 0; c < 3; c++) {
        double tau = a.rayleigh_scattering[c] * 8.0 * -expm1(-100.0 / 8.0);
        double expected = 1.0 - 2.0 * exponential_integral_3(tau);
        CHECK_NEAR(transfer[c] / expected, 1.0, 3e-4);
    }
}

static void test_shader_functions(struct vk_context *ctx)
{
    struct compute_pass pass;
    struct compute_pass_desc desc = {
        .name = "lut_selftest",
        .spirv = lut_selftest_spv,
        .spirv_bytes = sizeof lut_selftest_spv,
        .binding_count = 2,
        .bindings = { VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER },
    };
    struct gpu_buffer atmosphere = { 0 }, results = { 0 };
    CHECK(compute_pass_create(ctx, &desc, &pass) == VK_SUCCESS);
    CHECK(gpu_buffer_create(ctx, sizeof(struct sky_atmosphere_uniforms),
                            VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, "atmosphere",
                            &atmosphere) == VK_SUCCESS);
    CHECK(gpu_buffer_create(ctx, 8 * 4 * sizeof(float), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT,
                            "results", &results) == VK_SUCCESS);
    struct sky_render_atmosphere earth;
    test_earth_atmosphere(&earth);
    sky_uniforms_fill_atmosphere(&earth, atmosphere.mapped);
    struct compute_resource res[2] = { { .buffer = &atmosphere }, { .buffer = &results } };
    compute_pass_bind(ctx, &pass, res);
    VkCommandBuffer cmd;
    CHECK(vk_context_begin_commands(ctx, &cmd) == VK_SUCCESS);
    const uint32_t size[3] = { 6, 1, 1 }, local[3] = { 1, 1, 1 };
    compute_pass_record(cmd, &pass, NULL, size, local);
    gpu_barrier_to_host(cmd);
    CHECK(vk_context_submit_and_wait(ctx, &cmd) == VK_SUCCESS);

    const float *r = results.mapped;
    printf("transmittance round trip: unit %.3g, mu %.3g\n", r[0], r[1]);
    printf("sky-view round trip: %.3g; sub-uv round trip: %.3g\n", r[4], r[8]);
    CHECK_LE(r[0], 2e-3);
    CHECK_LE(r[1], 2e-3);
    CHECK_LE(r[4], 2e-3);
    CHECK_LE(r[8], 1e-6);
    for (int k = 3; k <= 5; k++) {
        const float *p = r + 4 * k;
        printf("phase integrals (g = %.1f): rayleigh %.6f, mie %.6f %.6f %.6f\n",
               k == 3   ? 0.8
               : k == 4 ? 0.5
                        : 0.3,
               p[0], p[1], p[2], p[3]);
        CHECK_NEAR(p[0], 1.0, 1e-3);
        CHECK_NEAR(p[1], 1.0, 1e-3);
        CHECK_NEAR(p[2], 1.0, 1e-3);
        CHECK_NEAR(p[3], 1.0, 1e-3);
    }
    gpu_buffer_destroy(ctx, &atmosphere);
    gpu_buffer_destroy(ctx, &results);
    compute_pass_destroy(ctx, &pass);
}

/* Cloud histories: least recently used among CLOUD_HISTORY_ENTRIES, and released after
 * CLOUD_HISTORY_IDLE_S without a view, so that views that have gone keep no images. */
static void test_cloud_history(struct vk_context *ctx)
{
    struct cloud_history h;
    memset(&h, 0, sizeof h);
    double t = 100.0;
    struct cloud_history_entry *a = cloud_history_acquire(ctx, &h, 1, 40, 20, 4, t);
    CHECK(a != NULL && a->width == 40 && a->color[0].width == 40);
    CHECK(cloud_history_acquire(ctx, &h, 1, 40, 20, 4, t + 1.0) == a); /* kept */
    for (uint64_t key = 2; key <= CLOUD_HISTORY_ENTRIES + 1; key++)
        CHECK(cloud_history_acquire(ctx, &h, key, 16, 8, 4, t + 1.0) != NULL);
    CHECK(cloud_history_entries_in_use(&h) == CLOUD_HISTORY_ENTRIES);
    /* Key 1 was the least recently used: a new acquisition gets a new entry for it. */
    bool key1_kept = false;
    for (int i = 0; i < CLOUD_HISTORY_ENTRIES; i++)
        key1_kept |= h.entries[i].use.in_use && h.entries[i].key == 1;
    CHECK(!key1_kept);
    /* Only the last key goes on being rendered: the others go once idle for long enough. */
    uint64_t last = CLOUD_HISTORY_ENTRIES + 1;
    CHECK(cloud_history_acquire(ctx, &h, last, 16, 8, 4, t + CLOUD_HISTORY_IDLE_S) != NULL);
    CHECK(cloud_history_entries_in_use(&h) == CLOUD_HISTORY_ENTRIES);
    struct cloud_history_entry *kept = cloud_history_acquire(ctx, &h, last, 16, 8, 4,
                                                             t + 1.5 + CLOUD_HISTORY_IDLE_S);
    CHECK(kept != NULL);
    CHECK(cloud_history_entries_in_use(&h) == 1);
    /* A slot filled again (here the idle entry's images released and a new key's made) has
     * a new `filled`: the composite knows the images by the entry's address, which a new
     * entry may share with the one before it. */
    uint64_t kept_filled = kept->use.filled;
    struct cloud_history_entry *again = cloud_history_acquire(ctx, &h, last + 1, 16, 8, 4,
                                                              t + 3.0 + 2 * CLOUD_HISTORY_IDLE_S);
    CHECK(again != NULL && again->key == last + 1 && again->use.filled != kept_filled);
    CHECK(cloud_history_acquire(ctx, &h, last + 1, 16, 8, 4, t + 3.5 + 2 * CLOUD_HISTORY_IDLE_S)
              ->use.filled == again->use.filled); /* found again: the same occupant */
    /* A new size for the same key is a new history. */
    CHECK(cloud_history_acquire(ctx, &h, last + 1, 32, 8, 4, t + 4.0 + 2 * CLOUD_HISTORY_IDLE_S) !=
          NULL);
    CHECK(cloud_history_entries_in_use(&h) == 2);
    cloud_history_destroy(ctx, &h);
    CHECK(cloud_history_entries_in_use(&h) == 0);
}

/* View outputs: one pair per size and format in use, so that views of different sizes
 * rendered in turn keep theirs; least recently used among VIEW_OUTPUTS_MAX, released after
 * VIEW_OUTPUT_IDLE_S unused. */
static void test_view_outputs(struct vk_context *ctx)
{
    struct view_outputs o;
    memset(&o, 0, sizeof o);
    const VkFormat rgba8 = VK_FORMAT_R8G8B8A8_UNORM, linear = VK_FORMAT_R32G32B32A32_SFLOAT;
    double t = 50.0;
    bool created;
    struct view_output *a = view_outputs_acquire(ctx, &o, 40, 20, rgba8, 4, t, &created);
    CHECK(a != NULL && created && a->image.width == 40 && a->readback.size == 40 * 20 * 4);
    struct view_output *b = view_outputs_acquire(ctx, &o, 24, 12, rgba8, 4, t, &created);
    CHECK(b != NULL && b != a && created);
    CHECK(view_outputs_acquire(ctx, &o, 40, 20, rgba8, 4, t + 1.0, &created) == a && !created);
    CHECK(view_outputs_acquire(ctx, &o, 24, 12, rgba8, 4, t + 1.0, &created) == b && !created);
    struct view_output *c = view_outputs_acquire(ctx, &o, 40, 20, linear, 16, t + 1.0, &created);
    CHECK(c != NULL && c != a && created && c->readback.size == 40 * 20 * 16);
    CHECK(view_outputs_in_use(&o) == 3);
    /* More sizes than room: the least recently used (40x20 rgba8) makes way. */
    for (uint32_t i = 0; i < VIEW_OUTPUTS_MAX - 2; i++)
        CHECK(view_outputs_acquire(ctx, &o, 8 + i, 8, rgba8, 4, t + 2.0, &created) && created);
    CHECK(view_outputs_in_use(&o) == VIEW_OUTPUTS_MAX);
    bool kept = false;
    for (int i = 0; i < VIEW_OUTPUTS_MAX; i++)
        kept |= o.slot[i].use.in_use && o.slot[i].image.width == 40 &&
                o.slot[i].image.format == rgba8;
    CHECK(!kept);
    /* Only one size goes on being drawn: the others go once idle for long enough. */
    CHECK(view_outputs_acquire(ctx, &o, 24, 12, rgba8, 4, t + 2.5 + VIEW_OUTPUT_IDLE_S, &created) !=
          NULL);
    CHECK(view_outputs_in_use(&o) == 1);
    view_outputs_destroy(ctx, &o);
    CHECK(view_outputs_in_use(&o) == 0);
}

int main(void)
{
    test_photometry();
    test_ground_transfer();
    unsigned validation_messages = 0;
    struct vk_context_params params = { .validation = test_validation_requested(),
                                        .validation_message_counter = &validation_messages };
    struct vk_context *ctx = vk_context_create(&params);
    CHECK(ctx != NULL);
    if (ctx) {
        test_shader_functions(ctx);
        test_cloud_history(ctx);
        test_view_outputs(ctx);
        vk_context_destroy(&ctx);
    }
    CHECK(validation_messages == 0); /* counted through destruction */
    return check_summary();
}
