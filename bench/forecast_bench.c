/* A large GRIB2 forecast and the time its read takes (docs/PERFORMANCE.md, "Forecast reads
 * off the render thread"): a global regular lat/lon grid (0.25 degrees: 1440 x 721 points, as
 * GFS's and ECMWF's open data) with the fields the forecast reader uses (lcc, mcc, hcc, 2t, 2d,
 * 10u, 10v, tp) at every step, 16 bits a value, made from ecCodes' GRIB2 sample; then read
 * for a place as the daemon's forecast folder would. The covers vary over the globe so that
 * packing keeps every value's bits.
 *
 * Usage: skyd_forecast_bench OUT.grib2 [STEPS [RESOLUTION_DEG]]   (defaults 40, 0.25)
 * The run is 2026-06-21 12:00 UTC, steps 3 h apart. */
#include <eccodes.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "forecast.h"
#include "monotonic_clock.h"

struct field {
    const char *short_name;
    double base, amplitude; /* values: base + amplitude * a pattern in 0..1 */
};

static const struct field fields[] = {
    { "lcc", 0.0, 1.0 },   { "mcc", 0.0, 1.0 },    { "hcc", 0.0, 1.0 },    { "2t", 260.0, 50.0 },
    { "2d", 250.0, 40.0 }, { "10u", -10.0, 20.0 }, { "10v", -10.0, 20.0 }, { "tp", 0.0, 0.02 },
};

#define CHECK_CODES(call)                                                                          \
    do {                                                                                           \
        int status_ = (call);                                                                      \
        if (status_ != CODES_SUCCESS) {                                                            \
            fprintf(stderr, "%s: %s\n", #call, codes_get_error_message(status_));                  \
            goto fail;                                                                             \
        }                                                                                          \
    } while (0)

/* The sample on the global grid; an accumulation (template 4.8) for tp. */
static codes_handle *make_handle(long ni, long nj, double resolution, bool accumulated)
{
    codes_handle *h = codes_grib_handle_new_from_samples(NULL, "regular_ll_sfc_grib2");
    if (!h)
        return NULL;
    if (accumulated)
        CHECK_CODES(codes_set_long(h, "productDefinitionTemplateNumber", 8));
    CHECK_CODES(codes_set_long(h, "Ni", ni));
    CHECK_CODES(codes_set_long(h, "Nj", nj));
    CHECK_CODES(codes_set_double(h, "latitudeOfFirstGridPointInDegrees", 90.0));
    CHECK_CODES(codes_set_double(h, "longitudeOfFirstGridPointInDegrees", 0.0));
    CHECK_CODES(codes_set_double(h, "latitudeOfLastGridPointInDegrees", -90.0));
    CHECK_CODES(codes_set_double(h, "longitudeOfLastGridPointInDegrees", 360.0 - resolution));
    CHECK_CODES(codes_set_double(h, "iDirectionIncrementInDegrees", resolution));
    CHECK_CODES(codes_set_double(h, "jDirectionIncrementInDegrees", resolution));
    CHECK_CODES(codes_set_long(h, "dataDate", 20260621));
    CHECK_CODES(codes_set_long(h, "dataTime", 1200));
    CHECK_CODES(codes_set_long(h, "bitsPerValue", 16));
    return h;
fail:
    codes_handle_delete(h);
    return NULL;
}

static bool write_file(const char *path, int steps, double resolution, long *messages)
{
    long ni = lround(360.0 / resolution), nj = lround(180.0 / resolution) + 1;
    size_t count = (size_t)ni * (size_t)nj;
    double *values = malloc(count * sizeof *values);
    FILE *out = fopen(path, "wb");
    codes_handle *instant = make_handle(ni, nj, resolution, false);
    codes_handle *accumulated = make_handle(ni, nj, resolution, true);
    bool ok = false;
    if (!values || !out || !instant || !accumulated) {
        fprintf(stderr, "cannot make %s\n", path);
        goto fail;
    }
    *messages = 0;
    for (int step = 0; step < steps; step++) {
        for (size_t f = 0; f < sizeof fields / sizeof fields[0]; f++) {
            bool tp = strcmp(fields[f].short_name, "tp") == 0;
            codes_handle *h = tp ? accumulated : instant;
            size_t length = strlen(fields[f].short_name);
            CHECK_CODES(codes_set_string(h, "shortName", fields[f].short_name, &length));
            if (tp) {
                char range[32];
                snprintf(range, sizeof range, "0-%d", 3 * step);
                length = strlen(range);
                CHECK_CODES(codes_set_string(h, "stepRange", range, &length));
            } else {
                CHECK_CODES(codes_set_long(h, "step", 3L * step));
            }
            for (long j = 0; j < nj; j++)
                for (long i = 0; i < ni; i++) {
                    double p = 0.5 + 0.5 * sin(0.05 * (double)i + 0.3 * step + (double)f) *
                                         cos(0.07 * (double)j);
                    double v = fields[f].base + fields[f].amplitude * p;
                    if (tp)
                        v *= 3.0 * step; /* accumulated from the run's start */
                    values[(size_t)j * (size_t)ni + (size_t)i] = v;
                }
            CHECK_CODES(codes_set_double_array(h, "values", values, count));
            const void *message = NULL;
            size_t size = 0;
            CHECK_CODES(codes_get_message(h, &message, &size));
            if (fwrite(message, 1, size, out) != size) {
                fprintf(stderr, "cannot write %s\n", path);
                goto fail;
            }
            ++*messages;
        }
    }
    ok = true;
fail:
    codes_handle_delete(instant);
    codes_handle_delete(accumulated);
    if (out && fclose(out) != 0)
        ok = false;
    free(values);
    return ok;
}

int main(int argc, char **argv)
{
    if (argc < 2 || argc > 4) {
        fprintf(stderr, "usage: %s OUT.grib2 [STEPS [RESOLUTION_DEG]]\n", argv[0]);
        return 2;
    }
    int steps = argc > 2 ? atoi(argv[2]) : 40;
    double resolution = argc > 3 ? atof(argv[3]) : 0.25;
    if (steps < 1 || steps > SKY_FORECAST_MAX_STEPS || !(resolution >= 0.1 && resolution <= 5)) {
        fprintf(stderr, "steps 1..%d, resolution 0.1..5 degrees\n", SKY_FORECAST_MAX_STEPS);
        return 2;
    }
    long messages = 0;
    double t0 = monotonic_seconds();
    if (!write_file(argv[1], steps, resolution, &messages))
        return 1;
    double made = monotonic_seconds() - t0;
    struct stat st;
    if (stat(argv[1], &st) != 0)
        return 1;
    printf("%s: %ld messages, %d steps, %.2f deg global, %.1f MB, made in %.2f s\n", argv[1],
           messages, steps, resolution, (double)st.st_size / 1e6, made);
    struct sky_forecast_request request = {
        .lat_deg = 45.0, .lon_deg = 5.0, .extent_km = 60.0, .grid_size = 16
    };
    for (int run = 0; run < 2; run++) { /* the second with the file in the page cache */
        struct sky_forecast_error error;
        t0 = monotonic_seconds();
        struct sky_forecast *forecast = sky_forecast_read(argv[1], &request, &error);
        double read_s = monotonic_seconds() - t0;
        if (!forecast) {
            fprintf(stderr, "refused: %s\n", error.text);
            return 1;
        }
        printf("read %d: %.2f s (%.1f ms a message), %d steps\n", run + 1, read_s,
               1e3 * read_s / (double)messages, sky_forecast_info(forecast)->step_count);
        sky_forecast_free(forecast);
    }
    return 0;
}
