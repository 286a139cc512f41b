#include "cloud_quality.h"

#include <math.h>
#include <string.h>

#include "cloud_params.h"

/* Frames in a row that must agree before the rung moves: one slow frame (a LUT slice, a map
 * row) does not. */
#define VOTES 3
/* A finer rung is tried only when the frame with its view passes as costly as that rung's
 * would be stays under this share of the budget. */
#define HEADROOM 0.8
/* Frames before a rung that overran the budget is tried again. */
#define OVERRUN_MEMORY 600
/* The bounds of clouds.quality.primary_steps (protocol/world_fields.c). */
#define STEPS_MIN 4
#define STEPS_MAX 512

/* Finest first. */
static const struct rung {
    enum sky_render_cloud_resolution resolution;
    double step_factor;
} ladder[] = {
    { SKY_RENDER_CLOUDS_FULL, 2.0 },        { SKY_RENDER_CLOUDS_FULL, 1.0 },
    { SKY_RENDER_CLOUDS_QUARTER, 1.0 },     { SKY_RENDER_CLOUDS_SIXTEENTH, 1.0 },
    { SKY_RENDER_CLOUDS_SIXTYFOURTH, 1.0 }, { SKY_RENDER_CLOUDS_SIXTYFOURTH, 0.5 },
};
#define RUNG_COUNT ((int)(sizeof ladder / sizeof ladder[0]))
#define START_RUNG 4 /* sixtyfourth with the clouds' own steps */

/* The trace's cost goes with the traced share of the output's pixels (one per block of the
 * cloud image, itself the output downscaled) times the march steps (the step length is the
 * layer's depth over the steps). */
static double rung_cost(int rung)
{
    enum sky_render_cloud_resolution r = ladder[rung].resolution;
    double pixels_per_trace = cloud_params_block(r) * cloud_params_downscale(r);
    return ladder[rung].step_factor / (pixels_per_trace * pixels_per_trace);
}

void cloud_quality_init(struct cloud_quality *q)
{
    memset(q, 0, sizeof *q);
    q->rung = START_RUNG;
    q->overran = -1;
}

void cloud_quality_set_budget(struct cloud_quality *q, double frame_budget_ms)
{
    q->budget_ms = frame_budget_ms;
    q->overran_frames = 0;
    q->votes_finer = q->votes_coarser = 0;
}

void cloud_quality_observe_pass(struct cloud_quality *q, const char *pass_name, double ms)
{
    if (ms > 0.0 &&
        (strcmp(pass_name, "cloud_trace") == 0 || strcmp(pass_name, "cloud_reconstruct") == 0))
        q->view_ms += ms;
}

void cloud_quality_observe_frame(struct cloud_quality *q, double frame_ms)
{
    double view_ms = q->view_ms;
    q->view_ms = 0.0;
    if (q->overran_frames > 0)
        q->overran_frames--;
    if (q->budget_ms <= 0.0 || !(frame_ms > 0.0) || !(view_ms > 0.0))
        return; /* no budget, or a frame without clouds: nothing to judge by */
    int finer = q->rung - 1;
    bool over = frame_ms > q->budget_ms && q->rung < RUNG_COUNT - 1;
    bool room = finer >= 0 &&
                frame_ms + (rung_cost(finer) / rung_cost(q->rung) - 1.0) * view_ms <=
                    HEADROOM * q->budget_ms &&
                !(q->overran_frames > 0 && finer <= q->overran);
    q->votes_coarser = over ? q->votes_coarser + 1 : 0;
    q->votes_finer = room ? q->votes_finer + 1 : 0;
    if (q->votes_coarser >= VOTES) {
        q->overran = q->rung;
        q->overran_frames = OVERRUN_MEMORY;
        q->rung++;
        q->votes_coarser = 0;
    } else if (q->votes_finer >= VOTES) {
        q->rung = finer;
        q->votes_finer = 0;
    }
}

enum sky_render_cloud_resolution cloud_quality_resolve(const struct cloud_quality *q,
                                                       enum sky_render_cloud_resolution asked)
{
    return asked == SKY_RENDER_CLOUDS_AUTO ? ladder[q->rung].resolution : asked;
}

int cloud_quality_steps(const struct cloud_quality *q, enum sky_render_cloud_resolution asked,
                        int steps)
{
    if (asked != SKY_RENDER_CLOUDS_AUTO)
        return steps;
    double scaled = round(steps * ladder[q->rung].step_factor);
    return (int)fmin(fmax(scaled, STEPS_MIN), STEPS_MAX);
}
