/* skyctl's JSON chores: PATH=VALUE assignments, path lookups, printing values. */
#include "skyctl.h"

#include <cjson/cJSON.h>
#include <math.h>
#include <stdlib.h>
#include <stdio.h>
#include <string.h>

bool skyctl_parse_number(const char *text, double lo, double hi, double *out)
{
    char *end = NULL;
    double value = strtod(text, &end);
    if (end == text || *end != '\0' || !isfinite(value) || value < lo || value > hi)
        return false;
    *out = value;
    return true;
}

/* The value text as JSON when it is JSON, else as a string. */
static cJSON *parse_value(const char *text)
{
    cJSON *value = cJSON_ParseWithOpts(text, NULL, 1); /* the whole text, or it is a string */
    if (value && !cJSON_IsObject(value))
        return value;
    cJSON_Delete(value);
    return cJSON_CreateString(text);
}

bool skyctl_assign(cJSON *root, const char *assignment, char *err, size_t errlen)
{
    const char *equals = strchr(assignment, '=');
    if (!equals || equals == assignment) {
        snprintf(err, errlen, "\"%s\" is not PATH=VALUE", assignment);
        return false;
    }
    size_t path_length = (size_t)(equals - assignment);
    char path[256];
    if (path_length >= sizeof path) {
        snprintf(err, errlen, "path too long in \"%.40s...\"", assignment);
        return false;
    }
    memcpy(path, assignment, path_length);
    path[path_length] = '\0';
    cJSON *node = root;
    char *save = NULL;
    char *part = strtok_r(path[0] == '/' ? path + 1 : path, "./", &save);
    while (part) {
        char *next = strtok_r(NULL, "./", &save);
        cJSON *child = cJSON_GetObjectItemCaseSensitive(node, part);
        if (!next) {
            if (child) {
                snprintf(err, errlen, "%.*s is given twice", (int)path_length, assignment);
                return false;
            }
            cJSON_AddItemToObject(node, part, parse_value(equals + 1));
            return true;
        }
        if (!child)
            child = cJSON_AddObjectToObject(node, part);
        else if (!cJSON_IsObject(child)) {
            snprintf(err, errlen, "%.*s: %s already has a value", (int)path_length, assignment,
                     part);
            return false;
        }
        node = child;
        part = next;
    }
    snprintf(err, errlen, "\"%s\" has an empty path", assignment);
    return false;
}

const cJSON *skyctl_lookup(const cJSON *root, const char *path)
{
    char copy[256];
    if (snprintf(copy, sizeof copy, "%s", path) >= (int)sizeof copy)
        return NULL;
    const cJSON *node = root;
    char *save = NULL;
    for (char *part = strtok_r(copy, "./", &save); part && node;
         part = strtok_r(NULL, "./", &save)) {
        if (cJSON_IsArray(node)) {
            char *end = NULL;
            long index = strtol(part, &end, 10);
            node = *end == '\0' ? cJSON_GetArrayItem(node, (int)index) : NULL;
        } else {
            node = cJSON_GetObjectItemCaseSensitive(node, part);
        }
    }
    return node;
}

void skyctl_print_value(const cJSON *value)
{
    if (cJSON_IsString(value)) {
        printf("%s\n", value->valuestring);
        return;
    }
    char *text = cJSON_Print(value);
    printf("%s\n", text ? text : "null");
    free(text);
}

void skyctl_print_json_line(const cJSON *value)
{
    char *text = cJSON_PrintUnformatted(value);
    printf("%s\n", text ? text : "null");
    free(text);
    fflush(stdout);
}

void skyctl_print_reply_json(cJSON *reply)
{
    cJSON_DeleteItemFromObjectCaseSensitive(reply, "id");
    skyctl_print_json_line(reply);
}
