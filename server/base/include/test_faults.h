/* Faults of the host for tests (the Vulkan device's are render/vk/fault_injection.h): a full
 * disk under the state file and a wall clock that steps, switched on and off while the daemon
 * runs, so that a soak can provoke them at moments of its choosing.
 *
 * SKYD_FAULT_DIR, read once per process, names a directory; unset (always, outside tests),
 * every hook below is one test of a flag that stays false. In that directory:
 *
 *   state_write        While this file exists, every write of the daemon's files through
 *                      state_store (the state file, the saved weather map) fails with ENOSPC
 *                      after creating its temporary file, as on a full disk; removing it is
 *                      the space coming back.
 *   wall_clock_offset  Seconds (a decimal number, negative for a clock stepped back) added to
 *                      CLOCK_REALTIME, as a clock stepped by NTP or by hand; read again at most
 *                      every 0.2 s. A missing or unreadable file is an offset of 0.
 *   forecast_read_delay
 *                      Seconds (a decimal number) that every read of a forecast file from the
 *                      forecast folder takes longer, as a large file would; read before each.
 *
 * The line saying that the faults are armed goes to stderr. Thread-safe. */
#ifndef SKYD_TEST_FAULTS_H
#define SKYD_TEST_FAULTS_H

#include <stdbool.h>

/* Whether the state_write fault is on now. */
bool test_fault_disk_full(void);

/* The wall_clock_offset fault's seconds now (0 when off). */
double test_fault_wall_clock_offset(void);

/* The forecast_read_delay fault's seconds now (0 when off). */
double test_fault_forecast_read_delay(void);

#endif
