/* The world simulation without a renderer: clock and time scale, ephemeris-driven sun and
 * moon, wind advection, weather transitions, the autopilot's determinism and physics, the
 * rules of a client `set`, the weather presets and the humidity-driven haze. argv[1] is the
 * config directory. */
#include "check.h"
#include "ephemeris.h"
#include "field_errors.h"
#include "presets.h"
#include "weather_autopilot.h"
#include "weather_timeline.h"
#include "wind_drift.h"
#include "world_render.h"
#include "world_sim.h"
#include "world_state.h"

#include <cjson/cJSON.h>

#include <math.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static const char *config_dir = "config";

/* The presets of the low layer's coverage, in increasing order (storm last), then the middle
 * layer's. */
static const char *const weather_preset_names[] = {
    "clear",    "fair_cumulus", "scattered",   "broken",
    "overcast", "storm",        "altocumulus", "warm_front",
};
#define PRESET_COUNT (sizeof weather_preset_names / sizeof weather_preset_names[0])
#define LOW_PRESET_COUNT 6

static double utc(const char *iso)
{
    double t = 0;
    char err[160];
    if (!proto_time_parse_iso8601(iso, &t, err, sizeof err))
        printf("bad time %s: %s\n", iso, err);
    return t;
}

static void load_preset(const char *name, struct proto_world_state *state)
{
    char msg[512];
    struct proto_field_errors errors;
    bool ok = world_preset_apply(config_dir, "weather", name, state, &errors, msg, sizeof msg);
    if (!ok)
        printf("preset %s: %s\n", name, msg);
    CHECK(ok);
}

static void test_clock(void)
{
    struct proto_world_state s, before;
    proto_world_state_defaults(&s);
    double t0 = s.clock.utc_unix_s;
    /* Not anchored: the clock reads what it holds, whatever the wall clock says. */
    CHECK(!world_sim_anchored(&s));
    CHECK_NEAR(world_sim_clock_at(&s, 1.8e9), t0, 0);
    /* Anchored at a wall instant, it runs at time_scale from there. */
    double wall0 = 1795000000.25;
    s.clock.time_scale = 600;
    world_sim_anchor(&s, wall0);
    CHECK(world_sim_anchored(&s));
    CHECK_NEAR(s.clock.epoch.wall_unix_s, wall0, 0);
    CHECK_NEAR(s.clock.epoch.utc_unix_s, t0, 0);
    world_sim_run_to(&s, wall0 + 0.5, NULL);
    CHECK_NEAR(s.clock.utc_unix_s, t0 + 300.0, 0);
    /* Paused (time scale 0 from the wall instant of the change): it stands still. */
    before = s;
    s.clock.time_scale = 0;
    world_sim_commit(&before, &s, wall0 + 0.5, NULL);
    world_sim_run_to(&s, wall0 + 10.5, NULL);
    CHECK_NEAR(s.clock.utc_unix_s, t0 + 300.0, 0);
    CHECK_NEAR(world_sim_clock_at(&s, wall0 + 1e6), t0 + 300.0, 0);
    /* Resumed at 2x: from where it stood, not from where it would have been. */
    before = s;
    s.clock.time_scale = 2;
    world_sim_commit(&before, &s, wall0 + 20.5, NULL);
    CHECK_NEAR(s.clock.utc_unix_s, t0 + 300.0, 0);
    CHECK_NEAR(world_sim_clock_at(&s, wall0 + 30.5), t0 + 320.0, 0);
    /* A wall instant between milliseconds: the epoch keeps whole ones and the clock its pace
     * (the reading at the change moves by less than a millisecond of the scale). */
    world_sim_run_to(&s, wall0 + 40.5004, NULL);
    before = s;
    s.clock.time_scale = 1000;
    world_sim_commit(&before, &s, wall0 + 40.5004, NULL);
    CHECK_NEAR(s.clock.epoch.wall_unix_s, wall0 + 40.5, 1e-6);
    CHECK_NEAR(s.clock.utc_unix_s, t0 + 340.0008, 0.5e-3);
    /* A clock a client sets reads that value at the change. */
    before = s;
    s.clock.utc_unix_s = utc("2030-01-01T00:00:00Z");
    world_sim_commit(&before, &s, wall0 + 50.25, NULL);
    CHECK_NEAR(s.clock.utc_unix_s, utc("2030-01-01T00:00:00Z"), 0);
    CHECK_NEAR(world_sim_clock_at(&s, wall0 + 51.25), utc("2030-01-01T00:16:40Z"), 0);
    /* The clock stops at the end of its range and the state stays valid. */
    before = s;
    s.clock.utc_unix_s = utc("2100-12-31T23:00:00Z");
    world_sim_commit(&before, &s, wall0 + 60.0, NULL);
    world_sim_run_to(&s, wall0 + 86400.0, NULL);
    CHECK_NEAR(s.clock.utc_unix_s, utc("2100-12-31T23:59:59Z"), 0);
    CHECK(proto_world_state_validate(&s, NULL));
    CHECK(s.revision == 0);
    /* world_sim_advance moves the clock by simulated seconds (offline time-lapses). */
    proto_world_state_defaults(&s);
    world_sim_advance(&s, 300.0);
    CHECK_NEAR(s.clock.utc_unix_s, t0 + 300.0, 0);
    world_sim_advance(&s, -5.0);
    CHECK_NEAR(s.clock.utc_unix_s, t0 + 300.0, 0);
}

