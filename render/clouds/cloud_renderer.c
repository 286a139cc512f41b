#include "cloud_renderer.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cloud_layouts.h"
#include "cloud_noise.h"
#include "cloud_params.h"
#include "cloud_passes.h"
#include "cloud_quality.h"
#include "cloud_view.h"
#include "compute_pass.h"
#include "gpu_timer.h"
#include "vk_check.h"
#include "vk_context.h"
#include "vk_resources.h"

#include "clouds_shaders.h"

/* Share of the last frame's GPU time that weather and shadow map builds may take. */
#define RELATIVE_MAP_BUDGET 0.1
/* What map builds take of frames back to back (ms, when the budget allows): more comes only
 * from the usable idle time before a frame. */
#define BACK_TO_BACK_MAP_MS 2.0
#define FLOAT_FORMAT VK_FORMAT_R32G32B32A32_SFLOAT
#define SUN_DEPTH_FORMAT VK_FORMAT_R32G32_SFLOAT
#define WEATHER_FORMAT VK_FORMAT_R16G16B16A16_SFLOAT
/* 59 m a texel over the default 60 km: the kinks of its bilinear lookup along the texel grid lie
 * below 120 m, where at 117 m they were the decks' whole texture from 118 to 200 m. */
#define WEATHER_SIZE 1024
#define SHADOW_SIZE 384
/* The shadow map follows the sun once it has moved this far (radians, about 0.3 degree). */
#define SHADOW_SUN_TOLERANCE 5e-3
/* Starting guesses of GPU ms per row on lavapipe; measured times replace them. */
#define INITIAL_MS_PER_WEATHER_ROW 0.02
#define INITIAL_MS_PER_SHADOW_ROW 0.15

/* The hemisphere averages come four times: without the moon's light (MOONLIT false), then
 * with it, for frames the moon lights; each for weather maps without towering clouds (TOWERING
 * false), then with them (march_variant). */
enum {
    P_WEATHER,
    P_SHADOW,
    P_SUN_COLUMNS,
    P_HEMISPHERE,
    P_HEMISPHERE_MOONLIT,
    P_HEMISPHERE_TOWERING,
    P_HEMISPHERE_TOWERING_MOONLIT,
    P_COUNT
};

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
    struct cloud_views *views; /* each view's trace, reconstruction and resolve */
    struct sky_render_clouds clouds;
    bool active;
    struct sky_cloud_uniforms u;
    struct weather_key weather_target;
    struct shadow_key shadow_target;
    float shadow_sun[3];       /* the sun the shadow map is (being) built for */
    float shown_shadow_sun[3]; /* the sun of the shown shadow map and sun-depth volume */
    bool shadow_has_sun, env_dirty;
    double budget_ms;
    double last_frame_ms;         /* GPU time of the last frame, for the relative map budget */
    double usable_idle_ms;        /* of the idle time before this frame, what maps may take */
    struct cloud_quality quality; /* the level resolution AUTO traces at */
    uint32_t params_generation;   /* counts changes of the clouds other than the wind's drift */
    float client_max_rain;        /* the largest precipitation of the client map */
    float client_max_type;        /* the largest cloud type of the client map */
    /* Whether each weather image may hold towering clouds (a type above
     * CLOUD_TOWERING_TYPE): the marches read the shown one's through their variant. */
    bool weather_towering[2];
};

static const struct gpu_image *shown(const struct cloud_renderer *cr, const struct cloud_map *m)
{
    return m->ready ? &m->image[m->shown] : &cr->dummy;
}

/* The procedural map varies the asked type by CLOUD_TYPE_VARIATION times a 2D gradient noise,
 * whose values stay within +-sqrt(1/2): at most this far above it. */
#define PROCEDURAL_TYPE_SPREAD (0.7072f * (float)CLOUD_TYPE_VARIATION)

double cloud_renderer_plain_type(void)
{
    return (double)((float)CLOUD_TOWERING_TYPE - PROCEDURAL_TYPE_SPREAD) - 0.01;
}

/* Offset of this frame's variant of a marching pass (P_HEMISPHERE, the views' trace): the
 * moon's light, and towering clouds in the shown weather map. */
