/* skyd probe: physical quantities as one line of JSON, through the renderer's own LUTs and
 * shading (the same code path as frames); the sun and moon positions from the ephemeris alone. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli_args.h"
#include "commands.h"
#include "ephemeris.h"
#include "error_text.h"
#include "renderer_host.h"
#include "world_render.h"

enum probe_kind { PROBE_TRANSMITTANCE, PROBE_LUMINANCE, PROBE_ILLUMINANCE };

struct probe_args {
    enum probe_kind kind;
    double altitude_km, mu, view_zenith_deg, view_azimuth_deg, sun_zenith_deg;
    bool has_altitude, has_mu, has_view_zenith, has_view_azimuth, has_sun_zenith;
};

static void usage(FILE *out)
{
    fprintf(
        out,
        "usage:\n"
        "  skyd probe transmittance --altitude KM --mu COS\n"
        "      prints {\"transmittance\":[r,g,b]} to the top of the atmosphere\n"
        "  skyd probe luminance --altitude KM --view-zenith DEG --view-azimuth DEG"
        " --sun-zenith DEG\n"
        "      prints {\"luminance\":[r,g,b]} in cd/m2 before exposure; azimuth from the sun's\n"
        "  skyd probe illuminance --sun-zenith DEG\n"
        "      prints {\"sun_lux\":S,\"sky_lux\":K}, horizontal illuminance at the ground\n"
        "  skyd probe sun --time ISO8601 --lat DEG --lon DEG [--altitude M] [--refraction]\n"
        "      prints {\"azimuth_deg\":A,\"elevation_deg\":E}, azimuth from north through"
        " east,\n"
        "      elevation without refraction unless --refraction (1010 mbar, 10 C); the time is"
        " UTC\n"
        "      (2026-06-21T12:00:00Z) or has an offset (2026-06-21T14:00+02:00); longitude"
        " east positive\n"
        "  skyd probe moon (the same options)\n"
        "      prints {\"azimuth_deg\":A,\"elevation_deg\":E,\"phase\":F}, F the illuminated"
        " fraction 0..1\n"
        "options of transmittance, luminance and illuminance: --preset NAME,"
        " --set PATH=VALUE,\n"
        "  --config FILE, --config-dir DIR, --device NAME, --validation\n");
}

struct body_args {
    double unix_seconds, latitude_deg, longitude_deg, altitude_m;
    bool has_time, has_latitude, has_longitude, has_altitude, refraction;
};

/* Parses one probe-specific option; 1 consumed, 0 unknown, -1 error printed. */
static int parse_probe_option(int argc, char **argv, int *i, struct probe_args *a)
{
    static const struct cli_number_option options[] = {
        { "--altitude", 0.0, 1e5, offsetof(struct probe_args, altitude_km),
          offsetof(struct probe_args, has_altitude) },
        { "--mu", -1.0, 1.0, offsetof(struct probe_args, mu), offsetof(struct probe_args, has_mu) },
        { "--view-zenith", 0.0, 180.0, offsetof(struct probe_args, view_zenith_deg),
          offsetof(struct probe_args, has_view_zenith) },
        { "--view-azimuth", -360.0, 360.0, offsetof(struct probe_args, view_azimuth_deg),
          offsetof(struct probe_args, has_view_azimuth) },
        { "--sun-zenith", 0.0, 180.0, offsetof(struct probe_args, sun_zenith_deg),
          offsetof(struct probe_args, has_sun_zenith) },
    };
    return cli_parse_number_option(argc, argv, i, options, sizeof options / sizeof options[0], a);
}

static bool require(bool present, const char *option, const char *probe)
{
    if (!present)
        fprintf(stderr, "skyd probe %s: %s is required\n", probe, option);
    return present;
}

/* Every missing option is named, not only the first: each require() runs. */
static bool check_required(const struct probe_args *a)
{
    bool ok = true;
    switch (a->kind) {
    case PROBE_TRANSMITTANCE:
        ok = require(a->has_altitude, "--altitude", "transmittance") && ok;
        ok = require(a->has_mu, "--mu", "transmittance") && ok;
        return ok;
    case PROBE_LUMINANCE:
        ok = require(a->has_altitude, "--altitude", "luminance") && ok;
        ok = require(a->has_view_zenith, "--view-zenith", "luminance") && ok;
        ok = require(a->has_view_azimuth, "--view-azimuth", "luminance") && ok;
        ok = require(a->has_sun_zenith, "--sun-zenith", "luminance") && ok;
        return ok;
    case PROBE_ILLUMINANCE:
        return require(a->has_sun_zenith, "--sun-zenith", "illuminance");
    }
    return false;
}

/* Parses one option of `skyd probe sun|moon`; 1 consumed, 0 unknown, -1 error printed. */
static int parse_body_option(int argc, char **argv, int *i, struct body_args *a)
{
    const char *option = argv[*i];
    if (strcmp(option, "--refraction") == 0) {
        a->refraction = true;
        return 1;
    }
    if (strcmp(option, "--time") == 0) {
        const char *value = cli_take_value(argc, argv, i);
        error_text err;
        if (!value)
            return -1;
        if (!proto_time_parse_iso8601(value, &a->unix_seconds, err, sizeof err)) {
            fprintf(stderr, "skyd: --time: \"%s\": %s\n", value, err);
            return -1;
        }
        a->has_time = true;
        return 1;
    }
    static const struct cli_number_option options[] = {
        { "--lat", -90.0, 90.0, offsetof(struct body_args, latitude_deg),
          offsetof(struct body_args, has_latitude) },
        { "--lon", -180.0, 180.0, offsetof(struct body_args, longitude_deg),
          offsetof(struct body_args, has_longitude) },
        { "--altitude", -1000.0, 100000.0, offsetof(struct body_args, altitude_m),
          offsetof(struct body_args, has_altitude) },
    };
    return cli_parse_number_option(argc, argv, i, options, sizeof options / sizeof options[0], a);
}

