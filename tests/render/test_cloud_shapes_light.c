/* test_cloud_shapes' light: a backlit cumulus' silver lining, the sky ambient on a deck in the
 * twilight, the sun through decks and cirrus (test_cloud_shapes.h). */
#include "test_cloud_shapes.h"

/* Mean luminance of the masked pixels on the outline (a 4-neighbour outside the mask) over
 * that of those at least 3 px inside it. */
static double rim_over_core(const float *luma)
{
    double rim = 0.0, core = 0.0;
    long rims = 0, cores = 0;
    for (int y = 3; y < H - 3; y++)
        for (int x = 3; x < W - 3; x++) {
            size_t i = (size_t)y * W + (size_t)x;
            if (!shapes_mask[i])
                continue;
            bool edge = !shapes_mask[i - 1] || !shapes_mask[i + 1] || !shapes_mask[i - W] ||
                        !shapes_mask[i + W];
            bool inner = true;
            for (int dy = -3; dy <= 3 && inner; dy++)
                for (int dx = -3; dx <= 3 && inner; dx++)
                    inner = shapes_mask[i + (size_t)(dy * W + dx)] != 0;
            if (edge) {
                rim += luma[i];
                rims++;
            } else if (inner) {
                core += luma[i];
                cores++;
            }
        }
    return rims > 0 && cores > 0 ? (rim / rims) / (core / cores) : NAN;
}

/* Silver lining: one cumulus 8 km away, seen from the ground against a sun 6 deg up just beside
 * it. With the renderer's forward-peaked phase its thin outline outshines its thick core, by
 * far more than with an isotropic phase (the same cloud, the same light otherwise). */
void test_silver_lining(void)
{
    double ratio[2];
    for (int k = 0; k < 2; k++) {
        struct proto_world_state s;
        if (!shapes_weather_state("fair_cumulus", &s))
            return;
        s.weather.map_source = PROTO_WEATHER_MAP_CLIENT;
        s.clouds.high.coverage = 0.0;
        s.camera.altitude_km = 0.2;
        s.camera.yaw_deg = 0.0;
        s.camera.pitch_deg = 12.0;
        s.camera.fov_deg = 40.0;
        s.sun.azimuth_deg = 8.0;
        s.sun.elevation_deg = 6.0;
        if (k == 1)
            s.clouds.phase_g0 = s.clouds.phase_g1 = 0.0;
        shapes_set_cell_map(&s, 1.5, 8.0, 168, 0);
        shapes_render(&s, shapes_cloudy);
        shapes_save_render(k == 0 ? "silver_lining" : "silver_lining_isotropic");
        s.weather.map_source = PROTO_WEATHER_MAP_PROCEDURAL;
        s.clouds.low.coverage = 0.0;
        shapes_render(&s, shapes_clear);
        double cover;
        shapes_label(&s, BELOW_NONE, &cover);
        ratio[k] = rim_over_core(shapes_cloudy);
        printf("silver lining (%s phase): cloud cover %.3f, outline / core luminance %.3f\n",
               k == 0 ? "the renderer's" : "an isotropic", cover, ratio[k]);
    }
    CHECK(sky_renderer_set_weather_map(shapes_renderer, NULL, 0, 0) == 0);
    CHECK_MSG(ratio[0] > 1.2, "silver lining: outline / core %.3f", ratio[0]);
    CHECK_MSG(ratio[0] > 1.5 * ratio[1], "silver lining: %.3f, isotropic %.3f", ratio[0], ratio[1]);
}

/* The overcast deck alone (no high layer, no rain), the camera 200 m over its top. */
static bool deck_state(struct proto_world_state *s)
{
    if (!shapes_weather_state("overcast", s))
        return false;
    s->clouds.high.coverage = 0.0;
    s->clouds.precipitation = 0.0;
    s->camera.altitude_km = s->clouds.low.bottom_km + s->clouds.low.thickness_km + 0.2;
    return true;
}

/* Powder: a sunlit deck seen from 200 m over its top, at a grazing 8 deg below the horizon and
 * straight down. Multiply scattered light builds up below the lit surface
 * (clouds.multiscatter.powder), so a view that grazes the surface gathers its light from the
 * shallow, darker layer and one that looks into it from deeper: the deck darkens toward its
 * horizon, as the Monte Carlo decks of test_cloud_accuracy do (grazing / head-on reflected
 * radiance 0.6-0.7 there). Returns grazing / straight down, mean luminance. */
