/* Fills the std140 uniform blocks of shaders/include/sky_shared.h from the renderer's
 * atmosphere and view descriptions (unit conversions, camera basis, sun photometry). */
#ifndef SKYD_SKY_UNIFORMS_H
#define SKYD_SKY_UNIFORMS_H

#include <stdbool.h>
#include <stdint.h>

#include "sky_renderer.h"
#include "sky_shared.h"

void sky_uniforms_fill_atmosphere(const struct sky_render_atmosphere *a,
                                  struct sky_atmosphere_uniforms *u);
/* The same without the ground's multiple-scattering transfer (left 0): it costs an integral on
 * the CPU, and only the multiple-scattering and shading passes read it. */
void sky_uniforms_fill_atmosphere_media(const struct sky_render_atmosphere *a,
                                        struct sky_atmosphere_uniforms *u);
/* zenith_transmittance: sky_zenith_transmittance() of the same atmosphere; it depends on the
 * atmosphere alone, so callers compute it once per atmosphere rather than per frame. */
void sky_uniforms_fill_frame(const struct sky_render_atmosphere *a, const struct sky_render_view *v,
                             const double zenith_transmittance[3], struct sky_frame_uniforms *u);

/* The rows [rows[0], rows[1]) holding every pixel whose ray may meet the ground (below the
 * horizon, cos zenith < horizon_cos, frame uniforms' horizon.z); false when none may. */
bool sky_uniforms_ground_rows(const struct sky_render_view *v, double horizon_cos,
                              uint32_t rows[2]);
/* The sun disk's bounding box in pixels (x0, y0, width, height) with a margin, clipped to the
 * image; false when the sun is not on screen. */
bool sky_uniforms_sun_rect(const struct sky_render_view *v, int32_t rect[4]);
/* The same for any disc: toward unit local direction `dir`, of the given angular diameter. */
bool sky_uniforms_disk_rect(const struct sky_render_view *v, const double dir[3],
                            double angular_diameter_deg, int32_t rect[4]);

#endif
