/* test_cloud_shapes' storm cell: a tower taller than wide, and a rain shaft under its base
 * (test_cloud_shapes.h). */
#include "test_cloud_shapes.h"

/* The storm preset from the ground with the sun behind the camera, on a client map (by
 * shapes_set_cell_map) and without the high layer. */
static bool storm_cell_state(struct proto_world_state *s)
{
    if (!shapes_weather_state("storm", s))
        return false;
    s->weather.map_source = PROTO_WEATHER_MAP_CLIENT;
    s->clouds.high.coverage = 0.0;
    s->camera.altitude_km = 0.2;
    s->camera.yaw_deg = 0.0;
    s->camera.pitch_deg = 12.0;
    s->camera.fov_deg = 60.0;
    s->sun.azimuth_deg = 180.0;
    s->sun.elevation_deg = 30.0;
    return true;
}

/* One storm cell, alone: a single cumulonimbus footprint 6 km across, 25 km north of the camera,
 * whose repeats lie outside the view or behind the cell. Seen from the ground, lit from behind
 * the camera (cloud = brighter than the clear sky: the air its shadow darkens is not), the cell
 * is a whole object taller than it is wide: a tower, not a pancake or a dome. */
void test_storm_tower(void)
{
    struct proto_world_state s;
    if (!storm_cell_state(&s))
        return;
    shapes_set_cell_map(&s, 3.0, 25.0, 255, 230);
    for (int c = 0; c < 3; c++)
        s.atmosphere.ground_albedo[c] = 0.0;
    shapes_render(&s, shapes_cloudy);
    shapes_save_render("storm_cell");
    s.weather.map_source = PROTO_WEATHER_MAP_PROCEDURAL; /* the clear sky: no low layer */
    s.clouds.low.coverage = 0.0;
    shapes_render(&s, shapes_clear);
    double cover;
    int n = shapes_label(&s, BRIGHTER_ABOVE, &cover), largest = -1;
    shapes_save_mask("storm_cell_mask", n, 1, 8);
    for (int i = 0; i < n; i++)
        if (largest < 0 || shapes_objects[i].area > shapes_objects[largest].area)
            largest = i;
    CHECK_MSG(largest >= 0, "storm cell: no cloud in view");
    if (largest < 0)
        return;
    const struct cloud_object *o = &shapes_objects[largest];
    double width = o->x1 - o->x0 + 1, height = o->y1 - o->y0 + 1;
    printf("storm cell: cloud cover %.3f, %d objects; the largest %d px, %.0f x %.0f px "
           "(height/width %.2f)%s\n",
           cover, n, o->area, width, height, height / width,
           o->touches_border ? ", touches the border" : "");
    CHECK_MSG(!o->touches_border, "storm cell: the tower leaves the view");
    CHECK_MSG(height > width, "storm cell: %.0f px tall, %.0f px wide", height, width);
    CHECK(sky_renderer_set_weather_map(shapes_renderer, NULL, 0, 0) == 0);
}

/* Rain shafts: the same cell with its base at 1.5 km, raining and not. Between the horizon and
 * the base (0.5-2.5 deg up) the air under the cell changes by more than 10 % with its rain;
 * beside it (15 deg and more off the cell's azimuth) by under 1 %. */
