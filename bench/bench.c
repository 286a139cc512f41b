/* skyd bench: renders N frames per resolution through the daemon's render path and prints
 * per-pass GPU times (timestamp queries) and whole-frame times, medians and p99 over the
 * frames, plus the full atmosphere LUT rebuild time. Not a test: it asserts nothing. */
#include <errno.h>
#include <math.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "cli_args.h"
#include "field_errors.h"
#include "trivial_write.h"
#include "world_render.h"

#define MAX_FRAMES 1000
#define MAX_SIZES 8

static int compare_doubles(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

static double percentile(double *values, int n, double p)
{
    qsort(values, (size_t)n, sizeof *values, compare_doubles);
    int i = (int)(p * (n - 1) + 0.5);
    return values[i];
}

struct series {
    const char *names[SKY_RENDER_MAX_PASSES];
    int pass_count;
    double pass_ms[SKY_RENDER_MAX_PASSES][MAX_FRAMES];
    double gpu_ms[MAX_FRAMES], wall_ms[MAX_FRAMES], cpu_ms[MAX_FRAMES];
    enum sky_render_cloud_resolution last_cloud_resolution; /* what the last frame traced at */
    int last_cloud_steps;                                   /* with these march steps */
};

/* CPU time of the whole process (lavapipe's worker threads included): unlike wall time it
 * barely moves when other processes load the machine. */
static double process_cpu_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return (double)ts.tv_sec * 1e3 + (double)ts.tv_nsec * 1e-6;
}

static void print_series(const char *label, struct series *s, int n)
{
    printf("%-22s frame wall median %8.2f ms  p99 %8.2f ms  min %8.2f ms | gpu median %8.2f ms | "
           "process cpu median %8.2f ms\n",
           label, percentile(s->wall_ms, n, 0.5), percentile(s->wall_ms, n, 0.99),
           percentile(s->wall_ms, n, 0.0), percentile(s->gpu_ms, n, 0.5),
           percentile(s->cpu_ms, n, 0.5));
    /* The minimum too: on a machine shared with other loads it is the steadiest figure. */
    for (int p = 0; p < s->pass_count; p++)
        printf("    %-20s median %8.3f ms  p99 %8.3f ms  min %8.3f ms\n", s->names[p],
               percentile(s->pass_ms[p], n, 0.5), percentile(s->pass_ms[p], n, 0.99),
               percentile(s->pass_ms[p], n, 0.0));
}

static void record_sample(struct series *s, int i, const struct sky_render_stats *st, double cpu_ms)
{
    s->cpu_ms[i] = cpu_ms;
    s->pass_count = st->pass_count;
    for (int p = 0; p < st->pass_count; p++) {
        s->names[p] = st->pass_names[p];
        s->pass_ms[p][i] = st->pass_ms[p];
    }
    s->gpu_ms[i] = st->gpu_ms;
    s->wall_ms[i] = st->wall_ms;
    s->last_cloud_resolution = st->cloud_resolution < SKY_RENDER_CLOUDS_AUTO
                                   ? st->cloud_resolution
                                   : SKY_RENDER_CLOUDS_SIXTYFOURTH;
    s->last_cloud_steps = st->cloud_primary_steps;
}

static int bench_rebuild(struct sky_renderer *r, const struct sky_render_atmosphere *atm, int n,
                         struct series *s)
{
    for (int i = 0; i < n; i++) {
        struct sky_render_stats st;
        double cpu0 = process_cpu_ms();
        if (sky_renderer_rebuild_atmosphere(r, atm, &st) != 0)
            return -1;
        record_sample(s, i, &st, process_cpu_ms() - cpu0);
    }
    print_series("atmosphere LUT rebuild", s, n);
    return 0;
}

static enum sky_render_projection projection = SKY_RENDER_PROJECTION_PERSPECTIVE;

/* The state's atmosphere and an sRGB view of w x h, with a pixel buffer for it (NULL when
 * out of memory; the caller frees it). */
static void *frame_setup(struct sky_renderer *r, const struct cli_common *c, unsigned w, unsigned h,
                         struct sky_render_atmosphere *atm, struct sky_render_view *view,
                         size_t *bytes)
{
    struct sky_render_clouds clouds;
    world_to_render_clouds(&c->state, &clouds);
    if (sky_renderer_set_clouds(r, &clouds) != 0)
        return NULL;
    world_to_render_atmosphere(&c->state, atm);
    world_to_render_view(&c->state, w, h, SKY_RENDER_OUTPUT_SRGB8, view);
    view->projection = projection;
    *bytes = (size_t)w * h * 4;
    return malloc(*bytes);
}

