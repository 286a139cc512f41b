/* What `skyd serve` does at SIGHUP: reads its configuration again (with the command line's
 * overrides) and applies what a running daemon can change without dropping anyone: the
 * protocol limits, the controller token and read-only mode, the allowed origins (through
 * live_settings); presets are read from disk at each use, so it checks them all and says which
 * appeared, went or no longer apply. Everything else waits for a restart, and it says so. One
 * log line says what changed; a configuration that does not load changes nothing. */
#ifndef SKYD_SERVE_RELOAD_H
#define SKYD_SERVE_RELOAD_H

#include <stdbool.h>

#include "config.h"
#include "control_token.h"
#include "live_settings.h"
#include "presets.h"
#include "service_notify.h"

#define SERVE_RELOAD_MAX_PRESETS 128

struct serve_reload {
    /* Loads the configuration as at start (the file, then the command line); false after
     * printing why. */
    bool (*load)(const void *options, struct skyd_config *config);
    const void *options;
    struct skyd_config running; /* as the daemon started, token settled */
    enum control_token_source token_source;
    struct live_settings *settings;
    struct service_notify *notify;
    const char *config_dir;
    const char *url; /* for a control line when the token file is new */
    int preset_count[2];
    char presets[2][SERVE_RELOAD_MAX_PRESETS][WORLD_PRESET_NAME_MAX + 1];
};

/* Notes the presets as they are at start. */
void serve_reload_init(struct serve_reload *reload);
/* One reload (from the signal thread). */
void serve_reload_run(struct serve_reload *reload);

#endif
