#include "world_render.h"

#include <math.h>
#include <string.h>

#include "ephemeris.h"
#include "messages.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif
#define DEG (M_PI / 180.0)
#define MOON_RADIUS_KM 1737.4
#define SUN_DISTANCE_KM 1.495978707e8

static void copy3(double dst[3], const double src[3])
{
    memcpy(dst, src, 3 * sizeof(double));
}

/* Hygroscopic growth of the aerosol: its scattering grows as f(RH) = (1 - RH)^-gamma (Hanel
 * 1976), normalised to 1 at the default humidity, so the stored atmosphere.mie.* are the
 * values at WORLD_HAZE_REFERENCE_HUMIDITY. Water uptake adds scattering, not absorption: the
 * single-scattering albedo rises toward 1 as the air gets moister. */
double world_haze_growth_factor(double humidity)
{
    double rh = fmin(fmax(humidity, 0.0), WORLD_HAZE_MAX_HUMIDITY);
    return pow((1.0 - rh) / (1.0 - WORLD_HAZE_REFERENCE_HUMIDITY), -WORLD_HAZE_GAMMA);
}

/* Mist and fog near saturation: grey extinction from 0 at WORLD_FOG_ONSET_HUMIDITY to
 * 3.912 /km at saturation, a 1 km visibility by Koschmieder's V = 3.912 / sigma (fog's
 * definition). */
double world_humidity_fog_per_km(double humidity)
{
    double t = fmin(
        fmax((humidity - WORLD_FOG_ONSET_HUMIDITY) / (1.0 - WORLD_FOG_ONSET_HUMIDITY), 0.0), 1.0);
    return 3.912 * t * t * (3.0 - 2.0 * t);
}

void world_to_render_atmosphere(const struct proto_world_state *state,
                                struct sky_render_atmosphere *out)
{
    const struct proto_atmosphere_state *a = &state->atmosphere;
    memset(out, 0, sizeof *out);
    out->bottom_radius_km = a->bottom_radius_km;
    out->top_radius_km = a->top_radius_km;
    copy3(out->rayleigh_scattering, a->rayleigh_scattering_per_km);
    out->rayleigh_scale_height_km = a->rayleigh_scale_height_km;
    double growth = world_haze_growth_factor(state->weather.humidity);
    for (int i = 0; i < 3; i++)
        out->mie_scattering[i] = a->mie_scattering_per_km[i] * growth; /* Hanel f(RH) */
    copy3(out->mie_absorption, a->mie_absorption_per_km);
    out->mie_scale_height_km = a->mie_scale_height_km;
    copy3(out->mie_g, a->mie_g);
    copy3(out->ozone_absorption, a->ozone_absorption_per_km);
    out->ozone_peak_km = a->ozone_peak_altitude_km;
    out->ozone_width_km = a->ozone_width_km;
    copy3(out->ground_albedo, a->ground_albedo);
    out->fog_density_per_km = a->fog_density_per_km +
                              world_humidity_fog_per_km(state->weather.humidity);
    out->fog_scale_height_km = a->fog_scale_height_km;
}

static enum sky_render_limb limb_model(enum proto_limb_darkening model)
{
    switch (model) {
    case PROTO_LIMB_DARKENING_NECKEL96:
        return SKY_RENDER_LIMB_NECKEL96;
    case PROTO_LIMB_DARKENING_HM98:
        return SKY_RENDER_LIMB_HM98;
    default:
        return SKY_RENDER_LIMB_NONE;
    }
}

static enum sky_render_tonemap tonemap_op(enum proto_tonemap tonemap)
{
    switch (tonemap) {
    case PROTO_TONEMAP_REINHARD:
        return SKY_RENDER_TONEMAP_REINHARD;
    case PROTO_TONEMAP_CLAMP:
        return SKY_RENDER_TONEMAP_CLAMP;
    default:
        return SKY_RENDER_TONEMAP_ACES;
    }
}

void world_to_render_view(const struct proto_world_state *state, uint32_t width, uint32_t height,
                          enum sky_render_output_kind output, struct sky_render_view *out)
{
    memset(out, 0, sizeof *out);
    out->width = width;
    out->height = height;
    out->camera_altitude_km = state->camera.altitude_km;
    out->camera_yaw_deg = state->camera.yaw_deg;
    out->camera_pitch_deg = state->camera.pitch_deg;
    out->camera_fov_deg = state->camera.fov_deg;
    out->sun_azimuth_deg = state->sun.azimuth_deg;
    out->sun_elevation_deg = state->sun.elevation_deg;
    out->sun_illuminance_lux = state->sun.illuminance_lux;
    out->sun_angular_diameter_deg = state->sun.angular_diameter_deg;
    out->limb_darkening = limb_model(state->sun.limb_darkening);
    out->auto_exposure = state->exposure.mode == PROTO_EXPOSURE_AUTO;
    out->night_adaptation = state->exposure.night_adaptation == PROTO_SWITCH_ON;
    out->ev100 = state->exposure.ev100;
    out->exposure_compensation_ev = state->exposure.compensation_ev;
    out->tonemap = tonemap_op(state->exposure.tonemap);
    out->aerial_perspective_max_km = state->render.aerial_perspective_max_km;
    out->output = output;
}