static double deck_grazing_over_down(double powder)
{
    double mean[2];
    for (int k = 0; k < 2; k++) {
        struct proto_world_state s;
        if (!deck_state(&s))
            return NAN;
        s.clouds.multiscatter_powder = powder;
        s.camera.yaw_deg = 0.0;
        s.camera.pitch_deg = k == 0 ? -8.0 : -90.0;
        s.camera.fov_deg = 8.0;
        s.sun.azimuth_deg = 90.0;
        s.sun.elevation_deg = 70.0;
        shapes_render(&s, shapes_cloudy);
        if (powder > 0.0)
            shapes_save_render(k == 0 ? "powder_grazing" : "powder_down");
        double sum = 0.0;
        for (size_t i = 0; i < (size_t)W * H; i++)
            sum += shapes_cloudy[i];
        mean[k] = sum / ((double)W * H);
    }
    printf("sunlit deck (powder %g): grazing %.4g, straight down %.4g cd/m2 (%.3f)\n", powder,
           mean[0], mean[1], mean[0] / mean[1]);
    return mean[0] / mean[1];
}

void test_powder(void)
{
    struct proto_world_state defaults;
    proto_world_state_defaults(&defaults);
    double with = deck_grazing_over_down(defaults.clouds.multiscatter_powder);
    double without = deck_grazing_over_down(0.0);
    CHECK_MSG(defaults.clouds.multiscatter_powder > 0.0, "powder is on by default");
    /* 1.244 against 1.330 when written: the build-up is fitted to the Monte Carlo decks, which
     * leave room for no more (docs/ACCURACY.md). */
    CHECK_MSG(with < 0.96 * without, "powder: grazing / down %.3f, without the build-up %.3f", with,
              without);
}

/* Sky ambient from the sky-view LUT: an overcast deck seen from 200 m over its top in the
 * twilight (sun 4 deg down: no sunlight reaches the deck), looking down toward the glow and away
 * from it. The deck scatters the sky behind it forward, so the side toward the glow is
 * brighter; with an isotropic phase the ambient is isotropic too and both sides match. */
static double deck_toward_over_away(bool isotropic)
{
    double mean[2];
    for (int k = 0; k < 2; k++) {
        struct proto_world_state s;
        if (!deck_state(&s))
            return NAN;
        s.camera.yaw_deg = k == 0 ? 0.0 : 180.0;
        s.camera.pitch_deg = -30.0;
        s.camera.fov_deg = 30.0;
        s.sun.azimuth_deg = 0.0;
        s.sun.elevation_deg = -4.0;
        if (isotropic)
            s.clouds.phase_g0 = s.clouds.phase_g1 = 0.0;
        shapes_render(&s, shapes_cloudy);
        if (!isotropic)
            shapes_save_render(k == 0 ? "deck_twilight_toward" : "deck_twilight_away");
        double sum = 0.0;
        for (size_t i = 0; i < (size_t)W * H; i++)
            sum += shapes_cloudy[i];
        mean[k] = sum / ((double)W * H);
    }
    printf("twilight deck (%s phase): toward the glow %.4g, away %.4g cd/m2 (%.3f)\n",
           isotropic ? "an isotropic" : "the renderer's", mean[0], mean[1], mean[0] / mean[1]);
    return mean[0] / mean[1];
}

void test_sky_ambient(void)
{
    double shaped = deck_toward_over_away(false), flat = deck_toward_over_away(true);
    CHECK_MSG(shaped > 1.12 && shaped > flat + 0.08,
              "sky ambient: toward / away %.3f, "
              "isotropic %.3f",
              shaped, flat);
    CHECK_MSG(shaped < 2.0, "sky ambient: toward / away %.3f", shaped);
}

/* The brightest pixel whose centre lies within disk_deg of the sun (the pinhole of
 * shaders/include/camera.glsl, as cloud_metrics_sun_contrast measures it). */
static double sun_peak(const struct proto_world_state *s, const double sun[3], double disk_deg)
{
    double f[3], r[3], u[3], d[3], tan_half = shapes_camera_basis(s, f, r, u), peak = 0.0;
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
            shapes_pixel_direction(f, r, u, tan_half, x, y, d);
            if (d[0] * sun[0] + d[1] * sun[1] + d[2] * sun[2] >= cos(disk_deg * DEG))
                peak = fmax(peak, shapes_cloudy[(size_t)y * W + (size_t)x]);
        }
    return peak;
}

