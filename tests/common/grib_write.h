/* GRIB2 forecasts on a global regular lat/lon grid written through ecCodes from its GRIB2
 * sample, for benchmarks and tests: the fields the forecast reader uses (lcc, mcc, hcc, 2t, 2d,
 * 10u, 10v, tp) at every step, 3 h apart from a run at 2026-06-21 12:00 UTC, 16 bits a value,
 * values that vary over the globe so that packing keeps every value's bits. */
#ifndef SKYD_TEST_GRIB_WRITE_H
#define SKYD_TEST_GRIB_WRITE_H

#include <stdbool.h>

/* Writes `steps` steps on a grid `resolution_deg` apart (0.25: 1440 x 721 points); *messages
 * counts what was written. false after a line on stderr. */
bool grib_write_global(const char *path, int steps, double resolution_deg, long *messages);

#endif