static void test_ephemeris_mode(void)
{
    struct proto_world_state s;
    proto_world_state_defaults(&s);
    /* Manual mode leaves the angles alone. */
    world_sim_advance(&s, 3600.0);
    CHECK_NEAR(s.sun.elevation_deg, 45.0, 0);
    CHECK_NEAR(s.moon.azimuth_deg, 90.0, 0);

    s.clock.sky_bodies = PROTO_BODIES_EPHEMERIS;
    s.location.latitude_deg = 48.85;
    s.location.longitude_deg = 2.35;
    s.location.altitude_m = 35;
    s.clock.utc_unix_s = utc("2026-03-20T06:00:00Z");
    world_sim_anchor_wind(&s);
    struct world_site site = { 48.85, 2.35, 35, WORLD_SITE_PRESSURE_MBAR,
                               WORLD_SITE_TEMPERATURE_C };
    double min_elevation = 90, max_elevation = -90;
    for (int hour = 0; hour < 24; hour++) {
        world_sim_advance(&s, 3600.0);
        struct world_body_position sun, moon;
        world_sun_position(s.clock.utc_unix_s, &site, true, &sun);
        world_moon_position(s.clock.utc_unix_s, &site, true, &moon, NULL, NULL);
        CHECK_NEAR(s.sun.azimuth_deg, sun.azimuth_deg, 1e-9);
        CHECK_NEAR(s.sun.elevation_deg, sun.elevation_deg, 1e-9);
        CHECK_NEAR(s.moon.azimuth_deg, moon.azimuth_deg, 1e-9);
        CHECK_NEAR(s.moon.elevation_deg, moon.elevation_deg, 1e-9);
        min_elevation = fmin(min_elevation, s.sun.elevation_deg);
        max_elevation = fmax(max_elevation, s.sun.elevation_deg);
        CHECK(proto_world_state_validate(&s, NULL));
    }
    /* Equinox in Paris: noon sun near 90 - 48.85, night below -30. */
    CHECK_NEAR(max_elevation, 41.1, 1.0);
    CHECK(min_elevation < -30);
    /* Settling a set clock moves the bodies at once. */
    s.clock.utc_unix_s = utc("2026-03-20T12:00:00Z");
    world_sim_settle(&s);
    CHECK(s.sun.elevation_deg > 38);
    CHECK(fabs(s.sun.azimuth_deg - 180.0) < 10);
}

