#include "illuminance.h"

#include <math.h>
#include <stdlib.h>

#include "sky_photometry.h"

#define PI 3.14159265358979323846
#define DEG (PI / 180.0)
/* Hemisphere quadrature for sky illuminance: midpoint rule in zenith and azimuth. */
#define HOST_ZENITH_STEPS 48
#define HOST_AZIMUTH_STEPS 96

static void local_direction(double zenith, double azimuth, double out[3])
{
    out[0] = sin(azimuth) * sin(zenith);
    out[1] = cos(azimuth) * sin(zenith);
    out[2] = cos(zenith);
}

int host_ground_illuminance(struct sky_renderer *r, const struct sky_render_atmosphere *atm,
                            const struct sky_render_view *sun_view, double sun_zenith_deg,
                            double *sun_lux, double *sky_lux)
{
    struct sky_render_view view = *sun_view;
    view.camera_altitude_km = 0.0;
    view.sun_elevation_deg = 90.0 - sun_zenith_deg;

    /* Sun: E_top * T(ground -> sun) * cos(zenith), zero below the horizon. */
    double mu_s = cos(sun_zenith_deg * DEG), ground = 0.0, t[1][3], e_top[3], sun_rgb[3];
    if (sky_renderer_probe_transmittance(r, atm, &ground, &mu_s, 1, t) != 0)
        return -1;
    sky_sun_illuminance_top(atm, view.sun_illuminance_lux, e_top);
    for (int ch = 0; ch < 3; ch++)
        sun_rgb[ch] = mu_s > 0.0 ? e_top[ch] * t[0][ch] * mu_s : 0.0;

    /* Sky: E = sum of L cos(theta) sin(theta) dtheta dphi over the upper hemisphere. */
    size_t n = HOST_ZENITH_STEPS * HOST_AZIMUTH_STEPS;
    double(*dirs)[3] = malloc(n * sizeof *dirs);
    double(*lum)[3] = malloc(n * sizeof *lum);
    int status = -1;
    if (!dirs || !lum)
        goto done;
    double d_theta = 0.5 * PI / HOST_ZENITH_STEPS, d_phi = 2.0 * PI / HOST_AZIMUTH_STEPS;
    for (int i = 0; i < HOST_ZENITH_STEPS; i++)
        for (int j = 0; j < HOST_AZIMUTH_STEPS; j++)
            local_direction((i + 0.5) * d_theta, (j + 0.5) * d_phi,
                            dirs[i * HOST_AZIMUTH_STEPS + j]);
    if (sky_renderer_probe_luminance(r, atm, &view, (const double(*)[3])dirs, n, false, lum) != 0)
        goto done;
    double sky_rgb[3] = { 0, 0, 0 };
    for (int i = 0; i < HOST_ZENITH_STEPS; i++) {
        double theta = (i + 0.5) * d_theta;
        double w = cos(theta) * sin(theta) * d_theta * d_phi;
        for (int j = 0; j < HOST_AZIMUTH_STEPS; j++)
            for (int ch = 0; ch < 3; ch++)
                sky_rgb[ch] += lum[i * HOST_AZIMUTH_STEPS + j][ch] * w;
    }
    *sun_lux = sky_rgb_to_luminance(sun_rgb);
    *sky_lux = sky_rgb_to_luminance(sky_rgb);
    status = 0;
done:
    free(dirs);
    free(lum);
    return status;
}
