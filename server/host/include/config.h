/* skyd's configuration file (config/skyd.json): where to listen, what to serve, which device
 * renders, limits and roles. Loaded once at start; every field is optional (zero means the
 * default below) and an unknown or invalid field is an error that names it. */
#ifndef SKYD_CONFIG_H
#define SKYD_CONFIG_H

#include <stdbool.h>
#include <stddef.h>

#include "messages.h"
#include "world_state.h"

#define SKYD_CONFIG_MAX_ORIGINS 16
#define SKYD_CONFIG_STRING 256

struct skyd_config {
    char listen_address[64]; /* "127.0.0.1" */
    int listen_port;         /* 8080; 0 asks the kernel for a free port */
    /* TLS: both set = https/wss on the same port; both empty = plain http/ws. PEM files. */
    char tls_certificate[SKYD_CONFIG_STRING];
    char tls_private_key[SKYD_CONFIG_STRING];
    /* Relative paths resolve against the working directory skyd starts in. Empty web_root and
     * presets_dir: the installed ones, else a developer's source tree (server/cli's
     * install_paths.h). */
    char web_root[SKYD_CONFIG_STRING];    /* "" */
    char presets_dir[SKYD_CONFIG_STRING]; /* "": atmosphere/NAME.json, weather/NAME.json */
    char state_file[SKYD_CONFIG_STRING];  /* "var/skyd-state.json" */
    double state_save_delay_s;            /* 1: retry delay of a state write the daemon owes itself
                                      (client changes are written before their ack) */
    char render_device[64];               /* "" = automatic (a GPU when present, else lavapipe) */
    int encoder_threads;                  /* 0: skyd_config_encoder_threads() decides */
    /* Amortized atmosphere LUT rebuilds: GPU ms per frame (0 = at once) and blend frames. */
    double lut_budget_ms;       /* 8 */
    double lut_budget_fraction; /* 0.05: and at most this share of the rest of a frame */
    int lut_blend_frames;       /* 4 */
    double frame_budget_ms;     /* 16: clouds.quality.resolution auto fits frames to it */
    bool render_validation;
    int max_message_bytes;              /* 65536 */
    int max_clients;                    /* 64 */
    int max_width, max_height;          /* 3840 x 2160 */
    double max_fps;                     /* 60 */
    double control_messages_per_second; /* 20 */
    int max_upload_bytes;               /* 2 MiB: a controller's set_weather_map */
    /* 16: HTTP API requests (state, patches, snapshots) waiting for the render loop at once;
     * one more is answered 503 with Retry-After */
    int max_queued_http_requests;
    /* "" = `skyd serve` makes one (control_token.h); it stays "" only when read_only */
    char controller_token[128];
    bool read_only; /* nobody may control: auth is always refused */
    int origin_count;
    char allowed_origins[SKYD_CONFIG_MAX_ORIGINS][128];
    /* The world state the daemon starts from when no state file can be restored: the
     * defaults with the "initial_state" patch applied. Its "clock.utc" may be "now", the UTC
     * time at which the configuration is loaded. */
    struct proto_world_state initial_state;
    /* A world shared by many nodes (docs/SCALING.md): both set, or both empty (the state
     * file). The state file is then not used. */
    char cluster_redis[SKYD_CONFIG_STRING]; /* "redis://[USER[:PASSWORD]@]HOST:PORT[/DB]" */
    /* "" or a file (no group or other access) whose first line is the Redis password, read
     * when the node connects (shared_world.c), not here. */
    char cluster_redis_password_file[SKYD_CONFIG_STRING];
    char cluster_world[72]; /* [A-Za-z0-9_-]{1,64} */
    /* "" = off. A folder of GRIB2 forecasts (*.grib2, *.grb2) that the daemon polls every
     * forecast_poll_s (5); the newest valid one is what weather.source "forecast" follows. */
    char forecast_dir[SKYD_CONFIG_STRING];
    double forecast_poll_s;
};

void skyd_config_defaults(struct skyd_config *config);

/* The protocol limits the config sets (announced in hello and enforced per connection). */
void skyd_config_limits(const struct skyd_config *config, struct proto_msg_limits *limits);

/* Reads and validates `path` over the defaults. On failure *config keeps the defaults, errors
 * lists every bad field as a JSON Pointer, and msg says what went wrong (file, parse
 * position). */
bool skyd_config_load(const char *path, struct skyd_config *config,
                      struct proto_field_errors *errors, char *msg, size_t msglen);

/* The same for a configuration's text (`length` bytes, no terminator needed); `name` stands
 * for the file in messages. */
bool skyd_config_parse(const char *text, size_t length, const char *name,
                       struct skyd_config *config, struct proto_field_errors *errors, char *msg,
                       size_t msglen);

/* The configuration's JSON Schema (draft 2020-12), from the same rows that read it. NULL when
 * memory is out; the caller deletes it. */
struct cJSON *skyd_config_json_schema(void);

/* The encoder threads to start: render.encoder_threads, or when it is 0 one per online core but
 * one (the render thread's), from 2 to 64. */
int skyd_config_encoder_threads(const struct skyd_config *config);

#endif