static void test_wind(void)
{
    struct proto_world_state s, before;
    proto_world_state_defaults(&s);
    s.weather.wind.speed_m_s = 10;
    s.weather.wind.direction_deg = 270; /* a westerly blows toward the east */
    world_sim_anchor_wind(&s);
    world_sim_advance(&s, 600);
    CHECK_NEAR(s.weather.offset_east_km, 6.0, 1e-9);
    CHECK_NEAR(s.weather.offset_north_km, 0.0, 1e-9);
    before = s;
    s.weather.wind.direction_deg = 0; /* a northerly blows south: a client's change */
    s.weather.wind.speed_m_s = 5;
    world_sim_client_changed(&before, &s); /* re-anchors the wind where it is */
    CHECK_NEAR(s.weather.anchor.offset_east_km, 6.0, 1e-9);
    CHECK_NEAR(s.weather.anchor.utc_unix_s, s.clock.utc_unix_s, 0);
    world_sim_advance(&s, 3600);
    CHECK_NEAR(s.weather.offset_north_km, -18.0, 1e-9);
    CHECK_NEAR(s.weather.offset_east_km, 6.0, 1e-9);
    /* Many small steps give the same distance. */
    for (int i = 0; i < 1000; i++)
        world_sim_advance(&s, 0.036);
    CHECK_NEAR(s.weather.offset_north_km, -18.18, 1e-6);
    /* Far travel wraps inside the field's range. */
    before = s;
    s.weather.offset_east_km = 999999.0;
    s.weather.wind.direction_deg = 270;
    s.weather.wind.speed_m_s = 100;
    world_sim_client_changed(&before, &s);
    world_sim_advance(&s, 100);
    CHECK_NEAR(s.weather.offset_east_km, -999991.0, 1e-3);
    CHECK(proto_world_state_validate(&s, NULL));
    /* A change that does not touch the wind leaves its anchor. */
    before = s;
    s.camera.fov_deg = 50;
    world_sim_client_changed(&before, &s);
    CHECK(memcmp(&s.weather.anchor, &before.weather.anchor, sizeof s.weather.anchor) == 0);
}

#define PARAM_COUNT (sizeof(struct proto_weather_params) / sizeof(double))
#define PARAM_INDEX(member) (offsetof(struct proto_weather_params, member) / sizeof(double))

static void params_of(const struct proto_world_state *s, double out[PARAM_COUNT])
{
    struct proto_weather_params p;
    proto_weather_params_get(s, &p);
    memcpy(out, &p, sizeof p);
}

