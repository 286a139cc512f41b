#include "sky_uniforms.h"

#include <math.h>
#include <string.h>

#include "photometry.h"

#define DEG (3.14159265358979323846 / 180.0)

void sky_uniforms_fill_atmosphere(const struct sky_render_atmosphere *a,
                                     struct sky_atmosphere_uniforms *u)
{
#define V4(x_, y_, z_, w_) ((sky_vec4){ (float)(x_), (float)(y_), (float)(z_), (float)(w_) })
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
    u->ozone_absorption = V4(a->ozone_absorption[0], a->ozone_absorption[1],
                             a->ozone_absorption[2], 0);
    u->ground_albedo = V4(a->ground_albedo[0], a->ground_albedo[1], a->ground_albedo[2], 0);
    u->one = (sky_ivec4){ 1, 1, 1, 1 };
}

static void direction_from_angles(double azimuth_deg, double elevation_deg, double out[3])
{
    double az = azimuth_deg * DEG, el = elevation_deg * DEG;
    out[0] = sin(az) * cos(el);
    out[1] = cos(az) * cos(el);
    out[2] = sin(el);
}

void sky_uniforms_fill_frame(const struct sky_render_atmosphere *a,
                                const struct sky_render_view *v, struct sky_frame_uniforms *u)
{
    memset(u, 0, sizeof *u);
    double altitude = v->camera_altitude_km;
    u->camera_position = V4(0, 0, a->bottom_radius_km + altitude, altitude);

    double f[3], sun[3];
    direction_from_angles(v->camera_yaw_deg, v->camera_pitch_deg, f);
    /* Right from the yaw alone, so looking straight up or down stays well defined. */
    double yaw = v->camera_yaw_deg * DEG;
    double right[3] = { cos(yaw), -sin(yaw), 0.0 };
    double up[3] = { right[1] * f[2] - right[2] * f[1], right[2] * f[0] - right[0] * f[2],
                     right[0] * f[1] - right[1] * f[0] };
    double tan_half = tan(0.5 * v->camera_fov_deg * DEG);
    double aspect = v->height ? (double)v->width / (double)v->height : 1.0;
    u->camera_forward = V4(f[0], f[1], f[2], tan_half);
    u->camera_right = V4(right[0], right[1], right[2], aspect);
    u->camera_up = V4(up[0], up[1], up[2], 0);

    direction_from_angles(v->sun_azimuth_deg, v->sun_elevation_deg, sun);
    double radius = 0.5 * v->sun_angular_diameter_deg * DEG;
    u->sun_direction = V4(sun[0], sun[1], sun[2], cos(radius));
    double e_top[3];
    sky_sun_illuminance_top(a, v->sun_illuminance_lux, e_top);
    u->sun_illuminance = V4(e_top[0], e_top[1], e_top[2], v->limb_darkening);
    u->sun_disk = V4(sky_disk_solid_angle(v->sun_angular_diameter_deg), sin(radius), 0, 0);
    u->exposure = V4(sky_ev100_to_exposure(v->ev100), v->auto_exposure ? 1 : 0,
                     v->exposure_compensation_ev, v->tonemap);
    u->image = V4(v->width, v->height, v->aerial_perspective_max_km, v->output);
    /* The sky-view LUT frame puts the sun at azimuth 0: (sin zenith, 0, cos zenith). */
    double mu_s = sun[2];
    u->sun_local = V4(sqrt(fmax(0.0, 1.0 - mu_s * mu_s)), 0, mu_s, 0);
#undef V4
}

