/* Parameter-block and push-constant layouts of the cloud passes, shared by C (render/cloud_*.c) and
 * GLSL (shaders/cloud_*.comp). Only vec4/ivec4 members (std430 = C layout). Lengths km,
 * extinction per km, luminance cd/m2. Horizontal cloud coordinates are the planet-centred x
 * (east) and y (north) of a point minus the wind's displacement of the weather pattern: the
 * flat-planet projection around the camera that seed 001 (5.9) also uses for cloud shadows. */
#ifndef CLOUD_SHARED_H
#define CLOUD_SHARED_H

#include "sky_shared.h"

/* Cloud-type shapes (stratus, stratocumulus, cumulus, cumulonimbus): profiles[i] holds x the
 * height fraction of the layer a core reaches, y the base's rounding (height fraction), z how
 * much the detail noise erodes, w the anvil's spread under the layer top. */
#define CLOUD_PROFILE_COUNT 4

/* Coverage below this holds no cloud (cloud_density.glsl). The procedural map stores less than
 * it as a value falling below 0 (cloud_weather.comp), so that "coverage <= 0" marks texels
 * without cloud (the path tracer's majorant grid, cloud_majorant.comp). */
#define CLOUD_MIN_COVERAGE 0.02

/* Cloud types above this tower: turrets twice as large, anvils (cloud_density.glsl). The
 * procedural map varies the asked type by less than CLOUD_TYPE_VARIATION (cloud_weather.comp),
 * so the renderer knows which maps hold towering clouds (cloud_renderer.c). */
#define CLOUD_TOWERING_TYPE 0.8
#define CLOUD_TYPE_VARIATION 0.15
/* Cloud types above this spread an anvil under the layer's top (cloud_density.glsl). */
#define CLOUD_ANVIL_TYPE 0.85

/* Cloud types from 0 up to the first are sheets (stratus, stratocumulus), up from the second
 * heaped clouds; between them the sheet's share falls smoothly. A sheet's density grows with the
 * height above its base, up to twice the layer's (cloud_density.glsl), which the path tracer's
 * majorant grid bounds per cell (cloud_majorant.comp). */
#define CLOUD_SHEET_TYPES_END 0.3
#define CLOUD_HEAPED_TYPES_START 0.55
#if defined(VULKAN) || defined(GL_core_profile)
/* The share of a low-layer texel's cloud that is a sheet, from its type (weather map b). */
float cloud_sheet_share(float type)
{
    return 1.0 - smoothstep(CLOUD_SHEET_TYPES_END, CLOUD_HEAPED_TYPES_START, type);
}
#endif

/* Weather-map texel channels (procedural and client maps alike). */
#define CLOUD_WEATHER_LOW_COVERAGE 0  /* r */
#define CLOUD_WEATHER_HIGH_COVERAGE 1 /* g */
#define CLOUD_WEATHER_TYPE 2          /* b: low-layer cloud type, 0 stratus .. 1 cumulonimbus */
#define CLOUD_WEATHER_PRECIPITATION 3 /* a: darkens and thickens the low layer's base */

struct sky_cloud_uniforms {
    SKY_VEC4 low;          /* x bottom radius, y top radius (planet-centred km), z extinction per
                              km at full density (clouds.extinction_per_km * low.density), w 1 */
    SKY_VEC4 high;         /* the same for the high layer; w 1 when the layer is on */
    SKY_VEC4 media;        /* x single-scattering albedo, y precipitation, z ambient scale,
                              w high-layer type (0 smooth sheet .. 1 fibrous) */
    SKY_VEC4 phase;        /* x g0, y g1, z w (seed 000 eq. 14.17), w octave count */
    SKY_VEC4 octaves;      /* x a, y b, z c (seed 000 eq. 14.18), w light march steps */
    SKY_VEC4 weather;      /* xy wind displacement of the pattern (east, north km), z 1/extent,
                              w extent km */
    SKY_VEC4 march;        /* x primary steps, y longest march km, z 1 when any layer is on,
                              w blue-noise frame phase */
    SKY_VEC4 profiles[CLOUD_PROFILE_COUNT]; /* per type: x top, y base rounding, z erosion,
                                               w anvil (above) */
    SKY_VEC4 shadow_sun;   /* xyz sun direction the shadow map was built for; w 1 when built */
    SKY_VEC4 tiles;        /* km per repeat of the base, detail and curl noise (x, y, z): whole
                              fractions of the weather extent, so the pattern tiles with it */
    SKY_VEC4 build_up;     /* x the octaves' build-up rate K per optical depth below a lit
                              surface (0: none), yzw 0 */
    SKY_VEC4 mid;          /* the middle layer as `low`; w 1 when the layer is on */
    SKY_VEC4 mid_shape;    /* x the middle layer's coverage, y its type (0 altostratus .. 1
                              altocumulus), zw 0 */
};

