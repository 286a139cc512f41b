/* The square around a place on a regular latitude/longitude grid (forecast_grid.h). */
#include "forecast_grid.h"

#include <math.h>
#include <stdio.h>

#define DEG (FORECAST_PI / 180.0)
/* Rounding slack in grid coordinates: a point on the square's edge is inside. */
#define EDGE 1e-9

double forecast_longitude_normalized(double lon_deg)
{
    double lon = fmod(lon_deg, 360.0);
    if (lon > 180.0)
        lon -= 360.0;
    if (lon <= -180.0)
        lon += 360.0;
    return lon;
}

/* Degrees east of `from`, in [0, 360). */
static double degrees_east_of(double lon_deg, double from_deg)
{
    double d = fmod(lon_deg - from_deg, 360.0);
    if (d < 0.0)
        d += 360.0;
    return d >= 360.0 ? 0.0 : d;
}

bool forecast_grid_make(long ni, long nj, double lat_first, double lon_first, double lat_last,
                        double lon_last, struct forecast_grid_info *grid, char *why,
                        size_t why_size)
{
    if (ni < 2 || nj < 2) {
        snprintf(why, why_size, "a grid of %ld x %ld points has no cell to interpolate in", ni, nj);
        return false;
    }
    if (!isfinite(lat_first) || !isfinite(lat_last) || fabs(lat_first) > 90.0 ||
        fabs(lat_last) > 90.0 || lat_first == lat_last) {
        snprintf(why, why_size, "latitudes %g to %g do not make a grid", lat_first, lat_last);
        return false;
    }
    double span = degrees_east_of(lon_last, lon_first);
    if (!isfinite(lon_first) || !isfinite(lon_last) || span == 0.0) {
        snprintf(why, why_size, "longitudes %g to %g do not make a grid", lon_first, lon_last);
        return false;
    }
    grid->ni = ni;
    grid->nj = nj;
    grid->lat_first = lat_first;
    grid->lon_first = lon_first;
    grid->lat_last = lat_last;
    grid->lon_last = lon_last;
    grid->lat_step = (lat_last - lat_first) / (double)(nj - 1);
    grid->lon_step = span / (double)(ni - 1);
    /* Global when one more step east of the last point comes back to the first. */
    grid->global = fabs((double)ni * grid->lon_step - 360.0) <= 0.01 * grid->lon_step;
    return true;
}

static void describe_grid(const struct forecast_grid_info *grid, char *text, size_t size)
{
    double lat_lo = fmin(grid->lat_first, grid->lat_last);
    double lat_hi = fmax(grid->lat_first, grid->lat_last);
    if (grid->global)
        snprintf(text, size, "latitudes %g..%g, all longitudes", lat_lo, lat_hi);
    else
        snprintf(text, size, "latitudes %g..%g, longitudes %g..%g east", lat_lo, lat_hi,
                 grid->lon_first, grid->lon_first + (double)(grid->ni - 1) * grid->lon_step);
}