static int march_variant(const struct cloud_renderer *cr, const struct cloud_frame *f)
{
    bool towering = cr->weather.ready && cr->weather_towering[cr->weather.shown];
    return moonlit(f) + (towering ? 2 : 0);
}

/* clang-format off */
static const struct compute_pass_desc descs[P_COUNT] = {
    [P_WEATHER] = { .name = "cloud_weather", SPIRV(cloud_weather_spv),
                    SKY_PASS_LAYOUT(SKY_LAYOUT_CLOUD_WEATHER), ROWS_PUSH },
    [P_SHADOW] = { .name = "cloud_shadow", SPIRV(cloud_shadow_spv),
                   SKY_PASS_LAYOUT(SKY_LAYOUT_CLOUD_SHADOW), ROWS_PUSH },
    [P_SUN_COLUMNS] = { .name = "cloud_sun_columns", SPIRV(cloud_sun_columns_spv),
                        SKY_PASS_LAYOUT(SKY_LAYOUT_CLOUD_SUN_COLUMNS), ROWS_PUSH },
    [P_HEMISPHERE] = { .name = "cloud_hemisphere", SPIRV(cloud_hemisphere_spv),
                       SKY_PASS_LAYOUT(SKY_LAYOUT_CLOUD_HEMISPHERE), MARCH_SPEC(0, 0) },
    [P_HEMISPHERE_MOONLIT] = { .name = "cloud_hemisphere", SPIRV(cloud_hemisphere_spv),
                               SKY_PASS_LAYOUT(SKY_LAYOUT_CLOUD_HEMISPHERE), MARCH_SPEC(1, 0) },
    [P_HEMISPHERE_TOWERING] = { .name = "cloud_hemisphere", SPIRV(cloud_hemisphere_spv),
                                SKY_PASS_LAYOUT(SKY_LAYOUT_CLOUD_HEMISPHERE), MARCH_SPEC(0, 1) },
    [P_HEMISPHERE_TOWERING_MOONLIT] = { .name = "cloud_hemisphere", SPIRV(cloud_hemisphere_spv),
                                        SKY_PASS_LAYOUT(SKY_LAYOUT_CLOUD_HEMISPHERE),
                                        MARCH_SPEC(1, 1) },
};
/* clang-format on */

static int map_create(struct vk_context *ctx, struct cloud_map *m, VkFormat format, uint32_t size,
                      const char *name, double ms_per_row)
{
    memset(m, 0, sizeof *m);
    m->ms_per_row = ms_per_row;
    for (int i = 0; i < 2; i++)
        if (gpu_image_create(ctx, format, size, size, 1, name, &m->image[i]) != VK_SUCCESS)
            return -1;
    return 0;
}

static void map_destroy(struct vk_context *ctx, struct cloud_map *m)
{
    gpu_image_destroy(ctx, &m->image[0]);
    gpu_image_destroy(ctx, &m->image[1]);
}

