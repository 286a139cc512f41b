/* The renderer's failures on lavapipe with validation, provoked through SKYD_FAULT
 * (render/vk/fault_injection.h), which ctest sets for each run; argv[1] names the scenario it
 * set up for:
 *
 *   out_of_memory  (SKYD_FAULT=out_of_memory:after_frames=1:times=2) The first allocation
 *                  after a frame, new LUT sizes, fails: sky_renderer_status says out of memory
 *                  and names the image, and the renderer keeps its old LUTs (the next frame
 *                  equals the first). The second, a new output size, fails the same way; the
 *                  same size then renders, and so does the first one again, unchanged.
 *   device_lost    (SKYD_FAULT=device_lost:after_frames=2) The third frame's submission is
 *                  lost: that call and every later one fail at once with the status
 *                  device lost; destroying the renderer does not wait; a new renderer renders
 *                  the first frame again.
 *   timeout        (SKYD_FAULT=timeout:after_frames=2) The wait for the third frame gives up
 *                  while the device still runs it (a CPU device slower than the bound): the
 *                  call fails with the status device lost naming VK_TIMEOUT, the submission is
 *                  waited for before its command buffer is freed (validation would report
 *                  freeing one in use, and lavapipe crashed on it), and a new renderer renders
 *                  the first frame again.
 *
 * Validation messages are counted through each renderer's destruction: a failed create that
 * left an object behind, or one a lost renderer did not destroy, would be reported there. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "check.h"
#include "test_support.h"

#define W 48
#define H 27

static void test_view(uint32_t width, uint32_t height, struct sky_render_view *v)
{
    struct proto_world_state s;
    proto_world_state_defaults(&s);
    s.exposure.mode = PROTO_EXPOSURE_MANUAL;
    s.sun.elevation_deg = 20.0;
    world_to_render_view(&s, width, height, SKY_RENDER_OUTPUT_SRGB8, v);
}

static int render(struct sky_renderer *r, uint32_t width, uint32_t height, uint8_t *pixels)
{
    struct sky_render_atmosphere atm;
    test_earth_atmosphere(&atm);
    struct sky_render_view view;
    test_view(width, height, &view);
    return sky_renderer_render(r, &atm, &view, pixels, (size_t)width * height * 4, NULL);
}

static bool contains(const char *text, const char *part)
{
    return text && strstr(text, part) != NULL;
}

static void out_of_memory(void)
{
    unsigned validation_messages = 0;
    struct sky_renderer *r = test_renderer_create(&validation_messages);
    CHECK(r != NULL);
    if (!r)
        return;
    static uint8_t first[W * H * 4], again[W * H * 4];
    static uint8_t other[(W + 16) * (H + 9) * 4];
    CHECK(render(r, W, H, first) == 0);
    const char *detail = NULL;
    CHECK(sky_renderer_status(r, &detail) == SKY_RENDER_OK);

    struct sky_render_lut_sizes bigger = { .transmittance = { 128, 32 },
                                           .multiscattering = { 16, 16 },
                                           .skyview = { 96, 54 },
                                           .aerial_perspective = { 16, 16, 16 } };
    CHECK(sky_renderer_set_lut_sizes(r, &bigger) != 0);
    CHECK(sky_renderer_status(r, &detail) == SKY_RENDER_OUT_OF_MEMORY);
    CHECK_MSG(contains(detail, "creating image") &&
                  contains(detail, "VK_ERROR_OUT_OF_DEVICE_MEMORY"),
              "detail \"%s\"", detail ? detail : "(null)");
    CHECK(render(r, W, H, again) == 0);
    CHECK(sky_renderer_status(r, NULL) == SKY_RENDER_OK); /* a call forgets the last failure */
    CHECK_MSG(memcmp(first, again, sizeof first) == 0, "the frame changed after the failed "
                                                       "resize: the old LUTs were not kept");

    CHECK(render(r, W + 16, H + 9, other) != 0);
    CHECK(sky_renderer_status(r, &detail) == SKY_RENDER_OUT_OF_MEMORY);
    CHECK_MSG(contains(detail, "\"output\" (64x36"), "detail \"%s\"", detail);
    CHECK(render(r, W + 16, H + 9, other) == 0);
    CHECK(render(r, W, H, again) == 0);
    CHECK(memcmp(first, again, sizeof first) == 0);
    sky_renderer_destroy(&r);
    CHECK(r == NULL);
    CHECK_MSG(validation_messages == 0, "%u validation messages", validation_messages);
}