static void test_transition(void)
{
    struct proto_world_state s;
    proto_world_state_defaults(&s);
    load_preset("clear", &s);
    struct proto_world_state target = s;
    load_preset("storm", &target);
    struct proto_weather_params goal;
    proto_weather_params_get(&target, &goal);
    double start[PARAM_COUNT], end[PARAM_COUNT], previous[PARAM_COUNT], now[PARAM_COUNT];
    params_of(&s, start);
    memcpy(end, &goal, sizeof end);

    world_sim_start_transition(&s, &goal, 1200);
    CHECK(weather_timeline_active(&s));
    CHECK_NEAR(s.weather.transition.progress, 0, 0);
    memcpy(previous, start, sizeof previous);
    int violations = 0;
    for (int i = 0; i < 1250; i++) {
        world_sim_advance(&s, 1.0);
        params_of(&s, now);
        for (size_t k = 0; k < PARAM_COUNT; k++) {
            double step = now[k] - previous[k];
            double way = end[k] - start[k];
            if (k ==
                PARAM_INDEX(
                    wind_direction_deg)) { /* direction: along the shorter arc, 300 -> 250 goes down */
                step = fmod(step + 540.0, 360.0) - 180.0;
                way = fmod(way + 540.0, 360.0) - 180.0;
            }
            if (step * way < -1e-12 || (way == 0 && fabs(step) > 0))
                violations++;
        }
        memcpy(previous, now, sizeof previous);
        if (i == 599) { /* halfway in time is halfway in value (smoothstep(0.5) = 0.5) */
            CHECK_NEAR(s.weather.transition.progress, 0.5, 1e-9);
            CHECK_NEAR(s.clouds.low.coverage, 0.5 * (start[0] + end[0]), 1e-9);
            CHECK_NEAR(s.weather.humidity,
                       0.5 * (start[PARAM_INDEX(humidity)] + end[PARAM_INDEX(humidity)]), 1e-9);
            CHECK_NEAR(s.weather.wind.direction_deg, 275.0, 1e-9);
        }
        if (i == 1198)
            CHECK(weather_timeline_active(&s));
    }
    CHECK(violations == 0);
    CHECK(!weather_timeline_active(&s));
    CHECK_NEAR(s.weather.transition.progress, 1.0, 0);
    params_of(&s, now);
    CHECK(memcmp(now, end, sizeof now) == 0); /* exactly the preset at the end */
    CHECK(proto_world_state_validate(&s, NULL));

    /* A zero-length transition applies at once. */
    load_preset("clear", &target);
    proto_weather_params_get(&target, &goal);
    world_sim_start_transition(&s, &goal, 0);
    CHECK(!weather_timeline_active(&s));
    CHECK_NEAR(s.clouds.low.coverage, 0.0, 0);

    /* A clock set past the end finishes it exactly. */
    load_preset("overcast", &target);
    proto_weather_params_get(&target, &goal);
    world_sim_start_transition(&s, &goal, 3600);
    world_sim_advance(&s, 60);
    struct proto_world_state before = s;
    s.clock.utc_unix_s += 7200;
    world_sim_client_changed(&before, &s);
    CHECK(!weather_timeline_active(&s));
    CHECK_NEAR(s.clouds.low.coverage, 1.0, 0);
    CHECK_NEAR(s.clouds.low.bottom_km, 0.4, 0);

    /* The middle layer moves with the others: halfway to an altostratus sheet. */
    load_preset("warm_front", &target);
    proto_weather_params_get(&target, &goal);
    double mid_from = s.clouds.mid.coverage;
    world_sim_start_transition(&s, &goal, 1000);
    world_sim_advance(&s, 500);
    CHECK(weather_timeline_active(&s));
    CHECK_NEAR(s.clouds.mid.coverage, 0.5 * (mid_from + goal.mid.coverage), 1e-9);
    CHECK_NEAR(s.weather.transition.to.mid.coverage, goal.mid.coverage, 0);
    CHECK(goal.mid.coverage > mid_from + 0.5);
}

static void test_set_during_transition(void)
{
    struct proto_world_state s;
    proto_world_state_defaults(&s);
    load_preset("clear", &s);
    struct proto_world_state target = s;
    load_preset("broken", &target);
    struct proto_weather_params goal;
    proto_weather_params_get(&target, &goal);
    world_sim_start_transition(&s, &goal, 1000);
    world_sim_advance(&s, 250);
    struct proto_world_state before = s;
    s.clouds.low.density = 3.0; /* a client's set */
    world_sim_client_changed(&before, &s);
    world_sim_advance(&s, 500);
    CHECK_NEAR(s.clouds.low.density, 3.0, 0);                          /* holds */
    CHECK(s.clouds.low.coverage > 0.3 && s.clouds.low.coverage < 0.7); /* others go on */
    world_sim_advance(&s, 500);
    CHECK_NEAR(s.clouds.low.density, 3.0, 0);
    CHECK_NEAR(s.clouds.low.coverage, 0.7, 0);

    /* A parameter held at the top of its range stays exactly there all the way: the blend of
     * two equal values used to round one ulp past them (15.000000000000002 km), and the
     * state then failed validation, so that every later set was refused and a saved state
     * was thrown away at the next start. */
    load_preset("clear", &s);
    world_sim_start_transition(&s, &goal, 1000);
    world_sim_advance(&s, 10);
    before = s;
    s.clouds.low.thickness_km = 15.0;
    s.clouds.high.thickness_km = 5.0;
    world_sim_client_changed(&before, &s);
    int outside = 0, invalid = 0;
    for (int i = 0; i < 1000; i++) {
        world_sim_advance(&s, 1.0);
        outside += s.clouds.low.thickness_km != 15.0 || s.clouds.high.thickness_km != 5.0;
        invalid += !proto_world_state_validate(&s, NULL);
    }
    CHECK(outside == 0);
    CHECK(invalid == 0);
}

