#include "state_store.h"
#include "error_text.h"
#include "field_errors.h"
#include "png_write.h"
#include "test_faults.h"
#include "text_file.h"

#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include <cjson/cJSON.h>
#include <dirent.h>

#define STATE_FILE_MAX_BYTES (1 << 20)
/* A 512 x 512 RGBA8 PNG of noise, stored uncompressed, with room to spare. */
#define WEATHER_MAP_FILE_MAX_BYTES (4 << 20)

bool state_store_parse(const char *text, size_t length, struct proto_world_state *out, char *msg,
                       size_t msglen)
{
    const char *end = NULL;
    cJSON *root = cJSON_ParseWithLengthOpts(text, length, &end, 0);
    if (!root) {
        snprintf(msg, msglen, "not valid JSON (byte %td)", end ? end - text : (ptrdiff_t)0);
        return false;
    }
    bool ok = false;
    const cJSON *revision = cJSON_GetObjectItemCaseSensitive(root, "revision");
    if (!cJSON_IsObject(root)) {
        snprintf(msg, msglen, "not a JSON object");
    } else if (!cJSON_IsNumber(revision) || revision->valuedouble < 0 ||
               revision->valuedouble > 9007199254740991.0 ||
               revision->valuedouble != floor(revision->valuedouble)) {
        snprintf(msg, msglen, "/revision: expected an integer in [0, 2^53 - 1]");
    } else {
        struct proto_world_state state;
        struct proto_field_errors errors;
        proto_world_state_defaults(&state);
        state.revision = (uint64_t)revision->valuedouble;
        cJSON_DeleteItemFromObjectCaseSensitive(root, "revision");
        if (proto_world_state_apply_json(&state, root, &errors)) {
            *out = state;
            ok = true;
        } else {
            char detail[512];
            proto_field_errors_format(&errors, detail, sizeof detail);
            snprintf(msg, msglen, "invalid state: %s", detail);
        }
    }
    cJSON_Delete(root);
    return ok;
}

/* Splits `copy` (a writable copy of a path) in place into its directory, returned, and its
 * last component. */
static const char *split_path(char *copy, const char **base)
{
    char *slash = strrchr(copy, '/');
    if (!slash) {
        *base = copy;
        return ".";
    }
    *slash = '\0';
    *base = slash + 1;
    return slash == copy ? "/" : copy;
}

void state_store_remove_temporaries(const char *path)
{
    char *copy = strdup(path);
    if (!copy)
        return;
    const char *base;
    const char *dir = split_path(copy, &base);
    size_t base_length = strlen(base);
    DIR *d = opendir(dir);
    struct dirent *entry;
    while (d && (entry = readdir(d))) {
        const char *name = entry->d_name;
        const char *tmp = name + base_length; /* must be ".tmp" and digits */
        if (strncmp(name, base, base_length) != 0 || strncmp(tmp, ".tmp", 4) != 0 ||
            tmp[4] == '\0' || strspn(tmp + 4, "0123456789") != strlen(tmp + 4))
            continue;
        char full[4096];
        if ((size_t)snprintf(full, sizeof full, "%s/%s", dir, name) < sizeof full)
            unlink(full);
    }
    if (d)
        closedir(d);
    free(copy);
}

enum state_load_result state_store_load(const char *path, struct proto_world_state *state,
                                        char *msg, size_t msglen)
{
    char stem[4096];
    state_store_remove_temporaries(path);
    state_store_weather_map_path(path, stem, sizeof stem);
    state_store_remove_temporaries(stem);
    state_store_forecast_map_path(path, stem, sizeof stem);
    state_store_remove_temporaries(stem);
    if (access(path, F_OK) != 0) {
        snprintf(msg, msglen, "no state file at %s: starting from the defaults", path);
        return STATE_LOAD_ABSENT;
    }
    error_text reason;
    size_t length = 0;
    char *text = text_file_read(path, STATE_FILE_MAX_BYTES, &length);
    if (!text)
        text_file_describe_error(path, STATE_FILE_MAX_BYTES, reason, sizeof reason);
    bool ok = text && state_store_parse(text, length, state, reason, sizeof reason);
    free(text);
    if (ok)
        return STATE_LOAD_RESTORED;
    size_t n = strlen(path) + 48;
    char *aside = malloc(n);
    if (!aside) {
        snprintf(msg, msglen, "%s: %s; out of memory", path, reason);
        return STATE_LOAD_FAILED;
    }
    snprintf(aside, n, "%s.corrupt-%lld", path, (long long)time(NULL));
    enum state_load_result result = STATE_LOAD_CORRUPT;
    if (rename(path, aside) == 0) {
        snprintf(msg, msglen,
                 "state file %s unusable (%s); moved to %s, starting from the "
                 "defaults",
                 path, reason, aside);
    } else {
        snprintf(msg, msglen, "state file %s unusable (%s) and cannot be moved aside: %s", path,
                 reason, strerror(errno));
        result = STATE_LOAD_FAILED;
    }
    free(aside);
    return result;
}