struct cloud_renderer *cloud_renderer_create(struct vk_context *ctx, bool quiet,
                                             const char *cache_dir)
{
    struct cloud_renderer *cr = calloc(1, sizeof *cr);
    if (!cr)
        return NULL;
    cr->quiet = quiet;
    cloud_quality_init(&cr->quality);
    VK_CHECK_GOTO(gpu_linear_sampler_create(ctx, VK_SAMPLER_ADDRESS_MODE_REPEAT, &cr->repeat),
                  destroy_partial);
    if (cloud_noise_create(ctx, &cr->noise, cache_dir) != 0 ||
        map_create(ctx, &cr->weather, WEATHER_FORMAT, WEATHER_SIZE, "cloud_weather",
                   INITIAL_MS_PER_WEATHER_ROW) != 0 ||
        map_create(ctx, &cr->shadow, FLOAT_FORMAT, SHADOW_SIZE, "cloud_shadow",
                   INITIAL_MS_PER_SHADOW_ROW) != 0)
        goto destroy_partial;
    for (int i = 0; i < 2; i++)
        VK_CHECK_GOTO(gpu_image_create(ctx, SUN_DEPTH_FORMAT, SHADOW_SIZE, SHADOW_SIZE,
                                       SKY_CLOUD_SUN_DEPTH_LEVELS, "cloud_sun_depth",
                                       &cr->sun_depth[i]),
                      destroy_partial);
    VK_CHECK_GOTO(gpu_image_create(ctx, FLOAT_FORMAT, 1, 1, 1, "cloud_none", &cr->dummy),
                  destroy_partial);
    VK_CHECK_GOTO(
        gpu_image_create(ctx, SUN_DEPTH_FORMAT, 1, 1, 2, "cloud_none_volume", &cr->dummy_volume),
        destroy_partial);
    VK_CHECK_GOTO(gpu_buffer_create(ctx, sizeof(struct sky_cloud_uniforms),
                                    VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, "cloud_params",
                                    &cr->params),
                  destroy_partial);
    VK_CHECK_GOTO(gpu_buffer_create(ctx, 8 * sizeof(float), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT,
                                    "cloud_env", &cr->env),
                  destroy_partial);
    memset(cr->params.mapped, 0, sizeof(struct sky_cloud_uniforms));
    const float no_clouds[8] = { 0, 0, 0, 0, 1, 1, 1, 1 };
    memcpy(cr->env.mapped, no_clouds, sizeof no_clouds);
    for (int i = 0; i < P_COUNT; i++)
        VK_CHECK_GOTO(compute_pass_create(ctx, &descs[i], &cr->pass[i]), destroy_partial);
    if (!(cr->views = cloud_views_create(ctx)))
        goto destroy_partial;
    return cr;
destroy_partial:
    cloud_renderer_destroy(ctx, &cr);
    return NULL;
}

void cloud_renderer_destroy(struct vk_context *ctx, struct cloud_renderer **pcr)
{
    struct cloud_renderer *cr = pcr ? *pcr : NULL;
    if (!cr)
        return;
    for (int i = 0; i < P_COUNT; i++)
        compute_pass_destroy(ctx, &cr->pass[i]);
    cloud_views_destroy(ctx, &cr->views);
    cloud_noise_destroy(ctx, &cr->noise);
    map_destroy(ctx, &cr->weather);
    map_destroy(ctx, &cr->shadow);
    gpu_image_destroy(ctx, &cr->sun_depth[0]);
    gpu_image_destroy(ctx, &cr->sun_depth[1]);
    gpu_image_destroy(ctx, &cr->client_map);
    gpu_image_destroy(ctx, &cr->dummy);
    gpu_image_destroy(ctx, &cr->dummy_volume);
    gpu_buffer_destroy(ctx, &cr->params);
    gpu_buffer_destroy(ctx, &cr->env);
    if (cr->repeat)
        vkDestroySampler(ctx->device, cr->repeat, NULL);
    free(cr);
    *pcr = NULL;
}

int cloud_renderer_set(struct vk_context *ctx, struct cloud_renderer *cr,
                       const struct sky_render_clouds *clouds)
{
    struct sky_render_clouds before = cr->clouds, after = *clouds;
    before.wind_offset_east_km = before.wind_offset_north_km = 0.0;
    after.wind_offset_east_km = after.wind_offset_north_km = 0.0;
    if (memcmp(&before, &after, sizeof before) != 0)
        cr->params_generation++;
    cr->clouds = *clouds;
    cr->active = cloud_params_any_layer(clouds);
    if (cr->active && (!cr->noise.generated || cr->noise.seed != clouds->noise_seed))
        return cloud_noise_generate(ctx, &cr->noise, clouds->noise_seed, cr->quiet);
    return 0;
}

int cloud_renderer_prepare_noise(struct vk_context *ctx, struct cloud_renderer *cr, uint32_t seed)
{
    if (cr->noise.generated && cr->noise.seed == seed)
        return 0;
    return cloud_noise_generate(ctx, &cr->noise, seed, cr->quiet);
}

void cloud_renderer_set_budget(struct cloud_renderer *cr, double budget_ms)
{
    cr->budget_ms = budget_ms;
}

void cloud_renderer_observe_idle(struct cloud_renderer *cr, double usable_idle_ms)
{
    cr->usable_idle_ms = usable_idle_ms > 0.0 && isfinite(usable_idle_ms) ? usable_idle_ms : 0.0;
}

