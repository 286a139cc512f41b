/* The night sky's frame uniforms (shaders/include/sky_shared.h, "Night sky"): the moon lit as
 * a sphere by the sun, its disc normalised to the illuminance asked for, the star field's
 * rotation and blur, the airglow. Pure CPU code, no Vulkan. */
#ifndef SKYD_NIGHT_SKY_H
#define SKYD_NIGHT_SKY_H

#include <stdbool.h>
#include <stdint.h>

#include "sky_renderer.h"
#include "sky_shared.h"

/* Fills the night members of `u`, whose sun members sky_uniforms_fill_frame already filled.
 * brightest_star_lux: of the star field (for the daylight cull). Returns true when the
 * moonlit sky-view LUT must be computed this frame. */
bool night_fill_uniforms(const struct sky_render_night *night, const struct sky_render_view *v,
                         double brightest_star_lux, struct sky_frame_uniforms *u);

/* Whether the night sky can add anything visible (over 0.1 %) to a frame seen from inside the
 * atmosphere; when not, frames use pipelines without it. The moon's disc is drawn either way. */
bool night_sky_visible(const struct sky_render_night *night, const struct sky_render_view *v,
                       double brightest_star_lux);

/* The moon disc's pixel rectangle (x0, y0, width, height); false when it is not drawn or not
 * on screen. */
bool night_moon_rect(const struct sky_render_night *night, const struct sky_render_view *v,
                     int32_t rect[4]);

/* Albedo of the lunar near side relative to the highlands at disc coordinates q (x toward
 * lunar east as seen, y lunar north; |q| <= 1): the maria of night_shared.h. */
double night_moon_albedo(double qx, double qy);

/* Lommel-Seeliger reflectance mu0 / (mu0 + mu) of the disc point q (seed 001 4.2 leaves the
 * moon's lit side to the renderer; Hapke 1981 eq. 16 single-scattering limit). */
double night_moon_reflectance(double qx, double qy, const double sun_in_disc[3]);

#endif
