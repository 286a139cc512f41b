/* test_night's moon: the disc's phase, bright limb and illuminance, a full moon's luminance,
 * the disc hidden below the horizon (test_night.h). */
#include "test_night.h"

#include "night_shared.h"

/* ---- moon ---- */

struct disc_stats {
    int pixels, lit;
    double flux;        /* sum of (L - sky) x pixel solid angle over the disc, lux */
    double centroid[3]; /* mean direction of the lit pixels */
};

/* background: the same frame without the moon (NULL: none). */
static void measure_disc(const struct proto_world_state *s, const double *background,
                         double threshold, struct disc_stats *d)
{
    struct camera c = camera_of(s);
    double moon[3];
    local_dir(s->moon.azimuth_deg, s->moon.elevation_deg, moon);
    double cos_r = cos(0.5 * s->moon.angular_diameter_deg * DEG);
    memset(d, 0, sizeof *d);
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
            double dir[3];
            pixel_dir(&c, x + 0.5, y + 0.5, dir);
            double excess = lum_at(x, y) - (background ? background[y * W + x] : 0.0);
            if (dot3(dir, moon) >= cos(0.5 * 1.04 * s->moon.angular_diameter_deg * DEG))
                d->flux += excess * pixel_solid_angle(&c, x, y); /* with the edge pixels */
            if (dot3(dir, moon) < cos_r)
                continue;
            d->pixels++;
            if (excess > threshold) {
                d->lit++;
                for (int i = 0; i < 3; i++)
                    d->centroid[i] += dir[i];
            }
        }
}

void night_test_moon_scene(struct proto_world_state *s, double sun_az, double sun_el)
{
    night_test_state(s);
    s->moon.azimuth_deg = 180;
    s->moon.elevation_deg = 12;
    s->moon.angular_diameter_deg = 0.518;
    s->sun.azimuth_deg = sun_az;
    s->sun.elevation_deg = sun_el;
    s->camera.yaw_deg = 180;
    s->camera.pitch_deg = 12;
    s->camera.fov_deg = 0.6; /* the disc is 155 pixels across */
    s->night.star_brightness = 0;
}

static double max_lum(void)
{
    double m = 0;
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++)
            m = fmax(m, lum_at(x, y));
    return m;
}

void test_moon_phases(void)
{
    static double background[W * H];
    /* Sun below the horizon at several elongations from the moon. */
    const double sun_az[] = { 200, 240, 290, 330, 0 };
    for (size_t i = 0; i < sizeof sun_az / sizeof *sun_az; i++) {
        struct proto_world_state s;
        night_test_moon_scene(&s, sun_az[i], -8);
        struct sky_render_night night;
        world_to_render_night(&s, &night);
        night.moon_illuminance_lux = 0;
        night_test_render(&s, &night);
        for (int p = 0; p < W * H; p++)
            background[p] = lum_at(p % W, p / W);
        night_test_render(&s, NULL);
        CHECK(night_test_count_bad() == 0);
        double peak = max_lum();
        struct disc_stats d;
        measure_disc(&s, background, 0.005 * (peak - background[0]), &d);
        double sun[3], moon[3];
        local_dir(s.sun.azimuth_deg, s.sun.elevation_deg, sun);
        local_dir(s.moon.azimuth_deg, s.moon.elevation_deg, moon);
        double distance = 1737.4 / sin(0.5 * s.moon.angular_diameter_deg * DEG);
        double phase = world_moon_phase_angle_deg(sun, moon, distance);
        double k = 0.5 * (1.0 + cos(phase * DEG)), lit = (double)d.lit / d.pixels;
        /* The bright limb faces the sun: the lit pixels' centroid lies toward it. */
        double off[3], toward[3], along = dot3(sun, moon);
        for (int j = 0; j < 3; j++) {
            off[j] = d.centroid[j] / (d.lit ? d.lit : 1) - moon[j];
            toward[j] = sun[j] - along * moon[j];
        }
        double cos_limb = dot3(off, toward) / (sqrt(dot3(off, off) * dot3(toward, toward)) + 1e-30);
        printf("moon phase angle %.1f deg: lit fraction of the disc %.3f, illuminated fraction "
               "%.3f, bright limb %.1f deg from the sun's direction\n",
               phase, lit, k, acos(fmin(1.0, cos_limb)) / DEG);
        CHECK_NEAR(lit, k, 0.03);
        if (phase > 5)
            CHECK(cos_limb > cos(3 * DEG));
        /* Illuminance: the disc delivers the phase law's illuminance through the atmosphere. */
        world_to_render_night(&s, &night);
        double expected = night.moon_illuminance_lux *
                          night_test_transmittance_at(&s, s.moon.elevation_deg);
        printf("    disc %.4g lux, expected %.4g lux\n", d.flux, expected);
        CHECK_NEAR(d.flux / expected, 1.0, 0.03);
    }
}

void test_full_moon_luminance(void)
{
    /* Seed 001 4.2: a 0.568 deg full moon of 0.26 lux has a mean luminance of about 3658
     * cd/m2 (E / solid angle gives 3368; the two agree to 10 %). Outside the atmosphere: a
     * camera at 200 km. */
    struct proto_world_state s;
    night_test_moon_scene(&s, 0, -12);
    s.moon.angular_diameter_deg = 0.568;
    s.camera.altitude_km = 200;
    struct sky_render_night night;
    world_to_render_night(&s, &night);
    night.moon_illuminance_lux = 0.26;
    night_test_render(&s, &night);
    double background = lum_at(2, 2), sum = 0;
    int n = 0;
    struct camera c = camera_of(&s);
    double moon[3];
    local_dir(s.moon.azimuth_deg, s.moon.elevation_deg, moon);
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
            double dir[3];
            pixel_dir(&c, x + 0.5, y + 0.5, dir);
            if (dot3(dir, moon) >= cos(0.5 * 0.568 * DEG * 0.95))
                sum += lum_at(x, y) - background, n++;
        }
    double mean = sum / (n ? n : 1);
    printf("full moon from 200 km: mean disc luminance %.0f cd/m2 (seed 001: 3658)\n", mean);
    CHECK_NEAR(mean / 3658.0, 1.0, 0.1);
    CHECK(night_test_count_bad() == 0);
}

void test_moon_hidden_below_horizon(void)
{
    struct proto_world_state s;
    night_test_moon_scene(&s, 0, -20);
    s.moon.elevation_deg = -1.0;
    s.camera.pitch_deg = -1.0;
    night_test_render(&s, NULL);
    struct disc_stats d;
    measure_disc(&s, NULL, 0.0, &d);
    double lo = 1e30, hi = 0;
    struct camera c = camera_of(&s);
    double moon[3];
    local_dir(s.moon.azimuth_deg, s.moon.elevation_deg, moon);
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
            double dir[3];
            pixel_dir(&c, x + 0.5, y + 0.5, dir);
            if (dot3(dir, moon) >= cos(0.5 * s.moon.angular_diameter_deg * DEG))
                lo = fmin(lo, lum_at(x, y)), hi = fmax(hi, lum_at(x, y));
        }
    printf("moon below the horizon: disc area luminance %.3g..%.3g cd/m2\n", lo, hi);
    CHECK(d.pixels > 100);
    CHECK_LE(hi, 1.5 * lo); /* the ground, no disc */
}
