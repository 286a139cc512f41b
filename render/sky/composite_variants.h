/* The composite pipelines: one SPIR-V per output kind, specialized by what a dispatch needs
 * (composite.comp, the SKY_CONST_* of sky_layouts.h), so each pipeline carries only its own paths. lavapipe
 * executes both sides of every branch under a mask, so a uniform `if (no clouds) return` still
 * costs the clouds' work: leaving code out of the pipeline is the only way to skip it.
 * Pipelines are created at first use and bound to the resources last given. With warm-up, the
 * first frame of each output kind uses all of that kind's (composite_variants_claim_warm_up),
 * so their number and memory are fixed from then on, whatever combinations later views need. */
#ifndef SKYD_COMPOSITE_VARIANTS_H
#define SKYD_COMPOSITE_VARIANTS_H

#include <stdbool.h>

#include "compute_pass.h"
#include "sky_layouts.h"

struct vk_context;

enum composite_flag {
    COMPOSITE_LINEAR = 1 << 0,     /* float luminance output (else sRGB8) */
    COMPOSITE_FROM_SPACE = 1 << 1, /* the camera above the atmosphere: every pixel marched */
    COMPOSITE_SUN_REGION = 1 << 2, /* the sun and moon discs included (their rectangles only) */
    COMPOSITE_NIGHT_SKY = 1 << 3,  /* stars, moonlit sky and airglow */
    COMPOSITE_CLOUDS = 1 << 4,     /* the cloud layer, its shadows and light shafts */
    COMPOSITE_GROUND = 1 << 5,     /* some pixel of the dispatch may see the ground */
};
#define COMPOSITE_VARIANT_COUNT 64
#define COMPOSITE_BINDING_COUNT SKY_LAYOUT_COUNT(SKY_LAYOUT_COMPOSITE)

struct composite_variants;

struct composite_variants *composite_variants_create(bool warm_up);
void composite_variants_destroy(struct vk_context *ctx, struct composite_variants **cv);

/* Points every pipeline, those created later included, at `resources` (binding order of
 * composite.comp, COMPOSITE_BINDING_COUNT entries), each when it is next got. */
void composite_variants_bind(struct composite_variants *cv,
                             const struct compute_resource *resources);

/* The pipeline for `flags` (combinations that change nothing share one), created and bound
 * at first use; NULL when it cannot be created. */
const struct compute_pass *composite_variants_get(struct vk_context *ctx,
                                                  struct composite_variants *cv, unsigned flags);

/* With warm-up, true once per output kind (0 or COMPOSITE_LINEAR): the caller then dispatches
 * every one of that kind's pipelines, listed by composite_variants_of_kind, once. */
bool composite_variants_claim_warm_up(struct composite_variants *cv, unsigned kind);

/* The flag sets of the distinct pipelines of one output kind; returns their number. */
int composite_variants_of_kind(unsigned kind, unsigned flags[COMPOSITE_VARIANT_COUNT]);

#endif
