#include "serve_reload.h"

#include <stdarg.h>
#include <stdio.h>
#include <string.h>

#include "error_text.h"
#include "log.h"
#include "world_state.h"

static const char *const preset_kinds[2] = { "atmosphere", "weather" };

struct text {
    char *buffer;
    size_t size, used;
};

static void add(struct text *t, const char *format, ...)
{
    if (t->used + 1 >= t->size)
        return;
    va_list args;
    va_start(args, format);
    int n = vsnprintf(t->buffer + t->used, t->size - t->used, format, args);
    va_end(args);
    if (n > 0)
        t->used += (size_t)n < t->size - t->used ? (size_t)n : t->size - t->used - 1;
}

void serve_reload_init(struct serve_reload *r)
{
    for (int k = 0; k < 2; k++) {
        int n = world_preset_list(r->config_dir, preset_kinds[k], r->presets[k],
                                  SERVE_RELOAD_MAX_PRESETS);
        r->preset_count[k] = n > 0 ? n : 0;
    }
}

static bool listed(char names[][WORLD_PRESET_NAME_MAX + 1], int count, const char *name)
{
    for (int i = 0; i < count; i++)
        if (strcmp(names[i], name) == 0)
            return true;
    return false;
}

/* Presets that appeared or went since the last look, and those that no longer apply. */
static void check_presets(struct serve_reload *r, struct text *t)
{
    for (int k = 0; k < 2; k++) {
        char now[SERVE_RELOAD_MAX_PRESETS][WORLD_PRESET_NAME_MAX + 1];
        int n = world_preset_list(r->config_dir, preset_kinds[k], now, SERVE_RELOAD_MAX_PRESETS);
        n = n > 0 ? n : 0;
        for (int i = 0; i < n; i++) {
            if (!listed(r->presets[k], r->preset_count[k], now[i]))
                add(t, "; %s preset %s added", preset_kinds[k], now[i]);
            struct proto_world_state scratch;
            proto_world_state_defaults(&scratch);
            error_text why;
            if (!world_preset_apply(r->config_dir, preset_kinds[k], now[i], &scratch, NULL, why,
                                    sizeof why))
                add(t, "; %s preset %s does not apply: %s", preset_kinds[k], now[i], why);
        }
        for (int i = 0; i < r->preset_count[k]; i++)
            if (!listed(now, n, r->presets[k][i]))
                add(t, "; %s preset %s removed", preset_kinds[k], r->presets[k][i]);
        memcpy(r->presets[k], now, sizeof now);
        r->preset_count[k] = n;
    }
}

/* The fields only a restart applies, named when the file changed them. */
static void note_restart_fields(const struct skyd_config *a, const struct skyd_config *b,
                                struct text *t)
{
    struct {
        const char *name;
        bool differs;
    } fields[] = {
        { "listen", strcmp(a->listen_address, b->listen_address) != 0 ||
                        a->listen_port != b->listen_port ||
                        strcmp(a->tls_certificate, b->tls_certificate) != 0 ||
                        strcmp(a->tls_private_key, b->tls_private_key) != 0 },
        { "web_root", strcmp(a->web_root, b->web_root) != 0 },
        { "presets_dir", strcmp(a->presets_dir, b->presets_dir) != 0 },
        { "state_file", strcmp(a->state_file, b->state_file) != 0 },
        { "state_save_delay_s", a->state_save_delay_s != b->state_save_delay_s },
        { "render", strcmp(a->render_device, b->render_device) != 0 ||
                        a->encoder_threads != b->encoder_threads ||
                        a->lut_budget_ms != b->lut_budget_ms ||
                        a->lut_budget_fraction != b->lut_budget_fraction ||
                        a->lut_blend_frames != b->lut_blend_frames ||
                        a->frame_budget_ms != b->frame_budget_ms ||
                        a->render_validation != b->render_validation },
        { "cluster",
          strcmp(a->cluster_redis, b->cluster_redis) != 0 ||
              strcmp(a->cluster_world, b->cluster_world) != 0 ||
              strcmp(a->cluster_redis_password_file, b->cluster_redis_password_file) != 0 },
    };
    bool first = true;
    for (size_t i = 0; i < sizeof fields / sizeof fields[0]; i++) {
        if (!fields[i].differs)
            continue;
        add(t, "%s%s", first ? "; not applied until a restart: " : ", ", fields[i].name);
        first = false;
    }
}

/* The token the reloaded configuration gives, as at start; a token made for this process only
 * stays, or every reload would change it. */
static bool settle_token(struct serve_reload *r, struct skyd_config *next)
{
    bool keep_unsaved = r->token_source == CONTROL_TOKEN_UNSAVED && !next->read_only &&
                        !next->controller_token[0];
    if (keep_unsaved) {
        memcpy(next->controller_token, r->running.controller_token, sizeof next->controller_token);
        return true;
    }
    char note[1536];
    enum control_token_source source = control_token_settle(next, note, sizeof note);
    if (note[0])
        skyd_log(SKYD_LOG_INFO, "%s", note);
    if (source == CONTROL_TOKEN_FAILED)
        return false;
    if (control_token_shown(source) &&
        strcmp(next->controller_token, r->running.controller_token) != 0) {
        printf("skyd: control at %s#token=%s\n", r->url, next->controller_token);
        fflush(stdout);
    }
    r->token_source = source;
    return true;
}

void serve_reload_run(struct serve_reload *r)
{
    service_notify_reloading(r->notify);
    struct skyd_config next;
    if (!r->load(r->options, &next) || !settle_token(r, &next)) {
        skyd_log(SKYD_LOG_ERROR, "reload failed: the running configuration stays");
        service_notify_ready(r->notify, "serving (the last reload failed)");
        return;
    }
    char changes[1024];
    live_settings_update(r->settings, &next, changes, sizeof changes);
    char extra[2048] = "";
    struct text t = { extra, sizeof extra, 0 };
    note_restart_fields(&r->running, &next, &t);
    check_presets(r, &t);
    skyd_log(SKYD_LOG_INFO, "reloaded the configuration: %s%s", changes, extra);
    memcpy(r->running.controller_token, next.controller_token, sizeof r->running.controller_token);
    r->running.read_only = next.read_only;
    service_notify_ready(r->notify, "serving");
}