static double now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + ts.tv_nsec * 1e-9;
}

/* The third frame fails with the device lost (its detail naming `result`); later calls fail at
 * once, destroying the renderer does not wait, and a new renderer draws the first frame. */
static void third_frame_lost(const char *result)
{
    unsigned validation_messages = 0;
    struct sky_renderer *r = test_renderer_create(&validation_messages);
    CHECK(r != NULL);
    if (!r)
        return;
    static uint8_t first[W * H * 4], pixels[W * H * 4];
    CHECK(render(r, W, H, first) == 0);
    CHECK(render(r, W, H, pixels) == 0);
    CHECK(render(r, W, H, pixels) != 0);
    const char *detail = NULL;
    CHECK(sky_renderer_status(r, &detail) == SKY_RENDER_DEVICE_LOST);
    CHECK_MSG(contains(detail, result), "detail \"%s\"", detail);

    /* Everything fails at once from now on, and the status stays. */
    struct sky_render_atmosphere atm;
    test_earth_atmosphere(&atm);
    CHECK(sky_renderer_rebuild_atmosphere(r, &atm, NULL) != 0);
    double altitude = 1.0, mu = 0.5, rgb[1][3];
    CHECK(sky_renderer_probe_transmittance(r, &atm, &altitude, &mu, 1, rgb) != 0);
    uint8_t map[4] = { 255, 0, 128, 0 };
    CHECK(sky_renderer_set_weather_map(r, map, 1, 1) != 0);
    CHECK(sky_renderer_prepare_cloud_noise(r, 7) != 0);
    CHECK(render(r, W, H, pixels) != 0);
    CHECK(sky_renderer_status(r, NULL) == SKY_RENDER_DEVICE_LOST);
    double start = now_s();
    sky_renderer_destroy(&r);
    CHECK_LE(now_s() - start, 5.0);
    CHECK_MSG(validation_messages == 0, "%u validation messages", validation_messages);

    /* The fault was injected once: a new renderer works and draws the same frame. */
    validation_messages = 0;
    r = test_renderer_create(&validation_messages);
    CHECK(r != NULL);
    if (!r)
        return;
    CHECK(render(r, W, H, pixels) == 0);
    CHECK(sky_renderer_status(r, NULL) == SKY_RENDER_OK);
    CHECK(memcmp(first, pixels, sizeof first) == 0);
    sky_renderer_destroy(&r);
    CHECK_MSG(validation_messages == 0, "%u validation messages", validation_messages);
}

int main(int argc, char **argv)
{
    const char *scenario = argc > 1 ? argv[1] : "";
    const char *fault = getenv("SKYD_FAULT");
    printf("scenario %s, SKYD_FAULT=%s\n", scenario, fault ? fault : "(unset)");
    if (strcmp(scenario, "out_of_memory") == 0 && fault &&
        strcmp(fault, "out_of_memory:after_frames=1:times=2") == 0) {
        out_of_memory();
    } else if (strcmp(scenario, "device_lost") == 0 && fault &&
               strcmp(fault, "device_lost:after_frames=2") == 0) {
        third_frame_lost("VK_ERROR_DEVICE_LOST");
    } else if (strcmp(scenario, "timeout") == 0 && fault &&
               strcmp(fault, "timeout:after_frames=2") == 0) {
        third_frame_lost("VK_TIMEOUT");
    } else {
        printf("usage: SKYD_FAULT=out_of_memory:after_frames=1:times=2 test_render_faults "
               "out_of_memory\n       SKYD_FAULT=device_lost:after_frames=2 "
               "test_render_faults device_lost\n       SKYD_FAULT=timeout:after_frames=2 "
               "test_render_faults timeout\n");
        return 2;
    }
    return check_summary();
}
