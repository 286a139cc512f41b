#include "ms_refine.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "compute_pass.h"
#include "gpu_timer.h"
#include "sky_layouts.h"
#include "sky_shared.h"
#include "vk_check.h"
#include "vk_context.h"
#include "vk_resources.h"

#include "sky_shaders.h"

#define TABLE_WIDTH (SKY_MS_NU * SKY_MS_MU_S)
/* A slice: one workgroup's SKY_MS_LOCAL texels (row-major). */
#define TABLE_TEXELS (TABLE_WIDTH * SKY_MS_MU * SKY_MS_R)
#define TABLE_SLICES ((TABLE_TEXELS + SKY_MS_LOCAL - 1) / SKY_MS_LOCAL)
/* The moments: one invocation per (mu_s, r). */
#define MOMENT_POINTS (SKY_MS_MU_S * SKY_MS_R)
#define MOMENT_SLICES ((MOMENT_POINTS + SKY_MS_LOCAL - 1) / SKY_MS_LOCAL)
/* Starting guesses of GPU ms per slice on lavapipe (2 cores); measured times replace them. */
#define INITIAL_MS_PER_RADIANCE_SLICE 0.025
#define INITIAL_MS_PER_DENSITY_SLICE 0.04
#define INITIAL_MS_GROUND 0.5
#define INITIAL_MS_PER_MOMENT_SLICE 0.2

enum step_kind { STEP_DENSITY, STEP_RADIANCE, STEP_GROUND, STEP_MOMENTS, STEP_KINDS };
enum state { STATE_EMPTY, STATE_BUILDING, STATE_COMPLETE };

/* Order n: the moments of L_{n-1} and the density J_n from them and L_{n-1} (n >= 2), the
 * radiance L_n, the ground irradiance E_n (n < last). */
#define STEP_COUNT (4 * MS_REFINE_ORDERS - 3)
struct step {
    enum step_kind kind;
    uint32_t order;
};

static const char *const pass_names[STEP_KINDS] = { "ms_density", "ms_radiance", "ms_ground",
                                                    "ms_moments" };

struct ms_refine {
    /* The order's radiance ping-pongs between two tables (L_n and L_{n-1}). */
    struct gpu_image radiance[2], density, sum, ground, moments;
    /* Per kind, one pass per radiance table it reads or writes (the order's parity) and per
     * variant (variant_of: radiance of order 1 or >= 2, density of order 2 or >= 3; the ground
     * has one). */
    struct compute_pass pass[STEP_KINDS][2][2];
    struct step steps[STEP_COUNT];
    enum state state;
    struct sky_render_atmosphere built_for; /* the table's atmosphere (building or complete) */
    uint32_t step, next_slice;
    double weight, last_now, build_start, build_seconds;
    double ms_per_slice[STEP_KINDS]; /* per slice; ground: per dispatch */
    bool warmed;                     /* every pipeline has run once */
    /* Slices of each dispatch recorded this frame, per kind in recording order: the timer's
     * marks come back in that order, one per dispatch. */
    uint32_t pending[STEP_KINDS][8], pending_head[STEP_KINDS], pending_count[STEP_KINDS];
};

/* clang-format off */
static const struct compute_pass_desc descs[STEP_KINDS] = {
    [STEP_DENSITY] = { .name = "ms_density", .spirv = ms_density_spv,
                       .spirv_bytes = sizeof ms_density_spv,
                       SKY_PASS_LAYOUT(SKY_LAYOUT_MS_DENSITY),
                       .push_constant_bytes = sizeof(struct sky_ms_push) },
    [STEP_RADIANCE] = { .name = "ms_radiance", .spirv = ms_radiance_spv,
                        .spirv_bytes = sizeof ms_radiance_spv,
                        SKY_PASS_LAYOUT(SKY_LAYOUT_MS_RADIANCE),
                        .push_constant_bytes = sizeof(struct sky_ms_push) },
    [STEP_GROUND] = { .name = "ms_ground", .spirv = ms_ground_spv,
                      .spirv_bytes = sizeof ms_ground_spv, SKY_PASS_LAYOUT(SKY_LAYOUT_MS_GROUND) },
    [STEP_MOMENTS] = { .name = "ms_moments", .spirv = ms_moments_spv,
                       .spirv_bytes = sizeof ms_moments_spv,
                       SKY_PASS_LAYOUT(SKY_LAYOUT_MS_MOMENTS),
                       .push_constant_bytes = sizeof(struct sky_ms_push) },
};
/* clang-format on */

