/* skyd's renderer: physically based sky and aerial perspective with Vulkan compute.
 *
 * The public face of render/. Knows nothing of sockets, JSON or files. One thread owns a
 * renderer (it owns every Vulkan object); calls are synchronous. Units: km, per km, degrees,
 * lux, cd/m2. The local frame at the camera is x east, y north, z up. */
#ifndef SKYD_SKY_RENDERER_H
#define SKYD_SKY_RENDERER_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

struct sky_render_atmosphere {
    double bottom_radius_km, top_radius_km;
    double rayleigh_scattering[3], rayleigh_scale_height_km;
    double mie_scattering[3], mie_absorption[3], mie_scale_height_km, mie_g[3];
    double ozone_absorption[3], ozone_peak_km, ozone_width_km;
    double ground_albedo[3];
    double fog_density_per_km, fog_scale_height_km;
};

/* The sizes asked for. A side that is a power of two is made two texels shorter (4: two
 * longer; sky_passes.c says why), which sky_renderer_read_lut's size shows. */
struct sky_render_lut_sizes {
    uint32_t transmittance[2];      /* 256 x 64 */
    uint32_t multiscattering[2];    /* 32 x 32 */
    uint32_t skyview[2];            /* 192 x 108 */
    uint32_t aerial_perspective[3]; /* 32 x 32 x 32 */
};

enum sky_render_output_kind {
    SKY_RENDER_OUTPUT_SRGB8 = 0,  /* exposed, tonemapped, sRGB-encoded RGBA8 */
    SKY_RENDER_OUTPUT_LINEAR = 1, /* luminance in cd/m2 as RGBA float32, before exposure */
};

/* The sun disk's limb darkening; the values are the shaders' SKY_LIMB_* (checked in
 * sky_uniforms.c). */
enum sky_render_limb {
    SKY_RENDER_LIMB_NONE = 0,
    SKY_RENDER_LIMB_NECKEL96 = 1, /* Neckel & Labs 1994, fifth-order polynomial */
    SKY_RENDER_LIMB_HM98 = 2,     /* Hestroffer & Magnan 1998, power law */
};

/* The sRGB output's tone curve; the values are the shaders' SKY_TONEMAP_OP_*. */
enum sky_render_tonemap {
    SKY_RENDER_TONEMAP_ACES = 0,
    SKY_RENDER_TONEMAP_REINHARD = 1,
    SKY_RENDER_TONEMAP_CLAMP = 2,
};

/* How pixels map to directions. */
enum sky_render_projection {
    SKY_RENDER_PROJECTION_PERSPECTIVE = 0, /* pinhole: yaw, pitch, vertical fov */
    /* The whole sphere, 2:1: column u = (x + 0.5) / width is the azimuth yaw + (u - 0.5) 360
     * deg (the camera's yaw at the centre, increasing to the right: north through east), row
     * v = (y + 0.5) / height the elevation 90 - 180 v deg. Pitch and fov play no part. */
    SKY_RENDER_PROJECTION_EQUIRECTANGULAR = 1,
};

struct sky_render_view {
    uint32_t width, height;
    enum sky_render_projection projection;
    double camera_altitude_km, camera_yaw_deg, camera_pitch_deg, camera_fov_deg;
    double sun_azimuth_deg, sun_elevation_deg;
    double sun_illuminance_lux; /* ground illuminance with the sun at zenith */
    double sun_angular_diameter_deg;
    enum sky_render_limb limb_darkening;
    bool auto_exposure;
    bool night_adaptation;           /* auto exposure darkens dim scenes (exposure_resolve.comp) */
    double ev100;                    /* manual exposure */
    double exposure_compensation_ev; /* for auto exposure */
    enum sky_render_tonemap tonemap;
    double aerial_perspective_max_km;
    enum sky_render_output_kind output;
    /* Which cloud history (temporal reprojection) this view continues: views of one key share
     * it, so each independent camera of a caller needs its own key. Histories are kept for a
     * few keys (least recently used goes first) and also per size; 0 is a valid key. */
    uint64_t history_key;
    /* A stream of frames: a new cloud history shows its first frame at once and converges
     * over the next ones, where a one-off view (false) first accumulates several internal
     * frames so that it comes out converged. */
    bool live;
};