void cloud_renderer_set_frame_budget(struct cloud_renderer *cr, double frame_budget_ms)
{
    cloud_quality_set_budget(&cr->quality, frame_budget_ms);
}

enum sky_render_cloud_resolution cloud_renderer_resolution(const struct cloud_renderer *cr)
{
    return cloud_quality_resolve(&cr->quality, cr->clouds.resolution);
}

int cloud_renderer_primary_steps(const struct cloud_renderer *cr)
{
    return cloud_quality_steps(&cr->quality, cr->clouds.resolution, cr->clouds.primary_steps);
}

/* ---- client weather map ---- */

int cloud_renderer_set_weather_map(struct vk_context *ctx, struct cloud_renderer *cr,
                                   const uint8_t *rgba8, uint32_t width, uint32_t height)
{
    if (!rgba8) {
        vk_context_wait_idle(ctx);
        gpu_image_destroy(ctx, &cr->client_map);
        cr->has_client_map = false;
        cr->client_generation++;
        return 0;
    }
    if (width == 0 || height == 0 || width > 4096 || height > 4096)
        return -1;
    VkDeviceSize bytes = (VkDeviceSize)width * height * 4;
    struct gpu_buffer staging;
    if (gpu_buffer_create(ctx, bytes, VK_BUFFER_USAGE_TRANSFER_SRC_BIT, "weather_upload",
                          &staging) != VK_SUCCESS)
        return -1;
    memcpy(staging.mapped, rgba8, (size_t)bytes);
    uint8_t max_rain = 0, max_type = 0;
    for (size_t i = 0; i < (size_t)bytes; i += 4) {
        max_type = rgba8[i + 2] > max_type ? rgba8[i + 2] : max_type;
        max_rain = rgba8[i + 3] > max_rain ? rgba8[i + 3] : max_rain;
    }
    /* The new map is complete before it replaces the old one: a failure keeps the old map. */
    struct gpu_image uploaded = { 0 };
    int rc = -1;
    VkCommandBuffer cmd;
    if (gpu_image_create(ctx, VK_FORMAT_R8G8B8A8_UNORM, width, height, 1, "client_weather",
                         &uploaded) == VK_SUCCESS &&
        vk_context_begin_commands(ctx, &cmd) == VK_SUCCESS) {
        VkBufferImageCopy region = {
            .imageSubresource = { VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1 },
            .imageExtent = { width, height, 1 },
        };
        vkCmdCopyBufferToImage(cmd, staging.buffer, uploaded.image, VK_IMAGE_LAYOUT_GENERAL, 1,
                               &region);
        gpu_barrier_compute_to_compute(cmd);
        if (vk_context_submit_and_wait(ctx, &cmd) == VK_SUCCESS)
            rc = 0;
    }
    gpu_buffer_destroy(ctx, &staging);
    if (rc != 0) {
        gpu_image_destroy(ctx, &uploaded);
        return -1;
    }
    vk_context_wait_idle(ctx); /* frames in flight may still sample the old map */
    gpu_image_destroy(ctx, &cr->client_map);
    cr->client_map = uploaded;
    cr->client_max_rain = max_rain / 255.0f;
    cr->client_max_type = max_type / 255.0f;
    cr->has_client_map = true;
    cr->client_generation++;
    return 0;
}

/* ---- amortized maps ---- */

/* Records rows of a map under *budget (all of them when budget_ms <= 0, at least one row per
 * frame); true when the map is complete and now shown. */
static bool map_record(struct cloud_renderer *cr, struct cloud_map *m, VkCommandBuffer cmd,
                       struct gpu_timer *timer, struct compute_pass *pass,
                       struct sky_cloud_rows_push *push, double *budget)
{
    uint32_t total = m->image[0].height, rows = total - m->next_row;
    if (cr->budget_ms > 0.0) {
        double affordable = floor(*budget / m->ms_per_row);
        if (affordable < 1.0)
            affordable = 1.0;
        if (affordable < rows)
            rows = (uint32_t)affordable;
    }
    push->row_offset = m->next_row;
    const uint32_t size[3] = { m->image[0].width, rows, 1 };
    compute_pass_record(cmd, pass, push, size, local_2d);
    gpu_timer_mark(timer, cmd, pass->name);
    m->rows_this_frame = rows;
    *budget -= rows * m->ms_per_row;
    m->next_row += rows;
    if (m->next_row < total)
        return false;
    m->building = false;
    m->ready = true;
    m->shown = 1 - m->shown;
    m->generation++;
    return true;
}

