/* Deterministic worlds: nodes that hold the same state read the same world at the same wall
 * instant, bit for bit, whatever their tick patterns and start times, through a weather
 * transition, with the autopilot on and with wind; a node that joins late from the state's
 * JSON (saved at any moment) agrees; a paused clock stands still everywhere. Each "node" here
 * does what the world host does: world_sim_run_to at every tick with its own wind drift,
 * world_sim_commit for a client's change. argv[1] is the config directory. */
#include "check.h"
#include "field_errors.h"
#include "field_schema.h"
#include "presets.h"
#include "weather_timeline.h"
#include "wind_drift.h"
#include "world_sim.h"
#include "world_state.h"

#include <cjson/cJSON.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static const char *config_dir = "config";

/* A wall instant in 2026 with a fraction, where the nodes start. */
static const double W0 = 1795000000.123;

struct node {
    struct proto_world_state state;
    struct wind_drift *drift;
    double wall_s;    /* the last tick */
    unsigned step_ms; /* its tick pattern: every step_ms, or 0: irregular */
    unsigned rng;
};

static void node_start(struct node *n, const struct proto_world_state *from, double wall_s,
                       unsigned pattern)
{
    n->state = *from;
    n->drift = wind_drift_create();
    n->step_ms = pattern;
    n->rng = 12345u + pattern;
    n->wall_s = wall_s;
    if (!world_sim_anchored(&n->state))
        world_sim_anchor(&n->state, wall_s);
    world_sim_run_to(&n->state, wall_s, n->drift);
}

static void node_stop(struct node *n)
{
    wind_drift_destroy(&n->drift);
}

static void node_tick(struct node *n, double wall_s)
{
    n->wall_s = wall_s;
    world_sim_run_to(&n->state, wall_s, n->drift);
}

/* Ticks every 1 to 40 ms (pattern 0: irregular) or in fixed steps of `pattern` ms, ending on
 * wall_s exactly. */
static void node_run_until(struct node *n, double wall_s)
{
    for (;;) {
        double step;
        if (n->step_ms) {
            step = n->step_ms * 1e-3;
        } else {
            n->rng = n->rng * 1103515245u + 12345u;
            step = (1 + (n->rng >> 16) % 40) * 1e-3;
        }
        if (n->wall_s + step >= wall_s)
            break;
        node_tick(n, n->wall_s + step);
    }
    node_tick(n, wall_s);
}

/* A client's change at the node's last tick, as the world host commits it. */
static void node_commit(struct node *n, const struct proto_world_state *changed)
{
    struct proto_world_state before = n->state;
    n->state = *changed;
    world_sim_client_changed(&before, &n->state);
    world_sim_commit(&before, &n->state, n->wall_s, n->drift);
}

/* The state written to JSON and read back as state_store does. */
static void through_json(const struct proto_world_state *state, struct proto_world_state *out)
{
    char *text = proto_world_state_to_text(state);
    cJSON *root = cJSON_Parse(text);
    free(text);
    cJSON_DeleteItemFromObjectCaseSensitive(root, "revision");
    struct proto_field_errors errors;
    proto_world_state_defaults(out);
    bool ok = proto_world_state_apply_json(out, root, &errors);
    CHECK(ok);
    if (!ok) {
        char why[512];
        proto_field_errors_format(&errors, why, sizeof why);
        printf("  state JSON refused: %s\n", why);
    }
    out->revision = state->revision;
    cJSON_Delete(root);
}

/* Bit for bit: every field's JSON (numbers to 17 digits) and the doubles the text rounds. */
static bool same_world(const char *what, const struct proto_world_state *a,
                       const struct proto_world_state *b)
{
    char *ta = proto_world_state_to_text(a), *tb = proto_world_state_to_text(b);
    struct proto_weather_params pa, pb;
    proto_weather_params_get(a, &pa);
    proto_weather_params_get(b, &pb);
    bool same = strcmp(ta, tb) == 0 && a->clock.utc_unix_s == b->clock.utc_unix_s &&
                a->weather.offset_east_km == b->weather.offset_east_km &&
                a->weather.offset_north_km == b->weather.offset_north_km &&
                memcmp(&pa, &pb, sizeof pa) == 0 && a->sun.elevation_deg == b->sun.elevation_deg &&
                a->moon.azimuth_deg == b->moon.azimuth_deg &&
                a->weather.transition.progress == b->weather.transition.progress;
    if (!same)
        printf("  %s: the worlds differ: clock %.9f / %.9f, offset east %.17g / %.17g, "
               "coverage %.17g / %.17g\n",
               what, a->clock.utc_unix_s, b->clock.utc_unix_s, a->weather.offset_east_km,
               b->weather.offset_east_km, a->clouds.low.coverage, b->clouds.low.coverage);
    free(ta);
    free(tb);
    return same;
}

