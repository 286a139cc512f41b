/* Double-precision Monte Carlo reference for light transport in a homogeneous plane-parallel
 * cloud deck, to calibrate the renderer's multiple-scattering approximation (Wrenninge's
 * octaves, seed 000 eq. 14.18) against.
 *
 * Method: the standard Monte Carlo radiative-transfer photon tracer (Witt 1977, ApJS 35, 1):
 * weighted photons, free paths by inverting exp(-tau), absorption carried in the weights
 * (multiplied by omega at each scattering) with Russian roulette, the first collision forced
 * inside the slab (the unscattered beam is the analytic T_direct).
 *
 * The slab
 *   - Homogeneous, optical depth tau (> 0; 0.01..128 is the tested range), single-scattering
 *     albedo omega in (0, 1], no ground below it, nothing above it.
 *   - Phase: the renderer's dual-lobe Henyey-Greenstein (seed 000 eq. 14.17)
 *       p(c) = p_HG(c, g0) + w (p_HG(c, g1) - p_HG(c, g0)),   |g0|, |g1| < 1, 0 <= w <= 1,
 *     sampled by picking lobe g1 with probability w, else g0, then inverting HG exactly.
 *     Its mean cosine is (1 - w) g0 + w g1.
 *   - A parallel sun beam of irradiance E (perpendicular to the beam) falls on the top at the
 *     cosine mu0 in (0, 1]; the incident flux through the top is E mu0.
 *
 * Results (all per unit incident flux E mu0)
 *   - R: diffusely reflected flux; T_diffuse: flux leaving the bottom after >= 1 scattering;
 *     T_direct = exp(-tau / mu0) (analytic); absorbed. R + T_diffuse + T_direct + absorbed = 1
 *     up to Monte Carlo noise (exactly, up to rounding, when omega = 1).
 *   - Radiance factors, averaged over azimuth, in CLOUD_MC_BINS equal bins of the outgoing
 *     direction's cosine to the slab normal, mu (bin b covers b/N < mu <= (b+1)/N):
 *       rho(mu) = pi L(mu) / (E mu0)   (the BRDF times pi; 1 everywhere for a white
 *     Lambertian surface), estimated as (flux fraction leaving through the bin) /
 *     (mu_hi^2 - mu_lo^2); i.e. the bin average of rho weighted by mu dmu. reflect_factor at
 *     the top (upward directions), transmit_factor at the bottom (downward, diffuse only).
 *     Summing factor[b] * (mu_hi^2 - mu_lo^2) over the bins gives R (resp. T_diffuse).
 *   - *_stderr: standard errors (sample standard deviation of the per-photon contributions
 *     / sqrt(photons)).
 *
 * Determinism: photons run in fixed chunks, each with its own xoshiro256** stream seeded by
 * splitmix64 from (seed, chunk); chunk sums are reduced in chunk order. The result is
 * bit-identical for the same slab and seed whatever the thread count.
 *
 * Cost: roughly 0.1-0.2 us per scattering event per thread; a photon scatters ~1 + O(tau)
 * times in a thick slab (on average ~67 at tau 64, omega 0.99; ~160 at omega 1).
 */
#ifndef SKYD_CLOUD_MC_REFERENCE_H
#define SKYD_CLOUD_MC_REFERENCE_H

#define CLOUD_MC_BINS 8

struct cloud_mc_slab {
    double tau;              /* optical depth, > 0 */
    double omega;            /* single-scattering albedo, (0, 1] */
    double mu0;              /* cosine of the sun's zenith angle, (0, 1] */
    double g0, g1, w;        /* dual-lobe HG phase (seed 000 eq. 14.17) */
    long photons;            /* >= 2 */
    unsigned long long seed; /* any value */
    int threads;             /* >= 1 (capped at 64) */
};

struct cloud_mc_result {
    double R, T_diffuse, T_direct, absorbed;
    double R_stderr, T_stderr, absorbed_stderr; /* T_stderr is that of T_diffuse */
    double reflect_factor[CLOUD_MC_BINS], transmit_factor[CLOUD_MC_BINS];
    double reflect_factor_stderr[CLOUD_MC_BINS], transmit_factor_stderr[CLOUD_MC_BINS];
    double mean_scatterings; /* collisions per photon (incl. the one a roulette ends) */
};

/* Runs the tracer. Returns 0 on success, -1 (and leaves *out zeroed) if an argument is out
 * of range or memory runs out. Reentrant; starts in->threads - 1 POSIX threads and joins
 * them before returning (works on in the calling thread if one cannot be started). */
int cloud_mc_slab_run(const struct cloud_mc_slab *in, struct cloud_mc_result *out);

/* The edges of radiance-factor bin b (0 <= b < CLOUD_MC_BINS): lo = b/N, hi = (b+1)/N. */
void cloud_mc_bin_edges(int b, double *mu_lo, double *mu_hi);

/* The dual-lobe phase function (1/sr, normalised over the sphere) at the scattering-angle
 * cosine c, as above; the tests use it for the single-scattering limit. */
double cloud_mc_phase(double c, double g0, double g1, double w);

/* n-point Gauss-Legendre nodes xs[] and weights ws[] on (lo, hi): the quadrature over outgoing
 * cosines that the deck's references and the renderer's comparison share. */
void cloud_gauss_legendre(int n, double lo, double hi, double *xs, double *ws);

#endif