/* Whether this frame builds its maps whole (no map budget). */
static bool at_once(const struct cloud_renderer *cr)
{
    return cr->budget_ms <= 0.0;
}

static void map_start(struct cloud_map *m)
{
    m->building = true;
    m->next_row = 0;
}

static void record_weather(struct vk_context *ctx, struct cloud_renderer *cr, VkCommandBuffer cmd,
                           struct gpu_timer *timer, double *budget)
{
    const struct sky_render_clouds *c = &cr->clouds;
    bool client = c->use_client_map && cr->has_client_map;
    struct weather_key key = {
        .params = { (float)c->low.coverage, (float)c->high.coverage, (float)c->low.type,
                    (float)c->precipitation },
        .seed = c->weather_seed,
        .mode = client ? (c->client_map_drives_procedural ? 2u : 1u) : 0u,
        .client_generation = client ? cr->client_generation : 0u,
        .high_fibrous = (uint32_t)lround(fmin(fmax(c->high.type, 0.0), 1.0) * 1000.0),
    };
    cloud_params_weather_periods(c, key.periods);
    /* A build runs to the end with the inputs it started from, and the next one starts from the
     * newest inputs: parameters that change every tick (a weather transition) would otherwise
     * restart it for ever. The shown map stays until a build completes. A frame that builds at
     * once (budget 0: a snapshot nobody streams) starts a stale build over instead, or it
     * would show the inputs that build started from rather than its own. */
    bool differs = memcmp(&key, &cr->weather_target, sizeof key) != 0;
    if (cr->weather.building ? at_once(cr) && differs : !cr->weather.ready || differs) {
        cr->weather_target = key;
        float max_type = client ? cr->client_max_type : key.params[2];
        if (key.mode != 1u) /* the procedural field's own variation */
            max_type += PROCEDURAL_TYPE_SPREAD;
        cr->weather_towering[1 - cr->weather.shown] = max_type > (float)CLOUD_TOWERING_TYPE;
        map_start(&cr->weather);
    }
    if (!cr->weather.building)
        return;
    const struct weather_key *build = &cr->weather_target;
    struct compute_resource r[SKY_LAYOUT_COUNT(SKY_LAYOUT_CLOUD_WEATHER)] = {
        [SKY_CLOUD_WEATHER_CLIENT_MAP] =
            tex(build->mode && cr->has_client_map ? &cr->client_map : &cr->dummy, cr->repeat),
        [SKY_CLOUD_WEATHER_OUT] = img(&cr->weather.image[1 - cr->weather.shown]),
    };
    compute_pass_bind(ctx, &cr->pass[P_WEATHER], r);
    struct sky_cloud_rows_push push = {
        .mode = build->mode,
        .seed = build->seed,
        .high_fibrous = build->high_fibrous,
        .params = { build->params[0], build->params[1], build->params[2], build->params[3] },
        .size = { build->periods[0], build->periods[1], build->periods[2], build->periods[3] },
    };
    map_record(cr, &cr->weather, cmd, timer, &cr->pass[P_WEATHER], &push, budget);
}

static float angle_between(const float a[3], const float b[3])
{
    float d = a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    return acosf(fminf(1.0f, fmaxf(-1.0f, d)));
}

