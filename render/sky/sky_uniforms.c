#include "sky_uniforms.h"

#include <math.h>
#include <string.h>

#include "ground_transfer.h"
#include "sky_photometry.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif
#define DEG (M_PI / 180.0)
/* The public enums are the shaders' constants. */
_Static_assert(SKY_RENDER_LIMB_NONE == SKY_LIMB_NONE &&
                   SKY_RENDER_LIMB_NECKEL96 == SKY_LIMB_NECKEL96 &&
                   SKY_RENDER_LIMB_HM98 == SKY_LIMB_HM98,
               "limb darkening models");
_Static_assert(SKY_RENDER_TONEMAP_ACES == SKY_TONEMAP_OP_ACES &&
                   SKY_RENDER_TONEMAP_REINHARD == SKY_TONEMAP_OP_REINHARD &&
                   SKY_RENDER_TONEMAP_CLAMP == SKY_TONEMAP_OP_CLAMP,
               "tone curves");
#define V4(x_, y_, z_, w_) ((sky_vec4){ (float)(x_), (float)(y_), (float)(z_), (float)(w_) })

void sky_uniforms_fill_atmosphere(const struct sky_render_atmosphere *a,
                                  struct sky_atmosphere_uniforms *u)
{
    sky_uniforms_fill_atmosphere_media(a, u);
    double transfer[3];
    sky_ground_transfer(a, transfer);
    u->ground_transfer = V4(transfer[0], transfer[1], transfer[2], 0);
}

void sky_uniforms_fill_atmosphere_media(const struct sky_render_atmosphere *a,
                                        struct sky_atmosphere_uniforms *u)
{
    u->radii = V4(a->bottom_radius_km, a->top_radius_km, a->rayleigh_scale_height_km,
                  a->mie_scale_height_km);
    u->rayleigh_scattering = V4(a->rayleigh_scattering[0], a->rayleigh_scattering[1],
                                a->rayleigh_scattering[2], a->ozone_peak_km);
    u->mie_scattering = V4(a->mie_scattering[0], a->mie_scattering[1], a->mie_scattering[2],
                           a->ozone_width_km);
    u->mie_absorption = V4(a->mie_absorption[0], a->mie_absorption[1], a->mie_absorption[2],
                           a->fog_density_per_km);
    u->mie_extinction = V4(a->mie_scattering[0] + a->mie_absorption[0],
                           a->mie_scattering[1] + a->mie_absorption[1],
                           a->mie_scattering[2] + a->mie_absorption[2], a->fog_scale_height_km);
    u->mie_g = V4(a->mie_g[0], a->mie_g[1], a->mie_g[2], 0);
    u->ozone_absorption = V4(a->ozone_absorption[0], a->ozone_absorption[1], a->ozone_absorption[2],
                             0);
    u->ground_albedo = V4(a->ground_albedo[0], a->ground_albedo[1], a->ground_albedo[2], 0);
    u->ground_transfer = V4(0, 0, 0, 0);
}

void sky_direction_from_angles(double azimuth_deg, double elevation_deg, double out[3])
{
    double az = azimuth_deg * DEG, el = elevation_deg * DEG;
    out[0] = sin(az) * cos(el);
    out[1] = cos(az) * cos(el);
    out[2] = sin(el);
}

struct camera_basis {
    double forward[3], right[3], up[3], tan_half, aspect;
    bool equirectangular;
};

static void camera_basis(const struct sky_render_view *v, struct camera_basis *b)
{
    b->equirectangular = v->projection == SKY_RENDER_PROJECTION_EQUIRECTANGULAR;
    /* A panorama keeps the horizon level: its basis is the yaw's horizontal frame. */
    double pitch = b->equirectangular ? 0.0 : v->camera_pitch_deg;
    sky_direction_from_angles(v->camera_yaw_deg, pitch, b->forward);
    /* Right from the yaw alone, so looking straight up or down stays well defined. */
    double yaw = v->camera_yaw_deg * DEG;
    const double *f = b->forward;
    b->right[0] = cos(yaw);
    b->right[1] = -sin(yaw);
    b->right[2] = 0.0;
    const double *r = b->right;
    b->up[0] = r[1] * f[2] - r[2] * f[1];
    b->up[1] = r[2] * f[0] - r[0] * f[2];
    b->up[2] = r[0] * f[1] - r[1] * f[0];
    b->tan_half = tan(0.5 * v->camera_fov_deg * DEG);
    b->aspect = v->height ? (double)v->width / (double)v->height : 1.0;
}

