#include "sky_renderer.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "atmosphere_luts.h"
#include "cloud_renderer.h"
#include "compute_pass.h"
#include "fault_injection.h"
#include "gpu_timer.h"
#include "ms_refine.h"
#include "night_sky.h"
#include "night_stars.h"
#include "sky_photometry.h"
#include "sky_passes.h"
#include "sky_uniforms.h"
#include "sky_shared.h"
#include "vk_check.h"
#include "vk_context.h"
#include "vk_resources.h"

/* Of the time the renderer sat idle before a frame, the share background work (LUT rebuilds,
 * refinement, cloud maps) may take: the rest absorbs jitter and leaves the CPU to the
 * encoders. */
#define IDLE_SHARE 0.5

/* What the sky-view LUTs depend on besides the displayed atmosphere LUTs: the camera's
 * distance from the planet's centre and the sun and moon in the camera's local frame. */
struct skyview_inputs {
    bool valid;
    uint64_t luts_generation; /* atmosphere_luts_display_generation */
    bool moonlit;
    float radius_km;
    float sun[3], moon[3];
    float converged[2]; /* the converged multiple scattering's weights (ms_refine.h) */
};

/* Below these changes a rebuilt sky-view LUT would differ by well under 1 % (the LUT's own
 * texels are about 1.9 degrees wide), so the last one is kept: 0.02 degrees of sun or moon
 * (about 5 s of the real sun's motion) and 1 m of altitude. */
#define SKYVIEW_KEEP_RAD 3.5e-4f
#define SKYVIEW_KEEP_KM 0.001f

static bool directions_close(const float a[3], const float b[3])
{
    float dx = a[0] - b[0], dy = a[1] - b[1], dz = a[2] - b[2];
    return dx * dx + dy * dy + dz * dz < SKYVIEW_KEEP_RAD * SKYVIEW_KEEP_RAD;
}

static struct skyview_inputs skyview_inputs_of(const struct sky_frame_uniforms *fu, bool moonlit,
                                               uint64_t luts_generation)
{
    const sky_vec4 *c = &fu->camera_position;
    return (struct skyview_inputs){
        .valid = true,
        .luts_generation = luts_generation,
        .moonlit = moonlit,
        .radius_km = sqrtf(c->x * c->x + c->y * c->y + c->z * c->z),
        .sun = { fu->sun_local.x, fu->sun_local.y, fu->sun_local.z },
        .moon = { fu->moon_local.x, fu->moon_local.y, fu->moon_local.z },
        .converged = { fu->multiple_scattering.x, fu->multiple_scattering.y },
    };
}

/* True when the sky-view LUTs built for `shown` serve `now` (moonlit ones also serve a view
 * that does not need the moon's). */
static bool skyview_still_valid(const struct skyview_inputs *shown,
                                const struct skyview_inputs *now)
{
    return shown->valid && shown->luts_generation == now->luts_generation &&
           (shown->moonlit || !now->moonlit) && shown->converged[0] == now->converged[0] &&
           shown->converged[1] == now->converged[1] &&
           fabsf(shown->radius_km - now->radius_km) < SKYVIEW_KEEP_KM &&
           directions_close(shown->sun, now->sun) &&
           (!now->moonlit || directions_close(shown->moon, now->moon));
}

struct sky_renderer {
    struct vk_context *ctx;
    struct gpu_timer *timer;
    struct sky_passes *passes;
    struct sky_render_lut_sizes sizes;
    struct atmosphere_luts *luts; /* which atmosphere the LUTs show, and rebuilds under way */
    struct cloud_renderer *clouds;
    struct sky_render_night night;
    struct skyview_inputs skyview_shown; /* what the sky-view LUTs were last built for */
    enum sky_render_probe_ms probe_ms;   /* which multiple scattering probes answer with */
    struct sky_render_log log;           /* the caller's sink, which the context's forwards to */
    double frame_end_ms; /* when the last frame's call returned (now_ms); 0 before the first */
};

