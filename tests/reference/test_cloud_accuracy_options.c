/* test_cloud_accuracy's command line (test_cloud_accuracy.h; the options are described in
 * test_cloud_accuracy.c). */
#include <errno.h>
#include <stddef.h>

#include "test_cloud_accuracy.h"

/* ------------------------------------------------------------------ options */

static bool parse_list(const char *text, struct list *out)
{
    out->n = 0;
    const char *p = text;
    while (*p) {
        if (out->n == MAX_LIST)
            return false;
        char *end;
        errno = 0;
        double v = strtod(p, &end);
        if (end == p || errno || !isfinite(v))
            return false;
        out->v[out->n++] = v;
        p = end;
        if (*p == ',')
            p++;
        else if (*p)
            return false;
    }
    return out->n > 0;
}

static bool parse_number(const char *text, double lo, double hi, double *out)
{
    char *end;
    errno = 0;
    double v = strtod(text, &end);
    if (end == text || *end || errno || !(v >= lo && v <= hi))
        return false;
    *out = v;
    return true;
}

static void single(struct list *l, double v)
{
    l->v[0] = v;
    l->n = 1;
}

/* The options that take a value: a list (sweepable), a number or an integer in [lo, hi]. */
enum option_kind { OPT_LIST, OPT_NUMBER, OPT_INT, OPT_LONG };
struct option_spec {
    const char *name;
    enum option_kind kind;
    size_t offset;
    double lo, hi;
};
/* clang-format off */
#define OPT(name, kind, field, lo, hi) { name, kind, offsetof(struct options, field), lo, hi }
/* clang-format on */
static const struct option_spec option_specs[] = {
    OPT("--a", OPT_LIST, a, 0, 1),
    OPT("--b", OPT_LIST, b, 0, 1),
    OPT("--c", OPT_LIST, c, 0, 1),
    OPT("--octaves", OPT_LIST, octaves, 1, 8),
    OPT("--powder", OPT_LIST, powder, 0, 64),
    OPT("--g0", OPT_LIST, g0, -0.99, 0.99),
    OPT("--g1", OPT_LIST, g1, -0.99, 0.99),
    OPT("--w", OPT_LIST, w, 0, 1),
    OPT("--albedo", OPT_NUMBER, albedo, 1e-3, 1),
    OPT("--steps", OPT_INT, primary_steps, 4, 512),
    OPT("--light-steps", OPT_INT, light_steps, 1, 32),
    OPT("--photons", OPT_LONG, photons, 100, 1e9),
    OPT("--thickness", OPT_NUMBER, thickness_km, 0, 15),
    OPT("--radius", OPT_NUMBER, radius_km, 100, 1e5),
    OPT("--jitters", OPT_INT, jitters, 1, 64),
    OPT("--azimuths", OPT_INT, azimuths, 1, 64),
    OPT("--nodes", OPT_INT, nodes, 1, MAX_NODES),
    OPT("--floor", OPT_NUMBER, floor, 0, 1),
};

static bool parse_value(const struct option_spec *spec, const char *v, struct options *o)
{
    void *field = (char *)o + spec->offset;
    if (spec->kind == OPT_LIST) {
        struct list *l = field;
        if (!parse_list(v, l))
            return false;
        for (int i = 0; i < l->n; i++)
            if (!(l->v[i] >= spec->lo && l->v[i] <= spec->hi))
                return false;
        o->sweep |= l->n > 1;
        return true;
    }
    double x;
    if (!parse_number(v, spec->lo, spec->hi, &x))
        return false;
    if (spec->kind == OPT_NUMBER)
        *(double *)field = x;
    else if (x != floor(x))
        return false;
    else if (spec->kind == OPT_INT)
        *(int *)field = (int)x;
    else
        *(long *)field = (long)x;
    return true;
}

bool slab_parse_options(int argc, char **argv, const struct proto_world_state *state,
                        struct options *o)
{
    const struct proto_cloud_state *c = &state->clouds;
    memset(o, 0, sizeof *o);
    single(&o->a, c->multiscatter_a);
    single(&o->b, c->multiscatter_b);
    single(&o->c, c->multiscatter_c);
    single(&o->octaves, c->multiscatter_octaves);
    single(&o->powder, c->multiscatter_powder);
    single(&o->g0, c->phase_g0);
    single(&o->g1, c->phase_g1);
    single(&o->w, c->phase_w);
    o->albedo = c->albedo;
    o->primary_steps = c->primary_steps;
    o->light_steps = c->light_steps;
    o->photons = 40000;
    o->radius_km = 1000.0;
    o->jitters = 8;
    o->azimuths = 16;
    o->nodes = 3;
    o->floor = DEFAULT_FLOOR;
    for (int i = 1; i < argc; i++) {
        const char *k = argv[i];
        if (strcmp(k, "--verbose") == 0 || strcmp(k, "--single") == 0) {
            *(k[2] == 'v' ? &o->verbose : &o->single) = true;
            continue;
        }
        const struct option_spec *spec = NULL;
        for (size_t j = 0; j < sizeof option_specs / sizeof option_specs[0]; j++)
            if (strcmp(k, option_specs[j].name) == 0)
                spec = &option_specs[j];
        if (!spec) {
            fprintf(stderr, "unknown option %s\n", k);
            return false;
        }
        if (i + 1 >= argc || !parse_value(spec, argv[i + 1], o)) {
            fprintf(stderr, "%s: a %s in [%g, %g] expected\n", k,
                    spec->kind == OPT_LIST ? "comma-separated list of numbers" : "number", spec->lo,
                    spec->hi);
            return false;
        }
        i++;
    }
    for (int i = 0; i < o->octaves.n; i++)
        if (o->octaves.v[i] != floor(o->octaves.v[i])) {
            fprintf(stderr, "--octaves: whole numbers\n");
            return false;
        }
    return true;
}
