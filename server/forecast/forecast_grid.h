/* The square around a place on a regular latitude/longitude grid: which grid points it holds,
 * the window of points the reader keeps, the means and the bilinear samples taken there. Pure
 * functions. Distances use the local east/north plane around the place (an equirectangular
 * projection: 1 degree of latitude is R pi / 180 km, of longitude that times cos(latitude)),
 * with R the Earth's mean radius. */
#ifndef SKYD_FORECAST_GRID_H
#define SKYD_FORECAST_GRID_H

#include <stdbool.h>
#include <stddef.h>

#include "forecast.h"

#define FORECAST_EARTH_RADIUS_KM 6371.0 /* mean radius (IUGG) */
#define FORECAST_PI 3.14159265358979323846
/* Window points a file's steps may keep in all (each field's values over the window). */
#define FORECAST_MAX_WINDOW_VALUES (4L * 1024 * 1024)

/* The rectangle of grid points the reader keeps: every point a mean or a bilinear sample of the
 * square needs. Columns are unwrapped (first_column may be negative, or the last beyond ni, on
 * a global grid) and taken modulo ni for a value's index. */
struct forecast_window {
    long first_row, first_column;
    int rows, columns;
    /* The points inside the square, window coordinates, inclusive; inside_rows 0: none. */
    int inside_row, inside_column, inside_rows, inside_columns;
    double center_row, center_column; /* the place, fractional grid coordinates (unwrapped) */
    double rows_per_km_north, columns_per_km_east;
};

/* The grid of a regular_ll message, from its first and last points (degrees) and counts, with
 * i scanning eastwards: false with the reason when it is not one this reader can sample (fewer
 * than two points along an axis, the points on top of each other). */
bool forecast_grid_make(long ni, long nj, double lat_first, double lon_first, double lat_last,
                        double lon_last, struct forecast_grid_info *grid, char *why,
                        size_t why_size);

/* The window and the points of the request's square on the grid; false with the reason
 * (FORECAST_ERR_OUTSIDE or ..._TOO_LARGE in *code) when the square reaches beyond the grid
 * or a pole, or holds too many points. */
bool forecast_window_locate(const struct forecast_grid_info *grid,
                            const struct forecast_request *request, struct forecast_window *window,
                            struct forecast_points *points, enum forecast_error_code *code,
                            char *why, size_t why_size);

/* Index in a message's values (scan order, i fastest) of window point (row, column). */
long forecast_window_value_index(const struct forecast_grid_info *grid,
                                 const struct forecast_window *window, int row, int column);

/* The mean of a field (window values, row-major) over the points inside the square, or its
 * bilinear value at the place when none is inside. */
double forecast_window_mean(const struct forecast_window *window, const double *values);

/* The field's bilinear value east_km and north_km from the place (inside the square). */
double forecast_window_bilinear(const struct forecast_window *window, const double *values,
                                double east_km, double north_km);

/* The square as size x size cells, row-major from the north-west corner, each the bilinear
 * value at its centre. */
void forecast_window_grid(const struct forecast_window *window, const double *values,
                          double extent_km, int size, double *cells);

/* Longitude in (-180, 180]. */
double forecast_longitude_normalized(double lon_deg);

#endif