static void run_autopilot(int seed, double span_s, int steps, struct proto_world_state *out)
{
    proto_world_state_defaults(out);
    out->clock.utc_unix_s = utc("2026-07-01T00:00:00Z");
    out->weather.autopilot = PROTO_SWITCH_ON;
    out->weather.autopilot_seed = seed;
    out->clock.sky_bodies = PROTO_BODIES_EPHEMERIS;
    world_sim_anchor_wind(out);
    struct wind_drift *drift = wind_drift_create();
    double t0 = out->clock.utc_unix_s;
    for (int i = 1; i <= steps; i++)
        world_sim_set_time(out, t0 + span_s * i / steps, drift);
    wind_drift_destroy(&drift);
}

static void test_determinism(void)
{
    struct proto_world_state a, b, c, d;
    run_autopilot(7, 600, 600, &a);
    run_autopilot(7, 600, 600, &b);
    char *ta = proto_world_state_to_text(&a), *tb = proto_world_state_to_text(&b);
    CHECK(strcmp(ta, tb) == 0); /* same seed, same steps: identical */
    free(tb);
    run_autopilot(7, 600, 1, &c);
    /* Step sizes: the weather and the wind offsets are functions of time, bit for bit. */
    char *tc = proto_world_state_to_text(&c);
    CHECK(strcmp(ta, tc) == 0);
    free(tc);
    CHECK(c.clock.utc_unix_s == a.clock.utc_unix_s);
    CHECK(c.weather.offset_east_km == a.weather.offset_east_km);
    CHECK(c.weather.offset_north_km == a.weather.offset_north_km);
    /* A day in 1 s steps against 24 one-hour steps: the same. */
    run_autopilot(11, 86400, 86400, &c);
    run_autopilot(11, 86400, 24, &d);
    CHECK(c.weather.offset_east_km == d.weather.offset_east_km);
    CHECK(c.weather.offset_north_km == d.weather.offset_north_km);
    CHECK(c.weather.humidity == d.weather.humidity);
    CHECK(fabs(c.weather.offset_east_km) + fabs(c.weather.offset_north_km) > 50);
    /* Another seed, another weather. */
    run_autopilot(8, 600, 600, &b);
    tb = proto_world_state_to_text(&b);
    CHECK(strcmp(ta, tb) != 0);
    free(ta);
    free(tb);
}

