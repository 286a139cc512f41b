/* Photometric conversions for the sun and the camera (seed 001 section 4.1; Lagarde & de
 * Rousiers 2014 for exposure). Pure functions. */
#ifndef SKYD_PHOTOMETRY_H
#define SKYD_PHOTOMETRY_H

struct sky_render_atmosphere;

/* Solid angle of a disk of the given angular diameter: 2 pi (1 - cos(theta / 2)) (eq. 14). */
double sky_disk_solid_angle(double angular_diameter_deg);

/* Transmittance from the ground straight up to the top of the atmosphere, per channel. */
void sky_zenith_transmittance(const struct sky_render_atmosphere *atmosphere, double out[3]);

/* Extraterrestrial sun illuminance per channel such that the ground illuminance with the sun
 * at zenith is `ground_zenith_lux`: E_top = E_zenith / T_zenith (seed 001 section 4.1). */
/* sun.illuminance_lux is the ground's with the sun at the zenith, so the illuminance outside
 * the atmosphere is that over the zenith transmittance. An opaque atmosphere (a valid state:
 * Mie absorption of 10 /km gives e^-110) would need an astronomical E_top whose products
 * overflow single precision into inf and NaN; the transmittance is taken as at least this,
 * so such a sky stays finite and dark. */
#define SKY_MIN_ZENITH_TRANSMITTANCE 1e-12

void sky_sun_illuminance_top(const struct sky_render_atmosphere *atmosphere,
                             double ground_zenith_lux, double out[3]);

/* Sun disk luminance outside the atmosphere: E_top / solid angle (seed 001 eq. 16). */
double sky_sun_disk_luminance(double illuminance_top, double angular_diameter_deg);

/* EV100 -> exposure multiplier 1 / (1.2 * 2^EV100) (saturation-based sensitivity). */
double sky_ev100_to_exposure(double ev100);
/* Average luminance -> EV100 = log2(L * 100 / 12.5) (reflected-light meter, K = 12.5). */
double sky_luminance_to_ev100(double average_luminance);

/* Photometric luminance of a linear Rec.709/sRGB triple. */
double sky_rgb_to_luminance(const double rgb[3]);

#endif