static bool per_frame; /* --per-frame: every frame's times, to find outliers */
/* --stream: frames as a subscription's are (a live view, the clouds' maps and the LUTs under
 * the daemon's budget), instead of one-off views whose history starts over, 64 internal
 * frames, whenever the clouds' maps change, and maps built at once. */
static bool stream;

/* One frame: wall and GPU time, and its costliest pass. */
static void print_frame(int i, const struct sky_render_stats *st)
{
    int top = 0;
    for (int p = 1; p < st->pass_count; p++)
        if (st->pass_ms[p] > st->pass_ms[top])
            top = p;
    printf("  frame %4d: wall %8.2f ms, gpu %8.2f ms; costliest %s %.2f ms\n", i, st->wall_ms,
           st->gpu_ms, st->pass_count ? st->pass_names[top] : "-",
           st->pass_count ? st->pass_ms[top] : 0.0);
    if (getenv("SKYD_BENCH_PASSES"))
        for (int p = 0; p < st->pass_count; p++)
            printf("      %s %.2f\n", st->pass_names[p], st->pass_ms[p]);
}

static int bench_frames(struct sky_renderer *r, const struct cli_common *c, unsigned w, unsigned h,
                        int n, int warmup, struct series *s)
{
    double trivial = trivial_write_ms(c->device, w, h, 15);
    struct sky_render_atmosphere atm;
    struct sky_render_view view;
    size_t bytes;
    void *pixels = frame_setup(r, c, w, h, &atm, &view, &bytes);
    if (!pixels)
        return -1;
    view.live = stream;
    sky_renderer_set_amortization(
        r, &(struct sky_render_amortization){
               .budget_ms = stream ? 8.0 : 0.0, .budget_fraction = 0.05, .blend_frames = 4 });
    struct sky_render_night night; /* the state's moon, stars and airglow */
    world_to_render_night(&c->state, &night);
    sky_renderer_set_night(r, &night);
    for (int i = -warmup; i < n; i++) {
        struct sky_render_stats st;
        /* The sun moves a little every frame so per-view LUTs really are per frame, and the
         * wind carries the clouds (10 m/s at 30 frames/s) so their history must reproject. */
        view.sun_azimuth_deg = c->state.sun.azimuth_deg + 0.01 * i;
        if (c->state.clouds.low.coverage > 0.0 || c->state.clouds.high.coverage > 0.0) {
            struct sky_render_clouds clouds;
            world_to_render_clouds(&c->state, &clouds);
            clouds.wind_offset_east_km += 3.3e-4 * (i + warmup);
            if (sky_renderer_set_clouds(r, &clouds) != 0) {
                free(pixels);
                return -1;
            }
        }
        double cpu0 = process_cpu_ms();
        if (sky_renderer_render(r, &atm, &view, pixels, bytes, &st) != 0) {
            free(pixels);
            return -1;
        }
        if (i >= 0)
            record_sample(s, i, &st, process_cpu_ms() - cpu0);
        if (i >= 0 && per_frame)
            print_frame(i, &st);
    }
    char label[64];
    snprintf(label, sizeof label, "frame %ux%u", w, h);
    print_series(label, s, n);
    static const char *const levels[] = { "full", "quarter", "sixteenth", "sixtyfourth" };
    if (s->pass_count > 0 && c->state.clouds.resolution == PROTO_CLOUD_RESOLUTION_AUTO)
        printf("    clouds.quality.resolution auto: the last frame traced at %s with %d "
               "march steps\n",
               levels[s->last_cloud_resolution], s->last_cloud_steps);
    double wall = percentile(s->wall_ms, n, 0.5), gpu = percentile(s->gpu_ms, n, 0.5);
    printf("    trivial write %ux%u: %.2f ms; frame/trivial: wall %.2fx, gpu %.2fx\n", w, h,
           trivial, wall / trivial, gpu / trivial);
    free(pixels);
    return 0;
}

/* Frames while an atmosphere parameter is dragged (changed every frame), against steady frames,
 * with the LUT rebuild amortized under budget_ms and, for comparison, rebuilt at once. */
