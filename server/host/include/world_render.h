/* Maps the world state (protocol/) onto the renderer's inputs (render/): the one place where
 * a state becomes a render input and a client's view a render view. */
#ifndef SKYD_WORLD_RENDER_H
#define SKYD_WORLD_RENDER_H

#include <stdint.h>

#include "render_input.h"
#include "sky_renderer.h"
#include "world_state.h"

struct proto_msg_view;

/* The state's render input: its atmosphere (also the one frames show, built amortized),
 * clouds, night and LUT sizes; no client map, nothing pending (settled_revision is the
 * state's). */
void world_render_input(const struct proto_world_state *state, struct render_input *out);
/* The view a client asks for (size, format, projection, camera and exposure overrides) of the
 * input's state. Equal views compare equal bytewise (the struct is zero-filled first). */
void world_render_view(const struct render_input *input, const struct proto_msg_view *view,
                       struct sky_render_view *out);

void world_to_render_atmosphere(const struct proto_world_state *state,
                                struct sky_render_atmosphere *out);
/* The state's camera, sun and exposure as a view of width x height. */
void world_to_render_view(const struct proto_world_state *state, uint32_t width, uint32_t height,
                          enum sky_render_output_kind output, struct sky_render_view *out);
/* The state's clouds.* and weather.* as the renderer's clouds (sky_renderer_set_clouds). */
void world_to_render_clouds(const struct proto_world_state *state, struct sky_render_clouds *out);
/* The world state's name for a resolution the renderer traced at (the way back of the above). */
enum proto_cloud_resolution world_render_cloud_resolution(enum sky_render_cloud_resolution traced);

/* The state's moon, stars and airglow: the moon's illuminance from its phase angle (the sun-moon
 * elongation) and distance (its angular diameter) through server/ephemeris' phase law; the
 * star rotation from clock.utc and location (sidereal time) and precession from J2000. */
void world_to_render_night(const struct proto_world_state *state, struct sky_render_night *out);
/* J2000 equatorial -> local east/north/up at the site and time (rows are the local axes). */
void world_star_rotation(double unix_seconds, double latitude_deg, double longitude_deg,
                         double out[3][3]);
/* The moon's phase angle (deg, 0 = full) from the sun and moon directions and its distance. */
double world_moon_phase_angle_deg(const double sun_dir[3], const double moon_dir[3],
                                  double moon_distance_km);
void world_to_lut_sizes(const struct proto_world_state *state, struct sky_render_lut_sizes *out);

/* Humidity in world_to_render_atmosphere: the Mie scattering is atmosphere.mie.* times
 * world_haze_growth_factor(weather.humidity) (1 at the reference humidity), and the height fog
 * density gains world_humidity_fog_per_km(weather.humidity). */
#define WORLD_HAZE_REFERENCE_HUMIDITY 0.5
#define WORLD_HAZE_GAMMA 0.5         /* Hanel's exponent for continental aerosol scattering */
#define WORLD_HAZE_MAX_HUMIDITY 0.99 /* f(RH) diverges at saturation */
#define WORLD_FOG_ONSET_HUMIDITY 0.9
double world_haze_growth_factor(double humidity);
double world_humidity_fog_per_km(double humidity);

#endif
