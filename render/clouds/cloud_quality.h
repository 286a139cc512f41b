/* clouds.quality.resolution "auto": the finest cloud resolution whose frames fit a GPU-time
 * budget per frame, chosen from the frames' measured cost. It starts at the coarsest (half
 * size, one pixel in 64 traced per frame: what two CPU cores afford) and steps one level finer
 * while the frame, with its cloud trace and reconstruction four times as costly, stays under
 * most of the budget; one level coarser when frames overrun it. A fast device so reaches every
 * pixel traced at full size each frame; lavapipe stays where it is. */
#ifndef SKYD_CLOUD_QUALITY_H
#define SKYD_CLOUD_QUALITY_H

#include "sky_renderer.h"

struct cloud_quality {
    enum sky_render_cloud_resolution level;
    double budget_ms; /* <= 0: no budget, the level stays */
    double view_ms;   /* this frame's trace and reconstruction so far */
    int votes_finer, votes_coarser;
    /* After an overrun, the level that overran is not tried again for a while. */
    enum sky_render_cloud_resolution overran;
    int overran_frames;
};

void cloud_quality_init(struct cloud_quality *q);
/* A new budget (render.frame_budget_ms) also forgets an overrun. */
void cloud_quality_set_budget(struct cloud_quality *q, double frame_budget_ms);
/* A pass of the frame being measured (only the view's cloud passes count). */
void cloud_quality_observe_pass(struct cloud_quality *q, const char *pass_name, double ms);
/* The frame's whole GPU time, after its passes: may move the level for the next frame. */
void cloud_quality_observe_frame(struct cloud_quality *q, double frame_ms);
/* The resolution a frame traces at: `asked`, or the chosen level when `asked` is AUTO. */
enum sky_render_cloud_resolution cloud_quality_resolve(const struct cloud_quality *q,
                                                       enum sky_render_cloud_resolution asked);

#endif