void world_to_lut_sizes(const struct proto_world_state *state, struct sky_render_lut_sizes *out)
{
    const struct proto_render_settings *r = &state->render;
    for (int i = 0; i < 2; i++) {
        out->transmittance[i] = (uint32_t)r->transmittance_lut[i];
        out->multiscattering[i] = (uint32_t)r->multiscattering_lut[i];
        out->skyview[i] = (uint32_t)r->skyview_lut[i];
    }
    for (int i = 0; i < 3; i++)
        out->aerial_perspective[i] = (uint32_t)r->aerial_perspective_lut[i];
}

static void layer(const struct proto_cloud_layer_state *in, struct sky_render_cloud_layer *out)
{
    out->coverage = in->coverage;
    out->type = in->type;
    out->density = in->density;
    out->bottom_km = in->bottom_km;
    out->thickness_km = in->thickness_km;
}

void world_to_render_clouds(const struct proto_world_state *state, struct sky_render_clouds *out)
{
    const struct proto_cloud_state *c = &state->clouds;
    const struct proto_weather_state *w = &state->weather;
    memset(out, 0, sizeof *out);
    layer(&c->low, &out->low);
    layer(&c->mid, &out->mid);
    layer(&c->high, &out->high);
    out->extinction_per_km = c->extinction_per_km;
    out->albedo = c->albedo;
    out->precipitation = c->precipitation;
    out->phase_g0 = c->phase_g0;
    out->phase_g1 = c->phase_g1;
    out->phase_w = c->phase_w;
    out->multiscatter_a = c->multiscatter_a;
    out->multiscatter_b = c->multiscatter_b;
    out->multiscatter_c = c->multiscatter_c;
    out->multiscatter_octaves = c->multiscatter_octaves;
    out->multiscatter_powder = c->multiscatter_powder;
    out->ambient_scale = c->ambient_scale;
    out->noise_seed = (uint32_t)c->noise_seed;
    out->primary_steps = c->primary_steps;
    out->light_steps = c->light_steps;
    switch (c->resolution) {
    case PROTO_CLOUD_RESOLUTION_FULL:
        out->resolution = SKY_RENDER_CLOUDS_FULL;
        break;
    case PROTO_CLOUD_RESOLUTION_QUARTER:
        out->resolution = SKY_RENDER_CLOUDS_QUARTER;
        break;
    case PROTO_CLOUD_RESOLUTION_SIXTEENTH:
        out->resolution = SKY_RENDER_CLOUDS_SIXTEENTH;
        break;
    case PROTO_CLOUD_RESOLUTION_AUTO:
        out->resolution = SKY_RENDER_CLOUDS_AUTO;
        break;
    default:
        out->resolution = SKY_RENDER_CLOUDS_SIXTYFOURTH;
        break;
    }
    out->temporal = c->temporal == PROTO_SWITCH_ON;
    out->wind_offset_east_km = w->offset_east_km;
    out->wind_offset_north_km = w->offset_north_km;
    out->weather_seed = (uint32_t)w->seed;
    out->map_extent_km = w->map_extent_km;
    out->use_client_map = w->map_source != PROTO_WEATHER_MAP_PROCEDURAL;
    out->client_map_drives_procedural = w->map_source == PROTO_WEATHER_MAP_FORECAST;
}

/* ---- night sky ---- */

static void matmul3(const double a[3][3], const double b[3][3], double out[3][3])
{
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            out[i][j] = a[i][0] * b[0][j] + a[i][1] * b[1][j] + a[i][2] * b[2][j];
}

/* Precession J2000 -> mean equator and equinox of date (Meeus 21.2-21.4, IAU 1976):
 * P = Rz(-z) Ry(theta) Rz(-zeta) acting on column vectors. */
static void precession_matrix(double unix_seconds, double p[3][3])
{
    double t = (world_julian_day(unix_seconds) - 2451545.0) / 36525.0;
    double zeta = (2306.2181 * t + 0.30188 * t * t + 0.017998 * t * t * t) / 3600.0 * DEG;
    double z = (2306.2181 * t + 1.09468 * t * t + 0.018203 * t * t * t) / 3600.0 * DEG;
    double theta = (2004.3109 * t - 0.42665 * t * t - 0.041833 * t * t * t) / 3600.0 * DEG;
    double cz = cos(zeta), sz = sin(zeta), cZ = cos(z), sZ = sin(z);
    double ct = cos(theta), st = sin(theta);
    p[0][0] = cZ * ct * cz - sZ * sz;
    p[0][1] = -cZ * ct * sz - sZ * cz;
    p[0][2] = -cZ * st;
    p[1][0] = sZ * ct * cz + cZ * sz;
    p[1][1] = -sZ * ct * sz + cZ * cz;
    p[1][2] = -sZ * st;
    p[2][0] = st * cz;
    p[2][1] = -st * sz;
    p[2][2] = ct;
}