bool forecast_window_locate(const struct forecast_grid_info *grid,
                            const struct forecast_request *request, struct forecast_window *window,
                            struct forecast_points *points, enum forecast_error_code *code,
                            char *why, size_t why_size)
{
    char area[160];
    describe_grid(grid, area, sizeof area);
    double half_km = 0.5 * request->extent_km;
    /* Equirectangular: half_km of latitude is half_km / R radians, of longitude that over
     * cos(latitude). */
    double half_lat = half_km / FORECAST_EARTH_RADIUS_KM / DEG;
    double lat = request->lat_deg;
    *code = FORECAST_ERR_OUTSIDE;
    if (fabs(lat) + half_lat >= 90.0) {
        snprintf(why, why_size, "the %g km square around %.4f, %.4f reaches a pole",
                 request->extent_km, lat, request->lon_deg);
        return false;
    }
    /* Clear of the poles, the square spans less than 180 degrees of longitude: half_lat / cos
     * reaches 180 only beyond 90 - half_lat, as sin(h) > h / 180 (degrees). */
    double half_lon = half_lat / cos(lat * DEG);
    double row_a = (lat - half_lat - grid->lat_first) / grid->lat_step;
    double row_b = (lat + half_lat - grid->lat_first) / grid->lat_step;
    double row_lo = fmin(row_a, row_b), row_hi = fmax(row_a, row_b);
    double last_row = (double)(grid->nj - 1), last_column = (double)(grid->ni - 1);
    double east = degrees_east_of(request->lon_deg, grid->lon_first);
    double column = east / grid->lon_step;
    double column_lo = (east - half_lon) / grid->lon_step;
    double column_hi = (east + half_lon) / grid->lon_step;
    bool lat_outside = row_lo < -EDGE || row_hi > last_row + EDGE;
    bool lon_outside = grid->global ? false : column_lo < -EDGE || column_hi > last_column + EDGE;
    if (lat_outside || lon_outside) {
        bool place_outside = (lat - grid->lat_first) / grid->lat_step < -EDGE ||
                             (lat - grid->lat_first) / grid->lat_step > last_row + EDGE ||
                             (!grid->global && column > last_column + EDGE);
        if (place_outside)
            snprintf(why, why_size, "%.4f, %.4f is outside the grid (%s)", lat, request->lon_deg,
                     area);
        else
            snprintf(why, why_size,
                     "the %g km square around %.4f, %.4f reaches beyond the grid (%s)",
                     request->extent_km, lat, request->lon_deg, area);
        return false;
    }
    /* Clamping to the grid only removes the rounding slack. */
    long first_row = (long)floor(fmax(row_lo, 0.0));
    long end_row = (long)ceil(fmin(row_hi, last_row));
    long first_column = (long)floor(grid->global ? column_lo : fmax(column_lo, 0.0));
    long end_column = (long)ceil(grid->global ? column_hi : fmin(column_hi, last_column));
    /* A square on a grid line still needs a cell around it. */
    if (end_row == first_row) {
        if (end_row < (long)last_row)
            end_row++;
        else
            first_row--;
    }
    if (end_column == first_column) {
        if (end_column < (long)last_column || grid->global)
            end_column++;
        else
            first_column--;
    }
    long rows = end_row - first_row + 1, columns = end_column - first_column + 1;
    if (rows * columns > FORECAST_MAX_WINDOW_VALUES / 4) {
        *code = FORECAST_ERR_TOO_LARGE;
        snprintf(why, why_size,
                 "the %g km square holds %ld x %ld grid points, more than this reader keeps; "
                 "ask for a smaller extent",
                 request->extent_km, rows, columns);
        return false;
    }
    window->first_row = first_row;
    window->first_column = first_column;
    window->rows = (int)rows;
    window->columns = (int)columns;
    window->center_row = (lat - grid->lat_first) / grid->lat_step;
    window->center_column = column;
    window->rows_per_km_north = 1.0 / (FORECAST_EARTH_RADIUS_KM * DEG) / grid->lat_step;
    window->columns_per_km_east = 1.0 / (FORECAST_EARTH_RADIUS_KM * DEG * cos(lat * DEG)) /
                                  grid->lon_step;
    /* The points inside the square: whole rows and columns within its bounds. */
    long in_row0 = (long)ceil(row_lo - EDGE), in_row1 = (long)floor(row_hi + EDGE);
    long in_col0 = (long)ceil(column_lo - EDGE), in_col1 = (long)floor(column_hi + EDGE);
    if (in_row0 < 0)
        in_row0 = 0;
    if (in_row1 > (long)last_row)
        in_row1 = (long)last_row;
    if (!grid->global && in_col0 < 0)
        in_col0 = 0;
    if (!grid->global && in_col1 > (long)last_column)
        in_col1 = (long)last_column;
    window->inside_row = (int)(in_row0 - first_row);
    window->inside_column = (int)(in_col0 - first_column);
    window->inside_rows = in_row1 >= in_row0 && in_col1 >= in_col0 ? (int)(in_row1 - in_row0 + 1)
                                                                   : 0;
    window->inside_columns = window->inside_rows ? (int)(in_col1 - in_col0 + 1) : 0;
    points->bilinear = window->inside_rows == 0;
    if (points->bilinear) {
        in_row0 = (long)floor(window->center_row);
        in_col0 = (long)floor(window->center_column);
        in_row1 = in_row0 + 1;
        in_col1 = in_col0 + 1;
        if (in_row1 > (long)last_row) {
            in_row0--;
            in_row1--;
        }
        if (!grid->global && in_col1 > (long)last_column) {
            in_col0--;
            in_col1--;
        }
    }
    points->count = (int)((in_row1 - in_row0 + 1) * (in_col1 - in_col0 + 1));
    long ni = grid->ni;
    points->first_row = in_row0;
    points->last_row = in_row1;
    points->first_column = ((in_col0 % ni) + ni) % ni;
    points->last_column = ((in_col1 % ni) + ni) % ni;
    double lat0 = grid->lat_first + (double)in_row0 * grid->lat_step;
    double lat1 = grid->lat_first + (double)in_row1 * grid->lat_step;
    points->lat_min = fmin(lat0, lat1);
    points->lat_max = fmax(lat0, lat1);
    points->lon_west =
        forecast_longitude_normalized(grid->lon_first + (double)in_col0 * grid->lon_step);
    points->lon_east =
        forecast_longitude_normalized(grid->lon_first + (double)in_col1 * grid->lon_step);
    return true;
}

