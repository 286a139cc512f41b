/* What the files of test_cloud_accuracy share (see test_cloud_accuracy.c): the cases (optical
 * depths and sun cosines), the options, the answers, and the device harness:
 *   test_cloud_accuracy.c          the comparison with the Monte Carlo, main
 *   test_cloud_accuracy_options.c  the command line
 *   test_cloud_accuracy_harness.c  the renderer's march on the device
 * All files count into check.h's one set of counters. */
#ifndef SKYD_TEST_CLOUD_ACCURACY_H
#define SKYD_TEST_CLOUD_ACCURACY_H

#include <math.h>
#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "cloud_mc_reference.h"
#include "compute_pass.h"
#include "vk_context.h"
#include "vk_resources.h"
#include "world_state.h"

#define PI 3.14159265358979323846
#define NTAU 7
#define NMU0 3
#define NCASE (NTAU * NMU0)
#define NBIN CLOUD_MC_BINS
#define MAX_LIST 16
#define MAX_NODES 8
#define MC_THREADS 2

/* The cases: every optical depth with every sun cosine, case ci = tau index * NMU0 + mu0
 * index. */
extern const double slab_taus[NTAU];
extern const double slab_mu0s[NMU0];

/* The relative errors divide by max(reference, floor): by default 1 % of the incident flux
 * (see the bounds in test_cloud_accuracy.c). */
#define DEFAULT_FLOOR 0.01

struct list {
    double v[MAX_LIST];
    int n;
};

struct options {
    struct list a, b, c, octaves, powder, g0, g1, w;
    double albedo;
    int primary_steps, light_steps;
    long photons;
    double thickness_km; /* 0: tau / default extinction */
    double radius_km;
    int jitters, azimuths, nodes;
    double floor;
    bool verbose;
    bool single; /* octaves 1 against exact single scattering instead of the tracer */
    bool sweep;  /* a list was given */
};

/* R and T_diffuse with their radiance factors per bin (pi L / (E mu0), mu-weighted bin mean). */
struct slab_answer {
    double R, T, reflect[NBIN], transmit[NBIN];
    double R_stderr, T_stderr;
};

struct phase_set {
    double g0, g1, w;
};
struct octave_set {
    double a, b, c;
    int octaves;
    double powder; /* the build-up rate below a lit surface (clouds.multiscatter.powder) */
};

struct harness {
    struct vk_context *ctx;
    struct compute_pass pass;
    struct gpu_buffer atmo, frame, cloud, cases, rays, results;
    struct gpu_image transmittance, multiscattering, irradiance, base, detail, curl, weather,
        sun_depth, skyview;
    VkSampler sampler;
    uint32_t ray_count;
};

/* Rays per case: 2 sides x NBIN bins x nodes x azimuths x jitters. */
static inline uint32_t rays_per_case(const struct options *o)
{
    return (uint32_t)(2 * NBIN * o->nodes * o->azimuths * o->jitters);
}

/* test_cloud_accuracy_options.c: the defaults from `state`, then the arguments; false (with
 * a message on stderr) when they are not understood. */
bool slab_parse_options(int argc, char **argv, const struct proto_world_state *state,
                        struct options *o);

/* test_cloud_accuracy_harness.c */
bool slab_harness_create(struct vk_context *ctx, const struct options *o, struct harness *h);
bool slab_harness_run(struct harness *h, const struct proto_world_state *state,
                      const struct options *o, const struct phase_set *ph,
                      const struct octave_set *os, struct slab_answer out[NCASE]);
void slab_harness_destroy(struct harness *h);

#endif