static void base_state(struct proto_world_state *s, const char *preset, double time_scale)
{
    proto_world_state_defaults(s);
    char msg[512];
    struct proto_field_errors errors;
    bool ok = world_preset_apply(config_dir, "weather", preset, s, &errors, msg, sizeof msg);
    if (!ok)
        printf("preset %s: %s\n", preset, msg);
    CHECK(ok);
    s->clock.time_scale = time_scale;
    s->clock.sky_bodies = PROTO_BODIES_EPHEMERIS;
    s->location.latitude_deg = 46.2;
    s->location.longitude_deg = 6.1;
    s->weather.wind.speed_m_s = 9;
    s->weather.wind.direction_deg = 250;
}

/* The autopilot switched on by a client (a 900 s blend into it), the clock at 120x: node A
 * from the start ticking irregularly, B started 4.7 s later from the committed state's JSON
 * ticking every 370 ms, C and D joining much later from A's state saved mid-blend and after
 * it, E computing each instant from the anchors alone. */
static void test_autopilot_nodes(void)
{
    struct proto_world_state s, changed, stored, mid_blend = { 0 }, after_blend = { 0 };
    base_state(&s, "fair_cumulus", 120);
    struct node a, b, c, d;
    node_start(&a, &s, W0, 0);
    node_run_until(&a, W0 + 1.0);
    changed = a.state;
    changed.weather.autopilot = PROTO_SWITCH_ON;
    changed.weather.autopilot_seed = 5;
    node_commit(&a, &changed);
    CHECK(weather_timeline_active(&a.state));
    through_json(&a.state, &stored); /* what the change wrote */
    CHECK(same_world("read back", &stored, &a.state));
    node_start(&b, &stored, W0 + 4.7, 370);
    bool started_c = false, started_d = false;
    double first_c_cells = 0;
    for (double t = W0 + 2.0; t <= W0 + 90.0 + 1e-9; t += 2.0) {
        node_run_until(&a, t);
        if (t >= W0 + 5.0)
            node_run_until(&b, t);
        if (fabs(t - (W0 + 4.0)) < 1e-9) {
            CHECK(weather_timeline_active(&a.state)); /* 900 s at 120x: 7.5 s */
            through_json(&a.state, &mid_blend);
        }
        if (fabs(t - (W0 + 34.0)) < 1e-9) {
            CHECK(!weather_timeline_active(&a.state));
            through_json(&a.state, &after_blend);
        }
        if (t >= W0 + 50.0 && !started_c) {
            node_start(&c, &mid_blend, t, 0);
            first_c_cells = (double)wind_drift_cells_summed(c.drift);
            node_start(&d, &after_blend, t, 23);
            started_c = started_d = true;
        } else if (started_c) {
            node_run_until(&c, t);
            node_run_until(&d, t);
        }
        char what[64];
        snprintf(what, sizeof what, "A and B at W0 + %.0f s", t - W0);
        if (t >= W0 + 5.0)
            CHECK(same_world(what, &a.state, &b.state));
        if (started_c) {
            snprintf(what, sizeof what, "A and C (mid-blend JSON) at W0 + %.0f s", t - W0);
            CHECK(same_world(what, &a.state, &c.state));
            snprintf(what, sizeof what, "A and D (after-blend JSON) at W0 + %.0f s", t - W0);
            CHECK(same_world(what, &a.state, &d.state));
        }
        struct proto_world_state e = stored;
        world_sim_run_to(&e, t, NULL);
        snprintf(what, sizeof what, "A and the anchors alone at W0 + %.0f s", t - W0);
        CHECK(same_world(what, &a.state, &e));
    }
    /* The autopilot moved the weather and the wind moved the map. */
    CHECK(a.state.clouds.low.coverage != s.clouds.low.coverage);
    CHECK(fabs(a.state.weather.offset_east_km) + fabs(a.state.weather.offset_north_km) > 30);
    /* C summed every cell from the anchor once; A's ticks each cross at most one. */
    CHECK(first_c_cells >= 97); /* (50 - 1) s x 120 / 60 s */
    node_tick(&a, a.wall_s + 0.01);
    CHECK(wind_drift_cells_summed(a.drift) <= 1);
    /* A wall clock that steps back reads the world of that instant. */
    node_tick(&a, W0 + 60.0);
    node_tick(&c, W0 + 60.0);
    struct proto_world_state e = stored;
    world_sim_run_to(&e, W0 + 60.0, NULL);
    CHECK(same_world("stepped back", &a.state, &e));
    CHECK(same_world("stepped back, C", &c.state, &e));
    node_stop(&a);
    node_stop(&b);
    node_stop(&c);
    node_stop(&d);
}

/* A weather preset reached through a 1200 s transition at 60x (20 s of wall time), no
 * autopilot: B ticks coarsely from the stored change; L joins after the end from a state saved
 * mid-transition, so the cell where it ends is summed from a state that still blends. */