/* A slice of rows of an amortized cloud map (weather map, shadow map). */
struct sky_cloud_rows_push {
    SKY_UINT row_offset;
    SKY_UINT mode;         /* weather: 0 procedural, 1 client map, 2 procedural under a map */
    SKY_UINT seed;
    SKY_UINT high_fibrous; /* weather: the high layer's type, 0 a veil .. 1000 fibrous */
    SKY_VEC4 params;       /* weather: x low coverage, y high coverage, z low type,
                              w precipitation; shadow: xyz the sun the map is built for (the
                              block's shadow_sun is the shown map's) */
    SKY_VEC4 size;         /* resolve: xy the cloud image's size in texels (its extent may be
                              larger: gpu_image_create_view_sized); weather: cells across
                              the map of the cumulus, cumulonimbus, stratocumulus and
                              stratus patterns */
};

/* Noise generation: one z slab of a volume per dispatch. */
struct sky_cloud_noise_push {
    SKY_UINT seed;
    SKY_UINT z_offset;
    SKY_UINT pad0;
    SKY_UINT pad1;
};

/* Per-view constants of the trace and reconstruct passes. The traced pixel of each block of
 * block x block pixels of the cloud image cycles through the block frame by frame. */
struct sky_cloud_view_push {
    SKY_VEC4 prev_forward;  /* previous frame's camera: xyz forward, w tan(fov/2) */
    SKY_VEC4 prev_right;    /* xyz right, w aspect */
    SKY_VEC4 prev_up;       /* xyz up, w 1 when a history exists */
    SKY_IVEC4 frame;        /* x frame index, y block size, z/w traced pixel in the block */
    SKY_IVEC4 target;       /* xy size of the cloud image (the output, or half of it), z the
                               history's SKY_PROJECTION_* */
    SKY_VEC4 motion;        /* xy wind displacement since the history (km), z smallest blend
                               weight of a new sample, w 1 = temporal accumulation on */
};

/* Per-dispatch constants of the path-traced reference (cloud_pathtrace.comp). */
struct sky_cloud_reference_push {
    SKY_IVEC4 samples;     /* x samples per pixel before this dispatch, y in it, z seed */
    SKY_IVEC4 target;      /* xy size of the cloud image (the output's), z 0 (a loop's trip
                              count no compiler knows), w 1 in the last dispatch (no samples:
                              it writes the image) */
    SKY_VEC4 media;        /* x the largest precipitation of the weather map */
};

/* The reference's counters (cloud_pathtrace.comp's pt_stats). */
struct sky_cloud_reference_stats {
    SKY_UINT violations;     /* density samples above the majorant */
    SKY_UINT max_ratio_bits; /* the largest density / majorant among them (float bits) */
    SKY_UINT kilo_samples;   /* density samples, thousands */
    SKY_UINT overflows;      /* segments that ran out of steps */
    SKY_UINT truncated;      /* samples whose loops the device's loop limit cut short */
};

/* Hemisphere averages of the clouds seen from the ground (seed 001 eq. 22 inputs). */
#define CLOUD_HEMISPHERE_RAYS 64

#endif
