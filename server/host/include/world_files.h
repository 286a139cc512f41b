/* The world's files as the command line reads them before any render thread runs: the state
 * file `skyd serve` resumes from, and a weather map PNG given to `skyd render`. The render
 * thread reads and writes the same files (state_store.c). */
#ifndef SKYD_WORLD_FILES_H
#define SKYD_WORLD_FILES_H

#include <stdbool.h>
#include <stddef.h>

#include "weather_map.h"
#include "world_state.h"

/* *state: the state file's state and revision when it can be read, else `configured` (no file,
 * state_file "", or one that cannot be used, which is moved aside). What happened is logged. */
void world_files_resume_state(const char *state_file, const struct proto_world_state *configured,
                              struct proto_world_state *state);

/* A weather map PNG of at most max_bytes at `path`, as a client would send it: false with msg
 * saying why it cannot be read or used. Free *map with proto_weather_map_free. */
bool world_files_read_weather_map(const char *path, size_t max_bytes, struct proto_weather_map *map,
                                  char *msg, size_t msglen);

#endif
