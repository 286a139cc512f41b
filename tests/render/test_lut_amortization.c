/* Amortized atmosphere LUT rebuilds (seed 001, 3.5.1) on lavapipe with validation: a rebuild
 * spread over frames ends with the same LUTs as a one-shot rebuild; while it runs, frames are
 * exactly those of the last complete atmosphere; progress rises monotonically to 1; a change
 * during a rebuild restarts it and ends at the newest atmosphere. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "test_support.h"

#define W 96
#define H 54
#define MAX_FRAMES 2000

static const char *const lut_names[] = { "transmittance", "multiscattering", "irradiance" };

static void atmosphere_variant(int which, struct sky_render_atmosphere *out)
{
    test_earth_atmosphere(out);
    if (which >= 1) {
        out->mie_g[0] = out->mie_g[1] = out->mie_g[2] = 0.6;
        for (int c = 0; c < 3; c++)
            out->rayleigh_scattering[c] *= 1.4;
        out->ground_albedo[0] = 0.1;
    }
    if (which >= 2) {
        for (int c = 0; c < 3; c++)
            out->mie_scattering[c] *= 3.0;
        out->top_radius_km = out->bottom_radius_km + 90.0;
    }
}

static void view_for(struct sky_render_view *v)
{
    struct proto_world_state s;
    proto_world_state_defaults(&s);
    s.exposure.mode = PROTO_EXPOSURE_MANUAL;
    s.sun.elevation_deg = 12.0;
    world_to_render_view(&s, W, H, SKY_RENDER_OUTPUT_SRGB8, v);
}

/* Largest |a - b| over the three atmosphere LUTs of two renderers. */
static double max_lut_difference(struct sky_renderer *a, struct sky_renderer *b)
{
    double worst = 0.0;
    for (size_t k = 0; k < sizeof lut_names / sizeof lut_names[0]; k++) {
        uint32_t sa[3], sb[3];
        float *la = sky_renderer_read_lut(a, lut_names[k], sa);
        float *lb = sky_renderer_read_lut(b, lut_names[k], sb);
        CHECK(la && lb && memcmp(sa, sb, sizeof sa) == 0);
        if (la && lb && memcmp(sa, sb, sizeof sa) == 0) {
            size_t n = (size_t)sa[0] * sa[1] * sa[2] * 4;
            for (size_t i = 0; i < n; i++)
                worst = fmax(worst, fabs((double)la[i] - lb[i]));
        }
        free(la);
        free(lb);
    }
    return worst;
}

/* Renders frames of `atm` until the rebuild and its blend are over; returns the frame count
 * (or MAX_FRAMES). Checks progress is monotonic while building. */
static int render_until_settled(struct sky_renderer *r, const struct sky_render_atmosphere *atm,
                                int blend_frames, uint8_t *pixels)
{
    struct sky_render_view view;
    view_for(&view);
    double last_progress = -1.0;
    int frames_after_build = -1;
    for (int frame = 1; frame <= MAX_FRAMES; frame++) {
        struct sky_render_stats stats;
        CHECK(sky_renderer_render(r, atm, &view, pixels, W * H * 4, &stats) == 0);
        if (frames_after_build < 0) {
            CHECK(stats.lut_rebuild_progress >= last_progress);
            last_progress = stats.lut_rebuild_progress;
            if (stats.lut_rebuild_progress >= 1.0)
                frames_after_build = 0;
        } else if (++frames_after_build == blend_frames) {
            return frame;
        }
    }
    return MAX_FRAMES;
}