long forecast_window_value_index(const struct forecast_grid_info *grid,
                                 const struct forecast_window *window, int row, int column)
{
    long ni = grid->ni;
    long i = ((window->first_column + column) % ni + ni) % ni;
    return (window->first_row + row) * ni + i;
}

double forecast_window_mean(const struct forecast_window *window, const double *values)
{
    if (window->inside_rows == 0)
        return forecast_window_bilinear(window, values, 0.0, 0.0);
    double sum = 0.0;
    for (int r = 0; r < window->inside_rows; r++)
        for (int c = 0; c < window->inside_columns; c++)
            sum += values[(window->inside_row + r) * window->columns + window->inside_column + c];
    return sum / (double)(window->inside_rows * window->inside_columns);
}

/* The cell [i, i + 1] of 0..n-1 that holds x and x's place in it. */
static int cell_of(double x, int n, double *t)
{
    if (x < 0.0)
        x = 0.0;
    if (x > (double)(n - 1))
        x = (double)(n - 1);
    int i = (int)floor(x);
    if (i > n - 2)
        i = n - 2;
    *t = x - (double)i;
    return i;
}

double forecast_window_bilinear(const struct forecast_window *window, const double *values,
                                double east_km, double north_km)
{
    double row = window->center_row + north_km * window->rows_per_km_north -
                 (double)window->first_row;
    double column = window->center_column + east_km * window->columns_per_km_east -
                    (double)window->first_column;
    double tr, tc;
    int r = cell_of(row, window->rows, &tr);
    int c = cell_of(column, window->columns, &tc);
    const double *p = values + r * window->columns + c;
    double top = p[0] + (p[1] - p[0]) * tc;
    double bottom = p[window->columns] + (p[window->columns + 1] - p[window->columns]) * tc;
    return top + (bottom - top) * tr; /* bilinear: lerp of the two lerps along the rows */
}

void forecast_window_grid(const struct forecast_window *window, const double *values,
                          double extent_km, int size, double *cells)
{
    double cell_km = extent_km / (double)size;
    for (int y = 0; y < size; y++) {
        double north = 0.5 * extent_km - ((double)y + 0.5) * cell_km;
        for (int x = 0; x < size; x++) {
            double east = -0.5 * extent_km + ((double)x + 0.5) * cell_km;
            cells[y * size + x] = forecast_window_bilinear(window, values, east, north);
        }
    }
}
