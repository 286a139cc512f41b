/* The wall clock: CLOCK_REALTIME in unix seconds. Only the world's clock reads it (its epoch
 * is a wall-clock instant, so that every node reads the same simulated time); schedules, rate
 * limits and stalls run on monotonic_clock.h. */
#ifndef SKYD_WALL_CLOCK_H
#define SKYD_WALL_CLOCK_H

#include <time.h>

static inline double wall_clock_seconds(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_REALTIME, &ts);
    return (double)ts.tv_sec + ts.tv_nsec * 1e-9;
}

#endif
