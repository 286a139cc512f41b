/* The world state on disk: one JSON file (the `state` message's tree plus "revision"),
 * written atomically (temporary file, fsync, rename, fsync of the directory) and read back at
 * start. A file that cannot be used is moved aside, never silently discarded. */
#ifndef SKYD_STATE_STORE_H
#define SKYD_STATE_STORE_H

#include <stddef.h>
#include <sys/types.h>

#include "weather_map.h"
#include "world_state.h"

enum state_load_result {
    STATE_LOAD_RESTORED = 0, /* *state holds the file's state and revision */
    STATE_LOAD_ABSENT = 1,   /* no file: *state untouched */
    STATE_LOAD_CORRUPT = 2,  /* unreadable or invalid: moved to msg's path, *state untouched */
    STATE_LOAD_FAILED = 3,   /* invalid and could not be moved aside: *state untouched */
};

/* msg says what happened (the reason and where the file went) for anything but RESTORED. */
enum state_load_result state_store_load(const char *path, struct proto_world_state *state,
                                        char *msg, size_t msglen);

/* A state's JSON text (as saved: the `state` tree plus "revision") onto a copy of the
 * defaults; false with a reason and *state untouched. The cluster's entries carry the same. */
bool state_store_parse(const char *text, size_t length, struct proto_world_state *state, char *msg,
                       size_t msglen);

/* Creates missing parent directories. Returns 0, or -1 with a message. */
int state_store_save(const char *path, const struct proto_world_state *state, char *err,
                     size_t errlen);

/* Writes length bytes to path as the state is written: a temporary "<path>.tmp<pid>" made
 * with `mode` (less the umask), fsync, rename, fsync of the directory. Creates missing parent
 * directories. Returns 0, or -1 with a message. */
int state_store_write_file(const char *path, const void *data, size_t length, mode_t mode,
                           char *err, size_t errlen);

/* Removes the "<path>.tmp<pid>" a daemon killed while writing path left beside it. */
void state_store_remove_temporaries(const char *path);

/* The client weather map lives beside the state file, as a PNG: "var/skyd-state.json" keeps
 * it in "var/skyd-state.weather-map.png". */
void state_store_weather_map_path(const char *state_path, char *out, size_t outlen);

/* Writes the map atomically like the state; NULL (or no texels) removes the file. Returns 0,
 * or -1 with a message. */
int state_store_save_weather_map(const char *state_path, const struct proto_weather_map *map,
                                 char *err, size_t errlen);

/* RESTORED fills *map (free it with proto_weather_map_free); ABSENT, CORRUPT (not a usable PNG;
 * the file is left where it is) and FAILED (unreadable) leave it empty, with msg saying why. */
enum state_load_result state_store_load_weather_map(const char *state_path,
                                                    struct proto_weather_map *map, char *msg,
                                                    size_t msglen);

/* The followed forecast's map (weather.map_source "forecast") beside it too, as
 * "var/skyd-state.forecast-map.png": saved and loaded like the client's. */
void state_store_forecast_map_path(const char *state_path, char *out, size_t outlen);
int state_store_save_forecast_map(const char *state_path, const struct proto_weather_map *map,
                                  char *err, size_t errlen);
enum state_load_result state_store_load_forecast_map(const char *state_path,
                                                     struct proto_weather_map *map, char *msg,
                                                     size_t msglen);

/* A weather map PNG of at most max_bytes at `path` (the state's, or one given to skyd render):
 * RESTORED, CORRUPT (not a usable map) or FAILED (unreadable), with msg saying why. */
enum state_load_result state_store_read_weather_map(const char *path, size_t max_bytes,
                                                    struct proto_weather_map *map, char *msg,
                                                    size_t msglen);

#endif
