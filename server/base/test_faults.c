#include "test_faults.h"

#include "monotonic_clock.h"

#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

static pthread_once_t faults_once = PTHREAD_ONCE_INIT;
static char fault_dir[1024];
static bool armed;

static pthread_mutex_t offset_lock = PTHREAD_MUTEX_INITIALIZER;
static double offset_s;
static double offset_read_at = -1.0;

static void read_environment(void)
{
    const char *dir = getenv("SKYD_FAULT_DIR");
    if (!dir || !*dir)
        return;
    if (strlen(dir) + 32 > sizeof fault_dir) {
        fprintf(stderr, "skyd: SKYD_FAULT_DIR is too long; no host fault is injected\n");
        return;
    }
    snprintf(fault_dir, sizeof fault_dir, "%s", dir);
    armed = true;
    fprintf(stderr, "skyd: host fault injection armed (tests only): SKYD_FAULT_DIR=%s\n", dir);
}

static bool fault_path(const char *name, char *out, size_t outlen)
{
    pthread_once(&faults_once, read_environment);
    if (!armed)
        return false;
    snprintf(out, outlen, "%s/%s", fault_dir, name);
    return true;
}

bool test_fault_disk_full(void)
{
    char path[1100];
    return fault_path("state_write", path, sizeof path) && access(path, F_OK) == 0;
}

static double read_seconds(const char *path)
{
    double value = 0.0;
    FILE *f = fopen(path, "r");
    if (f) {
        char text[64] = { 0 };
        if (fgets(text, sizeof text, f)) {
            char *end = NULL;
            double v = strtod(text, &end);
            if (end != text && v > -1e9 && v < 1e9)
                value = v;
        }
        fclose(f);
    }
    return value;
}

double test_fault_forecast_read_delay(void)
{
    char path[1100];
    if (!fault_path("forecast_read_delay", path, sizeof path))
        return 0.0;
    double delay = read_seconds(path);
    return delay > 0.0 ? delay : 0.0;
}

double test_fault_wall_clock_offset(void)
{
    char path[1100];
    if (!fault_path("wall_clock_offset", path, sizeof path))
        return 0.0;
    double now = monotonic_seconds();
    pthread_mutex_lock(&offset_lock);
    if (offset_read_at < 0 || now - offset_read_at >= 0.2) {
        offset_read_at = now;
        offset_s = read_seconds(path);
    }
    double v = offset_s;
    pthread_mutex_unlock(&offset_lock);
    return v;
}
