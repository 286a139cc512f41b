/* Cloud shapes against the targets, measured on skyd's renders (tests/common/cloud_metrics.h)
 * with the weather presets applied as `skyd render --weather NAME` applies them:
 * - seen from above, fair cumulus outlines have an area-perimeter fractal dimension of
 *   1.25-1.45 over at least 30 whole clouds (Lovejoy 1982: 1.35), and at coverage 0.3 they
 *   are many small cumuli, not ten blobs (three weather seeds and sun azimuths; from 14 km with
 *   a 90 deg field of view and from 40 km with 40 deg, nearer the vertical everywhere);
 * - seen from the side (from the ground toward the horizon, the field thinned so that clouds
 *   stand apart), fair cumulus have a median height / width of at least 0.35 over at least 10
 *   whole clouds;
 * - a storm cell (the storm preset's layer, one cumulonimbus footprint on a client weather
 *   map) is a tower taller than it is wide, and its rain makes a shaft under its base;
 * - a cumulus backlit by a low sun has a silver lining: its outline outshines its core;
 * - overcast and storm decks hide the sun's disk; thin cirrus dims it and leaves it visible.
 * argv[1]: where the renders and the masks measured on them are written as PNGs (boxes: green
 * the objects measured, red those cut by the image's border); argv[2]: the config directory. */
#include "test_cloud_shapes.h"

#include "field_errors.h"
#include "png_write.h"
#include "presets.h"

static const char *out_dir = ".";
static const char *config_dir = "config";
struct sky_renderer *shapes_renderer;
static float rgba[W * H * 4];
float shapes_cloudy[W * H], shapes_clear[W * H];
unsigned char shapes_mask[W * H];
struct cloud_object shapes_objects[MAX_OBJECTS];
static uint64_t next_history_key = 1;

/* The defaults with config/weather/<name>.json applied, as `skyd render --weather NAME`
 * does (server/cli/cli_args.c); clouds traced at every pixel. */
bool shapes_weather_state(const char *name, struct proto_world_state *s)
{
    proto_world_state_defaults(s);
    struct proto_field_errors errors = { 0 };
    char msg[1024] = "";
    bool ok = world_preset_apply(config_dir, "weather", name, s, &errors, msg, sizeof msg);
    CHECK_MSG(ok, "weather preset %s: %s", name, msg);
    s->clouds.resolution = PROTO_CLOUD_RESOLUTION_FULL;
    return ok;
}

/* Renders linear RGBA (cd/m2) into rgba[] and its luminance into luma[]. */
void shapes_render(const struct proto_world_state *s, float *luma)
{
    /* A one-off view, converged from scratch. */
    CHECK(test_render_world(shapes_renderer, s, W, H, SKY_RENDER_OUTPUT_LINEAR, next_history_key++,
                            false, rgba, sizeof rgba) == 0);
    CHECK(test_count_bad(rgba, (size_t)W * H) == 0);
    cloud_metrics_luma(rgba, W, H, luma);
}

static void write_png(const char *name, const uint8_t *pixels)
{
    char path[1024], err[256];
    snprintf(path, sizeof path, "%s/cloud_shapes_%s.png", out_dir, name);
    CHECK(png_write_rgba8_file(path, pixels, W, H, err, sizeof err) == 0);
}

/* The render in rgba[], exposed and tone mapped (cloud_metrics_picture). */
void shapes_save_render(const char *name)
{
    static uint8_t pixels[W * H * 4];
    cloud_metrics_picture(rgba, W, H, pixels);
    write_png(name, pixels);
}

bool shapes_measured(const struct cloud_object *o, int min_area, int min_width)
{
    return !o->touches_border && o->area >= min_area && o->x1 - o->x0 + 1 >= min_width;
}

struct measured_sizes {
    int min_area, min_width;
};

static bool measured_with(const struct cloud_object *o, const void *ctx)
{
    const struct measured_sizes *m = ctx;
    return shapes_measured(o, m->min_area, m->min_width);
}

/* The mask (white) with boxes around its objects: green the measured ones, red those cut by
 * the border; the others (specks, narrow ones) unboxed. */
void shapes_save_mask(const char *name, int count, int min_area, int min_width)
{
    static uint8_t pixels[W * H * 4];
    struct measured_sizes sizes = { min_area, min_width };
    cloud_metrics_mask_picture(shapes_mask, W, H, shapes_objects, count, measured_with, &sizes,
                               pixels);
    write_png(name, pixels);
}

