/* clouds.quality.resolution "auto": the finest cloud quality whose frames fit a GPU-time
 * budget per frame, chosen from the frames' measured cost. The qualities form one ladder, from
 * the coarsest (half size, one pixel in 64 traced per frame with half the march steps) through
 * the resolutions (sixtyfourth, sixteenth, quarter, full: four times the traced pixels each)
 * to every pixel traced at full size with twice the march steps. It starts at sixtyfourth with
 * the clouds' own steps (what two CPU cores afford) and moves one rung finer while the frame,
 * with its cloud trace and reconstruction as costly as the finer rung's would be, stays under
 * most of the budget; one rung coarser when frames overrun it. A fast device so reaches every
 * pixel traced at full size with more steps each frame; lavapipe stays where it is. */
#ifndef SKYD_CLOUD_QUALITY_H
#define SKYD_CLOUD_QUALITY_H

#include "sky_renderer.h"

struct cloud_quality {
    int rung;         /* on the ladder of cloud_quality.c, 0 the finest */
    double budget_ms; /* <= 0: no budget, the rung stays */
    double view_ms;   /* this frame's trace and reconstruction so far */
    int votes_finer, votes_coarser;
    /* After an overrun, the rung that overran is not tried again for a while. */
    int overran;
    int overran_frames;
};

void cloud_quality_init(struct cloud_quality *q);
/* A new budget (render.frame_budget_ms) also forgets an overrun. */
void cloud_quality_set_budget(struct cloud_quality *q, double frame_budget_ms);
/* A pass of the frame being measured (only the view's cloud passes count). */
void cloud_quality_observe_pass(struct cloud_quality *q, const char *pass_name, double ms);
/* The frame's whole GPU time, after its passes: may move the rung for the next frame. */
void cloud_quality_observe_frame(struct cloud_quality *q, double frame_ms);
/* The resolution a frame traces at: `asked`, or the chosen rung's when `asked` is AUTO. */
enum sky_render_cloud_resolution cloud_quality_resolve(const struct cloud_quality *q,
                                                       enum sky_render_cloud_resolution asked);
/* The low layer's march steps a frame takes: the clouds' own (`steps`), or when `asked` is
 * AUTO, scaled by the chosen rung (within the world's bounds of clouds.quality.primary_steps). */
int cloud_quality_steps(const struct cloud_quality *q, enum sky_render_cloud_resolution asked,
                        int steps);

#endif