/* Where direction d lands on the image, in pixels (shaders/include/camera.glsl's camera_uv);
 * false when it does not (behind a pinhole camera). */
static bool project(const struct sky_render_view *v, const struct camera_basis *b,
                    const double d[3], double *px, double *py)
{
    double x = d[0] * b->right[0] + d[1] * b->right[1] + d[2] * b->right[2];
    double y = d[0] * b->up[0] + d[1] * b->up[1] + d[2] * b->up[2];
    double z = d[0] * b->forward[0] + d[1] * b->forward[1] + d[2] * b->forward[2];
    if (b->equirectangular) {
        *px = (atan2(x, z) / (2.0 * M_PI) + 0.5) * v->width;
        *py = (0.5 - asin(fmax(-1.0, fmin(1.0, y))) / M_PI) * v->height;
        return true;
    }
    if (z <= 1e-6)
        return false;
    *px = (x / (z * b->tan_half * b->aspect) * 0.5 + 0.5) * v->width;
    *py = (0.5 - y / (z * b->tan_half) * 0.5) * v->height;
    return true;
}

static double dot3(const double a[3], const double b[3])
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

bool sky_uniforms_ground_rows(const struct sky_render_view *v, double horizon_cos, uint32_t rows[2])
{
    if (v->width == 0 || v->height == 0)
        return false;
    struct camera_basis b;
    camera_basis(v, &b);
    /* The margin covers the shader's single precision. */
    const double margin = 1e-3;
    int64_t first = -1, last = -1;
    if (b.equirectangular) {
        /* A panorama's row is one elevation: the ground is below the horizon's. */
        for (uint32_t y = 0; y < v->height; y++) {
            double elevation = M_PI * (0.5 - (y + 0.5) / v->height);
            if (sin(elevation) < horizon_cos + margin) {
                first = first < 0 ? y : first;
                last = y;
            }
        }
    }
    /* camera_basis' right is horizontal: along a row the unnormalized ray forward + s right +
     * t up keeps its height forward.z + t up.z, and its length sqrt(1 + s^2 + t^2) grows with
     * |s|. So a row's lowest ray is at its middle when it points down, else at its ends. */
    double s_end = (1.0 - 1.0 / v->width) * b.tan_half * b.aspect;
    for (uint32_t y = 0; y < v->height && !b.equirectangular; y++) {
        double t = (1.0 - 2.0 * (y + 0.5) / v->height) * b.tan_half;
        double height = b.forward[2] + b.up[2] * t;
        double lowest = height / sqrt(1.0 + t * t + (height < 0.0 ? 0.0 : s_end * s_end));
        if (lowest < horizon_cos + margin) {
            if (first < 0)
                first = y;
            last = y;
        }
    }
    if (first < 0)
        return false;
    rows[0] = (uint32_t)first;
    rows[1] = (uint32_t)last + 1;
    return true;
}

bool sky_uniforms_sun_rect(const struct sky_render_view *v, int32_t rect[4])
{
    double sun[3];
    sky_direction_from_angles(v->sun_azimuth_deg, v->sun_elevation_deg, sun);
    return sky_uniforms_disk_rect(v, sun, v->sun_angular_diameter_deg, rect);
}

