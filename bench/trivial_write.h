/* The bench's yardstick: GPU time of a trivial compute write of a W x H RGBA8 image on the
 * same device, so that frame times can be reported as ratios measured in one run. */
#ifndef SKYD_BENCH_TRIVIAL_WRITE_H
#define SKYD_BENCH_TRIVIAL_WRITE_H

#include <stdint.h>

/* Median GPU milliseconds over `runs` dispatches; negative on failure. */
double trivial_write_ms(const char *device_preference, uint32_t width, uint32_t height, int runs);

#endif