static void test_autopilot_physics(void)
{
    double lon = 6.0;
    double t0 = utc("2026-07-01T00:00:00Z");
    /* Local solar time at 12:00 UTC, 6 E on July 1st: 12:24 mean, minus the equation of
     * time's 3.7 minutes. */
    CHECK_NEAR(weather_local_solar_hour(t0 + 12 * 3600.0, lon), 12.4 - 3.7 / 60.0, 0.02);
    int seeds_with_cycle = 0;
    double wet_min = 1, wet_max = 0;
    double cover_min = 1, cover_max = 0;
    for (int seed = 1; seed <= 8; seed++) {
        double morning = 0, afternoon = 0, evening = 0;
        for (int day = 0; day < 20; day++) {
            double midnight = t0 + day * 86400.0 - lon / 15.0 * 3600.0;
            morning += weather_autopilot_convection(seed, midnight + 8 * 3600.0, lon);
            afternoon += weather_autopilot_convection(seed, midnight + 15 * 3600.0, lon);
            evening += weather_autopilot_convection(seed, midnight + 21 * 3600.0, lon);
            for (int hour = 0; hour < 24; hour += 3) {
                double t = midnight + hour * 3600.0;
                double w = weather_autopilot_wetness(seed, t);
                wet_min = fmin(wet_min, w);
                wet_max = fmax(wet_max, w);
                struct proto_world_state s;
                proto_world_state_defaults(&s);
                struct proto_weather_params p;
                weather_autopilot_sample(seed, t, lon, &p);
                proto_weather_params_put(&s, &p);
                CHECK(proto_world_state_validate(&s, NULL)); /* inside every range */
                cover_min = fmin(cover_min, p.low.coverage);
                cover_max = fmax(cover_max, p.low.coverage);
                /* Bases at the lifting condensation level: lower in moister air. */
                CHECK_NEAR(p.low.bottom_km, fmin(fmax(2.5 * (1 - p.humidity), 0.2), 3.0), 1e-9);
            }
        }
        if (afternoon > 5 * morning + 1 && afternoon > 5 * evening + 1)
            seeds_with_cycle++;
    }
    CHECK(seeds_with_cycle == 8); /* cumulus builds in the afternoon, not morning or night */
    CHECK(wet_min < 0.1 && wet_max > 0.9); /* fronts come and go */
    CHECK(cover_min < 0.15 && cover_max > 0.9);

    /* Rain comes with the wet fronts and with the thick cumulonimbus. */
    struct proto_weather_params p;
    int raining = 0, raining_wet = 0;
    for (int h = 0; h < 24 * 60; h++) {
        double t = t0 + h * 3600.0;
        weather_autopilot_sample(3, t, lon, &p);
        if (p.precipitation > 0.3) {
            raining++;
            raining_wet += weather_autopilot_wetness(3, t) > 0.7 && p.low.coverage > 0.7;
        }
    }
    CHECK(raining > 0);
    CHECK(raining_wet == raining);
}

static void test_autopilot_blend(void)
{
    struct proto_world_state s, before;
    proto_world_state_defaults(&s);
    load_preset("clear", &s);
    before = s;
    s.weather.autopilot = PROTO_SWITCH_ON;
    world_sim_client_changed(&before, &s);
    /* No jump: it starts where the weather was and blends in. */
    CHECK(weather_timeline_active(&s));
    CHECK_NEAR(s.clouds.low.coverage, 0.0, 1e-12);
    world_sim_advance(&s, WORLD_SIM_AUTOPILOT_BLEND_S);
    CHECK(!weather_timeline_active(&s));
    struct proto_weather_params p;
    weather_autopilot_sample(s.weather.autopilot_seed, s.clock.utc_unix_s, s.location.longitude_deg,
                             &p);
    CHECK_NEAR(s.clouds.low.coverage, p.low.coverage, 0);
    CHECK_NEAR(s.weather.wind.speed_m_s, p.wind_speed_m_s, 0);
    /* Switched off: the weather stays. */
    before = s;
    s.weather.autopilot = PROTO_SWITCH_OFF;
    world_sim_client_changed(&before, &s);
    world_sim_advance(&s, 7200);
    CHECK_NEAR(s.clouds.low.coverage, p.low.coverage, 0);
}

static bool check_patch(const struct proto_world_state *live, const char *patch_text,
                        const char *expect_pointer)
{
    cJSON *json = cJSON_Parse(patch_text);
    static struct proto_world_patch patch_storage;
    struct proto_world_patch *patch = &patch_storage;
    struct proto_world_state next = *live;
    struct proto_field_errors errors;
    proto_field_errors_clear(&errors);
    bool applied = proto_world_patch_compile(json, "", patch, &errors) &&
                   proto_world_state_apply_patch(&next, patch, &errors);
    CHECK(applied);
    proto_field_errors_clear(&errors);
    bool ok = applied && world_sim_check_client_patch(live, &next, patch, &errors);
    if (expect_pointer) {
        CHECK(!ok);
        CHECK(errors.count >= 1 && strcmp(errors.items[0].pointer, expect_pointer) == 0);
        if (errors.count >= 1 && strcmp(errors.items[0].pointer, expect_pointer) != 0)
            printf("  %s: got %s: %s\n", patch_text, errors.items[0].pointer,
                   errors.items[0].reason);
    } else {
        CHECK(ok);
        if (!ok)
            printf("  %s: refused: %s\n", patch_text, errors.items[0].reason);
    }
    cJSON_Delete(json);
    return ok;
}

