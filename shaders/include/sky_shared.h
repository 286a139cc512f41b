/* Parameter-block and push-constant layouts shared by C (render/) and GLSL (shaders/).
 *
 * Only vec4/ivec4 members, so std140, std430 and C agree without padding rules. Lengths are km,
 * coefficients per km, illuminance lux, luminance cd/m2. Coordinates: planet centred; the
 * camera stands above the point (0, 0, bottom_radius) and the local frame there is x east,
 * y north, z up. */
#ifndef SKY_SHARED_H
#define SKY_SHARED_H

#if defined(VULKAN) || defined(GL_core_profile)
#define SKY_VEC4 vec4
#define SKY_IVEC4 ivec4
#define SKY_UINT uint
/* A parameter block (atmosphere, frame, clouds): a read-only storage buffer NAME_block and a
 * private copy NAME that main() fills first (NAME = NAME_block). Not a uniform buffer: lavapipe
 * (Mesa 22.3) inlines uniform-buffer and push-constant values that decide an `if` or a loop's
 * end and, when the first such variant is less than half the code, compiles the pipeline again
 * at every dispatch and never frees the old code; whether it does depends on the state at the
 * first dispatch. Storage-buffer values are never inlined, and the copy lets marches read
 * registers instead of memory. */
#define SKY_PARAMETER_BLOCK(binding_, block_, type_, name_) \
    layout(std430, binding = binding_) readonly buffer block_ { type_ name_##_block; }; \
    type_ name_
#else
#include <stdint.h>
typedef struct { float x, y, z, w; } sky_vec4;
typedef struct { int32_t x, y, z, w; } sky_ivec4;
#define SKY_VEC4 sky_vec4
#define SKY_IVEC4 sky_ivec4
#define SKY_UINT uint32_t
#endif

/* Limb darkening models (sun_illuminance.w). */
#define SKY_LIMB_NONE 0
#define SKY_LIMB_NECKEL96 1
#define SKY_LIMB_HM98 2

/* Tonemapping operators (exposure.w). */
#define SKY_TONEMAP_OP_ACES 0
#define SKY_TONEMAP_OP_REINHARD 1
#define SKY_TONEMAP_OP_CLAMP 2

/* Composite output kinds (image.w). */
#define SKY_OUTPUT_SRGB8 0
#define SKY_OUTPUT_LINEAR_LUMINANCE 1

/* Camera projections (camera_up.w; sky_cloud_view_push.target.z for the history's). */
#define SKY_PROJECTION_PERSPECTIVE 0
#define SKY_PROJECTION_EQUIRECTANGULAR 1

/* Probe modes (probe push constants). */
#define SKY_PROBE_LUMINANCE 0
#define SKY_PROBE_TRANSMITTANCE 1
#define SKY_PROBE_SKY_LUMINANCE 2 /* luminance without the sun disk */

/* Auto-exposure metering grid workgroup size and resolve limits. */
#define SKY_METER_LOCAL 8
#define SKY_METER_MAX_GROUPS 1024

struct sky_atmosphere_uniforms {
    SKY_VEC4 radii;               /* x bottom, y top, z rayleigh scale height, w mie scale height */
    SKY_VEC4 rayleigh_scattering; /* xyz; w ozone peak altitude */
    SKY_VEC4 mie_scattering;      /* xyz; w ozone full width */
    SKY_VEC4 mie_absorption;      /* xyz; w fog density (scattering per km at the ground) */
    SKY_VEC4 mie_extinction;      /* xyz = scattering + absorption; w fog scale height */
    SKY_VEC4 mie_g;               /* xyz Cornette-Shanks asymmetry per channel */
    SKY_VEC4 ozone_absorption;    /* xyz */
    SKY_VEC4 ground_albedo;       /* xyz */
    SKY_VEC4 ground_transfer;     /* xyz: A of render/sky/ground_transfer.h */
};

struct sky_frame_uniforms {
    SKY_VEC4 camera_position;     /* xyz planet-centred km; w altitude km */
    SKY_VEC4 camera_forward;      /* xyz unit; w tan(vertical fov / 2) */
    SKY_VEC4 camera_right;        /* xyz unit; w aspect ratio (width / height) */
    SKY_VEC4 camera_up;           /* xyz unit; w SKY_PROJECTION_* (equirectangular: forward is
                                     the horizontal yaw direction and up the zenith) */
    SKY_VEC4 sun_direction;       /* xyz unit, toward the sun; w cos(angular radius) */
    SKY_VEC4 sun_illuminance;     /* xyz extraterrestrial illuminance per channel; w limb model */
    SKY_VEC4 sun_disk;            /* x solid angle (sr), y sin(angular radius), zw unused */
    SKY_VEC4 exposure;            /* x manual exposure multiplier, y 0 manual, 1 auto, 2 auto
                                     with night adaptation, z compensation EV, w tonemap operator */
    SKY_VEC4 image;               /* x width, y height, z aerial perspective max km, w output kind */
    SKY_VEC4 sun_local;           /* sun direction in the sky-view LUT frame (azimuth 0) */
    SKY_VEC4 sun_horizontal;      /* sun direction projected on the camera's horizontal plane,
                                     normalised; w 1, or 0 when the sun is at the zenith */
    SKY_VEC4 horizon;             /* camera's geometric horizon: x beta = acos(sqrt(r^2-R^2)/r),
                                     y pi - beta (zenith angle of the horizon), z cos of that */
    /* Night sky (render/night/night_sky.c, shaders/include/night_sky.glsl). */
    SKY_VEC4 moon_direction;      /* xyz unit, toward the moon; w cos(angular radius) */
    SKY_VEC4 moon_illuminance;    /* xyz per channel outside the atmosphere, phase included;
                                     w 1 when the moonlit sky-view LUT is computed this frame */
    SKY_VEC4 moon_disk;           /* x 1 / integral of albedo x reflectance over the disc (1/sr),
                                     y sin(angular radius), z 1 when the disc is drawn */
    SKY_VEC4 moon_earthshine;     /* xyz earthshine luminance of the highlands (cd/m2) */
    SKY_VEC4 moon_local;          /* moon direction in its sky-view LUT frame (azimuth 0) */
    SKY_VEC4 moon_horizontal;     /* as sun_horizontal, for the moon */
    SKY_VEC4 moon_up;             /* xyz lunar north on the disc (celestial pole, projected) */
    SKY_VEC4 star_rotation[3];    /* rows of the J2000 equatorial -> local east/north/up matrix */
    SKY_VEC4 night;               /* x airglow zenith luminance (cd/m2), y star brightness
                                     multiplier, z star blur sigma (rad), w sky luminance above
                                     which stars add under 0.1 % and are skipped */
    SKY_VEC4 multiple_scattering; /* x weight of the converged multiple scattering (ms_refine.h)
                                     against Hillaire's LUT in the sky-view; y 1, or 0 to leave
                                     the table out (single scattering alone, for tests); zw
                                     unused */
};

/* Per-dispatch constants of the probe pass. */
struct sky_probe_push {
    SKY_UINT count;
    SKY_UINT mode;
    SKY_UINT pad0;
    SKY_UINT pad1;
};

/* Per-dispatch constants of the composite: the pixel rectangle it covers (the whole image,
 * or the sun's bounding box for the sun-disk pass). */
struct sky_region_push {
    SKY_IVEC4 rect;   /* x0, y0, width, height in pixels */
    SKY_VEC4 clouds;  /* xy the cloud images' size in texels (their extent may be larger:
                         gpu_image_create_view_sized) */
};

/* A slice of rows of an atmosphere LUT: rebuilds are spread over frames (seed 001, 3.5.1). */
struct sky_rows_push {
    SKY_UINT row_offset;
    SKY_UINT pad0;
    SKY_UINT pad1;
    SKY_UINT pad2;
};

/* One step of the converged multiple scattering (ms_refine.h): the order, the texels
 * [first, end) of the table (row-major: x fastest, then y, then z) this dispatch covers, and
 * whether the order is the last. */
struct sky_ms_push {
    SKY_UINT order;
    SKY_UINT first;
    SKY_UINT last;
    SKY_UINT end;
};

/* out = mix(from, to, weight): the displayed LUTs blend from the last complete build to the
 * new one. */
struct sky_blend_push {
    float weight;
    float pad0;
    float pad1;
    float pad2;
};

/* Per-dispatch constants of the metering passes. */
struct sky_meter_push {
    SKY_UINT grid_width;
    SKY_UINT grid_height;
    SKY_UINT group_count;
    SKY_UINT pad0;
};

#endif
