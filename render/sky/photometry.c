#include "sky_photometry.h"

#include <math.h>

#include "sky_renderer.h"

#define PI 3.14159265358979323846

double sky_disk_solid_angle(double angular_diameter_deg)
{
    double half = 0.5 * angular_diameter_deg * PI / 180.0;
    return 2.0 * PI * (1.0 - cos(half));
}

static double ozone_tent(double h, double peak, double width)
{
    double v = 1.0 - fabs(h - peak) / (0.5 * width);
    return v > 0.0 ? v : 0.0;
}

void sky_zenith_transmittance(const struct sky_render_atmosphere *a, double out[3])
{
    /* Vertical optical depth by the composite midpoint rule on 1 m steps: the integrand is
     * smooth except at the ozone tent's kinks, which the fine grid resolves. */
    double thickness = a->top_radius_km - a->bottom_radius_km;
    int steps = (int)ceil(thickness * 1000.0);
    if (steps < 1000)
        steps = 1000;
    double dh = thickness / steps;
    double depth[3] = { 0, 0, 0 };
    for (int i = 0; i < steps; i++) {
        double h = (i + 0.5) * dh;
        double rayleigh = exp(-h / a->rayleigh_scale_height_km);
        double mie = exp(-h / a->mie_scale_height_km);
        double fog = a->fog_density_per_km * exp(-h / a->fog_scale_height_km);
        double ozone = ozone_tent(h, a->ozone_peak_km, a->ozone_width_km);
        for (int c = 0; c < 3; c++) {
            depth[c] += (a->rayleigh_scattering[c] * rayleigh +
                         (a->mie_scattering[c] + a->mie_absorption[c]) * mie + fog +
                         a->ozone_absorption[c] * ozone) *
                        dh;
        }
    }
    for (int c = 0; c < 3; c++)
        out[c] = exp(-depth[c]);
}

void sky_sun_illuminance_top(const struct sky_render_atmosphere *atmosphere,
                             double ground_zenith_lux, double out[3])
{
    double t[3];
    sky_zenith_transmittance(atmosphere, t);
    for (int c = 0; c < 3; c++)
        out[c] = ground_zenith_lux / fmax(t[c], SKY_MIN_ZENITH_TRANSMITTANCE);
}

double sky_sun_disk_luminance(double illuminance_top, double angular_diameter_deg)
{
    return illuminance_top / sky_disk_solid_angle(angular_diameter_deg);
}

double sky_ev100_to_exposure(double ev100)
{
    return 1.0 / (1.2 * pow(2.0, ev100));
}

double sky_luminance_to_ev100(double average_luminance)
{
    return log2(average_luminance * 100.0 / 12.5);
}

double sky_rgb_to_luminance(const double rgb[3])
{
    return 0.2126 * rgb[0] + 0.7152 * rgb[1] + 0.0722 * rgb[2];
}