bool sky_uniforms_disk_rect(const struct sky_render_view *v, const double dir[3],
                            double angular_diameter_deg, int32_t rect[4])
{
    struct camera_basis b;
    camera_basis(v, &b);
    /* A vector basis around the disc direction, then 16 points on a circle 1.5 disk radii out:
     * their projections bound the disk with room for bilinear edges. */
    double helper[3] = { 0, 0, 1 };
    if (fabs(dir[2]) > 0.9)
        helper[0] = 1, helper[2] = 0;
    double e1[3] = { dir[1] * helper[2] - dir[2] * helper[1],
                     dir[2] * helper[0] - dir[0] * helper[2],
                     dir[0] * helper[1] - dir[1] * helper[0] };
    double n1 = sqrt(dot3(e1, e1));
    for (int i = 0; i < 3; i++)
        e1[i] /= n1;
    double e2[3] = { dir[1] * e1[2] - dir[2] * e1[1], dir[2] * e1[0] - dir[0] * e1[2],
                     dir[0] * e1[1] - dir[1] * e1[0] };
    double angle = 1.5 * 0.5 * angular_diameter_deg * DEG;
    double x0 = 1e30, y0 = 1e30, x1 = -1e30, y1 = -1e30;
    for (int k = 0; k < 16; k++) {
        double phi = 2.0 * M_PI * k / 16.0, d[3], px, py;
        for (int i = 0; i < 3; i++)
            d[i] = cos(angle) * dir[i] + sin(angle) * (cos(phi) * e1[i] + sin(phi) * e2[i]);
        if (!project(v, &b, d, &px, &py))
            return false; /* behind or beside the camera: a fov this wide never shows it */
        x0 = fmin(x0, px), x1 = fmax(x1, px), y0 = fmin(y0, py), y1 = fmax(y1, py);
    }
    if (b.equirectangular) {
        /* Across the panorama's seam, or around a pole, the disk spans whole rows. */
        bool pole = fabs(dir[2]) > cos(angle);
        if (pole || x1 - x0 > 0.5 * v->width)
            x0 = 0.0, x1 = v->width;
        if (pole && dir[2] > 0.0)
            y0 = 0.0;
        else if (pole)
            y1 = v->height;
    }
    x0 = fmax(floor(x0) - 1, 0), y0 = fmax(floor(y0) - 1, 0);
    x1 = fmin(ceil(x1) + 1, v->width), y1 = fmin(ceil(y1) + 1, v->height);
    if (x1 <= x0 || y1 <= y0)
        return false;
    rect[0] = (int32_t)x0;
    rect[1] = (int32_t)y0;
    rect[2] = (int32_t)(x1 - x0);
    rect[3] = (int32_t)(y1 - y0);
    return true;
}

void sky_uniforms_fill_frame(const struct sky_render_atmosphere *a, const struct sky_render_view *v,
                             const double zenith_transmittance[3], struct sky_frame_uniforms *u)
{
    memset(u, 0, sizeof *u);
    double altitude = v->camera_altitude_km;
    u->camera_position = V4(0, 0, a->bottom_radius_km + altitude, altitude);

    struct camera_basis b;
    camera_basis(v, &b);
    double sun[3];
    u->camera_forward = V4(b.forward[0], b.forward[1], b.forward[2], b.tan_half);
    u->camera_right = V4(b.right[0], b.right[1], b.right[2], b.aspect);
    u->camera_up = V4(b.up[0], b.up[1], b.up[2],
                      b.equirectangular ? SKY_PROJECTION_EQUIRECTANGULAR
                                        : SKY_PROJECTION_PERSPECTIVE);

    sky_direction_from_angles(v->sun_azimuth_deg, v->sun_elevation_deg, sun);
    double radius = 0.5 * v->sun_angular_diameter_deg * DEG;
    u->sun_direction = V4(sun[0], sun[1], sun[2], cos(radius));
    /* Extraterrestrial illuminance E_top = E_zenith / T_zenith (seed 001 section 4.1). */
    double e_top[3];
    for (int c = 0; c < 3; c++)
        e_top[c] = v->sun_illuminance_lux /
                   fmax(zenith_transmittance[c], SKY_MIN_ZENITH_TRANSMITTANCE);
    u->sun_illuminance = V4(e_top[0], e_top[1], e_top[2], v->limb_darkening);
    u->sun_disk = V4(sky_disk_solid_angle(v->sun_angular_diameter_deg), sin(radius), 0, 0);
    u->exposure = V4(sky_ev100_to_exposure(v->ev100),
                     v->auto_exposure ? (v->night_adaptation ? 2 : 1) : 0,
                     v->exposure_compensation_ev, v->tonemap);
    u->image = V4(v->width, v->height, v->aerial_perspective_max_km, v->output);
    /* The sky-view LUT frame puts the sun at azimuth 0: (sin zenith, 0, cos zenith). */
    double mu_s = sun[2];
    u->sun_local = V4(sqrt(fmax(0.0, 1.0 - mu_s * mu_s)), 0, mu_s, 0);
    /* The camera's up is +z: the sun's horizontal projection is (x, y, 0). */
    double sun_h = hypot(sun[0], sun[1]);
    u->sun_horizontal = sun_h > 1e-7 ? V4(sun[0] / sun_h, sun[1] / sun_h, 0, 1) : V4(0, 0, 0, 0);
    /* The same clamp as the shaders: at least 1 m above the ground, below the top. */
    double r = fmin(fmax(a->bottom_radius_km + altitude, a->bottom_radius_km + 1e-3),
                    a->top_radius_km - 1e-3);
    double beta = acos(sqrt(fmax(0.0, r * r - a->bottom_radius_km * a->bottom_radius_km)) / r);
    u->horizon = V4(beta, M_PI - beta, cos(M_PI - beta), 0);
}