static void test_client_rules(void)
{
    struct proto_world_state s;
    proto_world_state_defaults(&s);
    check_patch(&s, "{\"sun\":{\"elevation_deg\":10}}", NULL);
    check_patch(&s, "{\"clock\":{\"sky_bodies\":\"ephemeris\"},\"sun\":{\"elevation_deg\":10}}",
                "/sun/elevation_deg");
    s.clock.sky_bodies = PROTO_BODIES_EPHEMERIS;
    world_sim_settle(&s);
    check_patch(&s, "{\"moon\":{\"azimuth_deg\":10}}", "/moon/azimuth_deg");
    check_patch(&s, "{\"clock\":{\"sky_bodies\":\"manual\"},\"sun\":{\"elevation_deg\":10}}", NULL);
    /* Sending back what `get` returned is fine. */
    char patch[160];
    snprintf(patch, sizeof patch, "{\"sun\":{\"elevation_deg\":%.17g}}", s.sun.elevation_deg);
    check_patch(&s, patch, NULL);
    check_patch(&s, "{\"weather\":{\"transition\":{\"duration_s\":5}}}",
                "/weather/transition/duration_s");
    check_patch(&s, "{\"weather\":{\"humidity\":0.9}}", NULL);
    check_patch(&s, "{\"weather\":{\"autopilot\":\"on\",\"humidity\":0.9}}", "/weather/humidity");
    s.weather.autopilot = PROTO_SWITCH_ON;
    check_patch(&s, "{\"clouds\":{\"low\":{\"coverage\":0.2}}}", "/clouds/low/coverage");
    check_patch(&s, "{\"weather\":{\"autopilot\":\"off\"},\"clouds\":{\"low\":{\"coverage\":0.2}}}",
                NULL);
    check_patch(&s, "{\"clouds\":{\"albedo\":0.9}}", NULL); /* not driven */
}

static void test_presets(void)
{
    char names[16][WORLD_PRESET_NAME_MAX + 1];
    int count = world_preset_list(config_dir, "weather", names, 16);
    CHECK(count == (int)PRESET_COUNT);
    double coverage[PRESET_COUNT];
    for (size_t i = 0; i < PRESET_COUNT; i++) {
        struct proto_world_state s, defaults;
        proto_world_state_defaults(&s);
        proto_world_state_defaults(&defaults);
        load_preset(weather_preset_names[i], &s);
        /* A weather preset touches the weather and nothing else. */
        CHECK(memcmp(&s.atmosphere, &defaults.atmosphere, sizeof s.atmosphere) == 0);
        CHECK(memcmp(&s.sun, &defaults.sun, sizeof s.sun) == 0);
        CHECK(memcmp(&s.camera, &defaults.camera, sizeof s.camera) == 0);
        CHECK(memcmp(&s.clock, &defaults.clock, sizeof s.clock) == 0);
        coverage[i] = s.clouds.low.coverage;
        /* Cumulus-type bases sit near the lifting condensation level of the humidity. */
        if (s.clouds.low.coverage > 0)
            CHECK_NEAR(s.clouds.low.bottom_km, 2.5 * (1 - s.weather.humidity), 0.2);
        CHECK_LE(s.clouds.low.bottom_km + s.clouds.low.thickness_km, s.clouds.high.bottom_km);
        /* A middle layer, where there is one, lies between the others. */
        if (s.clouds.mid.coverage > 0) {
            CHECK_LE(s.clouds.low.bottom_km + s.clouds.low.thickness_km, s.clouds.mid.bottom_km);
            CHECK_LE(s.clouds.mid.bottom_km + s.clouds.mid.thickness_km, s.clouds.high.bottom_km);
        }
        /* The low layer's presets carry an empty middle layer, so that one clears it. */
        if (i < LOW_PRESET_COUNT)
            CHECK(s.clouds.mid.coverage == 0);
    }
    for (size_t i = 1; i + 1 < LOW_PRESET_COUNT; i++)
        CHECK(coverage[i] > coverage[i - 1]); /* clear < fair < scattered < broken < overcast */
    struct proto_world_state s;
    proto_world_state_defaults(&s);
    load_preset("fair_cumulus", &s);
    CHECK(s.clouds.low.coverage >= 0.2 && s.clouds.low.coverage <= 0.4);
    CHECK(s.clouds.low.bottom_km >= 1.2 && s.clouds.low.bottom_km <= 1.5);
    CHECK(fabs(s.clouds.low.type - 0.67) < 0.1 && s.clouds.precipitation == 0);
    load_preset("overcast", &s);
    CHECK(s.clouds.low.coverage >= 0.95 && s.clouds.low.type <= 0.2 &&
          s.clouds.low.bottom_km <= 0.6);
    load_preset("storm", &s);
    CHECK(s.clouds.low.type >= 0.9 && s.clouds.low.thickness_km >= 6);
    CHECK(s.clouds.precipitation >= 0.5 && s.weather.wind.speed_m_s >= 15);
    load_preset("clear", &s);
    CHECK(s.clouds.low.coverage == 0 && s.clouds.precipitation == 0);
    load_preset("altocumulus", &s); /* cells, mid-level */
    CHECK(s.clouds.mid.coverage >= 0.4 && s.clouds.mid.type >= 0.8);
    CHECK(s.clouds.mid.bottom_km >= 2 && s.clouds.mid.bottom_km <= 7);
    load_preset("warm_front", &s); /* an altostratus sheet under cirrostratus */
    CHECK(s.clouds.mid.coverage >= 0.7 && s.clouds.mid.type <= 0.2);
    CHECK(s.clouds.high.coverage >= 0.5);
    load_preset("clear", &s); /* clears the middle layer */
    CHECK(s.clouds.mid.coverage == 0);
}