void world_star_rotation(double unix_seconds, double latitude_deg, double longitude_deg,
                         double out[3][3])
{
    /* Equatorial of date -> east/north/up through the local sidereal time (the hour angle is
     * LST - RA; Meeus 13.5-13.6 written as a rotation). */
    double lst = world_local_sidereal_time_deg(unix_seconds, longitude_deg) * DEG;
    double phi = latitude_deg * DEG;
    double sl = sin(lst), cl = cos(lst), sp = sin(phi), cp = cos(phi);
    const double local[3][3] = {
        { -sl, cl, 0.0 },
        { -sp * cl, -sp * sl, cp },
        { cp * cl, cp * sl, sp },
    };
    double p[3][3];
    precession_matrix(unix_seconds, p);
    matmul3(local, p, out);
}

double world_moon_phase_angle_deg(const double sun[3], const double moon[3],
                                  double moon_distance_km)
{
    double c = sun[0] * moon[0] + sun[1] * moon[1] + sun[2] * moon[2];
    double elongation = acos(fmin(1.0, fmax(-1.0, c)));
    /* Meeus 48.3: tan i = R sin psi / (Delta - R cos psi). */
    return atan2(SUN_DISTANCE_KM * sin(elongation),
                 moon_distance_km - SUN_DISTANCE_KM * cos(elongation)) /
           DEG;
}

void world_to_render_night(const struct proto_world_state *state, struct sky_render_night *out)
{
    memset(out, 0, sizeof *out);
    const struct proto_moon_state *moon = &state->moon;
    out->moon_azimuth_deg = moon->azimuth_deg;
    out->moon_elevation_deg = moon->elevation_deg;
    out->moon_angular_diameter_deg = moon->angular_diameter_deg;
    if (moon->angular_diameter_deg > 0.0) {
        double sun_dir[3], moon_dir[3];
        sky_direction_from_angles(state->sun.azimuth_deg, state->sun.elevation_deg, sun_dir);
        sky_direction_from_angles(moon->azimuth_deg, moon->elevation_deg, moon_dir);
        double distance = MOON_RADIUS_KM / sin(0.5 * moon->angular_diameter_deg * DEG);
        double phase = world_moon_phase_angle_deg(sun_dir, moon_dir, distance);
        out->moon_illuminance_lux = world_moon_illuminance_lux(phase, distance);
    }
    world_star_rotation(state->clock.utc_unix_s, state->location.latitude_deg,
                        state->location.longitude_deg, out->star_rotation);
    out->star_brightness = state->night.star_brightness;
    out->airglow_luminance_cd_m2 = state->night.airglow_luminance_cd_m2;
}

void world_render_input(const struct proto_world_state *state, struct render_input *out)
{
    memset(out, 0, sizeof *out);
    out->state = *state;
    world_to_render_atmosphere(state, &out->atmosphere);
    out->frame_atmosphere = out->atmosphere;
    out->settled_revision = state->revision;
    world_to_render_clouds(state, &out->clouds);
    world_to_render_night(state, &out->night);
    world_to_lut_sizes(state, &out->lut_sizes);
}

void world_render_view(const struct render_input *input, const struct proto_msg_view *view,
                       struct sky_render_view *out)
{
    struct proto_world_state resolved = input->state;
    proto_msg_view_resolve(view, &input->state, &resolved.camera, &resolved.exposure);
    world_to_render_view(&resolved, view->width, view->height,
                         view->format == PROTO_FRAME_FORMAT_PNG16 ? SKY_RENDER_OUTPUT_LINEAR
                                                                  : SKY_RENDER_OUTPUT_SRGB8,
                         out);
    out->projection = view->projection == PROTO_VIEW_PROJECTION_EQUIRECTANGULAR
                          ? SKY_RENDER_PROJECTION_EQUIRECTANGULAR
                          : SKY_RENDER_PROJECTION_PERSPECTIVE;
}

enum proto_cloud_resolution world_render_cloud_resolution(enum sky_render_cloud_resolution traced)
{
    switch (traced) {
    case SKY_RENDER_CLOUDS_FULL:
        return PROTO_CLOUD_RESOLUTION_FULL;
    case SKY_RENDER_CLOUDS_QUARTER:
        return PROTO_CLOUD_RESOLUTION_QUARTER;
    case SKY_RENDER_CLOUDS_SIXTEENTH:
        return PROTO_CLOUD_RESOLUTION_SIXTEENTH;
    case SKY_RENDER_CLOUDS_SIXTYFOURTH:
        return PROTO_CLOUD_RESOLUTION_SIXTYFOURTH;
    default:
        return PROTO_CLOUD_RESOLUTION_AUTO;
    }
}