enum sky_render_log_level {
    SKY_RENDER_LOG_ERROR = 0,
    SKY_RENDER_LOG_WARNING = 1,
    SKY_RENDER_LOG_INFO = 2,
    SKY_RENDER_LOG_DEBUG = 3,
};

/* Where the renderer's lines go (the device chosen, validation messages, failures): `write`
 * gets one line per call, without a newline and without the "skyd: " prefix, on the thread
 * that called the renderer (validation messages: the thread of the offending call), from
 * sky_renderer_create to the end of sky_renderer_destroy. No `write`: each line goes to stderr
 * after "skyd: ". */
struct sky_render_log {
    void (*write)(void *user, enum sky_render_log_level level, const char *line);
    void *user;
};

struct sky_renderer_params {
    const char *device_preference; /* see vk_context_params; NULL = auto */
    bool validation;               /* Khronos validation layer, messages counted */
    bool quiet;
    struct sky_render_lut_sizes lut_sizes; /* zero fields take the defaults above */
    /* Optional: incremented for every validation warning or error, including those raised
     * while the renderer is destroyed. Must outlive the renderer. */
    unsigned *validation_message_counter;
    struct sky_render_log log;
    /* The first frame of each output kind (sRGB, linear) dispatches every composite pipeline
     * of that kind, so none compiles later: a daemon then neither stalls a stream when a view
     * first needs one nor grows as views find new ones. One-shot renders leave it off. */
    bool warm_up_variants;
    /* Where the generated cloud noise is kept between runs, one file per seed, device and
     * build of its shaders (render/clouds/cloud_noise_cache.h): a start then reads it in
     * milliseconds instead of generating it for seconds. NULL or "": generated every time. */
    const char *cache_dir;
};

#define SKY_RENDER_MAX_PASSES 32 /* = GPU_TIMER_MAX_PASSES */

/* The converged multiple scattering (render/sky/ms_refine.h): while the atmosphere stands
 * still, an amortized multi-order integration refines Hillaire's approximation. */
struct sky_render_multiple_scattering {
    double weight;   /* of the converged table in what frames show: 0 Hillaire's fast path, 1
                        converged, between: fading */
    double progress; /* of the table's build, [0, 1]; 1: complete */
    int order;       /* the order being computed, 0 when none is */
    double build_s;  /* wall time of the last complete build (NAN before one) */
};

/* How many of the cloud pixels are traced each frame (the rest from reprojected history). */
enum sky_render_cloud_resolution {
    SKY_RENDER_CLOUDS_FULL = 0,      /* every pixel traced every frame */
    SKY_RENDER_CLOUDS_QUARTER = 1,   /* one pixel of each 2x2 block per frame */
    SKY_RENDER_CLOUDS_SIXTEENTH = 2, /* one pixel of each 4x4 block per frame */
    /* Clouds at half width and height, one pixel of each 4x4 block of those per frame
     * (Schneider 2015's scheme): 1/64 of the output's pixels. */
    SKY_RENDER_CLOUDS_SIXTYFOURTH = 3,
    /* One of the above, the finest whose frames fit the frame budget
     * (sky_renderer_set_frame_budget), from the measured GPU time, with the low layer's march
     * steps halved below the coarsest and doubled above full (render/clouds/cloud_quality.h);
     * sixtyfourth with the clouds' own steps without a budget. */
    SKY_RENDER_CLOUDS_AUTO = 4,
};

struct sky_render_stats {
    int pass_count;
    const char *pass_names[SKY_RENDER_MAX_PASSES];
    double pass_ms[SKY_RENDER_MAX_PASSES]; /* GPU time per pass from timestamp queries */
    double gpu_ms;                         /* sum of the passes */
    double wall_ms;                        /* CPU wall time of the whole call */
    bool luts_rebuilt;                     /* atmosphere LUT work was recorded */
    double lut_rebuild_progress;           /* of an amortized rebuild; 1 when none is under way */
    bool atmosphere_settled;               /* the frame shows exactly the atmosphere asked for */
    double metered_ev100;                  /* auto exposure result (when auto) */
    /* The exposure multiplier the frame used (auto or manual): the sRGB output tonemaps
     * luminance x exposure; with LINEAR output it says how the frame would have been exposed. */
    double exposure;
    struct sky_render_multiple_scattering multiple_scattering;
    /* The resolution the frame's clouds were traced at and the low layer's march steps (what
     * resolution AUTO chose, or the clouds' own). */
    enum sky_render_cloud_resolution cloud_resolution;
    int cloud_primary_steps;
};