/* After a failed submission or recreated images nothing the LUTs hold can be trusted. */
static void invalidate_luts(struct sky_renderer *r)
{
    atmosphere_luts_invalidate(r->luts);
    ms_refine_invalidate(sky_passes_ms_refine(r->passes));
    r->skyview_shown.valid = false;
}

static const struct sky_render_lut_sizes default_sizes = {
    .transmittance = { 256, 64 },
    .multiscattering = { 32, 32 },
    .skyview = { 192, 108 },
    .aerial_perspective = { 32, 32, 32 },
};

static uint32_t or_default(uint32_t value, uint32_t fallback)
{
    return value ? value : fallback;
}

static struct sky_render_lut_sizes sizes_with_defaults(const struct sky_render_lut_sizes *in)
{
    struct sky_render_lut_sizes s = default_sizes;
    if (!in)
        return s;
    for (int i = 0; i < 2; i++) {
        s.transmittance[i] = or_default(in->transmittance[i], s.transmittance[i]);
        s.multiscattering[i] = or_default(in->multiscattering[i], s.multiscattering[i]);
        s.skyview[i] = or_default(in->skyview[i], s.skyview[i]);
    }
    for (int i = 0; i < 3; i++)
        s.aerial_perspective[i] = or_default(in->aerial_perspective[i], s.aerial_perspective[i]);
    return s;
}

static double now_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec * 1e3 + (double)ts.tv_nsec * 1e-6;
}

_Static_assert(SKY_RENDER_LOG_ERROR == (int)VK_LOG_ERROR &&
                   SKY_RENDER_LOG_WARNING == (int)VK_LOG_WARNING &&
                   SKY_RENDER_LOG_INFO == (int)VK_LOG_INFO &&
                   SKY_RENDER_LOG_DEBUG == (int)VK_LOG_DEBUG,
               "the renderer's log levels are the context's");

static void forward_log(void *user, enum vk_log_level level, const char *line)
{
    const struct sky_render_log *log = user;
    log->write(log->user, (enum sky_render_log_level)level, line);
}

/* The context's sink: the caller's, or none (stderr). */
static struct vk_log_sink context_log(struct sky_renderer *r)
{
    if (!r->log.write)
        return (struct vk_log_sink){ 0 };
    return (struct vk_log_sink){ .write = forward_log, .user = &r->log };
}

struct sky_renderer *sky_renderer_create(const struct sky_renderer_params *params)
{
    struct sky_renderer_params defaults = { 0 };
    const struct sky_renderer_params *p = params ? params : &defaults;
    struct sky_renderer *r = calloc(1, sizeof *r);
    if (!r)
        return NULL;
    r->log = p->log;
    struct vk_context_params ctx_params = {
        .device_preference = p->device_preference,
        .validation = p->validation,
        .quiet = p->quiet,
        .validation_message_counter = p->validation_message_counter,
        .log = context_log(r),
    };
    r->ctx = vk_context_create(&ctx_params);
    if (!r->ctx)
        goto destroy_partial;
    r->timer = gpu_timer_create(r->ctx);
    r->luts = atmosphere_luts_create();
    if (!r->luts)
        goto destroy_partial;
    r->sizes = sizes_with_defaults(&p->lut_sizes);
    r->clouds = cloud_renderer_create(r->ctx, p->quiet, p->cache_dir);
    if (!r->clouds)
        goto destroy_partial;
    struct sky_cloud_bindings no_clouds;
    cloud_renderer_no_clouds(r->clouds, &no_clouds);
    struct night_stars *stars = night_stars_create();
    if (!stars)
        goto destroy_partial;
    size_t star_words;
    const uint32_t(*words)[4] = night_stars_words(stars, &star_words);
    struct sky_star_field field = { words, star_words, night_stars_brightest_lux(stars) };
    r->passes = sky_passes_create(r->ctx, &r->sizes, &no_clouds, &field, params->warm_up_variants);
    night_stars_destroy(&stars);
    if (!r->passes)
        goto destroy_partial;
    return r;
destroy_partial:
    sky_renderer_destroy(&r);
    return NULL;
}