/* The pipeline variant an order takes (SKY_MS_CONST_HIGHER). */
static uint32_t variant_of(enum step_kind kind, uint32_t order)
{
    if (kind == STEP_RADIANCE)
        return order >= 2;
    if (kind == STEP_DENSITY)
        return order >= 3;
    return 0;
}

static uint32_t variant_count(enum step_kind kind)
{
    return kind == STEP_GROUND || kind == STEP_MOMENTS ? 1 : 2;
}

/* Slices of a step (the ground's is one dispatch). */
static uint32_t slices_of(enum step_kind kind)
{
    return kind == STEP_MOMENTS ? MOMENT_SLICES : kind == STEP_GROUND ? 1 : TABLE_SLICES;
}

static uint32_t points_of(enum step_kind kind)
{
    return kind == STEP_MOMENTS ? MOMENT_POINTS : TABLE_TEXELS;
}

struct ms_refine *ms_refine_create(struct vk_context *ctx)
{
    struct ms_refine *m = calloc(1, sizeof *m);
    if (!m)
        return NULL;
    m->build_seconds = NAN;
    m->ms_per_slice[STEP_DENSITY] = INITIAL_MS_PER_DENSITY_SLICE;
    m->ms_per_slice[STEP_RADIANCE] = INITIAL_MS_PER_RADIANCE_SLICE;
    m->ms_per_slice[STEP_GROUND] = INITIAL_MS_GROUND;
    m->ms_per_slice[STEP_MOMENTS] = INITIAL_MS_PER_MOMENT_SLICE;
    int n = 0;
    for (uint32_t order = 1; order <= MS_REFINE_ORDERS; order++) {
        if (order >= 2) {
            m->steps[n++] = (struct step){ STEP_MOMENTS, order };
            m->steps[n++] = (struct step){ STEP_DENSITY, order };
        }
        m->steps[n++] = (struct step){ STEP_RADIANCE, order };
        if (order < MS_REFINE_ORDERS)
            m->steps[n++] = (struct step){ STEP_GROUND, order };
    }
    const VkFormat f = VK_FORMAT_R32G32B32A32_SFLOAT;
    VK_CHECK_GOTO(gpu_image_create(ctx, f, TABLE_WIDTH, SKY_MS_MU, SKY_MS_R, "ms_radiance_even",
                                   &m->radiance[0]),
                  destroy_partial);
    VK_CHECK_GOTO(gpu_image_create(ctx, f, TABLE_WIDTH, SKY_MS_MU, SKY_MS_R, "ms_radiance_odd",
                                   &m->radiance[1]),
                  destroy_partial);
    VK_CHECK_GOTO(
        gpu_image_create(ctx, f, TABLE_WIDTH, SKY_MS_MU, SKY_MS_R, "ms_density", &m->density),
        destroy_partial);
    VK_CHECK_GOTO(gpu_image_create(ctx, f, TABLE_WIDTH, SKY_MS_MU, SKY_MS_R, "ms_sum", &m->sum),
                  destroy_partial);
    VK_CHECK_GOTO(gpu_image_create(ctx, f, SKY_MS_GROUND, 1, 1, "ms_ground", &m->ground),
                  destroy_partial);
    VK_CHECK_GOTO(gpu_image_create(ctx, f, SKY_MS_MOMENTS * SKY_MS_MU_S, SKY_MS_R, 1, "ms_moments",
                                   &m->moments),
                  destroy_partial);
    for (int k = 0; k < STEP_KINDS; k++)
        for (uint32_t v = 0; v < variant_count(k); v++) {
            struct compute_pass_desc desc = descs[k];
            if (variant_count(k) > 1) {
                desc.spec_count = 1;
                desc.spec_values[SKY_MS_CONST_HIGHER] = v;
            }
            for (int parity = 0; parity < 2; parity++)
                VK_CHECK_GOTO(compute_pass_create(ctx, &desc, &m->pass[k][parity][v]),
                              destroy_partial);
        }
    return m;
destroy_partial:
    ms_refine_destroy(ctx, &m);
    return NULL;
}