struct sky_renderer;

/* The unit vector of a direction in the local frame (x east, y north, z up) from its azimuth
 * (north through east) and elevation, degrees. */
void sky_direction_from_angles(double azimuth_deg, double elevation_deg, double out[3]);

struct sky_renderer *sky_renderer_create(const struct sky_renderer_params *params);
void sky_renderer_destroy(struct sky_renderer **renderer);

/* Why the renderer's last call failed, as far as the device is concerned:
 *   SKY_RENDER_OK             no Vulkan failure since that call began (it may still have
 *                             failed on its arguments: said through the log);
 *   SKY_RENDER_FAILED         a Vulkan call failed; the renderer stays usable;
 *   SKY_RENDER_OUT_OF_MEMORY  host or device memory ran out; what that call was making is
 *                             undone, the renderer stays usable, and a later or a smaller
 *                             request may succeed;
 *   SKY_RENDER_DEVICE_LOST    the device is lost (VK_ERROR_DEVICE_LOST, or a submission that
 *                             did not finish in VK_CONTEXT_SUBMIT_TIMEOUT_S): every call fails
 *                             from now on, without waiting; destroy the renderer (which does
 *                             not wait for the device either) and create another.
 * `detail`, when not NULL, receives what failed and the Vulkan result, e.g.
 * "creating image "output" (640x360x1): VK_ERROR_OUT_OF_DEVICE_MEMORY" ("" when nothing did).
 * Each call that can fail begins by forgetting an earlier failure that did not lose the device.
 * render/vk/fault_injection.h can provoke the last two for tests (SKYD_FAULT). */
enum sky_render_status {
    SKY_RENDER_OK = 0,
    SKY_RENDER_FAILED,
    SKY_RENDER_OUT_OF_MEMORY,
    SKY_RENDER_DEVICE_LOST,
};
enum sky_render_status sky_renderer_status(const struct sky_renderer *renderer,
                                           const char **detail);
const char *sky_render_status_name(enum sky_render_status status);

/* Name of the Vulkan device in use. */
const char *sky_renderer_device_name(const struct sky_renderer *renderer);

/* Changes LUT sizes; images are recreated and the atmosphere LUTs rebuilt on the next call. */
int sky_renderer_set_lut_sizes(struct sky_renderer *renderer,
                               const struct sky_render_lut_sizes *sizes);

/* Renders one frame. `pixels` receives width*height RGBA texels, 4 bytes each for SRGB8 or
 * 4 floats each for LINEAR; its size in bytes is `pixels_bytes`. The atmosphere LUTs are
 * rebuilt first when `atmosphere` differs from the last one. Returns 0 or -1. */
int sky_renderer_render(struct sky_renderer *renderer,
                        const struct sky_render_atmosphere *atmosphere,
                        const struct sky_render_view *view, void *pixels, size_t pixels_bytes,
                        struct sky_render_stats *stats);

/* Rebuilds transmittance, multi-scattering and ground irradiance LUTs now (timed in stats). */
int sky_renderer_rebuild_atmosphere(struct sky_renderer *renderer,
                                    const struct sky_render_atmosphere *atmosphere,
                                    struct sky_render_stats *stats);

/* Transmittance to the top of the atmosphere from `altitude_km[i]` along cos-zenith `mu[i]`,
 * read from the transmittance LUT as every pass does. */
int sky_renderer_probe_transmittance(struct sky_renderer *renderer,
                                     const struct sky_render_atmosphere *atmosphere,
                                     const double *altitude_km, const double *mu, size_t count,
                                     double (*out_rgb)[3]);

/* Luminance (cd/m2, before exposure) seen from the view's camera in each local direction
 * (x east, y north, z up), through the same shading as a frame; with include_sun false the
 * sun disk is left out (sky and ground only). */
int sky_renderer_probe_luminance(struct sky_renderer *renderer,
                                 const struct sky_render_atmosphere *atmosphere,
                                 const struct sky_render_view *view, const double (*dirs)[3],
                                 size_t count, bool include_sun, double (*out_rgb)[3]);