void sky_renderer_destroy(struct sky_renderer **pr)
{
    struct sky_renderer *r = pr ? *pr : NULL;
    if (!r)
        return;
    if (r->ctx)
        vk_context_wait_idle(r->ctx); /* nothing the passes own may still be in use */
    sky_passes_destroy(r->ctx, &r->passes);
    cloud_renderer_destroy(r->ctx, &r->clouds);
    gpu_timer_destroy(r->ctx, &r->timer);
    atmosphere_luts_destroy(&r->luts);
    vk_context_destroy(&r->ctx);
    free(r);
    *pr = NULL;
}

const char *sky_renderer_device_name(const struct sky_renderer *r)
{
    return r->ctx->properties.deviceName;
}

/* The start of every call that can fail: none is tried on a lost device, and an earlier
 * failure is forgotten so that sky_renderer_status speaks of this call. */
static bool call_begins(struct sky_renderer *r)
{
    if (r->ctx->device_lost)
        return false;
    vk_context_clear_failure(r->ctx);
    return true;
}

enum sky_render_status sky_renderer_status(const struct sky_renderer *r, const char **detail)
{
    const struct vk_context *ctx = r->ctx;
    if (detail)
        *detail = ctx->failure_what;
    if (ctx->device_lost)
        return SKY_RENDER_DEVICE_LOST;
    if (ctx->failure == VK_SUCCESS)
        return SKY_RENDER_OK;
    return vk_result_is_out_of_memory(ctx->failure) ? SKY_RENDER_OUT_OF_MEMORY : SKY_RENDER_FAILED;
}

const char *sky_render_status_name(enum sky_render_status status)
{
    switch (status) {
    case SKY_RENDER_OK:
        return "ok";
    case SKY_RENDER_FAILED:
        return "failed";
    case SKY_RENDER_OUT_OF_MEMORY:
        return "out of memory";
    case SKY_RENDER_DEVICE_LOST:
        return "device lost";
    }
    return "unknown";
}

int sky_renderer_set_lut_sizes(struct sky_renderer *r, const struct sky_render_lut_sizes *sizes)
{
    if (!call_begins(r))
        return -1;
    struct sky_render_lut_sizes s = sizes_with_defaults(sizes);
    if (memcmp(&s, &r->sizes, sizeof s) == 0)
        return 0;
    if (sky_passes_resize_luts(r->ctx, r->passes, &s) != 0)
        return -1;
    r->sizes = s;
    invalidate_luts(r);
    return 0;
}

/* `frame`: a rendered frame, whose GPU time sets the relative LUT budget (a rebuild is not). */
static void collect_stats(struct sky_renderer *r, struct sky_render_stats *stats, double start,
                          bool rebuilt, bool frame)
{
    if (!stats)
        return;
    memset(stats, 0, sizeof *stats);
    /* before the frame moves them */
    stats->cloud_resolution = cloud_renderer_resolution(r->clouds);
    stats->cloud_primary_steps = cloud_renderer_primary_steps(r->clouds);
    struct gpu_timer_result t;
    if (gpu_timer_read(r->ctx, r->timer, &t)) {
        for (int i = 0; i < t.count && i < SKY_RENDER_MAX_PASSES; i++) {
            atmosphere_luts_observe(r->luts, t.names[i], t.ms[i]);
            ms_refine_observe(sky_passes_ms_refine(r->passes), t.names[i], t.ms[i]);
            cloud_renderer_observe(r->clouds, t.names[i], t.ms[i]);
            /* A pass recorded in several dispatches (the LUT blends) is one pass: its total. */
            int k = 0;
            while (k < stats->pass_count && strcmp(stats->pass_names[k], t.names[i]) != 0)
                k++;
            if (k == stats->pass_count) {
                stats->pass_names[stats->pass_count++] = t.names[i];
                stats->pass_ms[k] = 0.0;
            }
            stats->pass_ms[k] += t.ms[i];
        }
        stats->gpu_ms = t.total_ms;
        cloud_renderer_observe_frame(r->clouds, t.total_ms);
        atmosphere_luts_observe_frame(r->luts, frame ? t.total_ms : NAN);
    }
    stats->luts_rebuilt = rebuilt;
    stats->lut_rebuild_progress = atmosphere_luts_progress(r->luts);
    stats->atmosphere_settled = atmosphere_luts_settled(r->luts);
    sky_renderer_multiple_scattering(r, &stats->multiple_scattering);
    stats->metered_ev100 = sky_passes_metered_ev100(r->passes);
    stats->wall_ms = now_ms() - start;
}

