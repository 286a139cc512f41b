/* Double-precision brute-force CPU reference for a Hillaire-2020-style atmosphere.
 *
 * Written from the radiative transfer equation directly: no look-up tables, no
 * multiple-scattering approximation. Used by the tests to judge the GPU renderer.
 *
 * Conventions
 *   - Lengths in km, coefficients per km. The planet is centred at the origin; the camera
 *     sits at (0, 0, bottom_radius + altitude) in a local frame with z up, x east, y north.
 *     Every direction argument is given in that frame and is normalised internally.
 *   - h is the altitude above bottom_radius. The medium exists for bottom <= r <= top only;
 *     the camera may be anywhere at or above the ground (altitude >= 0), including above the
 *     atmosphere.
 *   - Densities: Rayleigh and Mie exp(-h/H); ozone tent max(0, 1 - |h - peak| / (width/2));
 *     fog is grey scattering fog_density * exp(-h/fog_scale_height) with the Mie phase.
 *     Scale heights must be > 0 (fog_scale_height only matters when fog_density > 0),
 *     |mie_g| < 1.
 *   - Phase functions take cos_theta = dot(ray direction away from the camera,
 *     direction toward the light source).
 *   - The sun is a directional light with unit extraterrestrial irradiance per channel
 *     (perpendicular to the sun direction). Radiances are per unit irradiance (1/sr),
 *     irradiances are dimensionless. The direct view of the sun disk is never included.
 *   - Scattering orders: each volume scattering event and each ground reflection counts
 *     as one order; order 1 is single scattering plus the directly sun-lit ground.
 *
 * Thread safety: every function is reentrant (no global state). The Monte Carlo
 * functions start `threads` POSIX threads internally and join them before returning.
 * Their results are bit-identical for the same seed whatever `threads` is: path i always
 * uses its own RNG stream derived from (seed, i), and partial sums are reduced in a fixed
 * order.
 *
 * Monte Carlo: paths are shared by the three channels (spectral MIS over the channels'
 * free-flight and phase-function pdfs), so `paths` is the number of paths for every channel.
 * std_error (may be NULL) receives the standard error of the Monte Carlo part per channel
 * (sample standard deviation of the per-path estimates / sqrt(paths)).
 */
#ifndef SKYD_ATMOSPHERE_REFERENCE_H
#define SKYD_ATMOSPHERE_REFERENCE_H

#include <stdint.h>

struct ref_atmosphere {
    double bottom_radius, top_radius;
    double rayleigh_scattering[3];
    double rayleigh_scale_height;
    double mie_scattering[3];
    double mie_absorption[3];
    double mie_scale_height;
    double mie_g[3];
    double ozone_absorption[3];
    double ozone_peak_altitude;
    double ozone_width;
    double ground_albedo[3];
    double fog_density;
    double fog_scale_height;
};

/* Earth-like defaults: radii 6360/6460, Rayleigh (5.802, 13.558, 33.1)e-3 H 8, Mie
 * scattering 3.996e-3 absorption 0.444e-3 H 1.2 g 0.8, ozone (0.650, 1.881, 0.085)e-3
 * peak 25 width 30, ground albedo 0.3, no fog. */
void ref_atmosphere_earth(struct ref_atmosphere *a);

/* Phase functions (1/sr), normalised over the sphere. */
double ref_phase_rayleigh(double cos_theta);
double ref_phase_mie(double cos_theta, double g); /* Cornette-Shanks */

/* Intersections of the ray o + t d (d unit length) with the sphere |x| = radius at the
 * origin. Returns 0 when the line misses, else 1 with *t_near <= *t_far (either may be
 * negative). */
int ref_ray_sphere(const double o[3], const double d[3], double radius, double *t_near,
                   double *t_far);

/* Transmittance from the point at `altitude` along the direction with cosine-zenith mu to
 * the top of the atmosphere (1 beyond it); 0 if the ray hits the ground. 5-point
 * Gauss-Legendre on pieces between spherical shells spaced by step_scale * 2 scale heights
 * (plus the ozone kinks); the optical depth is accurate to ~1e-11 relative at the default
 * step_scale 0.5, ~3e-7 at 3 (the value the Monte Carlo uses). */
void ref_transmittance(const struct ref_atmosphere *a, double altitude, double mu, double out[3]);
void ref_transmittance_ex(const struct ref_atmosphere *a, double altitude, double mu,
                          double step_scale, double out[3]);

/* Transmittance along the straight segment between two points given in planet-centred
 * coordinates (km); 0 if the segment passes through the planet. */
void ref_transmittance_segment(const struct ref_atmosphere *a, const double p0[3],
                               const double p1[3], double out[3]);