static int bench_drag(struct sky_renderer *r, const struct cli_common *c, unsigned w, unsigned h,
                      int n, double budget_ms, double budget_fraction, struct series *steady,
                      struct series *drag)
{
    static double lut_ms[MAX_FRAMES];
    struct sky_render_atmosphere atm;
    struct sky_render_view view;
    size_t bytes;
    void *pixels = frame_setup(r, c, w, h, &atm, &view, &bytes);
    if (!pixels)
        return -1;
    const double budgets[2] = { budget_ms, 0.0 };
    for (int b = 0; b < 2; b++) {
        sky_renderer_set_amortization(
            r, &(struct sky_render_amortization){ .budget_ms = budgets[b],
                                                  .budget_fraction = budget_fraction,
                                                  .blend_frames = 4 });
        double g0 = atm.mie_g[0];
        for (int phase = 0; phase < 2; phase++) {
            struct series *s = phase == 0 ? steady : drag;
            for (int i = -3; i < n; i++) {
                if (phase == 1) /* the drag: a new Mie g every frame */
                    for (int k = 0; k < 3; k++)
                        atm.mie_g[k] = g0 - 0.001 * (i + 4);
                struct sky_render_stats st;
                double cpu0 = process_cpu_ms();
                if (sky_renderer_render(r, &atm, &view, pixels, bytes, &st) != 0) {
                    free(pixels);
                    return -1;
                }
                if (i >= 0)
                    record_sample(s, i, &st, process_cpu_ms() - cpu0);
                if (i >= 0 && phase == 1) {
                    lut_ms[i] = 0.0;
                    for (int p = 0; p < st.pass_count; p++)
                        if (sky_render_pass_is_atmosphere_lut(st.pass_names[p]))
                            lut_ms[i] += st.pass_ms[p];
                }
            }
            for (int k = 0; k < 3; k++)
                atm.mie_g[k] = g0;
        }
        double steady_wall = percentile(steady->wall_ms, n, 0.5);
        double steady_gpu = percentile(steady->gpu_ms, n, 0.5);
        double steady_cpu = percentile(steady->cpu_ms, n, 0.5);
        printf("drag %ux%u, %s: steady median wall %.2f gpu %.2f cpu %.2f ms, steady p99 wall "
               "%.2f | drag median wall %.2f, p99 wall %.2f (%.2fx) gpu %.2f (%.2fx) cpu %.2f "
               "(%.2fx) ms\n",
               w, h, budgets[b] > 0 ? "amortized" : "one-shot", steady_wall, steady_gpu, steady_cpu,
               percentile(steady->wall_ms, n, 0.99), percentile(drag->wall_ms, n, 0.5),
               percentile(drag->wall_ms, n, 0.99), percentile(drag->wall_ms, n, 0.99) / steady_wall,
               percentile(drag->gpu_ms, n, 0.99), percentile(drag->gpu_ms, n, 0.99) / steady_gpu,
               percentile(drag->cpu_ms, n, 0.99), percentile(drag->cpu_ms, n, 0.99) / steady_cpu);
        printf("    atmosphere LUT passes per drag frame: median %.2f ms, p99 %.2f ms = %.3fx the "
               "steady median frame (gpu)%s\n",
               percentile(lut_ms, n, 0.5), percentile(lut_ms, n, 0.99),
               percentile(lut_ms, n, 0.99) / steady_gpu,
               budgets[b] > 0 ? "" : " [no budget: every frame rebuilds all]");
        if (b == 0)
            printf("    (LUT budget %.1f ms per frame, at most %.3f of the rest of the frame)\n",
                   budget_ms, budget_fraction);
    }
    free(pixels);
    return 0;
}

/* The converged multiple scattering (ms_refine.h): from an atmosphere change, frames under the
 * LUT budget until the table has faded in fully, then as many frames after. Prints the wall
 * time to each stage, the refinement's passes per frame and the frames' p99 during the
 * refinement against after it, in the same run. With fps > 0 the frames come at that rate, as
 * a stream's (the renderer idle between them); otherwise back to back. */
#define CONVERGE_GOAL_S 10.0

