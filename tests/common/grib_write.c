/* GRIB2 forecasts for benchmarks and tests (grib_write.h). */
#include "grib_write.h"

#include <eccodes.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

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

bool grib_write_global(const char *path, int steps, double resolution, long *messages)
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