/* Single-scattered radiance toward the camera along the view ray (to the top of the
 * atmosphere or to the ground), plus, when the view ray hits the ground, the directly
 * sun-lit Lambertian ground attenuated to the camera. Adaptive Gauss-Kronrod (7-15)
 * quadrature on pieces split at shell crossings and at the planet's shadow boundary; the
 * tests find it within ~1e-8 relative of a far finer run. About 3-5 ms per call. The _ex
 * variant takes the shell step scale (default 0.5) and the relative tolerance (1e-7). */
void ref_single_scattering(const struct ref_atmosphere *a, double altitude,
                           const double view_dir[3], const double sun_dir[3], double out[3]);
void ref_single_scattering_ex(const struct ref_atmosphere *a, double altitude,
                              const double view_dir[3], const double sun_dir[3], double step_scale,
                              double rel_tol, double out[3]);

/* Monte Carlo estimate of the radiance carried by scattering orders min_order..max_order
 * (min_order >= 1), by path tracing from the camera with next-event estimation toward the
 * sun. Unbiased (up to the ~1e-7 quadrature error of optical depths): free-flight sampling
 * by inverting the optical depth, forced collisions, Lambertian ground with cosine
 * sampling, absorption carried in the path weights, Russian roulette from the third vertex
 * on. Increasing max_order with the same seed never decreases any channel. */
void ref_radiance_mc(const struct ref_atmosphere *a, double altitude, const double view_dir[3],
                     const double sun_dir[3], int min_order, int max_order, int paths,
                     uint64_t seed, int threads, double out[3], double std_error[3]);

/* How the Monte Carlo estimates the sunlight scattered on each segment of a path.
 *   REF_MC_SUNLIT_SEGMENTS (what every function here uses): a segment whose line crosses the
 *     planet's shadow gets the expected value of its sun-lit in-scattering from points drawn
 *     in its sunlit parts only; the others from the path's collision on them. In twilight
 *     most collisions fall in the shadow and the light comes from a thin sunlit stretch far
 *     up, so this cuts the variance there by a large factor.
 *   REF_MC_COLLISION_ONLY: every segment from its collision alone (the simpler estimator;
 *     the tests check that the two agree). */
enum ref_mc_estimator { REF_MC_SUNLIT_SEGMENTS, REF_MC_COLLISION_ONLY };

/* ref_radiance_mc with a chosen estimator. */
void ref_radiance_mc_estimator(const struct ref_atmosphere *a, double altitude,
                               const double view_dir[3], const double sun_dir[3], int min_order,
                               int max_order, int paths, uint64_t seed, int threads,
                               enum ref_mc_estimator estimator, double out[3], double std_error[3]);

/* Total radiance of orders 1..max_order: order 1 from ref_single_scattering, orders
 * 2..max_order from ref_radiance_mc (same paths, seeds and result as that call).
 * std_error is that of the Monte Carlo part. Cost on 2 threads for the Earth defaults,
 * orders <= 10: ~15-30 us per path; ~20k paths reach 0.3% for most sky views with the sun
 * at 10-90 deg (near-horizon views up to ~50k; twilight needs several times more). */
void ref_radiance(const struct ref_atmosphere *a, double altitude, const double view_dir[3],
                  const double sun_dir[3], int max_order, int paths, uint64_t seed, int threads,
                  double out[3], double std_error[3]);

/* A uniform double in [0, 1) from a splitmix64 stream (Steele et al. 2014) whose state is
 * *state: the generator of the Monte Carlo's paths, for tests that draw their own samples. */
double ref_uniform(uint64_t *state);

/* ref_radiance with the path count chosen for a target precision: runs batches of paths
 * (min_paths first, then about as many as the measured variance says are still needed) until
 * max over channels of std_error / radiance <= rel_error, or max_paths have run. The result is
 * deterministic for given arguments (path i always uses stream (seed, i)). *paths_used (may be
 * NULL) receives the number of paths run. */
void ref_radiance_adaptive(const struct ref_atmosphere *a, double altitude,
                           const double view_dir[3], const double sun_dir[3], int max_order,
                           double rel_error, int min_paths, int max_paths, uint64_t seed,
                           int threads, double out[3], double std_error[3], int *paths_used);

/* Irradiance from the sky (orders 1..max_order, all by Monte Carlo, direct sun excluded)
 * on a horizontal surface at `altitude`: facing_up != 0 gives the downward flux through
 * a surface with normal +z (light from the upper hemisphere), facing_up == 0 the upward
 * flux from the lower hemisphere (e.g. at the top of the atmosphere). Cosine-weighted
 * directions, one path per direction. */
void ref_irradiance(const struct ref_atmosphere *a, double altitude, int facing_up,
                    const double sun_dir[3], int max_order, int paths, uint64_t seed, int threads,
                    double out[3], double std_error[3]);

/* ref_irradiance on the ground (altitude 0, normal up). */
void ref_sky_irradiance(const struct ref_atmosphere *a, const double sun_dir[3], int max_order,
                        int paths, uint64_t seed, int threads, double out[3], double std_error[3]);

#endif
