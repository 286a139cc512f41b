/* The call recorder of scripts/room-walk: linked into a skyd built with -finstrument-functions,
 * it records calls and returns between SIGUSR1 and SIGUSR2 and writes them to $WALK_OUT at exit. */
#define _GNU_SOURCE
#include <signal.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/syscall.h>
#include <time.h>
#include <unistd.h>

struct ev { uint64_t t; uintptr_t fn; uint32_t tid; int32_t kind; };
#define CAP (8u << 20)
static struct ev *buf;
static volatile int on;
static volatile size_t n;
extern char __executable_start;

__attribute__((no_instrument_function)) static void rec(void *fn, int kind)
{
    if (!on || !buf)
        return;
    size_t i = __atomic_fetch_add(&n, 1, __ATOMIC_RELAXED);
    if (i >= CAP)
        return;
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    buf[i].t = (uint64_t)ts.tv_sec * 1000000000u + (uint64_t)ts.tv_nsec;
    buf[i].fn = (uintptr_t)fn - (uintptr_t)&__executable_start;
    buf[i].tid = (uint32_t)syscall(SYS_gettid);
    buf[i].kind = kind;
}
__attribute__((no_instrument_function)) void __cyg_profile_func_enter(void *fn, void *site)
{ (void)site; rec(fn, 1); }
__attribute__((no_instrument_function)) void __cyg_profile_func_exit(void *fn, void *site)
{ (void)site; rec(fn, 0); }
__attribute__((no_instrument_function)) static void start(int s) { (void)s; on = 1; }
__attribute__((no_instrument_function)) static void stop(int s) { (void)s; on = 0; }
__attribute__((no_instrument_function, constructor)) static void init(void)
{
    if (!getenv("WALK_OUT"))
        return;
    buf = malloc(sizeof *buf * CAP);
    signal(SIGUSR1, start);
    signal(SIGUSR2, stop);
}
__attribute__((no_instrument_function, destructor)) static void dump(void)
{
    const char *p = getenv("WALK_OUT");
    if (!p || !buf)
        return;
    FILE *f = fopen(p, "wb");
    size_t count = n < CAP ? n : CAP;
    fwrite(buf, sizeof *buf, count, f);
    fclose(f);
}