/* mkdir -p of path's parent directory. */
static int make_parents(const char *path)
{
    char *copy = strdup(path);
    if (!copy)
        return -1;
    for (char *p = copy + 1; *p; p++) {
        if (*p != '/')
            continue;
        *p = '\0';
        if (mkdir(copy, 0755) != 0 && errno != EEXIST) {
            free(copy);
            return -1;
        }
        *p = '/';
    }
    free(copy);
    return 0;
}

static void sync_parent_directory(const char *path)
{
    char *copy = strdup(path);
    if (!copy)
        return;
    const char *base;
    int fd = open(split_path(copy, &base), O_RDONLY | O_DIRECTORY);
    if (fd >= 0) {
        fsync(fd);
        close(fd);
    }
    free(copy);
}

static int write_all(int fd, const void *bytes, size_t length)
{
    if (test_fault_disk_full()) { /* SKYD_FAULT_DIR/state_write (tests only) */
        errno = ENOSPC;
        return -1;
    }
    const char *data = bytes;
    while (length > 0) {
        ssize_t n = write(fd, data, length);
        if (n < 0 && errno == EINTR)
            continue;
        if (n <= 0)
            return -1;
        data += n;
        length -= (size_t)n;
    }
    return 0;
}

int state_store_write_file(const char *path, const void *data, size_t length, mode_t mode,
                           char *err, size_t errlen)
{
    size_t n = strlen(path) + 32;
    char *tmp = malloc(n);
    if (!tmp) {
        snprintf(err, errlen, "out of memory");
        return -1;
    }
    snprintf(tmp, n, "%s.tmp%ld", path, (long)getpid());
    int rc = -1;
    int fd = -1;
    if (make_parents(path) != 0) {
        snprintf(err, errlen, "cannot create the directory of %s: %s", path, strerror(errno));
    } else if (unlink(tmp) != 0 && errno != ENOENT) { /* one left there keeps its own mode */
        snprintf(err, errlen, "cannot remove %s: %s", tmp, strerror(errno));
    } else if ((fd = open(tmp, O_WRONLY | O_CREAT | O_EXCL, mode)) < 0) {
        snprintf(err, errlen, "cannot create %s: %s", tmp, strerror(errno));
    } else if (write_all(fd, data, length) != 0 || fsync(fd) != 0) {
        snprintf(err, errlen, "cannot write %s: %s", tmp, strerror(errno));
    } else if (close(fd) != 0) {
        fd = -1;
        snprintf(err, errlen, "cannot write %s: %s", tmp, strerror(errno));
    } else if ((fd = -1, rename(tmp, path) != 0)) {
        snprintf(err, errlen, "cannot rename %s to %s: %s", tmp, path, strerror(errno));
    } else {
        sync_parent_directory(path);
        rc = 0;
    }
    if (fd >= 0)
        close(fd);
    if (rc != 0)
        unlink(tmp);
    free(tmp);
    return rc;
}

int state_store_save(const char *path, const struct proto_world_state *state, char *err,
                     size_t errlen)
{
    cJSON *json = proto_world_state_to_json(state);
    char *text = json ? cJSON_Print(json) : NULL;
    cJSON_Delete(json);
    size_t length = text ? strlen(text) : 0;
    char *line = text ? realloc(text, length + 2) : NULL;
    if (!line) {
        snprintf(err, errlen, "out of memory");
        free(text);
        return -1;
    }
    memcpy(line + length, "\n", 2); /* newline and terminator */
    int rc = state_store_write_file(path, line, length + 1, 0644, err, errlen);
    free(line);
    return rc;
}

