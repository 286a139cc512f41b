/* Named presets: world-state patches stored as <config_dir>/<kind>/<name>.json.
 *
 * A preset file holds a patch for proto_world_state_apply_json, e.g. {"atmosphere": {...}}.
 * It may also carry one optional top-level member "description" (a string, for people and for
 * preset listings); it is removed before the patch is applied, so it is not a schema field.
 * Kinds and names match [a-z0-9_-]{1,64}, which also keeps them inside config_dir. Files
 * larger than WORLD_PRESET_MAX_FILE_BYTES are refused.
 */
#ifndef SKYD_PRESETS_H
#define SKYD_PRESETS_H

#include <stdbool.h>
#include <stddef.h>

#include "world_state.h"

#define WORLD_PRESET_NAME_MAX 64
#define WORLD_PRESET_MAX_FILE_BYTES (1024 * 1024)

/* True when name matches [a-z0-9_-]{1,64}. */
bool world_preset_name_is_valid(const char *name);

/* Loads <config_dir>/<kind>/<name>.json and applies it to *state, all or nothing. Returns true
 * when applied. On failure *state is untouched, msg says why (invalid name, missing preset with
 * the available ones listed, unreadable or oversized file, JSON syntax error with file, line
 * and column) and, when fields were rejected, errors lists them. errors and msg may be NULL. */
bool world_preset_apply(const char *config_dir, const char *kind, const char *name,
                        struct proto_world_state *state, struct proto_field_errors *errors,
                        char *msg, size_t msglen);

/* Stores the names of the presets of a kind (files <name>.json with a valid name) in names,
 * sorted bytewise; when there are more than max_names, the first max_names in that order.
 * Returns how many were stored, or -1 when the directory cannot be read. */
int world_preset_list(const char *config_dir, const char *kind,
                      char names[][WORLD_PRESET_NAME_MAX + 1], int max_names);

#endif