void test_rain_shaft(void)
{
    struct proto_world_state s;
    if (!storm_cell_state(&s))
        return;
    s.clouds.low.bottom_km = 1.5;
    s.clouds.low.thickness_km = 8.0;
    s.camera.pitch_deg = 5.0;
    double f[3], r[3], u[3], d[3], tan_half = shapes_camera_basis(&s, f, r, u);
    shapes_set_cell_map(&s, 3.0, 25.0, 255, 230);
    shapes_render(&s, shapes_cloudy);
    shapes_save_render("rain_shaft");
    shapes_set_cell_map(&s, 3.0, 25.0, 255, 0);
    shapes_render(&s, shapes_clear);
    double under[2] = { 0 }, beside[2] = { 0 };
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
            shapes_pixel_direction(f, r, u, tan_half, x, y, d);
            double up = asin(d[2]) / DEG, off = fabs(atan2(d[0], d[1])) / DEG;
            if (up < 0.5 || up > 2.5)
                continue;
            size_t i = (size_t)y * W + (size_t)x;
            double *sum = off < 2.0 ? under : off > 15.0 ? beside : NULL;
            if (sum) {
                sum[0] += fabs((double)shapes_cloudy[i] - shapes_clear[i]);
                sum[1] += shapes_clear[i];
            }
        }
    double change_under = under[0] / fmax(under[1], 1e-9);
    double change_beside = beside[0] / fmax(beside[1], 1e-9);
    printf("rain shaft: the air under the cell changes by %.3f with its rain, beside it by %.4f\n",
           change_under, change_beside);
    CHECK_MSG(change_under > 0.10, "rain shaft: %.3f under the cell", change_under);
    CHECK_MSG(change_beside < 0.01, "rain shaft: %.4f beside the cell", change_beside);
    CHECK(sky_renderer_set_weather_map(shapes_renderer, NULL, 0, 0) == 0);
}

/* Box blur of radius r (a (2r+1)^2 mean, shrunk at the image's edges) of the rows above
 * `rows`, from luma into out. */
static void box_blur(const float *luma, int rows, int r, float *out)
{
    for (int y = 0; y < rows; y++)
        for (int x = 0; x < W; x++) {
            double sum = 0.0;
            int n = 0;
            for (int dy = -r; dy <= r; dy++)
                for (int dx = -r; dx <= r; dx++) {
                    int yy = y + dy, xx = x + dx;
                    if (yy < 0 || yy >= rows || xx < 0 || xx >= W)
                        continue;
                    sum += luma[(size_t)yy * W + (size_t)xx];
                    n++;
                }
            out[(size_t)y * W + (size_t)x] = (float)(sum / n);
        }
}

/* Storm towers (the review sheet's cumulonimbus view) at the default primary steps and at four
 * times as many. A core holds tens of optical depths per km, so a step that entered it opaque
 * put the visible surface wherever its sample fell: bands the step's length apart across every
 * tower, which move when the step does. After a 9 x 9 blur (which leaves the bands and takes
 * the grain) and with the means matched, the two renders differ by 0.078 in the mean relative
 * difference; 0.144 before the march came in again in short steps at a dense surface. */
void test_storm_steps(void)
{
    enum { ROWS = H * 55 / 100 }; /* above the horizon */
    static float blurred[2][(size_t)W * ROWS];
    for (int k = 0; k < 2; k++) {
        struct proto_world_state s;
        if (!shapes_weather_state("storm", &s))
            return;
        s.clouds.low.coverage = 0.55;
        s.sun.elevation_deg = 40.0;
        s.sun.azimuth_deg = 150.0;
        s.camera.yaw_deg = 20.0;
        s.camera.pitch_deg = 10.0;
        s.camera.fov_deg = 70.0;
        if (k == 1)
            s.clouds.primary_steps *= 4;
        shapes_render(&s, shapes_cloudy);
        shapes_save_render(k == 0 ? "storm_steps" : "storm_steps_fine");
        box_blur(shapes_cloudy, ROWS, 4, blurred[k]);
    }
    double mean[2] = { 0.0, 0.0 }, diff = 0.0;
    for (size_t i = 0; i < (size_t)W * ROWS; i++)
        for (int k = 0; k < 2; k++)
            mean[k] += blurred[k][i];
    for (size_t i = 0; i < (size_t)W * ROWS; i++)
        diff += fabs(blurred[0][i] * mean[1] / mean[0] - blurred[1][i]);
    double relative = diff / mean[1];
    printf("storm towers: default steps against four times as many, blurred: mean relative "
           "difference %.4f (means %.4g, %.4g cd/m2)\n",
           relative, mean[0] / (W * ROWS), mean[1] / (W * ROWS));
    CHECK_MSG(relative < 0.12, "storm steps: %.4f", relative);
}
