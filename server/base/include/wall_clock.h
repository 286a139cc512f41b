/* The wall clock: CLOCK_REALTIME in unix seconds. Only the world's clock reads it (its epoch
 * is a wall-clock instant, so that every node reads the same simulated time); schedules, rate
 * limits and stalls run on monotonic_clock.h.
 *
 * The reading never goes back. A clock stepped back (by NTP, by hand, or by the test fault of
 * test_faults.h) would run the simulated clock backwards and re-anchor changes in the past, so
 * a reading below the last one is replaced by the last one plus the monotonic time since, and
 * the difference is kept as a skew added to later readings: the world's clock keeps its pace
 * across the step (and stays ahead of the stepped clock by the step). A step forward while a
 * skew is kept (the clock set right again) is taken from the skew first; other steps forward are
 * taken as they come. Each step is logged as a warning. Thread-safe. */
#ifndef SKYD_WALL_CLOCK_H
#define SKYD_WALL_CLOCK_H

double wall_clock_seconds(void);

#endif