/* Which multiple scattering luminance probes answer with. */
enum sky_render_probe_ms {
    SKY_RENDER_PROBE_MS_CURRENT = 0, /* what frames show now (the default) */
    SKY_RENDER_PROBE_MS_FAST = 1,    /* Hillaire's approximation alone */
    /* the converged table, built first for the atmosphere when it does not hold it (about a
     * second on lavapipe, once per atmosphere) */
    SKY_RENDER_PROBE_MS_CONVERGED = 2,
    /* single scattering and the sunlit ground alone (no multiple scattering: for tests) */
    SKY_RENDER_PROBE_MS_NONE = 3,
};
void sky_renderer_set_probe_multiple_scattering(struct sky_renderer *renderer,
                                                enum sky_render_probe_ms which);
/* Where the converged multiple scattering stands. */
void sky_renderer_multiple_scattering(const struct sky_renderer *renderer,
                                      struct sky_render_multiple_scattering *out);

/* Amortized atmosphere LUT updates (seed 001, 3.5.1). With budget_ms > 0, a frame whose
 * atmosphere differs from the displayed one starts a rebuild that is spread over frames, about
 * budget_ms of GPU time each, or budget_fraction of the frame's own GPU time (the rest of the
 * frame, smoothed over frames) when that is less and budget_fraction > 0, unless half the wall
 * time since the previous frame returned is more (the idle part of a stream's frame period,
 * which a fast device has most of: frames back to back leave none); at least one slice
 * (a transmittance row, a multiple-scattering texel) per frame. Frames keep using the last complete
 * LUTs and atmosphere; when it completes they blend to the new ones over blend_frames frames.
 * A different atmosphere during a rebuild restarts it. budget_ms <= 0 (the default) rebuilds at
 * once. Probes and sky_renderer_rebuild_atmosphere always finish a rebuild first. */
struct sky_render_amortization {
    double budget_ms;
    double budget_fraction;
    int blend_frames;
};
void sky_renderer_set_amortization(struct sky_renderer *renderer,
                                   const struct sky_render_amortization *amortization);

/* The GPU time a frame may take (ms; <= 0: none), which clouds at resolution AUTO fit. */
void sky_renderer_set_frame_budget(struct sky_renderer *renderer, double frame_budget_ms);

/* Whether a pass of sky_render_stats is atmosphere LUT work (a rebuild's slices, the save and
 * blend of the displayed LUTs). */
bool sky_render_pass_is_atmosphere_lut(const char *pass_name);

/* Reads back a LUT for tests: "transmittance" (optical depth per channel), "multiscattering",
 * "skyview", "irradiance", "ap_inscatter", "ap_transmittance", "ap_shafts" (3D, depth
 * slices; ap_shafts: the in-scattering cloud shadows took away). Fills
 * size (width, height, depth) and returns a malloc'd RGBA float array, x fastest then y then
 * slice (caller frees), or NULL. */
float *sky_renderer_read_lut(struct sky_renderer *renderer, const char *name, uint32_t size[3]);

/* ---- Clouds (seed 001 section 5) ---- */

struct sky_render_cloud_layer {
    double coverage; /* 0..1 */
    double type;     /* 0 stratus, 1/3 stratocumulus, 2/3 cumulus, 1 cumulonimbus; for the
                            middle layer 0 altostratus sheet .. 1 altocumulus cells; high
                            layer 0 smooth sheet .. 1 fibrous */
    double density;  /* multiplier of extinction_per_km */
    double bottom_km, thickness_km;
};

