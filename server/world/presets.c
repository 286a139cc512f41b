#include "presets.h"
#include "field_errors.h"
#include "text_file.h"

#include <cjson/cJSON.h>

#include <dirent.h>
#include <errno.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#if defined(__GNUC__)
#define PRINTF_LIKE(format_index, first_arg)                                                       \
    __attribute__((format(printf, format_index, first_arg)))
#else
#define PRINTF_LIKE(format_index, first_arg)
#endif

#define MAX_LISTED_PRESETS 32
#define PRESET_SUFFIX ".json"
#define NAME_RULE "[a-z0-9_-]{1,64}"

PRINTF_LIKE(3, 4)
static void set_message(char *msg, size_t msglen, const char *format, ...)
{
    if (!msg || msglen == 0)
        return;
    va_list args;
    va_start(args, format);
    vsnprintf(msg, msglen, format, args);
    va_end(args);
}

static bool is_name_char(char c)
{
    return (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '_' || c == '-';
}

bool world_preset_name_is_valid(const char *name)
{
    if (!name)
        return false;
    size_t length = 0;
    for (; name[length]; length++) {
        if (length >= WORLD_PRESET_NAME_MAX || !is_name_char(name[length]))
            return false;
    }
    return length > 0;
}

/* ---- listing ---------------------------------------------------------------------------- */

/* The preset name of a directory entry "<name>.json", if it is one. */
static bool preset_name_of_file(const char *file_name, char name[WORLD_PRESET_NAME_MAX + 1])
{
    size_t length = strlen(file_name);
    size_t suffix_length = strlen(PRESET_SUFFIX);
    if (length <= suffix_length || strcmp(file_name + length - suffix_length, PRESET_SUFFIX) != 0)
        return false;
    size_t name_length = length - suffix_length;
    if (name_length > WORLD_PRESET_NAME_MAX)
        return false;
    memcpy(name, file_name, name_length);
    name[name_length] = '\0';
    return world_preset_name_is_valid(name);
}

/* Keeps names sorted and at most max_names long, dropping whatever sorts last. */
static void insert_sorted(char names[][WORLD_PRESET_NAME_MAX + 1], int *count, int max_names,
                          const char *name)
{
    int position = 0;
    while (position < *count && strcmp(names[position], name) < 0)
        position++;
    if (position >= max_names)
        return;
    int last = *count < max_names ? *count : max_names - 1;
    for (int i = last; i > position; i--)
        memcpy(names[i], names[i - 1], sizeof names[i]);
    memcpy(names[position], name, strlen(name) + 1);
    if (*count < max_names)
        (*count)++;
}

static char *join_path(const char *directory, const char *kind, const char *file_name)
{
    size_t length = strlen(directory) + 1 + strlen(kind) + (file_name ? 1 + strlen(file_name) : 0);
    char *path = malloc(length + 1);
    if (!path)
        return NULL;
    if (file_name)
        snprintf(path, length + 1, "%s/%s/%s", directory, kind, file_name);
    else
        snprintf(path, length + 1, "%s/%s", directory, kind);
    return path;
}

int world_preset_list(const char *config_dir, const char *kind,
                      char names[][WORLD_PRESET_NAME_MAX + 1], int max_names)
{
    if (!config_dir || !world_preset_name_is_valid(kind) || max_names < 0 || (!names && max_names))
        return -1;
    char *directory_path = join_path(config_dir, kind, NULL);
    if (!directory_path)
        return -1;
    DIR *directory = opendir(directory_path);
    free(directory_path);
    if (!directory)
        return -1;
    int count = 0;
    struct dirent *entry;
    while ((entry = readdir(directory)) != NULL) {
        char name[WORLD_PRESET_NAME_MAX + 1];
        if (preset_name_of_file(entry->d_name, name))
            insert_sorted(names, &count, max_names, name);
    }
    closedir(directory);
    return count;
}

/* ---- loading ---------------------------------------------------------------------------- */

static void describe_available(const char *config_dir, const char *kind, char *text,
                               size_t capacity)
{
    char names[MAX_LISTED_PRESETS][WORLD_PRESET_NAME_MAX + 1];
    int count = world_preset_list(config_dir, kind, names, MAX_LISTED_PRESETS);
    size_t used = 0;
    text[0] = '\0';
    if (count <= 0) {
        snprintf(text, capacity, "none");
        return;
    }
    for (int i = 0; i < count && used + 1 < capacity; i++) {
        int written = snprintf(text + used, capacity - used, "%s%s", i > 0 ? ", " : "", names[i]);
        if (written < 0)
            break;
        used += (size_t)written;
    }
}

static void report_read_failure(const char *config_dir, const char *kind, const char *name,
                                const char *path, int error, char *msg, size_t msglen)
{
    if (error == ENOENT) {
        char available[512];
        describe_available(config_dir, kind, available, sizeof available);
        set_message(msg, msglen, "no %s preset named \"%s\" (%s not found); available: %s", kind,
                    name, path, available);
    } else if (error == EFBIG) {
        set_message(msg, msglen, "%s: preset file larger than the limit of %d bytes", path,
                    WORLD_PRESET_MAX_FILE_BYTES);
    } else if (error == EINVAL) {
        set_message(msg, msglen, "%s: not a regular file", path);
    } else {
        set_message(msg, msglen, "%s: cannot read: %s", path, strerror(error));
    }
}

/* The printable text of the error's line up to and including the error position (cJSON points
 * at or just past the offending character), for a "near ..." hint. */
static void excerpt_before(const char *contents, size_t offset, size_t length, char *text,
                           size_t capacity)
{
    size_t end = offset < length && contents[offset] != '\n' ? offset + 1 : offset;
    size_t start = end;
    while (start > 0 && contents[start - 1] != '\n' && end - start + 1 < capacity)
        start--;
    size_t used = 0;
    for (size_t i = start; i < end; i++) {
        char c = contents[i];
        text[used++] = (c >= 0x20 && c < 0x7f) ? c : '?';
    }
    text[used] = '\0';
}

static void report_syntax_error(const char *path, const char *contents, size_t length,
                                const char *error_position, char *msg, size_t msglen)
{
    size_t offset = 0;
    if (error_position && error_position >= contents && error_position <= contents + length)
        offset = (size_t)(error_position - contents);
    int line = 1, column = 1;
    for (size_t i = 0; i < offset; i++) {
        if (contents[i] == '\n') {
            line++;
            column = 1;
        } else {
            column++;
        }
    }
    char excerpt[24];
    excerpt_before(contents, offset, length, excerpt, sizeof excerpt);
    if (offset >= length)
        set_message(msg, msglen, "%s:%d:%d: invalid JSON: unexpected end of input", path, line,
                    column);
    else
        set_message(msg, msglen, "%s:%d:%d: invalid JSON near \"%s\"", path, line, column, excerpt);
}

static cJSON *parse_preset(const char *path, const char *contents, size_t length, char *msg,
                           size_t msglen)
{
    const char *nul = memchr(contents, '\0', length);
    if (nul) {
        report_syntax_error(path, contents, length, nul, msg, msglen);
        return NULL;
    }
    /* The length includes the terminating NUL: cJSON's null-termination check needs it. */
    const char *error_position = NULL;
    cJSON *patch = cJSON_ParseWithLengthOpts(contents, length + 1, &error_position, true);
    if (!patch)
        report_syntax_error(path, contents, length, error_position, msg, msglen);
    return patch;
}

/* Removes the optional "description" member; false (with an error) when it is not a string. */
static bool strip_description(cJSON *patch, struct proto_field_errors *errors)
{
    if (!cJSON_IsObject(patch))
        return true;
    cJSON *description;
    while ((description = cJSON_GetObjectItemCaseSensitive(patch, "description")) != NULL) {
        if (!cJSON_IsString(description)) {
            proto_field_errors_add(errors, PROTO_FIELD_WRONG_TYPE, "/description",
                                   "expected a string");
            return false;
        }
        cJSON_DeleteItemFromObjectCaseSensitive(patch, "description");
    }
    return true;
}

static void summarize_rejection(const char *path, const struct proto_field_errors *errors,
                                char *msg, size_t msglen)
{
    if (errors->count == 0) {
        set_message(msg, msglen, "%s: preset rejected", path);
        return;
    }
    const struct proto_field_error *first = &errors->items[0];
    set_message(msg, msglen, "%s: preset rejected, %d invalid field%s; first: %s: %s", path,
                errors->total, errors->total == 1 ? "" : "s",
                first->pointer[0] ? first->pointer : "(root)", first->reason);
}

static bool apply_preset_file(const char *path, const char *contents, size_t length,
                              struct proto_world_state *state, struct proto_field_errors *errors,
                              char *msg, size_t msglen)
{
    cJSON *patch = parse_preset(path, contents, length, msg, msglen);
    if (!patch)
        return false;
    bool applied = strip_description(patch, errors) &&
                   proto_world_state_apply_json(state, patch, errors);
    cJSON_Delete(patch);
    if (!applied)
        summarize_rejection(path, errors, msg, msglen);
    return applied;
}

bool world_preset_apply(const char *config_dir, const char *kind, const char *name,
                        struct proto_world_state *state, struct proto_field_errors *errors,
                        char *msg, size_t msglen)
{
    struct proto_field_errors scratch;
    if (!errors)
        errors = &scratch;
    proto_field_errors_clear(errors);
    set_message(msg, msglen, "%s", "");
    if (!config_dir || !state) {
        set_message(msg, msglen, "no config directory or state given");
        return false;
    }
    if (!world_preset_name_is_valid(kind)) {
        set_message(msg, msglen, "invalid preset kind \"%.80s\": must match %s", kind ? kind : "",
                    NAME_RULE);
        return false;
    }
    if (!world_preset_name_is_valid(name)) {
        set_message(msg, msglen, "invalid preset name \"%.80s\": must match %s", name ? name : "",
                    NAME_RULE);
        return false;
    }
    char file_name[WORLD_PRESET_NAME_MAX + sizeof PRESET_SUFFIX];
    snprintf(file_name, sizeof file_name, "%s%s", name, PRESET_SUFFIX);
    char *path = join_path(config_dir, kind, file_name);
    if (!path) {
        set_message(msg, msglen, "out of memory");
        return false;
    }
    size_t length = 0;
    char *contents = text_file_read(path, WORLD_PRESET_MAX_FILE_BYTES, &length);
    bool applied = false;
    if (!contents) {
        report_read_failure(config_dir, kind, name, path, errno, msg, msglen);
    } else {
        applied = apply_preset_file(path, contents, length, state, errors, msg, msglen);
        if (applied)
            set_message(msg, msglen, "applied %s preset \"%s\" from %s", kind, name, path);
    }
    free(contents);
    free(path);
    return applied;
}