/* skyd probe sun|moon: needs no renderer. */
static int probe_body(int argc, char **argv)
{
    const char *body = argv[0];
    struct body_args a = { 0 };
    for (int i = 1; i < argc; i++) {
        int rc = parse_body_option(argc, argv, &i, &a);
        if (rc < 0)
            return SKYD_EXIT_USAGE;
        if (rc == 0) {
            fprintf(stderr, "skyd probe %s: unknown option \"%s\"\n", body, argv[i]);
            return SKYD_EXIT_USAGE;
        }
    }
    bool given = require(a.has_time, "--time", body); /* each missing option is named */
    given = require(a.has_latitude, "--lat", body) && given;
    given = require(a.has_longitude, "--lon", body) && given;
    if (!given)
        return SKYD_EXIT_USAGE;

    struct world_site site = { a.latitude_deg, a.longitude_deg, a.altitude_m,
                               WORLD_SITE_PRESSURE_MBAR, WORLD_SITE_TEMPERATURE_C };
    struct world_body_position p;
    double fraction = 0.0;
    if (strcmp(body, "moon") == 0)
        world_moon_position(a.unix_seconds, &site, a.refraction, &p, &fraction, NULL);
    else
        world_sun_position(a.unix_seconds, &site, a.refraction, &p);
    /* Keep [0, 360) after rounding to the printed 6 decimals. */
    double azimuth = p.azimuth_deg >= 359.9999995 ? 0.0 : p.azimuth_deg;
    if (strcmp(body, "moon") == 0) {
        printf("{\"azimuth_deg\":%.6f,\"elevation_deg\":%.6f,\"phase\":%.6f}\n", azimuth,
               p.elevation_deg, fraction);
    } else {
        printf("{\"azimuth_deg\":%.6f,\"elevation_deg\":%.6f}\n", azimuth, p.elevation_deg);
    }
    return SKYD_EXIT_OK;
}

/* Runs the query and prints exactly the members `skyd probe` promises. */
static int run_probe(struct renderer_host *r, const struct cli_common *c,
                     const struct probe_args *a)
{
    static const enum proto_probe_quantity quantities[] = {
        [PROBE_TRANSMITTANCE] = PROTO_PROBE_TRANSMITTANCE,
        [PROBE_LUMINANCE] = PROTO_PROBE_LUMINANCE,
        [PROBE_ILLUMINANCE] = PROTO_PROBE_ILLUMINANCE,
    };
    struct proto_msg_probe query = { .quantity = quantities[a->kind],
                                     .altitude_km = a->altitude_km,
                                     .mu = a->mu,
                                     .view_zenith_deg = a->view_zenith_deg,
                                     .view_azimuth_deg = a->view_azimuth_deg,
                                     .sun_zenith_deg = a->sun_zenith_deg };
    struct proto_msg_probe_result result;
    renderer_host_converged_probes(r); /* a script wants the best answer, not the fastest */
    struct render_input input;
    world_render_input(&c->state, &input);
    if (renderer_host_probe(r, &input, &query, &result) != 0)
        return SKYD_EXIT_FAILURE;
    if (a->kind == PROBE_ILLUMINANCE)
        printf("{\"sun_lux\":%.6g,\"sky_lux\":%.6g}\n", result.sun_lux, result.sky_lux);
    else
        printf("{\"%s\":[%.9g,%.9g,%.9g]}\n",
               a->kind == PROBE_TRANSMITTANCE ? "transmittance" : "luminance", result.rgb[0],
               result.rgb[1], result.rgb[2]);
    return SKYD_EXIT_OK;
}

int skyd_cmd_probe(int argc, char **argv)
{
    if (argc < 1 || strcmp(argv[0], "--help") == 0 || strcmp(argv[0], "-h") == 0) {
        usage(argc < 1 ? stderr : stdout);
        return argc < 1 ? SKYD_EXIT_USAGE : SKYD_EXIT_OK;
    }
    if (strcmp(argv[0], "sun") == 0 || strcmp(argv[0], "moon") == 0)
        return probe_body(argc, argv);
    struct probe_args a = { 0 };
    if (strcmp(argv[0], "transmittance") == 0)
        a.kind = PROBE_TRANSMITTANCE;
    else if (strcmp(argv[0], "luminance") == 0)
        a.kind = PROBE_LUMINANCE;
    else if (strcmp(argv[0], "illuminance") == 0)
        a.kind = PROBE_ILLUMINANCE;
    else {
        fprintf(stderr,
                "skyd probe: unknown quantity \"%s\" (transmittance, luminance, "
                "illuminance, sun, moon)\n",
                argv[0]);
        return SKYD_EXIT_USAGE;
    }
    struct cli_common common;
    cli_common_init(&common);
    for (int i = 1; i < argc; i++) {
        int rc = cli_parse_common(argc, argv, &i, &common);
        if (rc == 0)
            rc = parse_probe_option(argc, argv, &i, &a);
        if (rc < 0)
            return SKYD_EXIT_USAGE;
        if (rc == 0) {
            fprintf(stderr, "skyd probe %s: unknown option \"%s\"\n", argv[0], argv[i]);
            return SKYD_EXIT_USAGE;
        }
    }
    if (!check_required(&a))
        return SKYD_EXIT_USAGE;

    struct renderer_host *renderer = cli_create_renderer(&common);
    if (!renderer)
        return SKYD_EXIT_FAILURE;
    int status = run_probe(renderer, &common, &a);
    return cli_finish(&common, &renderer, status);
}
