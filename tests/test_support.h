/* Shared fixtures for the render tests. */
#ifndef SKYD_TEST_SUPPORT_H
#define SKYD_TEST_SUPPORT_H

#include <stdbool.h>
#include <stdlib.h>
#include <string.h>

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
 * through its destruction (check it after sky_renderer_destroy). */
static inline struct sky_renderer *test_renderer_create(unsigned *validation_messages)
{
    struct sky_renderer_params params = { .validation = test_validation_requested(),
                                          .validation_message_counter = validation_messages };
    return sky_renderer_create(&params);
}

static inline void test_earth_atmosphere(struct sky_render_atmosphere *out)
{
    struct sky_world_state state;
    sky_world_state_defaults(&state);
    world_to_render_atmosphere(&state, out);
}

#endif
