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

static inline void test_earth_atmosphere(struct sky_render_atmosphere *out)
{
    struct sky_world_state state;
    sky_world_state_defaults(&state);
    world_to_render_atmosphere(&state, out);
}

#endif
