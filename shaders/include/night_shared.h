/* Constants of the night sky shared by C (render/night_*.c) and GLSL (night_sky.glsl).
 *
 * Star buffer (std430, one storage buffer of uvec4 words):
 *   word 0                      header: grid width, grid height, star count, cell capacity
 *   words 1 .. 1 + cells / 2    cells of a J2000 equatorial latitude/longitude grid, two per
 *                               word (xy, zw); a cell holds up to 4 star indices as 16-bit
 *                               halves, NIGHT_STAR_EMPTY when unused, brightest first
 *   then 2 words per star       float bits: J2000 unit direction (xyz), then illuminance per
 *                               channel outside the atmosphere (lux, xyz)
 * A star is listed in every cell that comes within NIGHT_STAR_SUPPORT_DEG of it, so a pixel
 * reads one cell. */
#ifndef NIGHT_SHARED_H
#define NIGHT_SHARED_H

#define NIGHT_STAR_GRID_W 360
#define NIGHT_STAR_GRID_H 180
#define NIGHT_STAR_CELL_CAPACITY 4
#define NIGHT_STAR_EMPTY 0xFFFFu
#define NIGHT_STAR_SUPPORT_DEG 0.8
/* The point-spread function's standard deviation is at most a third of the support. */
#define NIGHT_STAR_MAX_SIGMA_DEG (NIGHT_STAR_SUPPORT_DEG / 3.0)

/* Airglow emission layer altitude for the van Rhijn factor (km). */
#define NIGHT_AIRGLOW_LAYER_KM 90.0

/* Lunar maria on the near side: selenographic latitude, longitude (deg, east toward Mare
 * Crisium) and angular radius on the sphere (deg, from their diameters in km / 1737.4 km).
 * The albedo map is highlands 1 and maria NIGHT_MARE_ALBEDO relative, smoothed over 3 deg. */
#define NIGHT_MARE_ALBEDO 0.58
#define NIGHT_MARIA(X)                                                                       \
    X(33.0, -16.0, 18.9) /* Imbrium */                                                       \
    X(18.0, -57.0, 24.0) /* Oceanus Procellarum (north) */                                   \
    X(-2.0, -40.0, 16.0) /* Oceanus Procellarum (south) */                                   \
    X(28.0, 17.5, 11.1)  /* Serenitatis */                                                   \
    X(8.5, 31.4, 14.4)   /* Tranquillitatis */                                               \
    X(17.0, 59.1, 9.2)   /* Crisium */                                                       \
    X(-7.8, 51.3, 13.0)  /* Fecunditatis */                                                  \
    X(-21.3, -16.6, 11.8) /* Nubium */                                                       \
    X(-24.4, -38.6, 6.4) /* Humorum */                                                       \
    X(-15.2, 35.5, 5.5)  /* Nectaris */                                                      \
    X(56.0, 1.4, 7.0)    /* Frigoris */                                                      \
    X(13.3, 3.6, 4.0)    /* Vaporum */

#endif
