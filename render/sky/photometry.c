#include "sky_photometry.h"

#include <math.h>

#include "sky_renderer.h"

#define PI 3.14159265358979323846

double sky_disk_solid_angle(double angular_diameter_deg)
{
    double half = 0.5 * angular_diameter_deg * PI / 180.0;
    return 2.0 * PI * (1.0 - cos(half));
}

/* Integral from 0 to x of the ozone's tent max(0, 1 - |h - peak| / half), half = width / 2. */
static double ozone_tent_area_below(double x, double peak, double width)
{
    double half = 0.5 * width;
    if (!(half > 0.0) || x <= peak - half)
        return 0.0;
    if (x >= peak + half)
        return half;
    if (x <= peak) {
        double d = x - (peak - half);
        return d * d / (2.0 * half);
    }
    double d = peak + half - x;
    return half - d * d / (2.0 * half);
}

/* Integral from 0 to h of exp(-z / scale) dz. */
static double exponential_column(double h, double scale)
{
    return scale > 0.0 ? -scale * expm1(-h / scale) : 0.0;
}

void sky_zenith_transmittance(const struct sky_render_atmosphere *a, double out[3])
{
    /* Tr = exp(-integral of sigma_t) along the vertical (seed 001), the integral in closed
     * form: every profile (exponentials, the ozone tent) integrates exactly, so a quadrature
     * would only add error and CPU time to each rebuild. */
    double thickness = a->top_radius_km - a->bottom_radius_km;
    double rayleigh = exponential_column(thickness, a->rayleigh_scale_height_km);
    double mie = exponential_column(thickness, a->mie_scale_height_km);
    double fog = a->fog_density_per_km * exponential_column(thickness, a->fog_scale_height_km);
    double ozone = ozone_tent_area_below(thickness, a->ozone_peak_km, a->ozone_width_km) -
                   ozone_tent_area_below(0.0, a->ozone_peak_km, a->ozone_width_km);
    for (int c = 0; c < 3; c++) {
        double depth = a->rayleigh_scattering[c] * rayleigh +
                       (a->mie_scattering[c] + a->mie_absorption[c]) * mie + fog +
                       a->ozone_absorption[c] * ozone;
        out[c] = exp(-depth);
    }
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
