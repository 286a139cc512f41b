/* What cloud_renderer.c (setup, amortized maps, hemisphere) and cloud_view.c (per-view trace,
 * reconstruction and resolve) share inside render/clouds. */
#ifndef SKYD_CLOUD_RENDERER_INTERNAL_H
#define SKYD_CLOUD_RENDERER_INTERNAL_H

#include "cloud_history.h"
#include "cloud_layouts.h"
#include "cloud_noise.h"
#include "cloud_reference.h"
#include "cloud_renderer.h"
#include "compute_pass.h"
#include "vk_resources.h"

/* A map rebuilt a slice of rows per frame into the hidden image, shown when complete. */
struct cloud_map {
    struct gpu_image image[2];
    int shown;
    bool ready, building;
    uint32_t next_row, rows_this_frame;
    double ms_per_row;
    uint32_t generation;
};

/* What the weather map is built from. */
struct weather_key {
    float params[4];
    float periods[4]; /* cells across the map per cloud type (cloud_weather.comp) */
    uint32_t seed, mode, client_generation;
    uint32_t high_fibrous; /* the high layer's type in thousandths */
};

/* What the shadow map is built from, besides the sun. */
struct shadow_key {
    struct sky_cloud_uniforms u; /* with the wind displacement and frame phase zeroed */
    uint32_t weather_generation, noise_seed;
};

/* The marching passes come four times: without the moon's light (MOONLIT false), then with
 * it, for frames the moon lights; each for weather maps without towering clouds (TOWERING
 * false), then with them (march_variant). */
enum {
    P_WEATHER,
    P_SHADOW,
    P_SUN_COLUMNS,
    P_HEMISPHERE,
    P_HEMISPHERE_MOONLIT,
    P_HEMISPHERE_TOWERING,
    P_HEMISPHERE_TOWERING_MOONLIT,
    P_TRACE,
    P_TRACE_MOONLIT,
    P_TRACE_TOWERING,
    P_TRACE_TOWERING_MOONLIT,
    P_RECONSTRUCT_0,
    P_RECONSTRUCT_1,
    P_RESOLVE,        /* rows that see no ground (GROUND false) */
    P_RESOLVE_GROUND, /* rows that may */
    P_COUNT
};

struct cloud_renderer {
    bool quiet;
    VkSampler repeat;
    struct cloud_noise noise;
    struct cloud_map weather, shadow;
    /* The sun-space optical-depth volume, built and shown with the shadow map
     * (shadow.shown): SHADOW_SIZE^2 x SKY_CLOUD_SUN_DEPTH_LEVELS. */
    struct gpu_image sun_depth[2];
    struct gpu_image dummy_volume;
    struct gpu_image client_map, dummy;
    bool has_client_map;
    uint32_t client_generation;
    struct gpu_buffer params, env;
    struct compute_pass pass[P_COUNT];
    struct cloud_history history;
    struct sky_render_clouds clouds;
    bool active;
    struct sky_cloud_uniforms u;
    struct weather_key weather_target;
    struct shadow_key shadow_target;
    float shadow_sun[3];       /* the sun the shadow map is (being) built for */
    float shown_shadow_sun[3]; /* the sun of the shown shadow map and sun-depth volume */
    bool shadow_has_sun, env_dirty;
    double budget_ms;
    double last_frame_ms; /* GPU time of the last frame, for the relative map budget */
    uint32_t params_generation; /* counts changes of the clouds other than the wind's drift */
    float client_max_rain;      /* the largest precipitation of the client map */
    float client_max_type;      /* the largest cloud type of the client map */
    /* Whether each weather image may hold towering clouds (a type above
     * CLOUD_TOWERING_TYPE): the marches read the shown one's through their variant. */
    bool weather_towering[2];
    struct cloud_reference *reference; /* created with the first reference frame */
};

/* The workgroup of the 2D passes. */
static const uint32_t local_2d[3] = { SKY_CLOUD_LOCAL, SKY_CLOUD_LOCAL, 1 };

static inline struct compute_resource tex(const struct gpu_image *image, VkSampler sampler)
{
    return (struct compute_resource){ .image = image, .sampler = sampler };
}

static inline struct compute_resource img(const struct gpu_image *image)
{
    return (struct compute_resource){ .image = image };
}

static inline struct compute_resource buf(const struct gpu_buffer *buffer)
{
    return (struct compute_resource){ .buffer = buffer };
}

static inline const struct gpu_image *shown(const struct cloud_renderer *cr, const struct cloud_map *m)
{
    return m->ready ? &m->image[m->shown] : &cr->dummy;
}

/* 1 when the moon lights this frame's clouds (the frame uniforms' flag), else 0. */
static inline int moonlit(const struct cloud_frame *f)
{
    return f->frame->moon_illuminance.w > 0.5f ? 1 : 0;
}

/* Offset of this frame's variant of a marching pass (P_HEMISPHERE, P_TRACE): the moon's light,
 * and towering clouds in the shown weather map. */
static inline int march_variant(const struct cloud_renderer *cr, const struct cloud_frame *f)
{
    bool towering = cr->weather.ready && cr->weather_towering[cr->weather.shown];
    return moonlit(f) + (towering ? 2 : 0);
}

/* The bindings that the marching passes share (SKY_LAYOUT_CLOUD_MARCH). */
void cloud_march_resources(const struct cloud_renderer *cr, const struct cloud_frame *f,
                           struct compute_resource *r);

/* The view's trace, reconstruction and resolve (cloud_view.c). */
int cloud_view_record(struct vk_context *ctx, struct cloud_renderer *cr, VkCommandBuffer cmd,
                      struct gpu_timer *timer, const struct cloud_frame *f,
                      struct sky_cloud_bindings *out);

#endif
