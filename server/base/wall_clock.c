#include "wall_clock.h"

#include "log.h"
#include "monotonic_clock.h"
#include "test_faults.h"

#include <pthread.h>
#include <stdbool.h>
#include <time.h>

static pthread_mutex_t clock_lock = PTHREAD_MUTEX_INITIALIZER;
static bool have_last;
static double last_wall_s, last_monotonic_s, skew_s;

double wall_clock_seconds(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_REALTIME, &ts);
    double raw = (double)ts.tv_sec + ts.tv_nsec * 1e-9 + test_fault_wall_clock_offset();
    double mono = monotonic_seconds();
    pthread_mutex_lock(&clock_lock);
    double wall = raw + skew_s;
    double expected = have_last ? last_wall_s + (mono - last_monotonic_s) : wall;
    if (have_last && skew_s > 0 && wall > expected + 0.5) {
        /* A step forward after a step back (the clock set right again): the skew is given
         * back first, so that the world's clock does not jump ahead by the old step. */
        double taken = wall - expected < skew_s ? wall - expected : skew_s;
        skew_s -= taken;
        wall -= taken;
        skyd_log(SKYD_LOG_WARNING,
                 "the wall clock stepped forward by %.3f s; %.3f s of it taken from the skew of "
                 "an earlier step back (%.3f s left)",
                 raw + skew_s + taken - expected, taken, skew_s);
    }
    if (have_last && wall < last_wall_s) {
        double kept = expected;
        skew_s += kept - wall;
        skyd_log(SKYD_LOG_WARNING,
                 "the wall clock stepped back by %.3f s; the world's clock keeps its pace "
                 "(%.3f s ahead of the wall clock from now on)",
                 kept - wall, skew_s);
        wall = kept;
    }
    have_last = true;
    last_wall_s = wall;
    last_monotonic_s = mono;
    pthread_mutex_unlock(&clock_lock);
    return wall;
}