/* Looks at the sun (30 deg up) through the clouds of `s`: its contrast against the sky 3-6 deg
 * away (cloud_metrics_sun_contrast, disk 0.5 deg) and the brightest pixel of its disk. */
static double sun_view(struct proto_world_state *s, const char *name, double *peak)
{
    s->sun.elevation_deg = 30.0;
    s->camera.yaw_deg = s->sun.azimuth_deg;
    s->camera.pitch_deg = s->sun.elevation_deg;
    s->camera.fov_deg = 30.0;
    shapes_render(s, shapes_cloudy);
    shapes_save_render(name);
    double f[3], r[3], u[3], sun[3], tan_half = shapes_camera_basis(s, f, r, u);
    sky_direction_from_angles(s->sun.azimuth_deg, s->sun.elevation_deg, sun);
    const double ring[2] = { 3.0, 6.0 };
    *peak = sun_peak(s, sun, 0.5);
    return cloud_metrics_sun_contrast(shapes_cloudy, W, H, f, r, u, tan_half, sun, 0.5, ring);
}

/* Nominal optical depth of a layer along the sun's ray: extinction x density x thickness /
 * sin(elevation), at full density throughout (the noise thins it). */
static double nominal_tau(const struct proto_world_state *s,
                          const struct proto_cloud_layer_state *l)
{
    return s->clouds.extinction_per_km * l->density * l->thickness_km /
           sin(s->sun.elevation_deg * DEG);
}

/* Overcast and storm decks (optical depth along the sun's ray far above 5) show no disk: its
 * brightest pixel under twice the sky 3-6 deg away. Thin cirrus (optical depth ~1) dims the
 * disk and leaves it plainly visible (over ten times the sky around it). */
void test_sun_through_clouds(void)
{
    struct proto_world_state s;
    double clear_peak, peak;
    shapes_weather_state("clear", &s);
    s.clouds.low.coverage = s.clouds.high.coverage = 0.0;
    double clear_contrast = sun_view(&s, "sun_clear", &clear_peak);
    printf("sun, clear sky: contrast %.4g, disk peak %.4g cd/m2\n", clear_contrast, clear_peak);
    CHECK(clear_contrast > 100.0);

    static const char *decks[] = { "overcast", "storm" };
    for (int k = 0; k < 2; k++) {
        if (!shapes_weather_state(decks[k], &s))
            continue;
        s.sun.elevation_deg = 30.0;
        double tau = nominal_tau(&s, &s.clouds.low);
        char name[64];
        snprintf(name, sizeof name, "sun_%s", decks[k]);
        double contrast = sun_view(&s, name, &peak);
        printf("sun, %s (low layer's nominal optical depth along the sun's ray %.0f): "
               "contrast %.4g, disk peak %.4g cd/m2 (%.3g of the clear sky's)\n",
               decks[k], tau, contrast, peak, peak / clear_peak);
        CHECK_MSG(contrast < 2.0, "%s: sun contrast %.4g, want < 2 (no disk)", decks[k], contrast);
    }

    /* Cirrus alone, its density set for a nominal optical depth of 3 along the sun's ray: the
     * profile and the noise thin a layer to about a third of that, ~1. */
    shapes_weather_state("clear", &s);
    s.sun.elevation_deg = 30.0;
    s.clouds.low.coverage = 0.0;
    s.clouds.high.coverage = 1.0;
    s.clouds.high.density = 1.0;
    s.clouds.high.density = 3.0 / nominal_tau(&s, &s.clouds.high);
    double contrast = sun_view(&s, "sun_cirrus", &peak);
    printf("sun, thin cirrus (density %.4f, nominal optical depth 3): contrast %.4g, disk peak "
           "%.4g cd/m2 (%.3g of the clear sky's: optical depth %.2f)\n",
           s.clouds.high.density, contrast, peak, peak / clear_peak, -log(peak / clear_peak));
    CHECK_MSG(contrast > 10.0, "cirrus: sun contrast %.4g, want > 10 (a visible disk)", contrast);
    CHECK_MSG(peak < 0.9 * clear_peak, "cirrus: disk peak %.4g of the clear sky's, want < 0.9",
              peak / clear_peak);
}
