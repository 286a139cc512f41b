/* Horizontal illuminance at the ground from the sun disk and from the sky, through the
 * renderer's own LUTs and shading (what `skyd probe illuminance` prints). */
#ifndef SKYD_ILLUMINANCE_H
#define SKYD_ILLUMINANCE_H

#include "sky_renderer.h"

/* `view` supplies the sun's photometry (illuminance, size, limb darkening); the camera is put
 * on the ground and the sun at sun_zenith_deg. Returns 0 or -1. */
int host_ground_illuminance(struct sky_renderer *renderer,
                            const struct sky_render_atmosphere *atmosphere,
                            const struct sky_render_view *view, double sun_zenith_deg,
                            double *sun_lux, double *sky_lux);

#endif