int sky_renderer_rebuild_atmosphere(struct sky_renderer *r, const struct sky_render_atmosphere *a,
                                    struct sky_render_stats *stats)
{
    if (!call_begins(r))
        return -1;
    double start = now_ms();
    VkCommandBuffer cmd;
    if (vk_context_begin_commands(r->ctx, &cmd) != VK_SUCCESS)
        return -1;
    gpu_timer_begin(r->timer, cmd);
    invalidate_luts(r);
    atmosphere_luts_record_exact(r->luts, r->passes, cmd, r->timer, a);
    if (vk_context_submit_and_wait(r->ctx, &cmd) != VK_SUCCESS) {
        invalidate_luts(r);
        return -1;
    }
    collect_stats(r, stats, start, true, false);
    return 0;
}

static bool camera_in_atmosphere(const struct sky_render_atmosphere *a,
                                 const struct sky_render_view *v)
{
    return a->bottom_radius_km + v->camera_altitude_km < a->top_radius_km;
}

/* The start every view's command buffer shares: timestamps, the atmosphere LUT work (a share
 * of an amortized rebuild for frames, an exact rebuild for probes), the frame uniforms, and
 * the per-view LUTs when the camera is inside the atmosphere and they are wanted. */
static bool begin_view_commands(struct sky_renderer *r, const struct sky_render_atmosphere *a,
                                const struct sky_render_view *v, bool want_view_luts, bool exact,
                                VkCommandBuffer *cmd, bool *from_space, bool *rebuilt,
                                struct sky_frame_uniforms *fu)
{
    if (vk_context_begin_commands(r->ctx, cmd) != VK_SUCCESS)
        return false;
    gpu_timer_begin(r->timer, *cmd);
    *rebuilt = exact ? atmosphere_luts_record_exact(r->luts, r->passes, *cmd, r->timer, a)
                     : atmosphere_luts_record_frame(r->luts, r->passes, *cmd, r->timer, a);
    a = atmosphere_luts_displayed(r->luts);
    /* The converged multiple scattering: its share of the frame's LUT budget while the
     * atmosphere stands still (none when amortization is off), all of it for a converged probe. */
    struct ms_refine *ms = sky_passes_ms_refine(r->passes);
    if (*rebuilt && atmosphere_luts_settled(r->luts))
        ms_refine_record_warm_up(ms, *cmd); /* once, with the first whole LUT build */
    double budget = atmosphere_luts_frame_budget(r->luts);
    bool converged = exact && want_view_luts && r->probe_ms == SKY_RENDER_PROBE_MS_CONVERGED;
    bool fast = exact && r->probe_ms == SKY_RENDER_PROBE_MS_FAST;
    if (converged)
        ms_refine_record_all(ms, *cmd, r->timer, a);
    else if (!exact && budget > 0.0)
        ms_refine_record_frame(ms, *cmd, r->timer, a, atmosphere_luts_settled(r->luts), budget,
                               now_ms() * 1e-3);
    sky_uniforms_fill_frame(a, v, atmosphere_luts_zenith_transmittance(r->luts), fu);
    bool none = exact && r->probe_ms == SKY_RENDER_PROBE_MS_NONE;
    double weight = fast ? 0.0 : none ? 1.0 : ms_refine_weight_for(ms, a);
    fu->multiple_scattering = (sky_vec4){ (float)weight, none ? 0.0f : 1.0f, 0.0f, 0.0f };
    bool moonlit = night_fill_uniforms(&r->night, v, sky_passes_brightest_star_lux(r->passes), fu);
    sky_passes_upload_frame(r->passes, fu);
    *from_space = !camera_in_atmosphere(a, v);
    if (want_view_luts && !*from_space) {
        struct skyview_inputs now = skyview_inputs_of(fu, moonlit,
                                                      atmosphere_luts_display_generation(r->luts));
        bool keep = skyview_still_valid(&r->skyview_shown, &now);
        sky_passes_record_view_luts(r->passes, *cmd, r->timer, !keep, moonlit);
        if (!keep)
            r->skyview_shown = now;
    }
    return true;
}

