/* clouds.quality.resolution "auto" on lavapipe with validation (render/clouds/cloud_quality.c):
 * a small live view whose frames cost far less than a large budget climbs the ladder from the
 * start (half size, one pixel in 64 per frame) to every pixel traced at full size and then to
 * twice the march steps, one rung at a time; a budget its frames overrun brings it back down
 * to the coarsest, half the steps at half size; no budget leaves it at the start; a fixed
 * resolution is never moved and keeps the clouds' own steps. The frames' cost is measured, not
 * assumed: lavapipe with a large budget on a small view stands for a fast device. */
#include <stdio.h>
#include <stdlib.h>

#include "check.h"
#include "test_support.h"

#define W 64
#define H 36
#define MAX_FRAMES 60
#define STEPS 64 /* clouds.quality.primary_steps */

/* The rungs, finest first, as the frames report them: resolution and march steps. */
static const struct {
    enum sky_render_cloud_resolution resolution;
    int steps;
} rungs[] = {
    { SKY_RENDER_CLOUDS_FULL, 2 * STEPS },    { SKY_RENDER_CLOUDS_FULL, STEPS },
    { SKY_RENDER_CLOUDS_QUARTER, STEPS },     { SKY_RENDER_CLOUDS_SIXTEENTH, STEPS },
    { SKY_RENDER_CLOUDS_SIXTYFOURTH, STEPS }, { SKY_RENDER_CLOUDS_SIXTYFOURTH, STEPS / 2 },
};
#define RUNGS ((int)(sizeof rungs / sizeof rungs[0]))
#define FINEST 0
#define START 4
#define COARSEST (RUNGS - 1)

static uint8_t pixels[W * H * 4];

static void cumulus_state(struct proto_world_state *s, enum proto_cloud_resolution resolution)
{
    proto_world_state_defaults(s);
    s->exposure.mode = PROTO_EXPOSURE_MANUAL;
    s->exposure.ev100 = 14.5;
    s->clouds.low.coverage = 0.5;
    s->clouds.low.type = 0.67;
    s->camera.pitch_deg = 10.0;
    s->clouds.resolution = resolution;
    s->clouds.primary_steps = STEPS;
}

/* One live frame of the state; its rung (-1: none matches what it reports). */
static int frame(struct sky_renderer *r, const struct proto_world_state *s)
{
    struct sky_render_atmosphere atm;
    struct sky_render_view view;
    struct sky_render_clouds clouds;
    world_to_render_atmosphere(s, &atm);
    world_to_render_view(s, W, H, SKY_RENDER_OUTPUT_SRGB8, &view);
    view.live = true;
    world_to_render_clouds(s, &clouds);
    CHECK(sky_renderer_set_clouds(r, &clouds) == 0);
    struct sky_render_stats st;
    CHECK(sky_renderer_render(r, &atm, &view, pixels, sizeof pixels, &st) == 0);
    for (int k = 0; k < RUNGS; k++)
        if (rungs[k].resolution == st.cloud_resolution && rungs[k].steps == st.cloud_primary_steps)
            return k;
    printf("a frame traced at resolution %d with %d steps: no rung\n", (int)st.cloud_resolution,
           st.cloud_primary_steps);
    return -1;
}

/* Frames until the rung is `goal` (or MAX_FRAMES); checks it moves one rung at a time, in the
 * goal's direction. Returns the frames it took. */
static int frames_until(struct sky_renderer *r, const struct proto_world_state *s, int goal)
{
    int last = frame(r, s);
    for (int n = 1; n < MAX_FRAMES; n++) {
        if (last == goal)
            return n;
        int now = frame(r, s);
        CHECK(now == last || (goal < last ? now == last - 1 : now == last + 1));
        last = now;
    }
    return MAX_FRAMES;
}

int main(void)
{
    unsigned messages = 0;
    struct sky_renderer *r = test_renderer_create(&messages);
    CHECK(r);
    if (!r)
        return check_summary();
    struct proto_world_state s;
    cumulus_state(&s, PROTO_CLOUD_RESOLUTION_AUTO);

    /* No budget: the start, whatever the frames cost. */
    sky_renderer_set_frame_budget(r, 0.0);
    for (int i = 0; i < 10; i++)
        CHECK(frame(r, &s) == START);

    /* A budget far above a 64x36 frame: up to full size, every pixel, then twice the steps,
     * rung by rung. */
    sky_renderer_set_frame_budget(r, 1000.0);
    int up = frames_until(r, &s, FINEST);
    printf("budget 1000 ms: full resolution with twice the steps after %d frames\n", up);
    CHECK(up < MAX_FRAMES);
    for (int i = 0; i < 10; i++)
        CHECK(frame(r, &s) == FINEST);

    /* A budget every frame overruns: back down to the coarsest, and it stays there. */
    sky_renderer_set_frame_budget(r, 0.001);
    int down = frames_until(r, &s, COARSEST);
    printf("budget 0.001 ms: the coarsest (half the steps) after %d frames\n", down);
    CHECK(down < MAX_FRAMES);
    for (int i = 0; i < 10; i++)
        CHECK(frame(r, &s) == COARSEST);

    /* A fixed resolution is the one traced, with the clouds' own steps, whatever the budget. */
    struct proto_world_state fixed;
    cumulus_state(&fixed, PROTO_CLOUD_RESOLUTION_SIXTEENTH);
    sky_renderer_set_frame_budget(r, 1000.0);
    for (int i = 0; i < 10; i++)
        CHECK(frame(r, &fixed) == 3); /* sixteenth, the clouds' own steps */

    sky_renderer_destroy(&r);
    CHECK(messages == 0);
    return check_summary();
}