void ms_refine_destroy(struct vk_context *ctx, struct ms_refine **refine)
{
    struct ms_refine *m = refine ? *refine : NULL;
    if (!m)
        return;
    for (int k = 0; k < STEP_KINDS; k++)
        for (int parity = 0; parity < 2; parity++)
            for (int v = 0; v < 2; v++)
                compute_pass_destroy(ctx, &m->pass[k][parity][v]);
    gpu_image_destroy(ctx, &m->radiance[0]);
    gpu_image_destroy(ctx, &m->radiance[1]);
    gpu_image_destroy(ctx, &m->density);
    gpu_image_destroy(ctx, &m->sum);
    gpu_image_destroy(ctx, &m->ground);
    gpu_image_destroy(ctx, &m->moments);
    free(m);
    *refine = NULL;
}

void ms_refine_bind(struct vk_context *ctx, struct ms_refine *m,
                    const struct gpu_buffer *atmosphere_params,
                    const struct gpu_image *transmittance, VkSampler sampler)
{
    for (int parity = 0; parity < 2; parity++) {
        const struct gpu_image *own = &m->radiance[parity], *other = &m->radiance[1 - parity];
        struct compute_resource density[SKY_LAYOUT_COUNT(SKY_LAYOUT_MS_DENSITY)] = {
            [SKY_MS_DENSITY_ATMOSPHERE] = { .buffer = atmosphere_params },
            [SKY_MS_DENSITY_RADIANCE] = { .image = own, .sampler = sampler },
            [SKY_MS_DENSITY_OUT] = { .image = &m->density },
            [SKY_MS_DENSITY_MOMENTS] = { .image = &m->moments, .sampler = sampler },
        };
        for (int v = 0; v < 2; v++)
            compute_pass_bind(ctx, &m->pass[STEP_DENSITY][parity][v], density);
        struct compute_resource radiance[SKY_LAYOUT_COUNT(SKY_LAYOUT_MS_RADIANCE)] = {
            [SKY_MS_RADIANCE_ATMOSPHERE] = { .buffer = atmosphere_params },
            [SKY_MS_RADIANCE_TRANSMITTANCE] = { .image = transmittance, .sampler = sampler },
            [SKY_MS_RADIANCE_DENSITY] = { .image = &m->density, .sampler = sampler },
            [SKY_MS_RADIANCE_GROUND] = { .image = &m->ground, .sampler = sampler },
            [SKY_MS_RADIANCE_PREVIOUS] = { .image = other, .sampler = sampler },
            [SKY_MS_RADIANCE_OUT] = { .image = own },
            [SKY_MS_RADIANCE_SUM] = { .image = &m->sum },
        };
        for (int v = 0; v < 2; v++)
            compute_pass_bind(ctx, &m->pass[STEP_RADIANCE][parity][v], radiance);
        struct compute_resource ground[SKY_LAYOUT_COUNT(SKY_LAYOUT_MS_GROUND)] = {
            [SKY_MS_GROUND_ATMOSPHERE] = { .buffer = atmosphere_params },
            [SKY_MS_GROUND_RADIANCE] = { .image = own, .sampler = sampler },
            [SKY_MS_GROUND_OUT] = { .image = &m->ground },
        };
        compute_pass_bind(ctx, &m->pass[STEP_GROUND][parity][0], ground);
        struct compute_resource moments[SKY_LAYOUT_COUNT(SKY_LAYOUT_MS_MOMENTS)] = {
            [SKY_MS_MOMENTS_ATMOSPHERE] = { .buffer = atmosphere_params },
            [SKY_MS_MOMENTS_RADIANCE] = { .image = own, .sampler = sampler },
            [SKY_MS_MOMENTS_OUT] = { .image = &m->moments },
        };
        compute_pass_bind(ctx, &m->pass[STEP_MOMENTS][parity][0], moments);
    }
}

const struct gpu_image *ms_refine_table(const struct ms_refine *m)
{
    return &m->sum;
}