/* The bindings that the marching passes share (SKY_LAYOUT_CLOUD_MARCH), at the front of `r`. */
static void cloud_march_resources(const struct cloud_renderer *cr, const struct cloud_frame *f,
                                  struct compute_resource *r)
{
    const struct sky_pass_resources *s = &f->sky;
    r[SKY_CLOUD_MARCH_ATMOSPHERE] = buf(s->atmosphere_params);
    r[SKY_CLOUD_MARCH_FRAME] = buf(s->frame_params);
    r[SKY_CLOUD_MARCH_TRANSMITTANCE] = tex(s->transmittance, s->sampler);
    r[SKY_CLOUD_MARCH_MULTISCATTERING] = tex(s->multiscattering, s->sampler);
    r[SKY_CLOUD_MARCH_IRRADIANCE] = tex(s->irradiance, s->sampler);
    r[SKY_CLOUD_MARCH_CLOUD] = buf(&cr->params);
    r[SKY_CLOUD_MARCH_BASE_NOISE] = tex(&cr->noise.base, cr->repeat);
    r[SKY_CLOUD_MARCH_DETAIL_NOISE] = tex(&cr->noise.detail, cr->repeat);
    r[SKY_CLOUD_MARCH_CURL_NOISE] = tex(&cr->noise.curl, cr->repeat);
    r[SKY_CLOUD_MARCH_WEATHER] = tex(shown(cr, &cr->weather), cr->repeat);
    r[SKY_CLOUD_MARCH_SKYVIEW] = tex(s->skyview, s->sampler);
    r[SKY_CLOUD_MARCH_SUN_DEPTH] =
        tex(cr->shadow.ready ? &cr->sun_depth[cr->shadow.shown] : &cr->dummy_volume, cr->repeat);
    r[SKY_CLOUD_MARCH_SUN_COLUMNS] = tex(shown(cr, &cr->shadow), cr->repeat);
}

/* The columns' support, once the shadow map and volume just completed (now shown) are whole. */
static void record_sun_columns(struct vk_context *ctx, struct cloud_renderer *cr,
                               VkCommandBuffer cmd, struct gpu_timer *timer,
                               const struct sky_cloud_rows_push *push)
{
    struct compute_pass *pass = &cr->pass[P_SUN_COLUMNS];
    const struct gpu_image *map = &cr->shadow.image[cr->shadow.shown];
    struct compute_resource r[SKY_LAYOUT_COUNT(SKY_LAYOUT_CLOUD_SUN_COLUMNS)] = {
        [SKY_CLOUD_COLUMNS_CLOUD] = buf(&cr->params),
        [SKY_CLOUD_COLUMNS_SUN_DEPTH] = tex(&cr->sun_depth[cr->shadow.shown], cr->repeat),
        [SKY_CLOUD_COLUMNS_SHADOW] = img(map),
    };
    compute_pass_bind(ctx, pass, r);
    const uint32_t size[3] = { map->width, map->height, 1 };
    compute_pass_record(cmd, pass, push, size, local_2d);
    gpu_timer_mark(timer, cmd, pass->name);
}