int main(void)
{
    unsigned messages_reference = 0, messages_amortized = 0;
    struct sky_renderer *reference = test_renderer_create(&messages_reference);
    struct sky_renderer *amortized = test_renderer_create(&messages_amortized);
    CHECK(reference && amortized);
    if (!reference || !amortized)
        return check_summary();
    const int blend_frames = 3;
    sky_renderer_set_amortization(amortized, &(struct sky_render_amortization){
                                                 .budget_ms = 2.0, .blend_frames = blend_frames });
    struct sky_render_atmosphere atm[3];
    for (int i = 0; i < 3; i++)
        atmosphere_variant(i, &atm[i]);
    struct sky_render_view view;
    view_for(&view);
    static uint8_t before[W * H * 4], during[W * H * 4], after[W * H * 4];

    /* The first atmosphere is built at once (nothing to show before it). */
    struct sky_render_stats stats;
    CHECK(sky_renderer_render(amortized, &atm[0], &view, before, sizeof before, &stats) == 0);
    CHECK(stats.luts_rebuilt && stats.lut_rebuild_progress == 1.0);

    /* A change: the next frame starts the rebuild and is still the old atmosphere's. */
    CHECK(sky_renderer_render(amortized, &atm[1], &view, during, sizeof during, &stats) == 0);
    CHECK(stats.lut_rebuild_progress > 0.0 && stats.lut_rebuild_progress < 1.0);
    CHECK(memcmp(before, during, sizeof before) == 0);
    int frames = render_until_settled(amortized, &atm[1], blend_frames, after);
    printf("rebuild spread over %d frames (budget 2 ms, blend %d)\n", frames + 1, blend_frames);
    CHECK(frames > blend_frames + 1 && frames < MAX_FRAMES);
    CHECK(memcmp(before, after, sizeof before) != 0);

    CHECK(sky_renderer_rebuild_atmosphere(reference, &atm[1], NULL) == 0);
    double difference = max_lut_difference(reference, amortized);
    printf("amortized vs one-shot, atmosphere 1: max |difference| %.3g\n", difference);
    CHECK_LE(difference, 1e-6);

    /* Frames of the settled amortized renderer equal those of the one-shot one. */
    static uint8_t one_shot[W * H * 4];
    CHECK(sky_renderer_render(reference, &atm[1], &view, one_shot, sizeof one_shot, NULL) == 0);
    CHECK(sky_renderer_render(amortized, &atm[1], &view, after, sizeof after, NULL) == 0);
    CHECK(memcmp(one_shot, after, sizeof after) == 0);

    /* A change in the middle of a rebuild restarts it and ends at the newest atmosphere. */
    CHECK(sky_renderer_render(amortized, &atm[0], &view, during, sizeof during, &stats) == 0);
    CHECK(sky_renderer_render(amortized, &atm[0], &view, during, sizeof during, &stats) == 0);
    CHECK(stats.lut_rebuild_progress < 1.0);
    frames = render_until_settled(amortized, &atm[2], blend_frames, after);
    CHECK(frames < MAX_FRAMES);
    CHECK(sky_renderer_rebuild_atmosphere(reference, &atm[2], NULL) == 0);
    difference = max_lut_difference(reference, amortized);
    printf("after a restart, atmosphere 2: max |difference| %.3g\n", difference);
    CHECK_LE(difference, 1e-6);

    /* A probe finishes a rebuild under way at once: its answer is the new atmosphere's. */
    CHECK(sky_renderer_render(amortized, &atm[1], &view, during, sizeof during, &stats) == 0);
    CHECK(stats.lut_rebuild_progress < 1.0);
    double altitude = 0.0, mu = 0.3, t_amortized[1][3], t_reference[1][3];
    CHECK(sky_renderer_probe_transmittance(amortized, &atm[1], &altitude, &mu, 1, t_amortized) ==
          0);
    CHECK(sky_renderer_probe_transmittance(reference, &atm[1], &altitude, &mu, 1, t_reference) ==
          0);
    for (int c = 0; c < 3; c++)
        CHECK_NEAR(t_amortized[0][c], t_reference[0][c], 1e-6);

    /* A budget relative to the frame (2 % of the rest of it, here well under 2 ms) spreads
     * the same rebuild over more frames, slices of the multiple-scattering LUT finer than a
     * row, and still ends exactly. */
    CHECK(render_until_settled(amortized, &atm[1], blend_frames, after) < MAX_FRAMES);
    sky_renderer_set_amortization(
        amortized, &(struct sky_render_amortization){
                       .budget_ms = 2.0, .budget_fraction = 0.02, .blend_frames = blend_frames });
    int relative = render_until_settled(amortized, &atm[0], blend_frames, after);
    printf("with a 0.02 relative budget: %d frames (2 ms alone: %d)\n", relative + 1, frames + 1);
    CHECK(relative > frames && relative < MAX_FRAMES);
    CHECK(sky_renderer_rebuild_atmosphere(reference, &atm[0], NULL) == 0);
    difference = max_lut_difference(reference, amortized);
    printf("relative budget, atmosphere 0: max |difference| %.3g\n", difference);
    CHECK_LE(difference, 1e-6);

    sky_renderer_destroy(&reference);
    sky_renderer_destroy(&amortized);
    CHECK(messages_reference == 0 && messages_amortized == 0);
    return check_summary();
}