const struct gpu_image *ms_refine_image(const struct ms_refine *m, const char *name)
{
    const struct gpu_image *images[] = { &m->sum,         &m->density,     &m->ground,
                                         &m->radiance[0], &m->radiance[1], &m->moments };
    const char *const names[] = { "ms_sum",           "ms_density",      "ms_ground",
                                  "ms_radiance_even", "ms_radiance_odd", "ms_moments" };
    for (size_t i = 0; i < sizeof images / sizeof images[0]; i++)
        if (strcmp(name, names[i]) == 0)
            return images[i];
    return NULL;
}

void ms_refine_invalidate(struct ms_refine *m)
{
    m->state = STATE_EMPTY;
    m->weight = 0.0;
}

static bool same_atmosphere(const struct sky_render_atmosphere *a,
                            const struct sky_render_atmosphere *b)
{
    return memcmp(a, b, sizeof *a) == 0;
}

static void start(struct ms_refine *m, const struct sky_render_atmosphere *a, double now_s)
{
    m->built_for = *a;
    m->state = STATE_BUILDING;
    m->step = 0;
    m->next_slice = 0;
    m->build_start = now_s;
}

/* Records `slices` slices (or the ground's one dispatch) of the current step. */
static void record_step(struct ms_refine *m, VkCommandBuffer cmd, struct gpu_timer *timer,
                        uint32_t slices)
{
    const struct step *s = &m->steps[m->step];
    /* Moments and density J_n read L_{n-1}; radiance and ground of order n write / read L_n. */
    bool previous = s->kind == STEP_DENSITY || s->kind == STEP_MOMENTS;
    uint32_t parity = (previous ? s->order - 1 : s->order) % 2;
    struct sky_ms_push push = { .order = s->order,
                                .first = m->next_slice * SKY_MS_LOCAL,
                                .last = s->order == MS_REFINE_ORDERS,
                                .end = (m->next_slice + slices) * SKY_MS_LOCAL };
    if (push.end > points_of(s->kind))
        push.end = points_of(s->kind);
    const uint32_t size[3] = { s->kind == STEP_GROUND ? SKY_MS_GROUND : slices * SKY_MS_LOCAL, 1,
                               1 };
    const uint32_t local[3] = { SKY_MS_LOCAL, 1, 1 };
    compute_pass_record(cmd, &m->pass[s->kind][parity][variant_of(s->kind, s->order)], &push, size,
                        local);
    gpu_timer_mark(timer, cmd, pass_names[s->kind]);
    uint32_t k = s->kind;
    if (m->pending_head[k] + m->pending_count[k] < 8)
        m->pending[k][m->pending_head[k] + m->pending_count[k]++] = slices;
}

void ms_refine_record_warm_up(struct ms_refine *m, VkCommandBuffer cmd)
{
    if (m->warmed)
        return;
    /* An empty range: nothing is written but the ground table (rewritten before any read). */
    const struct sky_ms_push push = { .order = 1, .first = 0, .last = 0, .end = 0 };
    const uint32_t size[3] = { 1, 1, 1 }, local[3] = { SKY_MS_LOCAL, 1, 1 };
    for (int k = 0; k < STEP_KINDS; k++)
        for (int parity = 0; parity < 2; parity++)
            for (uint32_t v = 0; v < variant_count(k); v++)
                compute_pass_record(cmd, &m->pass[k][parity][v], &push, size, local);
    m->warmed = true;
}

/* Records steps worth about budget_ms (at least one slice); true when the table is complete. */
static bool record_slices(struct ms_refine *m, VkCommandBuffer cmd, struct gpu_timer *timer,
                          double budget_ms)
{
    double remaining = budget_ms;
    bool first = true;
    while (m->step < STEP_COUNT) {
        enum step_kind kind = m->steps[m->step].kind;
        double cost = m->ms_per_slice[kind];
        uint32_t slices = 1;
        if (kind != STEP_GROUND) {
            double fit = floor(remaining / cost);
            slices = fit > slices_of(kind) ? slices_of(kind) : (uint32_t)fmax(fit, 0.0);
            if (slices > slices_of(kind) - m->next_slice)
                slices = slices_of(kind) - m->next_slice;
        } else if (remaining < cost) {
            slices = 0;
        }
        if (slices == 0 && !first)
            return false;
        if (slices == 0)
            slices = 1;
        record_step(m, cmd, timer, slices);
        remaining -= slices * cost;
        first = false;
        m->next_slice += slices;
        if (kind != STEP_GROUND && m->next_slice < slices_of(kind))
            return false;
        m->step++;
        m->next_slice = 0;
    }
    return true;
}