/* Sleeps until `seconds` after t0 (CLOCK_MONOTONIC); at once when that has passed. */
static void sleep_until(const struct timespec *t0, double seconds)
{
    struct timespec due = *t0;
    due.tv_sec += (time_t)seconds;
    due.tv_nsec += (long)((seconds - floor(seconds)) * 1e9);
    if (due.tv_nsec >= 1000000000L) {
        due.tv_sec++;
        due.tv_nsec -= 1000000000L;
    }
    while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &due, NULL) == EINTR)
        ;
}

static int bench_converge(struct sky_renderer *r, const struct cli_common *c, unsigned w,
                          unsigned h, double budget_ms, double budget_fraction, double fps,
                          struct series *during, struct series *after)
{
    static double ms_passes[MAX_FRAMES];
    const char *const kinds[4] = { "ms_density", "ms_radiance", "ms_ground", "ms_moments" };
    double kind_total[4] = { 0 };
    struct sky_render_atmosphere atm;
    struct sky_render_view view;
    size_t bytes;
    void *pixels = frame_setup(r, c, w, h, &atm, &view, &bytes);
    if (!pixels)
        return -1;
    sky_renderer_set_amortization(
        r, &(struct sky_render_amortization){
               .budget_ms = budget_ms, .budget_fraction = budget_fraction, .blend_frames = 4 });
    struct sky_render_stats st;
    for (int i = 0; i < 3; i++)
        if (sky_renderer_render(r, &atm, &view, pixels, bytes, &st) != 0)
            goto fail;
    /* A new atmosphere: the LUTs rebuild, then the table starts from order 1. */
    for (int k = 0; k < 3; k++)
        atm.ground_albedo[k] += 0.01;
    struct timespec t0;
    clock_gettime(CLOCK_MONOTONIC, &t0);
    double settled_s = -1, complete_s = -1, faded_s = -1;
    int n_during = 0, n_after = 0;
    for (int i = 0; n_after < MAX_FRAMES && (faded_s < 0 || n_after < n_during); i++) {
        if (n_during == MAX_FRAMES)
            n_during--; /* keeps the last frames' samples past the series' length */
        double cpu0 = process_cpu_ms();
        if (sky_renderer_render(r, &atm, &view, pixels, bytes, &st) != 0)
            goto fail;
        struct timespec t;
        clock_gettime(CLOCK_MONOTONIC, &t);
        double now = (double)(t.tv_sec - t0.tv_sec) + (t.tv_nsec - t0.tv_nsec) * 1e-9;
        if (settled_s < 0 && st.atmosphere_settled)
            settled_s = now;
        if (complete_s < 0 && st.multiple_scattering.progress >= 1.0 && settled_s >= 0)
            complete_s = now;
        for (int p = 0; p < st.pass_count && faded_s < 0; p++)
            for (int k = 0; k < 4; k++)
                if (strcmp(st.pass_names[p], kinds[k]) == 0)
                    kind_total[k] += st.pass_ms[p];
        if (faded_s < 0) {
            if (settled_s >= 0 && complete_s < 0 && n_during < MAX_FRAMES) {
                /* the frames that carry the refinement's slices */
                record_sample(during, n_during, &st, process_cpu_ms() - cpu0);
                ms_passes[n_during] = 0.0;
                for (int p = 0; p < st.pass_count; p++)
                    if (strncmp(st.pass_names[p], "ms_", 3) == 0)
                        ms_passes[n_during] += st.pass_ms[p];
                n_during++;
            }
            if (st.multiple_scattering.weight >= 1.0)
                faded_s = now;
        } else {
            record_sample(after, n_after++, &st, process_cpu_ms() - cpu0);
        }
        if (now > 120.0) {
            fprintf(stderr, "bench: the table did not converge in 120 s\n");
            goto fail;
        }
        if (fps > 0.0)
            sleep_until(&t0, (double)(i + 1) / fps);
    }
    char rate[32] = "back to back";
    if (fps > 0.0)
        snprintf(rate, sizeof rate, "%.0f fps", fps);
    printf("converge %ux%u, %s (LUT budget %.1f ms, at most %.3f of the rest of the frame "
           "unless idle time leaves more): LUTs settled %.2f s, table complete %.2f s, faded in "
           "%.2f s after the change; %d frames refining\n",
           w, h, rate, budget_ms, budget_fraction, settled_s, complete_s, faded_s, n_during);
    if (n_during > 0 && n_after > 0) {
        printf(
            "    refinement passes per frame: median %.2f ms, p99 %.2f ms; in all: moments %.0f, "
            "density %.0f, radiance %.0f, ground %.0f ms gpu\n",
            percentile(ms_passes, n_during, 0.5), percentile(ms_passes, n_during, 0.99),
            kind_total[3], kind_total[0], kind_total[1], kind_total[2]);
        double p99_during = percentile(during->wall_ms, n_during, 0.99);
        double p99_after = percentile(after->wall_ms, n_after, 0.99);
        printf("    frame wall while refining: median %.2f p99 %.2f ms | after: median %.2f p99 "
               "%.2f ms | p99 ratio %.2fx; gpu median %.2f / %.2f ms\n",
               percentile(during->wall_ms, n_during, 0.5), p99_during,
               percentile(after->wall_ms, n_after, 0.5), p99_after, p99_during / p99_after,
               percentile(during->gpu_ms, n_during, 0.5), percentile(after->gpu_ms, n_after, 0.5));
    }
    /* The goal for 640x360 on two lavapipe cores (docs/PERFORMANCE.md); printed, not
     * enforced: a shared machine's load moves it by seconds. */
    printf("    goal: table shown within %.0f s of the change: %s (faded in %.2f s)\n",
           CONVERGE_GOAL_S, faded_s <= CONVERGE_GOAL_S ? "met" : "NOT met", faded_s);
    free(pixels);
    return 0;
fail:
    free(pixels);
    return -1;
}

