/* Fills the std140 uniform blocks of shaders/include/sky_shared.h from the renderer's
 * atmosphere and view descriptions (unit conversions, camera basis, sun photometry). */
#ifndef SKYD_SKY_UNIFORMS_H
#define SKYD_SKY_UNIFORMS_H

#include "sky_renderer.h"
#include "sky_shared.h"

void sky_uniforms_fill_atmosphere(const struct sky_render_atmosphere *a,
                                  struct sky_atmosphere_uniforms *u);
void sky_uniforms_fill_frame(const struct sky_render_atmosphere *a,
                             const struct sky_render_view *v, struct sky_frame_uniforms *u);

#endif