static void test_transition_nodes(void)
{
    struct proto_world_state s, target, goal_state, stored, mid = { 0 };
    base_state(&s, "clear", 60);
    base_state(&target, "storm", 60);
    struct proto_weather_params goal;
    proto_weather_params_get(&target, &goal);
    struct node a, b, l;
    node_start(&a, &s, W0, 0);
    node_run_until(&a, W0 + 1.0);
    goal_state = a.state;
    world_sim_start_transition(&goal_state, &goal, 1200);
    struct proto_world_state before = a.state;
    a.state = goal_state;
    world_sim_commit(&before, &a.state, a.wall_s, a.drift); /* as apply_preset commits */
    CHECK(a.state.weather.anchor.utc_unix_s == a.state.weather.transition.start_unix_s);
    through_json(&a.state, &stored);
    node_start(&b, &stored, W0 + 3.3, 997);
    node_run_until(&a, W0 + 12.345);
    node_run_until(&b, W0 + 12.345);
    CHECK(same_world("mid-transition", &a.state, &b.state));
    CHECK(a.state.weather.transition.progress > 0.4 && a.state.weather.transition.progress < 0.6);
    through_json(&a.state, &mid);
    node_start(&l, &mid, W0 + 40.0, 0);
    node_run_until(&a, W0 + 40.0);
    node_run_until(&b, W0 + 40.0);
    CHECK(same_world("after the end, A and B", &a.state, &b.state));
    CHECK(same_world("after the end, A and L", &a.state, &l.state));
    struct proto_weather_params now;
    proto_weather_params_get(&l.state, &now);
    CHECK(memcmp(&now, &goal, sizeof now) == 0); /* the preset's values, exactly */
    CHECK(l.state.weather.transition.progress == 1.0);
    node_stop(&a);
    node_stop(&b);
    node_stop(&l);
}

/* Paused: every node, at any wall instant, reads the same world; a late start reads the
 * running clock's current time, not the stored one. */
static void test_pause_and_late_start(void)
{
    struct proto_world_state s, changed, stored;
    base_state(&s, "scattered", 1);
    struct node a, b;
    node_start(&a, &s, W0, 0);
    node_run_until(&a, W0 + 2.0);
    changed = a.state;
    changed.clock.time_scale = 0;
    node_commit(&a, &changed);
    double paused_at = a.state.clock.utc_unix_s;
    CHECK(a.state.clock.epoch.utc_unix_s == paused_at);
    through_json(&a.state, &stored);
    node_run_until(&a, W0 + 30.0);
    node_start(&b, &stored, W0 + 1000.0, 0);
    CHECK(a.state.clock.utc_unix_s == paused_at);
    CHECK(b.state.clock.utc_unix_s == paused_at);
    CHECK(same_world("paused", &a.state, &b.state));

    /* Running again at 1x from W0 + 30: a node starting 100 s later reads 100 s on. */
    changed = a.state;
    changed.clock.time_scale = 1;
    node_commit(&a, &changed);
    through_json(&a.state, &stored);
    node_stop(&b);
    node_start(&b, &stored, W0 + 130.0, 0);
    CHECK_NEAR(b.state.clock.utc_unix_s, paused_at + 100.0, 1e-3);
    CHECK(stored.clock.utc_unix_s < b.state.clock.utc_unix_s - 99.0);
    node_run_until(&a, W0 + 130.0);
    CHECK(same_world("running again", &a.state, &b.state));
    node_stop(&a);
    node_stop(&b);
}

/* The anchors keep what their JSON keeps: whole milliseconds, and the numbers exactly. */
static void test_anchor_text(void)
{
    struct proto_world_state s, back;
    base_state(&s, "broken", 7);
    world_sim_anchor(&s, W0 + 0.0004567);
    world_sim_run_to(&s, W0 + 3.21, NULL);
    struct proto_weather_params goal;
    proto_weather_params_get(&s, &goal);
    goal.low.coverage = 0.2;
    world_sim_start_transition(&s, &goal, 100);
    through_json(&s, &back);
    CHECK(back.clock.epoch.wall_unix_s == s.clock.epoch.wall_unix_s);
    CHECK(back.clock.epoch.utc_unix_s == s.clock.epoch.utc_unix_s);
    CHECK(memcmp(&back.weather.anchor, &s.weather.anchor, sizeof s.weather.anchor) == 0);
    CHECK(back.weather.transition.start_unix_s == s.weather.transition.start_unix_s);
    CHECK_NEAR(s.clock.epoch.wall_unix_s, 1795000000.123, 1e-6);
    /* Not anchored in JSON: epoch.wall reads 1970. */
    struct proto_world_state fresh;
    proto_world_state_defaults(&fresh);
    cJSON *json = proto_world_state_to_json(&fresh);
    const cJSON *clock = cJSON_GetObjectItemCaseSensitive(json, "clock");
    const cJSON *epoch = cJSON_GetObjectItemCaseSensitive(clock, "epoch");
    const cJSON *wall = cJSON_GetObjectItemCaseSensitive(epoch, "wall");
    CHECK(cJSON_IsString(wall) && strcmp(wall->valuestring, "1970-01-01T00:00:00Z") == 0);
    cJSON_Delete(json);
    /* A client may not set them. */
    const struct proto_field_desc *f = proto_world_state_find_field("clock.epoch.utc");
    CHECK(f && f->read_only);
    f = proto_world_state_find_field("weather.anchor.offset_east_km");
    CHECK(f && f->read_only);
}

int main(int argc, char **argv)
{
    if (argc > 1)
        config_dir = argv[1];
    test_autopilot_nodes();
    test_transition_nodes();
    test_pause_and_late_start();
    test_anchor_text();
    return check_summary();
}
