/* The forecast folder watched from a worker thread of its own, so that reading a large GRIB2
 * file (a global grid, many steps: seconds) never holds up the render thread's frames. The
 * render thread asks for a look with the world's place (forecast_watch_look) and picks up what
 * the worker found (forecast_watch_take); the two meet under one mutex and nothing else is
 * shared. A look lists the folder's *.grib2 and *.grb2 files (names, sizes, times) and, when
 * they or the place changed, reads the newest that reads for the place; a refused file is not
 * read again until it changes. Destroy gives up a read under way (between two GRIB messages)
 * and joins the worker; nothing it read is left behind. */
#ifndef SKYD_FORECAST_WATCH_H
#define SKYD_FORECAST_WATCH_H

#include <stdbool.h>
#include <stdint.h>

#include "error_text.h"
#include "forecast.h"

struct forecast_watch_params {
    const char *dir;
    /* Called on the worker when news is ready to take (render_loop wakes its thread); may be
     * NULL. It must not call back into the watch. */
    void (*ready)(void *user);
    void *user;
};

/* What the worker found since the last take. */
struct forecast_watch_news {
    /* The forecast changed: `forecast` is the new one, which the taker owns, or NULL when no
     * file reads for the place any more. */
    bool replaced;
    struct forecast *forecast;
    char file[256];   /* its file's name in the folder */
    double read_s;    /* how long its read took */
    error_text error; /* the last refusal, "the folder cannot be read", or "" */
    uint64_t refusals;
};

struct forecast_watch;

/* NULL with the reason when memory is out or the thread cannot start. */
struct forecast_watch *forecast_watch_create(const struct forecast_watch_params *params, char *err,
                                             size_t errlen);
void forecast_watch_destroy(struct forecast_watch **watch);

/* Asks the worker to look at the folder for `request`; a look asked and not yet begun is
 * replaced. Never waits for a read. */
void forecast_watch_look(struct forecast_watch *watch, const struct forecast_request *request);

/* Moves what the worker found into *news: false when nothing is new. */
bool forecast_watch_take(struct forecast_watch *watch, struct forecast_watch_news *news);

#endif