/* Whether any of a disk (xyz its direction, w the cosine of its radius) reaches above the
 * horizon whose direction has z = horizon_z, with room for the region's 1.5-radius margin. */
static bool disk_above_horizon(sky_vec4 disk, double horizon_z)
{
    double top = asin(fmax(-1.0, fmin(1.0, disk.z))) + 1.5 * acos(fmin(1.0, disk.w));
    return sin(fmin(top, 1.5707963267948966)) >= horizon_z - 1e-3; /* top clamped at 90 deg */
}

int sky_renderer_render(struct sky_renderer *r, const struct sky_render_atmosphere *a,
                        const struct sky_render_view *v, void *pixels, size_t pixels_bytes,
                        struct sky_render_stats *stats)
{
    if (!call_begins(r))
        return -1;
    double start = now_ms();
    /* The time since the last frame is idle (a stream's period less its frames): LUT and map
     * work may take part of it without delaying the next frame. */
    double idle_ms = r->frame_end_ms > 0.0 ? start - r->frame_end_ms : 0.0;
    atmosphere_luts_observe_idle(r->luts, IDLE_SHARE * idle_ms);
    cloud_renderer_observe_idle(r->clouds, IDLE_SHARE * idle_ms);
    size_t texel = v->output == SKY_RENDER_OUTPUT_LINEAR ? 16 : 4;
    if (v->width == 0 || v->height == 0 || pixels_bytes < (size_t)v->width * v->height * texel) {
        vk_log(r->ctx, VK_LOG_ERROR, "render: output buffer too small for %ux%u", v->width,
               v->height);
        return -1;
    }
    if (sky_passes_prepare_output(r->ctx, r->passes, v->width, v->height, v->output,
                                  start * 1e-3) != 0)
        return -1;
    VkCommandBuffer cmd;
    bool from_space, rebuilt;
    struct sky_frame_uniforms fu;
    if (!begin_view_commands(r, a, v, true, false, &cmd, &from_space, &rebuilt, &fu))
        return -1;
    uint32_t ground_rows[2];
    bool ground = sky_uniforms_ground_rows(v, fu.horizon.z, ground_rows);
    struct cloud_frame cf = {
        .frame = &fu,
        .bottom_radius_km = atmosphere_luts_displayed(r->luts)->bottom_radius_km,
        .width = v->width,
        .height = v->height,
        .history_key = v->history_key,
        .now_s = start * 1e-3,
        .live = v->live,
        .ground_rows = ground ? ground_rows : NULL,
    };
    sky_passes_resources(r->passes, &cf.sky);
    struct sky_cloud_bindings clouds;
    if (cloud_renderer_record_maps(r->ctx, r->clouds, cmd, r->timer, &cf, &clouds) != 0) {
        vk_context_submit_and_wait(r->ctx, &cmd);
        return -1;
    }
    if (!from_space)
        sky_passes_record_aerial_perspective(r->ctx, r->passes, cmd, r->timer, &clouds);
    if (cloud_renderer_record_view(r->ctx, r->clouds, cmd, r->timer, &cf, &clouds) != 0) {
        vk_context_submit_and_wait(r->ctx, &cmd);
        return -1;
    }
    sky_passes_bind_clouds(r->passes, &clouds);
    bool night_visible = night_sky_visible(&r->night, v, sky_passes_brightest_star_lux(r->passes));
    if (v->auto_exposure)
        sky_passes_record_metering(r->passes, cmd, r->timer, v->width, v->height, from_space,
                                   night_visible);
    /* A disk wholly below the horizon is hidden by the ground: its pass would change nothing
     * (a panorama always has the sun and moon in the picture, by night and by day). */
    int32_t sun_rect[4], moon_rect[4];
    bool sun_on_screen = disk_above_horizon(fu.sun_direction, fu.horizon.z) &&
                         sky_uniforms_sun_rect(v, sun_rect);
    bool moon_on_screen = night_moon_rect(&r->night, v, moon_rect) &&
                          disk_above_horizon(fu.moon_direction, fu.horizon.z);
    struct sky_composite_job job = {
        .kind = v->output,
        .from_space = from_space,
        .night_sky = night_visible,
        .clouds = cloud_renderer_active(r->clouds),
        .ground_rows = ground ? ground_rows : NULL,
        .sun_rect = sun_on_screen ? sun_rect : NULL,
        .moon_rect = moon_on_screen ? moon_rect : NULL,
    };
    if (sky_passes_record_composite(r->ctx, r->passes, cmd, r->timer, &job) != 0) {
        vk_context_submit_and_wait(r->ctx, &cmd);
        return -1;
    }
    if (vk_context_submit_and_wait(r->ctx, &cmd) != VK_SUCCESS) {
        invalidate_luts(r);
        return -1;
    }
    sky_passes_copy_output(r->passes, pixels, (size_t)v->width * v->height * texel);
    collect_stats(r, stats, start, rebuilt, true);
    if (stats)
        stats->exposure = sky_ev100_to_exposure(v->auto_exposure ? stats->metered_ev100 : v->ev100);
    fault_injection_frame_rendered();
    r->frame_end_ms = now_ms();
    return 0;
}

