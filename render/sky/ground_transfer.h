/* The ground's share of the multiple-scattering transfer (an extension of Hillaire 2020's
 * f_ms): with every scattering point re-emitting an isotropic unit source per unit scattering
 * coefficient, the radiance the ground reflects is albedo * A, where
 *   A = (1/pi) * integral over the upper hemisphere of [ integral_0^top T(t) sigma_s(t) dt ] cos
 * seen from the ground. A depends on the atmosphere alone. */
#ifndef SKYD_GROUND_TRANSFER_H
#define SKYD_GROUND_TRANSFER_H

struct sky_render_atmosphere;

/* A per channel: Gauss-Legendre in zenith, a midpoint rule along each ray. */
void sky_ground_transfer(const struct sky_render_atmosphere *atmosphere, double out[3]);

#endif
