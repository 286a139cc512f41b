/* The daemon's one time base: CLOCK_MONOTONIC in seconds (schedules, rate limits, stalls). */
#ifndef SKYD_MONOTONIC_CLOCK_H
#define SKYD_MONOTONIC_CLOCK_H

#include <time.h>

static inline double monotonic_seconds(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + ts.tv_nsec * 1e-9;
}

#endif