/* ---- the client weather map ---- */

static void map_path(const char *state_path, const char *name, char *out, size_t outlen)
{
    size_t length = strlen(state_path);
    const char *suffix = ".json";
    size_t suffix_length = strlen(suffix);
    if (length >= suffix_length && strcmp(state_path + length - suffix_length, suffix) == 0)
        length -= suffix_length;
    snprintf(out, outlen, "%.*s.%s.png", (int)length, state_path, name);
}

void state_store_weather_map_path(const char *state_path, char *out, size_t outlen)
{
    map_path(state_path, "weather-map", out, outlen);
}

void state_store_forecast_map_path(const char *state_path, char *out, size_t outlen)
{
    map_path(state_path, "forecast-map", out, outlen);
}

static int save_map(const char *path, const struct proto_weather_map *map, char *err, size_t errlen)
{
    if (!map || !map->rgba) {
        if (unlink(path) != 0 && errno != ENOENT) {
            snprintf(err, errlen, "cannot remove %s: %s", path, strerror(errno));
            return -1;
        }
        sync_parent_directory(path);
        return 0;
    }
    uint8_t *png = NULL;
    size_t length = 0;
    if (png_encode_rgba8(map->rgba, map->width, map->height, PNG_EFFORT_FILE, &png, &length) != 0) {
        snprintf(err, errlen, "cannot encode the weather map as PNG");
        return -1;
    }
    int rc = state_store_write_file(path, png, length, 0644, err, errlen);
    free(png);
    return rc;
}

int state_store_save_weather_map(const char *state_path, const struct proto_weather_map *map,
                                 char *err, size_t errlen)
{
    char path[4096];
    state_store_weather_map_path(state_path, path, sizeof path);
    return save_map(path, map, err, errlen);
}

int state_store_save_forecast_map(const char *state_path, const struct proto_weather_map *map,
                                  char *err, size_t errlen)
{
    char path[4096];
    state_store_forecast_map_path(state_path, path, sizeof path);
    return save_map(path, map, err, errlen);
}

static enum state_load_result load_map(const char *path, struct proto_weather_map *map, char *msg,
                                       size_t msglen)
{
    memset(map, 0, sizeof *map);
    if (access(path, F_OK) != 0) {
        snprintf(msg, msglen, "no weather map at %s", path);
        return STATE_LOAD_ABSENT;
    }
    return state_store_read_weather_map(path, WEATHER_MAP_FILE_MAX_BYTES, map, msg, msglen);
}

enum state_load_result state_store_load_weather_map(const char *state_path,
                                                    struct proto_weather_map *map, char *msg,
                                                    size_t msglen)
{
    char path[4096];
    state_store_weather_map_path(state_path, path, sizeof path);
    return load_map(path, map, msg, msglen);
}

enum state_load_result state_store_load_forecast_map(const char *state_path,
                                                     struct proto_weather_map *map, char *msg,
                                                     size_t msglen)
{
    char path[4096];
    state_store_forecast_map_path(state_path, path, sizeof path);
    return load_map(path, map, msg, msglen);
}

enum state_load_result state_store_read_weather_map(const char *path, size_t max_bytes,
                                                    struct proto_weather_map *map, char *msg,
                                                    size_t msglen)
{
    memset(map, 0, sizeof *map);
    size_t length = 0;
    char *bytes = text_file_read(path, max_bytes, &length);
    if (!bytes) {
        text_file_describe_error(path, max_bytes, msg, msglen);
        return STATE_LOAD_FAILED;
    }
    error_text reason;
    bool ok = proto_weather_map_decode(PROTO_WEATHER_MAP_PNG, (const uint8_t *)bytes, length, 0, 0,
                                       map, reason, sizeof reason);
    free(bytes);
    if (!ok) {
        snprintf(msg, msglen, "%s: %s", path, reason);
        return STATE_LOAD_CORRUPT;
    }
    return STATE_LOAD_RESTORED;
}
