#include "probe_query.h"

#include <math.h>
#include <string.h>

#include "illuminance.h"
#include "world_render.h"

#define PI 3.14159265358979323846
#define DEG (PI / 180.0)

/* Local frame at the camera: x east, y north, z up; azimuth from north through east. */
static void local_direction(double zenith_deg, double azimuth_deg, double out[3])
{
    double z = zenith_deg * DEG, az = azimuth_deg * DEG;
    out[0] = sin(az) * sin(z);
    out[1] = cos(az) * sin(z);
    out[2] = cos(z);
}

int probe_query_run(struct sky_renderer *renderer, const struct render_input *input,
                    const struct proto_msg_probe *query, struct proto_msg_probe_result *result)
{
    /* The state's own atmosphere, not the one frames are still being moved to. */
    struct sky_render_atmosphere atm = input->atmosphere;
    struct sky_render_view view;
    const struct proto_msg_view pixel = { .width = 1,
                                          .height = 1,
                                          .format = PROTO_FRAME_FORMAT_PNG16 };
    world_render_view(input, &pixel, &view);
    sky_renderer_set_night(renderer, &input->night);
    memset(result, 0, sizeof *result);
    result->quantity = query->quantity;
    int rc = -1;
    switch (query->quantity) {
    case PROTO_PROBE_TRANSMITTANCE:
        return sky_renderer_probe_transmittance(renderer, &atm, &query->altitude_km, &query->mu, 1,
                                                &result->rgb);
    case PROTO_PROBE_LUMINANCE: {
        view.camera_altitude_km = query->altitude_km;
        view.sun_elevation_deg = 90.0 - query->sun_zenith_deg;
        double dir[1][3];
        local_direction(query->view_zenith_deg, view.sun_azimuth_deg + query->view_azimuth_deg,
                        dir[0]);
        rc = sky_renderer_probe_luminance(renderer, &atm, &view, (const double(*)[3])dir, 1, true,
                                          &result->rgb);
        break;
    }
    case PROTO_PROBE_ILLUMINANCE:
        rc = host_ground_illuminance(renderer, &atm, &view, query->sun_zenith_deg, &result->sun_lux,
                                     &result->sky_lux);
        break;
    }
    /* Which multiple scattering answered (ms_refine.h): the best there is now. */
    struct sky_render_multiple_scattering ms;
    sky_renderer_multiple_scattering(renderer, &ms);
    result->multiple_scattering = ms.weight >= 1.0  ? "converged"
                                  : ms.weight > 0.0 ? "blending"
                                                    : "fast";
    return rc;
}