/* The camera's basis as render/sky/sky_uniforms.c builds it, and tan(fov / 2). */
double shapes_camera_basis(const struct proto_world_state *s, double f[3], double r[3], double u[3])
{
    double yaw = s->camera.yaw_deg * DEG;
    sky_direction_from_angles(s->camera.yaw_deg, s->camera.pitch_deg, f);
    r[0] = cos(yaw);
    r[1] = -sin(yaw);
    r[2] = 0.0;
    u[0] = r[1] * f[2] - r[2] * f[1];
    u[1] = r[2] * f[0] - r[0] * f[2];
    u[2] = r[0] * f[1] - r[1] * f[0];
    return tan(0.5 * s->camera.fov_deg * DEG);
}

/* Pixel (x, y)'s direction in the pinhole of shaders/include/camera.glsl, unit length. */
void shapes_pixel_direction(const double f[3], const double r[3], const double u[3],
                            double tan_half, int x, int y, double d[3])
{
    double nx = 2.0 * ((x + 0.5) / W) - 1.0, ny = 1.0 - 2.0 * ((y + 0.5) / H), len = 0.0;
    for (int c = 0; c < 3; c++) {
        d[c] = f[c] + r[c] * nx * tan_half * W / H + u[c] * ny * tan_half;
        len += d[c] * d[c];
    }
    for (int c = 0; c < 3; c++)
        d[c] /= sqrt(len);
}

/* Renders the cloudy state `s`, then `s` without its low layer (its cirrus stays in both: the
 * shapes measured are the cumulus'), both over a black ground so that no shadow on it makes an
 * object; saves the cloudy render as <name>.png. */
void shapes_render_pair(struct proto_world_state *s, const char *name)
{
    for (int c = 0; c < 3; c++)
        s->atmosphere.ground_albedo[c] = 0.0;
    shapes_render(s, shapes_cloudy);
    shapes_save_render(name);
    double coverage = s->clouds.low.coverage;
    s->clouds.low.coverage = 0.0;
    shapes_render(s, shapes_clear);
    s->clouds.low.coverage = coverage;
}

/* shapes_mask: where the cloudy render differs from the clear one by more than 10 % of the
 * clear one, below the horizon as `below` says. Then its objects into shapes_objects[]: returns
 * how many, and the masked fraction of the image in *cover. */
int shapes_label(const struct proto_world_state *s, enum below_horizon below, double *cover)
{
    double f[3], r[3], u[3], d[3], tan_half = shapes_camera_basis(s, f, r, u);
    double radius = s->atmosphere.bottom_radius_km;
    double dip = -sqrt(1.0 - pow(radius / (radius + s->camera.altitude_km), 2.0));
    long on = 0;
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
            size_t i = (size_t)y * W + (size_t)x;
            double change = (double)shapes_cloudy[i] - shapes_clear[i];
            shapes_pixel_direction(f, r, u, tan_half, x, y, d);
            if (below != BELOW_BRIGHTER && d[2] < sin(2.0 * DEG))
                change = 0.0;
            else if (below == BELOW_NONE || d[2] >= dip)
                change = fabs(change);
            shapes_mask[i] = change > 0.10 * shapes_clear[i];
            on += shapes_mask[i];
        }
    *cover = (double)on / (W * H);
    int n = cloud_metrics_objects(shapes_mask, W, H, shapes_objects, MAX_OBJECTS);
    CHECK(n >= 0 && n <= MAX_OBJECTS);
    return n < 0 ? 0 : n > MAX_OBJECTS ? MAX_OBJECTS : n;
}

/* test_set_cell_map with the shapes' renderer. */
void shapes_set_cell_map(const struct proto_world_state *s, double radius, double north,
                         uint8_t type, uint8_t rain)
{
    CHECK(test_set_cell_map(shapes_renderer, s, radius, north, type, rain) == 0);
}

/* The tests, in order, with the renderer. */
static void run_tests(void)
{
    test_from_above("above_seed1", 1, 180.0, 14.0, 90.0);
    test_from_above("above_seed7", 7, 100.0, 14.0, 90.0);
    test_from_above("nadir_seed3", 3, 250.0, 40.0, 40.0);
    test_edge_on();
    test_storm_tower();
    test_storm_steps();
    test_rain_shaft();
    test_silver_lining();
    test_powder();
    test_sky_ambient();
    test_smooth_outlines();
    test_sun_through_clouds();
}

int main(int argc, char **argv)
{
    if (argc > 1)
        out_dir = argv[1];
    if (argc > 2)
        config_dir = argv[2];
    return test_run_with_renderer(&shapes_renderer, run_tests);
}
