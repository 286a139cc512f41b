/* Shared fixtures for the render tests. */
#ifndef SKYD_TEST_SUPPORT_H
#define SKYD_TEST_SUPPORT_H

#include <math.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "sky_renderer.h"
#include "world_render.h"
#include "world_state.h"

/* Validation is on unless SKYD_VALIDATION=0 (tests default to validated). */
static inline bool test_validation_requested(void)
{
    const char *v = getenv("SKYD_VALIDATION");
    return !(v && strcmp(v, "0") == 0);
}

/* A renderer with validation as requested, counting its messages into *validation_messages
 * through its destruction (check it after sky_renderer_destroy). Its cloud noise is kept in
 * $SKYD_CACHE_DIR (ctest sets one for the build's tests), as the daemon's is. */
static inline struct sky_renderer *test_renderer_create(unsigned *validation_messages)
{
    struct sky_renderer_params params = { .validation = test_validation_requested(),
                                          .validation_message_counter = validation_messages,
                                          .cache_dir = getenv("SKYD_CACHE_DIR") };
    return sky_renderer_create(&params);
}

/* Creates the test's renderer into *renderer (test_renderer_create), runs `tests`, destroys it
 * and checks that validation reported nothing, counted through destruction. Returns
 * check_summary(): a test's main in one line. */
static inline int test_run_with_renderer(struct sky_renderer **renderer, void (*tests)(void))
{
    unsigned validation_messages = 0;
    *renderer = test_renderer_create(&validation_messages);
    CHECK(*renderer != NULL);
    if (*renderer) {
        tests();
        sky_renderer_destroy(renderer);
        CHECK(validation_messages == 0);
    }
    return check_summary();
}

static inline void test_earth_atmosphere(struct sky_render_atmosphere *out)
{
    struct proto_world_state state;
    proto_world_state_defaults(&state);
    world_to_render_atmosphere(&state, out);
}

/* Luminance of a linear RGBA pixel (cd/m2 when the render is in cd/m2; Rec. 709 weights). */
static inline double test_pixel_luminance(const float *px)
{
    return 0.2126 * px[0] + 0.7152 * px[1] + 0.0722 * px[2];
}

/* Channels of `pixels` RGBA pixels that are NaN, infinite or negative. */
static inline int test_count_bad(const float *rgba, size_t pixels)
{
    int bad = 0;
    for (size_t i = 0; i < 4 * pixels; i++)
        bad += !isfinite(rgba[i]) || rgba[i] < 0.0f;
    return bad;
}

/* Mean |L(a) - L(b)| / mean L(b) over `pixels` RGBA pixels. */
static inline double test_relative_difference(const float *a, const float *b, size_t pixels)
{
    double diff = 0.0, sum = 0.0;
    for (size_t i = 0; i < pixels; i++) {
        diff += fabs(test_pixel_luminance(a + 4 * i) - test_pixel_luminance(b + 4 * i));
        sum += test_pixel_luminance(b + 4 * i);
    }
    return diff / fmax(sum, 1e-9);
}

/* A client weather map with one footprint of `radius` km (coverage 1 at its centre falling to 0
 * at its rim; cloud type `type`, 255 cumulonimbus; precipitation `rain` inside it) `north` km
 * north of the camera, given to `renderer`. Returns sky_renderer_set_weather_map's result. */
static inline int test_set_cell_map(struct sky_renderer *renderer,
                                    const struct proto_world_state *s, double radius, double north,
                                    uint8_t type, uint8_t rain)
{
    enum { MAP = 128 };
    static uint8_t map[MAP * MAP * 4];
    double extent = s->weather.map_extent_km;
    for (int y = 0; y < MAP; y++)
        for (int x = 0; x < MAP; x++) {
            double east_km = ((x + 0.5) / MAP - 0.5) * extent;
            double north_km = (0.5 - (y + 0.5) / MAP) * extent;
            double r = hypot(east_km, north_km - north) / radius;
            uint8_t *t = map + 4 * (y * MAP + x);
            t[0] = (uint8_t)lround(255.0 * fmax(0.0, 1.0 - r * r));
            t[1] = 0;
            t[2] = type;
            t[3] = r < 1.0 ? rain : 0;
        }
    return sky_renderer_set_weather_map(renderer, map, MAP, MAP);
}

/* Renders the world state `s` as the daemon does (atmosphere, clouds, night, view) at w x h
 * into `out` (`bytes` long) with the view's history `key`; `live` asks for a stream's frames
 * (see sky_render_view.live). Returns sky_renderer_render's result. */
static inline int test_render_world(struct sky_renderer *renderer,
                                    const struct proto_world_state *s, uint32_t w, uint32_t h,
                                    enum sky_render_output_kind output, uint64_t key, bool live,
                                    void *out, size_t bytes)
{
    struct sky_render_atmosphere atm;
    struct sky_render_view view;
    struct sky_render_clouds clouds;
    struct sky_render_night night;
    world_to_render_atmosphere(s, &atm);
    world_to_render_view(s, w, h, output, &view);
    view.history_key = key;
    view.live = live;
    world_to_render_clouds(s, &clouds);
    if (sky_renderer_set_clouds(renderer, &clouds) != 0)
        return -1;
    world_to_render_night(s, &night);
    sky_renderer_set_night(renderer, &night);
    return sky_renderer_render(renderer, &atm, &view, out, bytes, NULL);
}

#endif