static void test_haze(void)
{
    struct proto_world_state s;
    proto_world_state_defaults(&s);
    struct sky_render_atmosphere dry, humid, foggy;
    world_to_render_atmosphere(&s, &dry);
    CHECK_NEAR(dry.mie_scattering[0], s.atmosphere.mie_scattering_per_km[0], 0);
    CHECK_NEAR(dry.fog_density_per_km, 0, 0);
    s.weather.humidity = 0.9;
    world_to_render_atmosphere(&s, &humid);
    /* Hanel: (0.1 / 0.5)^-0.5 = sqrt(5) more scattering; absorption as it was. */
    CHECK_NEAR(humid.mie_scattering[1] / dry.mie_scattering[1], sqrt(5.0), 1e-12);
    CHECK_NEAR(humid.mie_absorption[1], dry.mie_absorption[1], 0);
    CHECK_NEAR(humid.fog_density_per_km, 0, 0);
    s.weather.humidity = 1.0;
    world_to_render_atmosphere(&s, &foggy);
    CHECK(isfinite(foggy.mie_scattering[0]) && foggy.mie_scattering[0] > humid.mie_scattering[0]);
    CHECK_NEAR(foggy.fog_density_per_km, 3.912, 1e-12); /* 1 km visibility */
    s.weather.humidity = 0.2;
    world_to_render_atmosphere(&s, &humid);
    CHECK(humid.mie_scattering[2] < dry.mie_scattering[2]);
    CHECK_NEAR(s.atmosphere.mie_scattering_per_km[0], 3.996e-3, 0); /* stored stays dry */
    for (double rh = 0; rh < 1.0; rh += 0.01)
        CHECK(world_haze_growth_factor(rh + 0.01) >= world_haze_growth_factor(rh));
}

int main(int argc, char **argv)
{
    if (argc > 1)
        config_dir = argv[1];
    test_clock();
    test_ephemeris_mode();
    test_wind();
    test_transition();
    test_set_during_transition();
    test_determinism();
    test_autopilot_physics();
    test_autopilot_blend();
    test_client_rules();
    test_presets();
    test_haze();
    return check_summary();
}