static void forget_pending(struct ms_refine *m)
{
    memset(m->pending_head, 0, sizeof m->pending_head);
    memset(m->pending_count, 0, sizeof m->pending_count);
}

static void complete(struct ms_refine *m, double now_s)
{
    m->state = STATE_COMPLETE;
    m->build_seconds = now_s - m->build_start;
}

bool ms_refine_record_frame(struct ms_refine *m, VkCommandBuffer cmd, struct gpu_timer *timer,
                            const struct sky_render_atmosphere *displayed, bool settled,
                            double budget_ms, double now_s)
{
    forget_pending(m); /* the last frame's marks were read (or never will be) */
    double dt = m->last_now > 0.0 ? fmax(0.0, now_s - m->last_now) : 0.0;
    m->last_now = now_s;
    bool current = settled && same_atmosphere(displayed, &m->built_for);
    /* Fade in once complete, out as soon as the atmosphere moves (the LUTs' own rebuild then
     * takes several frames before the display changes). */
    if (m->state == STATE_COMPLETE && current)
        m->weight = fmin(1.0, m->weight + dt / MS_REFINE_FADE_S);
    else
        m->weight = fmax(0.0, m->weight - dt / MS_REFINE_FADE_S);
    if (m->state == STATE_BUILDING && !current)
        m->state = STATE_EMPTY;
    /* The table is rewritten in place: only once nothing shows it. */
    if (m->state != STATE_BUILDING && !current && settled && m->weight == 0.0)
        start(m, displayed, now_s);
    if (m->state == STATE_EMPTY && settled && m->weight == 0.0)
        start(m, displayed, now_s);
    if (m->state != STATE_BUILDING)
        return false;
    if (record_slices(m, cmd, timer, budget_ms))
        complete(m, now_s);
    return true;
}

bool ms_refine_record_all(struct ms_refine *m, VkCommandBuffer cmd, struct gpu_timer *timer,
                          const struct sky_render_atmosphere *displayed)
{
    bool recorded = false;
    if (m->state != STATE_COMPLETE || !same_atmosphere(displayed, &m->built_for)) {
        start(m, displayed, m->last_now);
        record_slices(m, cmd, timer, INFINITY);
        /* the timestamps of a whole build would teach the slices nothing: forget them */
        forget_pending(m);
        complete(m, m->last_now);
        recorded = true;
    }
    m->weight = 1.0;
    return recorded;
}

double ms_refine_weight_for(const struct ms_refine *m, const struct sky_render_atmosphere *a)
{
    if (m->state != STATE_COMPLETE)
        return 0.0;
    /* During a fade-out the display may already have moved on for a few frames. */
    return same_atmosphere(a, &m->built_for) || m->weight < 1.0 ? m->weight : 0.0;
}

double ms_refine_progress(const struct ms_refine *m)
{
    if (m->state == STATE_COMPLETE)
        return 1.0;
    if (m->state == STATE_EMPTY)
        return 0.0;
    double per_step = 1.0 / STEP_COUNT;
    enum step_kind kind = m->steps[m->step].kind;
    double within = kind == STEP_GROUND ? 0.0 : (double)m->next_slice / slices_of(kind);
    return (m->step + within) * per_step;
}

int ms_refine_order(const struct ms_refine *m)
{
    return m->state == STATE_BUILDING ? (int)m->steps[m->step].order : 0;
}

double ms_refine_build_seconds(const struct ms_refine *m)
{
    return m->build_seconds;
}

void ms_refine_observe(struct ms_refine *m, const char *pass_name, double ms)
{
    for (int k = 0; k < STEP_KINDS; k++) {
        if (strcmp(pass_name, pass_names[k]) != 0 || m->pending_count[k] == 0)
            continue;
        uint32_t slices = m->pending[k][m->pending_head[k]++];
        m->pending_count[k]--;
        if (!(ms > 0.0) || slices == 0)
            return;
        /* Smoothed: lavapipe's timings jitter from frame to frame. */
        m->ms_per_slice[k] = 0.7 * m->ms_per_slice[k] + 0.3 * (ms / slices);
        return;
    }
}