static void record_shadow(struct vk_context *ctx, struct cloud_renderer *cr, VkCommandBuffer cmd,
                          struct gpu_timer *timer, const struct cloud_frame *f, double *budget)
{
    if (!cr->weather.ready)
        return;
    struct shadow_key key;
    memset(&key, 0, sizeof key);
    key.u = cr->u;
    key.u.weather.x = key.u.weather.y = 0.0f;
    key.u.march.w = 0.0f;
    key.u.shadow_sun = (sky_vec4){ 0, 0, 0, 0 };
    key.weather_generation = cr->weather.generation;
    key.noise_seed = cr->noise.seed;
    const float sun[3] = { f->frame->sun_direction.x, f->frame->sun_direction.y,
                           f->frame->sun_direction.z };
    bool moved = !cr->shadow_has_sun || angle_between(sun, cr->shadow_sun) > SHADOW_SUN_TOLERANCE;
    /* As for the weather map: a build in progress finishes before the next one starts, but
     * when the frame builds at once. */
    bool differs = moved || memcmp(&key, &cr->shadow_target, sizeof key) != 0;
    if (cr->shadow.building ? at_once(cr) && differs : !cr->shadow.ready || differs) {
        cr->shadow_target = key;
        memcpy(cr->shadow_sun, sun, sizeof sun);
        cr->shadow_has_sun = true;
        map_start(&cr->shadow);
    }
    if (!cr->shadow.building)
        return;
    const struct sky_pass_resources *s = &f->sky;
    struct compute_resource r[SKY_LAYOUT_COUNT(SKY_LAYOUT_CLOUD_SHADOW)] = {
        [SKY_CLOUD_SHADOW_ATMOSPHERE] = buf(s->atmosphere_params),
        [SKY_CLOUD_SHADOW_CLOUD] = buf(&cr->params),
        [SKY_CLOUD_SHADOW_BASE_NOISE] = tex(&cr->noise.base, cr->repeat),
        [SKY_CLOUD_SHADOW_DETAIL_NOISE] = tex(&cr->noise.detail, cr->repeat),
        [SKY_CLOUD_SHADOW_CURL_NOISE] = tex(&cr->noise.curl, cr->repeat),
        [SKY_CLOUD_SHADOW_WEATHER] = tex(shown(cr, &cr->weather), cr->repeat),
        [SKY_CLOUD_SHADOW_OUT] = img(&cr->shadow.image[1 - cr->shadow.shown]),
        [SKY_CLOUD_SHADOW_SUN_DEPTH_OUT] = img(&cr->sun_depth[1 - cr->shadow.shown]),
    };
    compute_pass_bind(ctx, &cr->pass[P_SHADOW], r);
    /* Its own sun, not the block's: a frame's block holds the shown map's sun, which the
     * slices of a build spread over frames would otherwise be built for. */
    struct sky_cloud_rows_push push = {
        .row_offset = 0,
        .params = { cr->shadow_sun[0], cr->shadow_sun[1], cr->shadow_sun[2], 0.0f },
    };
    if (map_record(cr, &cr->shadow, cmd, timer, &cr->pass[P_SHADOW], &push, budget)) {
        record_sun_columns(ctx, cr, cmd, timer, &push);
        cr->env_dirty = true;
        memcpy(cr->shown_shadow_sun, cr->shadow_sun, sizeof cr->shown_shadow_sun);
    }
}

/* The hemisphere averages (seed 001 eq. 22) follow each completed shadow map: same inputs. */
static void record_hemisphere(struct vk_context *ctx, struct cloud_renderer *cr,
                              VkCommandBuffer cmd, struct gpu_timer *timer,
                              const struct cloud_frame *f)
{
    if (!cr->env_dirty)
        return;
    struct compute_pass *pass = &cr->pass[P_HEMISPHERE + march_variant(cr, f)];
    struct compute_resource r[SKY_LAYOUT_COUNT(SKY_LAYOUT_CLOUD_HEMISPHERE)];
    cloud_march_resources(cr, f, r);
    r[SKY_CLOUD_HEMISPHERE_ENV_OUT] = buf(&cr->env);
    compute_pass_bind(ctx, pass, r);
    const uint32_t size[3] = { CLOUD_HEMISPHERE_RAYS, 1, 1 };
    const uint32_t local[3] = { CLOUD_HEMISPHERE_RAYS, 1, 1 };
    compute_pass_record(cmd, pass, NULL, size, local);
    gpu_timer_mark(timer, cmd, pass->name);
    cr->env_dirty = false;
}

bool cloud_renderer_active(const struct cloud_renderer *cr)
{
    return cr->active && cr->noise.generated;
}

void cloud_renderer_no_clouds(const struct cloud_renderer *cr, struct sky_cloud_bindings *out)
{
    *out = (struct sky_cloud_bindings){
        .over_sky = &cr->dummy,
        .over_ground = &cr->dummy,
        .shadow = &cr->dummy,
        .shadow_sampler = cr->repeat,
        .params = &cr->params,
        .env = &cr->env,
    };
}