/* Records whatever a probe needs before its dispatch, runs it, and copies the results. */
static int run_probe(struct sky_renderer *r, const struct sky_render_atmosphere *a,
                     const struct sky_render_view *v, uint32_t mode, const float (*in)[4],
                     size_t count, double (*out)[3])
{
    if (!call_begins(r))
        return -1;
    if (sky_passes_prepare_probe(r->ctx, r->passes, count, in) != 0)
        return -1;
    VkCommandBuffer cmd;
    bool from_space, rebuilt;
    struct sky_frame_uniforms fu;
    if (!begin_view_commands(r, a, v, mode != SKY_PROBE_TRANSMITTANCE, true, &cmd, &from_space,
                             &rebuilt, &fu))
        return -1;
    sky_passes_record_probe(r->passes, cmd, r->timer, mode, (uint32_t)count, from_space);
    if (vk_context_submit_and_wait(r->ctx, &cmd) != VK_SUCCESS) {
        invalidate_luts(r);
        return -1;
    }
    sky_passes_read_probe(r->passes, count, out);
    return 0;
}

static const struct sky_render_view probe_view_defaults = {
    .width = 1,
    .height = 1,
    .camera_fov_deg = 60,
    .sun_illuminance_lux = 120000,
    .sun_angular_diameter_deg = 0.545,
    .sun_elevation_deg = 45,
    .aerial_perspective_max_km = 64,
};

