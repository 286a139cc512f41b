/* The star field the night sky draws: the bright-star catalogue (render/night/star_catalogue.h) plus
 * a procedural field of fainter stars down to magnitude 6.5, packed into the GPU layout of
 * shaders/include/night_shared.h. Pure CPU code, no Vulkan. */
#ifndef SKYD_NIGHT_STARS_H
#define SKYD_NIGHT_STARS_H

#include <stddef.h>
#include <stdint.h>

/* Faintest magnitude of the procedural field, and the brightest (the catalogue covers the
 * stars above it). */
#define NIGHT_STARS_FAINTEST_MAG 6.5
#define NIGHT_STARS_FIELD_BRIGHTEST_MAG 3.0

struct night_stars;

struct night_stars *night_stars_create(void);
void night_stars_destroy(struct night_stars **stars);

/* The buffer to upload: `words` uvec4 words. */
const uint32_t (*night_stars_words(const struct night_stars *stars, size_t *words))[4];
size_t night_stars_count(const struct night_stars *stars);
/* Sum of the stars' photopic illuminance outside the atmosphere (lux), and the brightest. */
double night_stars_total_lux(const struct night_stars *stars);
double night_stars_brightest_lux(const struct night_stars *stars);

/* Illuminance of a star of visual magnitude m outside the atmosphere: V = -14.18 - 2.5 log10 E
 * (the zero point server/ephemeris uses for the moon). */
double night_star_illuminance_lux(double v_magnitude);
/* Linear Rec.709 colour of a black body of temperature_k with unit luminance (Planckian locus,
 * Kim et al. 2002 cubic fit, 1667..25000 K). */
void night_blackbody_rgb(double temperature_k, double rgb[3]);

#endif
