#include "cloud_quality.h"

#include <string.h>

/* Frames in a row that must agree before the level moves: one slow frame (a LUT slice, a
 * map row) does not. */
#define VOTES 3
/* A finer level is tried only when the frame with its view passes four times as costly
 * (four times the traced pixels) stays under this share of the budget. */
#define HEADROOM 0.8
/* Frames before a level that overran the budget is tried again. */
#define OVERRUN_MEMORY 600

void cloud_quality_init(struct cloud_quality *q)
{
    memset(q, 0, sizeof *q);
    q->level = SKY_RENDER_CLOUDS_SIXTYFOURTH;
    q->overran = SKY_RENDER_CLOUDS_AUTO;
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
    enum sky_render_cloud_resolution finer = q->level - 1;
    bool over = frame_ms > q->budget_ms && q->level < SKY_RENDER_CLOUDS_SIXTYFOURTH;
    bool room = q->level > SKY_RENDER_CLOUDS_FULL &&
                frame_ms + 3.0 * view_ms <= HEADROOM * q->budget_ms &&
                !(q->overran_frames > 0 && finer <= q->overran);
    q->votes_coarser = over ? q->votes_coarser + 1 : 0;
    q->votes_finer = room ? q->votes_finer + 1 : 0;
    if (q->votes_coarser >= VOTES) {
        q->overran = q->level;
        q->overran_frames = OVERRUN_MEMORY;
        q->level++;
        q->votes_coarser = 0;
    } else if (q->votes_finer >= VOTES) {
        q->level = finer;
        q->votes_finer = 0;
    }
}

enum sky_render_cloud_resolution cloud_quality_resolve(const struct cloud_quality *q,
                                                       enum sky_render_cloud_resolution asked)
{
    return asked == SKY_RENDER_CLOUDS_AUTO ? q->level : asked;
}
