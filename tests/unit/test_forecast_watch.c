/* The forecast folder's worker (server/host/forecast_watch.h): a GRIB2 file (grib_write.h) is
 * read for the place and handed over, the taker owning it; a file that is not GRIB is refused
 * once, with its name and the reader's error, and not read again until it changes; a look
 * asked while a read is under way (SKYD_FAULT_DIR's forecast_read_delay: a read as slow as a
 * large file's) returns at once; destroy during that read gives it up and joins the worker
 * promptly; a read whose cancel flag is set gives up between messages. Nothing is left behind
 * (the sanitizer build checks the leaks). */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "check.h"
#include "forecast_watch.h"
#include "grib_write.h"
#include "monotonic_clock.h"

static char faults[] = "/tmp/skyd-forecast-watch-faults-XXXXXX";
static char folder[] = "/tmp/skyd-forecast-watch-XXXXXX";
static int woken;

static void write_text(const char *dir, const char *name, const char *text)
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

static void remove_file(const char *dir, const char *name)
{
    char path[256];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    unlink(path);
}

static void on_ready(void *user)
{
    (void)user;
    __atomic_add_fetch(&woken, 1, __ATOMIC_SEQ_CST);
}

static bool take_within(struct forecast_watch *w, double seconds, struct forecast_watch_news *n)
{
    double until = monotonic_seconds() + seconds;
    while (monotonic_seconds() < until) {
        if (forecast_watch_take(w, n))
            return true;
        struct timespec ts = { 0, 10 * 1000 * 1000 };
        nanosleep(&ts, NULL);
    }
    return false;
}

static const struct forecast_request place = {
    .lat_deg = 45.0, .lon_deg = 6.0, .extent_km = 60.0, .grid_size = 16
};

static struct forecast_watch *make(void)
{
    char err[256] = "";
    struct forecast_watch_params params = { .dir = folder, .ready = on_ready };
    struct forecast_watch *w = forecast_watch_create(&params, err, sizeof err);
    CHECK_MSG(w != NULL, "%s", err);
    return w;
}

static void refusal(void)
{
    struct forecast_watch *w = make();
    if (!w)
        return;
    struct forecast_watch_news news;
    forecast_watch_look(w, &place);
    CHECK(!take_within(w, 0.3, &news)); /* an empty folder: nothing to say */
    write_text(folder, "broken.grib2", "not a forecast\n");
    forecast_watch_look(w, &place);
    CHECK(take_within(w, 5.0, &news));
    CHECK(!news.replaced);
    CHECK_INT(news.refusals, 1);
    CHECK(strncmp(news.error, "broken.grib2: ", 14) == 0);
    CHECK(__atomic_load_n(&woken, __ATOMIC_SEQ_CST) >= 1);
    forecast_watch_look(w, &place); /* the same folder: not read again */
    CHECK(!take_within(w, 0.3, &news));
    remove_file(folder, "broken.grib2");
    forecast_watch_destroy(&w);
    CHECK(w == NULL);
}

static void read_and_handed_over(void)
{
    char path[256];
    long messages = 0;
    snprintf(path, sizeof path, "%s/global.grib2", folder);
    CHECK(grib_write_global(path, 3, 2.0, &messages));
    CHECK_INT(messages, 24);
    struct forecast_watch *w = make();
    if (!w)
        return;
    struct forecast_watch_news news;
    forecast_watch_look(w, &place);
    CHECK(take_within(w, 10.0, &news));
    CHECK(news.replaced && news.forecast != NULL);
    CHECK_STR(news.file, "global.grib2");
    CHECK_INT(news.refusals, 0);
    if (news.forecast) {
        CHECK_INT(forecast_info(news.forecast)->step_count, 3);
        forecast_free(news.forecast);
    }
    forecast_watch_look(w, &place); /* the same file: nothing new */
    CHECK(!take_within(w, 0.3, &news));
    struct forecast_request elsewhere = place;
    elsewhere.lat_deg = -30.0;
    forecast_watch_look(w, &elsewhere); /* another place: read again for it */
    CHECK(take_within(w, 10.0, &news));
    CHECK(news.replaced && news.forecast != NULL);
    if (news.forecast) {
        CHECK_DOUBLE(forecast_info(news.forecast)->request.lat_deg, -30.0);
        forecast_free(news.forecast);
    }
    forecast_watch_destroy(&w);

    atomic_bool cancel;
    atomic_init(&cancel, true);
    struct forecast_error error;
    CHECK(forecast_read_until(path, &place, &cancel, &error) == NULL);
    CHECK_INT(error.code, FORECAST_ERR_CANCELLED);
    remove_file(folder, "global.grib2");
}

static void slow_read_given_up(void)
{
    write_text(faults, "forecast_read_delay", "30\n");
    write_text(folder, "slow.grib2", "not a forecast either\n");
    struct forecast_watch *w = make();
    if (!w)
        return;
    forecast_watch_look(w, &place);
    struct timespec ts = { 0, 200 * 1000 * 1000 }; /* the worker is in its read by now */
    nanosleep(&ts, NULL);
    double t0 = monotonic_seconds();
    forecast_watch_look(w, &place);
    struct forecast_watch_news news;
    CHECK(!forecast_watch_take(w, &news));
    CHECK_LE(monotonic_seconds() - t0, 0.05);
    t0 = monotonic_seconds();
    forecast_watch_destroy(&w);
    CHECK_LE(monotonic_seconds() - t0, 1.0);
    remove_file(folder, "slow.grib2");
    remove_file(faults, "forecast_read_delay");
}

int main(void)
{
    if (!mkdtemp(faults) || !mkdtemp(folder)) {
        perror("mkdtemp");
        return 1;
    }
    setenv("SKYD_FAULT_DIR", faults, 1); /* read once, at the first fault asked for */
    read_and_handed_over();
    refusal();
    slow_read_given_up();
    rmdir(folder);
    rmdir(faults);
    return check_summary();
}