int main(int argc, char **argv)
{
    struct cli_common common;
    cli_common_init(&common);
    int frames = 30, rebuilds = 10;
    double drag_budget_ms = 0.0, drag_fraction = 0.05; /* the daemon's defaults: 8 ms, 0.05 */
    double converge_fps = 0.0, frame_budget_ms = 0.0;
    bool converge = false;
    unsigned sizes[MAX_SIZES][2];
    int size_count = 0;
    for (int i = 1; i < argc; i++) {
        int rc = cli_parse_common(argc, argv, &i, &common);
        if (rc < 0)
            return 2;
        if (rc > 0)
            continue;
        const char *v;
        unsigned u;
        if (strcmp(argv[i], "--frames") == 0 || strcmp(argv[i], "--rebuilds") == 0) {
            if (!(v = cli_take_value(argc, argv, &i)) ||
                !cli_parse_uint(argv[i - 1], v, 1, MAX_FRAMES, &u))
                return 2;
            *(argv[i - 1][2] == 'f' ? &frames : &rebuilds) = (int)u;
        } else if (strcmp(argv[i], "--drag") == 0) {
            if (!(v = cli_take_value(argc, argv, &i)) ||
                !cli_parse_double("--drag", v, 0.1, 1000, &drag_budget_ms))
                return 2;
        } else if (strcmp(argv[i], "--converge") == 0) {
            converge = true;
        } else if (strcmp(argv[i], "--per-frame") == 0) {
            per_frame = true;
        } else if (strcmp(argv[i], "--stream") == 0) {
            stream = true;
        } else if (strcmp(argv[i], "--frame-budget") == 0) {
            if (!(v = cli_take_value(argc, argv, &i)) ||
                !cli_parse_double("--frame-budget", v, 0.0, 1000, &frame_budget_ms))
                return 2;
        } else if (strcmp(argv[i], "--fps") == 0) {
            if (!(v = cli_take_value(argc, argv, &i)) ||
                !cli_parse_double("--fps", v, 0.1, 1000, &converge_fps))
                return 2;
        } else if (strcmp(argv[i], "--drag-fraction") == 0) {
            if (!(v = cli_take_value(argc, argv, &i)) ||
                !cli_parse_double("--drag-fraction", v, 0.0, 1.0, &drag_fraction))
                return 2;
        } else if (strcmp(argv[i], "--projection") == 0) {
            if (!(v = cli_take_value(argc, argv, &i)) ||
                (strcmp(v, "perspective") != 0 && strcmp(v, "equirectangular") != 0)) {
                fprintf(stderr, "bench: --projection expects perspective or equirectangular\n");
                return 2;
            }
            projection = v[0] == 'e' ? SKY_RENDER_PROJECTION_EQUIRECTANGULAR
                                     : SKY_RENDER_PROJECTION_PERSPECTIVE;
        } else if (strcmp(argv[i], "--clouds") == 0) {
            /* A fair-weather cumulus sky with a thin high layer: the cloud benchmark scene. */
            static const char *const sets[] = { "clouds.low.coverage=0.45",
                                                "clouds.high.coverage=0.3" };
            for (size_t k = 0; k < sizeof sets / sizeof sets[0]; k++) {
                char path[64];
                const char *eq = strchr(sets[k], '=');
                snprintf(path, sizeof path, "%.*s", (int)(eq - sets[k]), sets[k]);
                struct proto_field_errors errors;
                if (!proto_world_state_set_path(&common.state, path, eq + 1, &errors))
                    return 2;
            }
        } else if (strcmp(argv[i], "--size") == 0) {
            unsigned w, h;
            if (!(v = cli_take_value(argc, argv, &i)) || sscanf(v, "%ux%u", &w, &h) != 2 ||
                w == 0 || h == 0 || w > 8192 || h > 8192 || size_count == MAX_SIZES) {
                fprintf(stderr, "bench: --size expects WxH\n");
                return 2;
            }
            sizes[size_count][0] = w;
            sizes[size_count][1] = h;
            size_count++;
        } else {
            fprintf(stderr, "usage: skyd_bench [--frames N] [--rebuilds N] [--size WxH]... "
                            "[--drag BUDGET_MS] [--drag-fraction F] [--converge [--fps N]] "
                            "[--clouds] [--frame-budget MS] [--per-frame] [--stream] "
                            "[--projection NAME] "
                            "[--preset NAME] "
                            "[--set PATH=VALUE] [--device NAME]\n");
            return 2;
        }
    }
    if (size_count == 0) {
        sizes[0][0] = 640, sizes[0][1] = 360;
        sizes[1][0] = 1280, sizes[1][1] = 720;
        size_count = 2;
    }
    /* The renderer itself (not the renderer host): the bench times its passes. */
    struct sky_renderer_params params = { .device_preference = common.device,
                                          .validation = common.validation };
    world_to_lut_sizes(&common.state, &params.lut_sizes);
    struct sky_renderer *r = sky_renderer_create(&params);
    if (!r) {
        fprintf(stderr, "skyd_bench: cannot start the Vulkan renderer\n");
        return 1;
    }
    sky_renderer_set_frame_budget(r, frame_budget_ms); /* clouds.quality.resolution auto */
    printf("device: %s; projection %s\n", sky_renderer_device_name(r),
           projection == SKY_RENDER_PROJECTION_EQUIRECTANGULAR ? "equirectangular" : "perspective");
    struct series *s = calloc(1, sizeof *s);
    struct sky_render_atmosphere atm;
    world_to_render_atmosphere(&common.state, &atm);
    int status = s ? 0 : 1;
    if (status == 0)
        status = bench_rebuild(r, &atm, rebuilds, s) == 0 ? 0 : 1;
    if (status == 0) {
        double trivial = trivial_write_ms(common.device, 1280, 720, 15);
        double rebuild = percentile(s->wall_ms, rebuilds, 0.5);
        printf("    trivial write 1280x720: %.2f ms; rebuild/trivial: %.2fx\n", trivial,
               rebuild / trivial);
    }
    for (int k = 0; k < size_count && status == 0; k++)
        status = bench_frames(r, &common, sizes[k][0], sizes[k][1], frames, 3, s) == 0 ? 0 : 1;
    struct series *drag = drag_budget_ms > 0 ? calloc(1, sizeof *drag) : NULL;
    for (int k = 0; k < size_count && status == 0 && drag; k++)
        status = bench_drag(r, &common, sizes[k][0], sizes[k][1], frames, drag_budget_ms,
                            drag_fraction, s, drag) == 0
                     ? 0
                     : 1;
    /* --converge: the table's convergence under the drag's budget (the daemon's 8 ms when not
     * given), at --fps or back to back. */
    struct series *after = converge ? calloc(1, sizeof *after) : NULL;
    struct series *during = converge ? calloc(1, sizeof *during) : NULL;
    if (converge && (!after || !during))
        status = 1;
    for (int k = 0; k < size_count && status == 0 && converge; k++)
        status = bench_converge(r, &common, sizes[k][0], sizes[k][1],
                                drag_budget_ms > 0 ? drag_budget_ms : 8.0, drag_fraction,
                                converge_fps, during, after) == 0
                     ? 0
                     : 1;
    free(after);
    free(during);
    free(drag);
    free(s);
    sky_renderer_destroy(&r);
    return status;
}
