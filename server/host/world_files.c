#include "world_files.h"

#include "error_text.h"
#include "log.h"
#include "state_store.h"

void world_files_resume_state(const char *state_file, const struct proto_world_state *configured,
                              struct proto_world_state *state)
{
    *state = *configured;
    if (!state_file[0])
        return;
    error_text msg;
    switch (state_store_load(state_file, state, msg, sizeof msg)) {
    case STATE_LOAD_RESTORED:
        skyd_log(SKYD_LOG_INFO, "restored the world state (revision %llu) from %s",
                 (unsigned long long)state->revision, state_file);
        break;
    case STATE_LOAD_ABSENT:
        skyd_log(SKYD_LOG_INFO, "%s", msg);
        break;
    case STATE_LOAD_CORRUPT:
    case STATE_LOAD_FAILED:
        skyd_log(SKYD_LOG_ERROR, "%s", msg);
        break;
    }
}

bool world_files_read_weather_map(const char *path, size_t max_bytes, struct proto_weather_map *map,
                                  char *msg, size_t msglen)
{
    return state_store_read_weather_map(path, max_bytes, map, msg, msglen) == STATE_LOAD_RESTORED;
}
