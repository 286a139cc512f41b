#include "log.h"

#include <stdarg.h>
#include <stdatomic.h>
#include <stdio.h>
#include <string.h>

static atomic_int current_level = SKYD_LOG_INFO;

static const char *const level_names[] = { "error", "warning", "info", "debug" };
static const char *const level_prefixes[] = { "error: ", "warning: ", "", "debug: " };

bool skyd_log_parse_level(const char *name, enum skyd_log_level *level)
{
    for (int i = 0; i < 4; i++) {
        if (strcmp(name, level_names[i]) == 0) {
            *level = (enum skyd_log_level)i;
            return true;
        }
    }
    return false;
}

void skyd_log_set_level(enum skyd_log_level level)
{
    atomic_store(&current_level, (int)level);
}

bool skyd_log_enabled(enum skyd_log_level level)
{
    return (int)level <= atomic_load(&current_level);
}

void skyd_log(enum skyd_log_level level, const char *format, ...)
{
    if (!skyd_log_enabled(level))
        return;
    char line[2048];
    int prefix = snprintf(line, sizeof line, "skyd: %s", level_prefixes[level]);
    va_list args;
    va_start(args, format);
    vsnprintf(line + prefix, sizeof line - (size_t)prefix - 1, format, args);
    va_end(args);
    size_t length = strlen(line);
    if (length == 0 || line[length - 1] != '\n') {
        line[length++] = '\n';
        line[length] = '\0';
    }
    fputs(line, stderr); /* one call per line: stdio locks the stream around it */
}