int sky_renderer_probe_transmittance(struct sky_renderer *r, const struct sky_render_atmosphere *a,
                                     const double *altitude_km, const double *mu, size_t count,
                                     double (*out_rgb)[3])
{
    float(*in)[4] = calloc(count ? count : 1, sizeof *in);
    if (!in)
        return -1;
    for (size_t i = 0; i < count; i++) {
        in[i][0] = (float)(a->bottom_radius_km + altitude_km[i]);
        in[i][1] = (float)mu[i];
    }
    int rc = run_probe(r, a, &probe_view_defaults, SKY_PROBE_TRANSMITTANCE, (const float(*)[4])in,
                       count, out_rgb);
    free(in);
    return rc;
}

int sky_renderer_probe_luminance(struct sky_renderer *r, const struct sky_render_atmosphere *a,
                                 const struct sky_render_view *v, const double (*dirs)[3],
                                 size_t count, bool include_sun, double (*out_rgb)[3])
{
    float(*in)[4] = calloc(count ? count : 1, sizeof *in);
    if (!in)
        return -1;
    for (size_t i = 0; i < count; i++)
        for (int c = 0; c < 3; c++)
            in[i][c] = (float)dirs[i][c];
    struct sky_render_view view = *v;
    view.width = view.height = 1;
    uint32_t mode = include_sun ? SKY_PROBE_LUMINANCE : SKY_PROBE_SKY_LUMINANCE;
    int rc = run_probe(r, a, &view, mode, (const float(*)[4])in, count, out_rgb);
    free(in);
    return rc;
}

void sky_renderer_set_probe_multiple_scattering(struct sky_renderer *r,
                                                enum sky_render_probe_ms which)
{
    r->probe_ms = which;
}

void sky_renderer_multiple_scattering(const struct sky_renderer *r,
                                      struct sky_render_multiple_scattering *out)
{
    const struct ms_refine *ms = sky_passes_ms_refine(r->passes);
    out->weight = ms_refine_weight_for(ms, atmosphere_luts_displayed(r->luts));
    out->progress = ms_refine_progress(ms);
    out->order = ms_refine_order(ms);
    out->build_s = ms_refine_build_seconds(ms);
}

void sky_renderer_set_frame_budget(struct sky_renderer *r, double frame_budget_ms)
{
    cloud_renderer_set_frame_budget(r->clouds, frame_budget_ms);
}

void sky_renderer_set_amortization(struct sky_renderer *r,
                                   const struct sky_render_amortization *amortization)
{
    atmosphere_luts_set_amortization(r->luts, amortization->budget_ms,
                                     amortization->budget_fraction, amortization->blend_frames);
    cloud_renderer_set_budget(r->clouds, amortization->budget_ms);
}

float *sky_renderer_read_lut(struct sky_renderer *r, const char *name, uint32_t size[3])
{
    if (!call_begins(r))
        return NULL;
    return sky_passes_read_lut(r->ctx, r->passes, name, size);
}

int sky_renderer_set_clouds(struct sky_renderer *r, const struct sky_render_clouds *clouds)
{
    if (!call_begins(r))
        return -1;
    return cloud_renderer_set(r->ctx, r->clouds, clouds);
}

double sky_renderer_plain_cloud_type(void)
{
    return cloud_renderer_plain_type();
}

int sky_renderer_prepare_cloud_noise(struct sky_renderer *r, uint32_t noise_seed)
{
    if (!call_begins(r))
        return -1;
    return cloud_renderer_prepare_noise(r->ctx, r->clouds, noise_seed);
}

int sky_renderer_set_weather_map(struct sky_renderer *r, const uint8_t *rgba8, uint32_t width,
                                 uint32_t height)
{
    if (!call_begins(r))
        return -1;
    return cloud_renderer_set_weather_map(r->ctx, r->clouds, rgba8, width, height);
}

void sky_renderer_set_night(struct sky_renderer *r, const struct sky_render_night *night)
{
    r->night = *night;
}

int sky_renderer_cloud_reference_stats(const struct sky_renderer *r,
                                       struct sky_render_reference_stats *out)
{
    return cloud_renderer_reference_stats(r->clouds, out);
}
