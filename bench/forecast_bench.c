/* A large GRIB2 forecast and the time its read takes (docs/PERFORMANCE.md, "Forecast reads
 * off the render thread"): a global regular lat/lon grid (0.25 degrees: 1440 x 721 points, as
 * GFS's and ECMWF's open data) with the fields the forecast reader uses (lcc, mcc, hcc, 2t, 2d,
 * 10u, 10v, tp) at every step, 16 bits a value, made from ecCodes' GRIB2 sample; then read
 * for a place as the daemon's forecast folder would. The covers vary over the globe so that
 * packing keeps every value's bits.
 *
 * Usage: skyd_forecast_bench OUT.grib2 [STEPS [RESOLUTION_DEG]]   (defaults 40, 0.25)
 * The run is 2026-06-21 12:00 UTC, steps 3 h apart. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "forecast.h"
#include "grib_write.h"
#include "monotonic_clock.h"

int main(int argc, char **argv)
{
    if (argc < 2 || argc > 4) {
        fprintf(stderr, "usage: %s OUT.grib2 [STEPS [RESOLUTION_DEG]]\n", argv[0]);
        return 2;
    }
    int steps = argc > 2 ? atoi(argv[2]) : 40;
    double resolution = argc > 3 ? atof(argv[3]) : 0.25;
    if (steps < 1 || steps > FORECAST_MAX_STEPS || !(resolution >= 0.1 && resolution <= 5)) {
        fprintf(stderr, "steps 1..%d, resolution 0.1..5 degrees\n", FORECAST_MAX_STEPS);
        return 2;
    }
    long messages = 0;
    double t0 = monotonic_seconds();
    if (!grib_write_global(argv[1], steps, resolution, &messages))
        return 1;
    double made = monotonic_seconds() - t0;
    struct stat st;
    if (stat(argv[1], &st) != 0)
        return 1;
    printf("%s: %ld messages, %d steps, %.2f deg global, %.1f MB, made in %.2f s\n", argv[1],
           messages, steps, resolution, (double)st.st_size / 1e6, made);
    struct forecast_request request = {
        .lat_deg = 45.0, .lon_deg = 5.0, .extent_km = 60.0, .grid_size = 16
    };
    for (int run = 0; run < 2; run++) { /* the second with the file in the page cache */
        struct forecast_error error;
        t0 = monotonic_seconds();
        struct forecast *forecast = forecast_read(argv[1], &request, &error);
        double read_s = monotonic_seconds() - t0;
        if (!forecast) {
            fprintf(stderr, "refused: %s\n", error.text);
            return 1;
        }
        printf("read %d: %.2f s (%.1f ms a message), %d steps\n", run + 1, read_s,
               1e3 * read_s / (double)messages, forecast_info(forecast)->step_count);
        forecast_free(forecast);
    }
    return 0;
}
