/* skyd probe: physical quantities as one line of JSON, through the renderer's own LUTs and
 * shading (the same code path as frames). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli_args.h"
#include "commands.h"
#include "illuminance.h"
#include "world_render.h"

#define PI 3.14159265358979323846
#define DEG (PI / 180.0)

enum probe_kind { PROBE_TRANSMITTANCE, PROBE_LUMINANCE, PROBE_ILLUMINANCE };

struct probe_args {
    enum probe_kind kind;
    double altitude_km, mu, view_zenith_deg, view_azimuth_deg, sun_zenith_deg;
    bool has_altitude, has_mu, has_view_zenith, has_view_azimuth, has_sun_zenith;
};

static void usage(FILE *out)
{
    fprintf(out,
            "usage:\n"
            "  skyd probe transmittance --altitude KM --mu COS\n"
            "      prints {\"transmittance\":[r,g,b]} to the top of the atmosphere\n"
            "  skyd probe luminance --altitude KM --view-zenith DEG --view-azimuth DEG"
            " --sun-zenith DEG\n"
            "      prints {\"luminance\":[r,g,b]} in cd/m2 before exposure; azimuth from the sun's\n"
            "  skyd probe illuminance --sun-zenith DEG\n"
            "      prints {\"sun_lux\":S,\"sky_lux\":K}, horizontal illuminance at the ground\n"
            "common options: --preset NAME, --set PATH=VALUE, --config FILE, --config-dir DIR,"
            " --device NAME,"
            " --validation\n");
}

/* Parses one probe-specific option; 1 consumed, 0 unknown, -1 error printed. */
static int parse_probe_option(int argc, char **argv, int *i, struct probe_args *a)
{
    static const struct {
        const char *name;
        double min, max;
        size_t value_offset, flag_offset;
    } options[] = {
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
    for (size_t k = 0; k < sizeof options / sizeof options[0]; k++) {
        if (strcmp(argv[*i], options[k].name) != 0)
            continue;
        const char *value = cli_take_value(argc, argv, i);
        double *target = (double *)((char *)a + options[k].value_offset);
        if (!value || !cli_parse_double(options[k].name, value, options[k].min, options[k].max,
                                        target))
            return -1;
        *(bool *)((char *)a + options[k].flag_offset) = true;
        return 1;
    }
    return 0;
}

static bool require(bool present, const char *option, const char *probe)
{
    if (!present)
        fprintf(stderr, "skyd probe %s: %s is required\n", probe, option);
    return present;
}

static bool check_required(const struct probe_args *a)
{
    switch (a->kind) {
    case PROBE_TRANSMITTANCE:
        return require(a->has_altitude, "--altitude", "transmittance") &
               require(a->has_mu, "--mu", "transmittance");
    case PROBE_LUMINANCE:
        return require(a->has_altitude, "--altitude", "luminance") &
               require(a->has_view_zenith, "--view-zenith", "luminance") &
               require(a->has_view_azimuth, "--view-azimuth", "luminance") &
               require(a->has_sun_zenith, "--sun-zenith", "luminance");
    case PROBE_ILLUMINANCE:
        return require(a->has_sun_zenith, "--sun-zenith", "illuminance");
    }
    return false;
}

static void local_direction(double zenith_deg, double azimuth_deg, double out[3])
{
    double z = zenith_deg * DEG, az = azimuth_deg * DEG;
    out[0] = sin(az) * sin(z);
    out[1] = cos(az) * sin(z);
    out[2] = cos(z);
}

static int probe_transmittance(struct sky_renderer *r, const struct cli_common *c,
                               const struct probe_args *a)
{
    struct sky_render_atmosphere atm;
    world_to_render_atmosphere(&c->state, &atm);
    double t[1][3];
    if (sky_renderer_probe_transmittance(r, &atm, &a->altitude_km, &a->mu, 1, t) != 0)
        return SKYD_EXIT_FAILURE;
    printf("{\"transmittance\":[%.9g,%.9g,%.9g]}\n", t[0][0], t[0][1], t[0][2]);
    return SKYD_EXIT_OK;
}

static void view_with_sun_zenith(const struct cli_common *c, double altitude_km,
                                 double sun_zenith_deg, struct sky_render_view *view)
{
    world_to_render_view(&c->state, 1, 1, SKY_RENDER_OUTPUT_LINEAR, view);
    view->camera_altitude_km = altitude_km;
    view->sun_elevation_deg = 90.0 - sun_zenith_deg;
}

static int probe_luminance(struct sky_renderer *r, const struct cli_common *c,
                           const struct probe_args *a)
{
    struct sky_render_atmosphere atm;
    struct sky_render_view view;
    world_to_render_atmosphere(&c->state, &atm);
    view_with_sun_zenith(c, a->altitude_km, a->sun_zenith_deg, &view);
    double dir[1][3], L[1][3];
    local_direction(a->view_zenith_deg, view.sun_azimuth_deg + a->view_azimuth_deg, dir[0]);
    if (sky_renderer_probe_luminance(r, &atm, &view, (const double (*)[3])dir, 1, true, L) != 0)
        return SKYD_EXIT_FAILURE;
    printf("{\"luminance\":[%.9g,%.9g,%.9g]}\n", L[0][0], L[0][1], L[0][2]);
    return SKYD_EXIT_OK;
}

static int probe_illuminance(struct sky_renderer *r, const struct cli_common *c,
                             const struct probe_args *a)
{
    struct sky_render_atmosphere atm;
    struct sky_render_view view;
    world_to_render_atmosphere(&c->state, &atm);
    world_to_render_view(&c->state, 1, 1, SKY_RENDER_OUTPUT_LINEAR, &view);
    double sun_lux, sky_lux;
    if (sky_ground_illuminance(r, &atm, &view, a->sun_zenith_deg, &sun_lux, &sky_lux) != 0)
        return SKYD_EXIT_FAILURE;
    printf("{\"sun_lux\":%.6g,\"sky_lux\":%.6g}\n", sun_lux, sky_lux);
    return SKYD_EXIT_OK;
}

int skyd_cmd_probe(int argc, char **argv)
{
    if (argc < 1 || strcmp(argv[0], "--help") == 0 || strcmp(argv[0], "-h") == 0) {
        usage(argc < 1 ? stderr : stdout);
        return argc < 1 ? SKYD_EXIT_USAGE : SKYD_EXIT_OK;
    }
    struct probe_args a = { 0 };
    if (strcmp(argv[0], "transmittance") == 0)
        a.kind = PROBE_TRANSMITTANCE;
    else if (strcmp(argv[0], "luminance") == 0)
        a.kind = PROBE_LUMINANCE;
    else if (strcmp(argv[0], "illuminance") == 0)
        a.kind = PROBE_ILLUMINANCE;
    else {
        fprintf(stderr, "skyd probe: unknown quantity \"%s\" (transmittance, luminance, "
                        "illuminance)\n", argv[0]);
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

    struct sky_renderer *renderer = cli_create_renderer(&common);
    if (!renderer)
        return SKYD_EXIT_FAILURE;
    int status;
    switch (a.kind) {
    case PROBE_TRANSMITTANCE: status = probe_transmittance(renderer, &common, &a); break;
    case PROBE_LUMINANCE: status = probe_luminance(renderer, &common, &a); break;
    default: status = probe_illuminance(renderer, &common, &a); break;
    }
    return cli_finish(&common, &renderer, status);
}