int cloud_renderer_record_maps(struct vk_context *ctx, struct cloud_renderer *cr,
                               VkCommandBuffer cmd, struct gpu_timer *timer,
                               const struct cloud_frame *f, struct sky_cloud_bindings *out)
{
    cloud_renderer_no_clouds(cr, out);
    if (!cloud_renderer_active(cr)) {
        memset(cr->params.mapped, 0, sizeof(struct sky_cloud_uniforms));
        return 0;
    }
    cloud_params_fill(&cr->clouds, f->bottom_radius_km, &cr->u);
    cr->u.march.x = (float)cloud_renderer_primary_steps(cr);
    /* The budget grows with the frame: on a slow device a fixed few ms would stretch a map
     * build over hundreds of frames, while a tenth of the frame keeps every frame within
     * about 10 % of its neighbours. Up to budget_ms, idle time before the frame is free. */
    double budget = cr->budget_ms;
    if (budget > 0.0) {
        budget = fmin(budget, fmax(BACK_TO_BACK_MAP_MS, cr->usable_idle_ms));
        budget = fmax(budget, RELATIVE_MAP_BUDGET * cr->last_frame_ms);
    }
    cr->weather.rows_this_frame = cr->shadow.rows_this_frame = 0;
    record_weather(ctx, cr, cmd, timer, &budget);
    record_shadow(ctx, cr, cmd, timer, f, &budget);
    /* The block the frame's passes read, written once before they run: the sun of the maps
     * they are shown (the shadow builder has its own in its push constants). */
    cr->u.shadow_sun = (sky_vec4){ cr->shown_shadow_sun[0], cr->shown_shadow_sun[1],
                                   cr->shown_shadow_sun[2], cr->shadow.ready ? 1.0f : 0.0f };
    memcpy(cr->params.mapped, &cr->u, sizeof cr->u);
    record_hemisphere(ctx, cr, cmd, timer, f);
    out->shadow = shown(cr, &cr->shadow);
    return 0;
}

int cloud_renderer_record_view(struct vk_context *ctx, struct cloud_renderer *cr,
                               VkCommandBuffer cmd, struct gpu_timer *timer,
                               const struct cloud_frame *f, struct sky_cloud_bindings *out)
{
    if (!cloud_renderer_active(cr))
        return 0;
    struct compute_resource march[CLOUD_MARCH_BINDINGS];
    cloud_march_resources(cr, f, march);
    /* The procedural map's precipitation is at most clouds.precipitation; a client map's is
     * its own, but the map shown may still be the other one while a build completes. */
    float ceiling = (float)cr->clouds.precipitation;
    if (cr->has_client_map && cr->client_max_rain > ceiling)
        ceiling = cr->client_max_rain;
    struct sky_render_clouds traced = cr->clouds;
    traced.resolution = cloud_renderer_resolution(cr);
    const struct cloud_view_inputs in = {
        .clouds = &traced,
        .march = march,
        .march_variant = march_variant(cr, f),
        .params = &cr->params,
        .env = &cr->env,
        .shadow = shown(cr, &cr->shadow),
        .repeat = cr->repeat,
        .look = cr->params_generation + cr->weather.generation + cr->shadow.generation,
        .precipitation_ceiling = ceiling,
    };
    return cloud_views_record(ctx, cr->views, cmd, timer, f, &in, out);
}

void cloud_renderer_observe(struct cloud_renderer *cr, const char *pass_name, double ms)
{
    cloud_quality_observe_pass(&cr->quality, pass_name, ms);
    struct cloud_map *m = strcmp(pass_name, "cloud_weather") == 0  ? &cr->weather
                          : strcmp(pass_name, "cloud_shadow") == 0 ? &cr->shadow
                                                                   : NULL;
    if (!m || m->rows_this_frame == 0 || !(ms > 0.0))
        return;
    m->ms_per_row = 0.7 * m->ms_per_row + 0.3 * ms / m->rows_this_frame;
    m->rows_this_frame = 0;
}

void cloud_renderer_observe_frame(struct cloud_renderer *cr, double gpu_ms)
{
    if (gpu_ms > 0.0)
        cr->last_frame_ms = gpu_ms;
    cloud_quality_observe_frame(&cr->quality, gpu_ms);
}

int cloud_renderer_reference_stats(const struct cloud_renderer *cr,
                                   struct sky_render_reference_stats *out)
{
    return cloud_views_reference_stats(cr->views, out);
}

double cloud_renderer_progress(const struct cloud_renderer *cr)
{
    if (!cr->active)
        return 1.0;
    double total = cr->weather.image[0].height + cr->shadow.image[0].height;
    double done = (cr->weather.building ? cr->weather.next_row : cr->weather.image[0].height) +
                  (cr->shadow.building || !cr->shadow.ready ? cr->shadow.next_row
                                                            : cr->shadow.image[0].height);
    return done / total;
}