struct sky_render_clouds {
    struct sky_render_cloud_layer low, mid, high;
    double extinction_per_km;                              /* at density 1 */
    double albedo;                                         /* single-scattering albedo */
    double precipitation;                                  /* 0..1 */
    double phase_g0, phase_g1, phase_w;                    /* seed 000 eq. 14.17 */
    double multiscatter_a, multiscatter_b, multiscatter_c; /* seed 000 eq. 14.18; a <= b */
    int multiscatter_octaves;
    double multiscatter_powder; /* build-up rate per optical depth below a lit surface; 0 none */
    double ambient_scale;
    uint32_t noise_seed;
    int primary_steps, light_steps;
    enum sky_render_cloud_resolution resolution;
    bool temporal;
    /* Weather map: the wind's displacement of the pattern, its seed and extent. */
    double wind_offset_east_km, wind_offset_north_km;
    uint32_t weather_seed;
    double map_extent_km;
    bool use_client_map; /* sample the map given to sky_renderer_set_weather_map */
    /* With use_client_map: the map's texels are the local coverage, type and rain of the
     * procedural field, whose cells and sheets fill them (a forecast's coarse grid of cloud
     * cover); false: the texels are the weather map itself (a client's painting). */
    bool client_map_drives_procedural;
    /* The path-traced reference instead of the real-time clouds (shaders/cloud_pathtrace.comp):
     * samples per pixel of every view, 0 off; every pixel traced, no temporal history, the
     * frame as slow as the samples make it. reference_seed varies its random numbers. */
    uint32_t reference_spp;
    uint32_t reference_seed;
};

/* What the last reference frame's path tracer counted (once sky_renderer_render returned). */
struct sky_render_reference_stats {
    double density_samples; /* evaluations of the cloud density */
    uint32_t
        bound_violations;   /* of them, above the majorant (0 unless the density's bound broke) */
    double max_bound_ratio; /* the largest density / majorant among those */
    uint32_t overflows;     /* ray segments cut short by the step limit */
    uint32_t truncated;     /* samples whose paths lavapipe's loop limit cut short (darker) */
};
/* Returns 0, or -1 when no reference frame has been rendered. */
int sky_renderer_cloud_reference_stats(const struct sky_renderer *renderer,
                                       struct sky_render_reference_stats *out);

/* Sets the clouds of the following frames. The noise volumes are generated (on the GPU, a few
 * hundred ms on lavapipe) the first time a layer has coverage and whenever noise_seed changes;
 * weather and shadow maps are rebuilt when their inputs change, amortized like the atmosphere
 * LUTs. Returns 0 or -1. */
int sky_renderer_set_clouds(struct sky_renderer *renderer, const struct sky_render_clouds *clouds);

/* Generates the cloud noise volumes for noise_seed now (a few hundred ms on lavapipe) unless
 * they exist: services call it at start-up so no frame pays for it later. Returns 0 or -1. */
int sky_renderer_prepare_cloud_noise(struct sky_renderer *renderer, uint32_t noise_seed);

/* The largest clouds.low.type whose procedural weather map holds no towering clouds (types
 * above it draw the marches' towering variants). */
double sky_renderer_plain_cloud_type(void);

/* A client weather map of width x height RGBA8 texels, row-major from the north-west corner
 * (x east, y south), tiled over map_extent_km around the camera's foot and moved by the wind:
 *   r  low-layer coverage   0..255 -> 0..1
 *   g  high-layer coverage
 *   b  low-layer cloud type (0 stratus .. 255 cumulonimbus)
 *   a  precipitation (darkens and thickens the low layer's base)
 * Used while sky_render_clouds.use_client_map is set. NULL forgets the map (procedural again).
 * Returns 0, or -1 for a bad size (1..4096 per side) or a Vulkan failure. */
int sky_renderer_set_weather_map(struct sky_renderer *renderer, const uint8_t *rgba8,
                                 uint32_t width, uint32_t height);

/* ---- Night sky: moon disc, stars, moonlit sky, airglow (render/night_*.c) ---- */

/* The night's light sources for the following frames and probes. The sun's direction is the
 * view's: it lights the moon as a sphere, so the phase and the bright limb follow. A zeroed
 * struct (the default) shows no moon, no stars and no airglow. */
struct sky_render_night {
    double moon_azimuth_deg, moon_elevation_deg, moon_angular_diameter_deg;
    /* Outside the atmosphere, on a surface facing the moon, phase included; 0 hides the moon. */
    double moon_illuminance_lux;
    /* J2000 equatorial unit vector -> local east/north/up (rows are the local axes): sidereal
     * time, latitude and precession. */
    double star_rotation[3][3];
    double star_brightness;         /* multiplier of the catalogue's illuminance; 0 hides stars */
    double airglow_luminance_cd_m2; /* natural night-sky background at the zenith */
};
void sky_renderer_set_night(struct sky_renderer *renderer, const struct sky_render_night *night);

#endif
