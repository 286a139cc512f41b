/* The host's test faults (server/base/test_faults.h) and what they test: the wall clock of
 * server/base/wall_clock.c never reads backwards across a step back (SKYD_FAULT_DIR's
 * wall_clock_offset), keeps its pace after it, and does not jump ahead when the clock is set
 * right again; a full disk (state_write) makes state_store_save fail with ENOSPC, leaves the
 * last saved file as it was and no temporary file, and the next save after the space comes
 * back succeeds. */
#include <dirent.h>
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "check.h"
#include "monotonic_clock.h"
#include "state_store.h"
#include "text_file.h"
#include "wall_clock.h"

static char dir[] = "/tmp/skyd-host-faults-XXXXXX";

static void write_text(const char *name, const char *text)
{
    char path[256];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    FILE *f = fopen(path, "w");
    CHECK(f != NULL);
    if (f) {
        fputs(text, f);
        fclose(f);
    }
}

static void remove_file(const char *name)
{
    char path[256];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    unlink(path);
}

static void sleep_s(double s)
{
    struct timespec ts = { (time_t)s, (long)((s - (time_t)s) * 1e9) };
    nanosleep(&ts, NULL);
}

static double realtime(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_REALTIME, &ts);
    return (double)ts.tv_sec + ts.tv_nsec * 1e-9;
}

static void wall_clock_steps(void)
{
    double w0 = wall_clock_seconds(), m0 = monotonic_seconds();
    CHECK_NEAR(w0, realtime(), 0.05);
    write_text("wall_clock_offset", "-3600\n");
    sleep_s(0.25); /* the offset is read again at most every 0.2 s */
    double lowest_step = 1e9, last = w0;
    for (int i = 0; i < 20; i++) {
        double w = wall_clock_seconds();
        if (w - last < lowest_step)
            lowest_step = w - last;
        last = w;
        sleep_s(0.01);
    }
    CHECK_MSG(lowest_step >= 0, "the wall clock went back by %.3f s", -lowest_step);
    /* Its pace kept: w - w0 follows the monotonic time, not the step. */
    CHECK_NEAR(last - w0, monotonic_seconds() - m0, 0.05);
    write_text("wall_clock_offset", "0\n");
    sleep_s(0.25);
    double after = wall_clock_seconds();
    CHECK_MSG(after - w0 < monotonic_seconds() - m0 + 0.05 && after >= last,
              "after the clock was set right: %.3f s from the start in %.3f monotonic s",
              after - w0, monotonic_seconds() - m0);
    CHECK_NEAR(after, realtime(), 0.05); /* the skew given back */
    remove_file("wall_clock_offset");
}

static int temporaries(void)
{
    int n = 0;
    DIR *d = opendir(dir);
    struct dirent *e;
    while (d && (e = readdir(d)))
        n += strstr(e->d_name, ".tmp") != NULL;
    if (d)
        closedir(d);
    return n;
}

static void disk_full(void)
{
    char path[256], err[512];
    snprintf(path, sizeof path, "%s/state.json", dir);
    struct proto_world_state a, b, back;
    proto_world_state_defaults(&a);
    a.revision = 7;
    b = a;
    b.revision = 8;
    CHECK_INT(state_store_save(path, &a, err, sizeof err), 0);
    write_text("state_write", "");
    err[0] = '\0';
    CHECK_INT(state_store_save(path, &b, err, sizeof err), -1);
    CHECK_CONTAINS(err, strerror(ENOSPC));
    CHECK_INT(temporaries(), 0);
    char msg[512];
    CHECK_INT(state_store_load(path, &back, msg, sizeof msg), STATE_LOAD_RESTORED);
    CHECK_INT(back.revision, 7); /* the last saved state, whole */
    remove_file("state_write");
    CHECK_INT(state_store_save(path, &b, err, sizeof err), 0);
    CHECK_INT(state_store_load(path, &back, msg, sizeof msg), STATE_LOAD_RESTORED);
    CHECK_INT(back.revision, 8);
    remove_file("state.json");
}

int main(void)
{
    if (!mkdtemp(dir)) {
        perror("mkdtemp");
        return 1;
    }
    setenv("SKYD_FAULT_DIR", dir, 1);
    wall_clock_steps();
    disk_full();
    rmdir(dir);
    return check_summary();
}
