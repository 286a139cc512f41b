#include "composite_variants.h"

#include <stdlib.h>

#include "vk_check.h"
#include "vk_context.h"

#include "sky_shaders.h"
#include "sky_shared.h"

struct composite_variant {
    bool created;
    uint64_t bound_generation; /* the resources' generation its descriptors point at */
    struct compute_pass pass;
};

struct composite_variants {
    struct composite_variant variant[COMPOSITE_VARIANT_COUNT];
    struct compute_resource resources[COMPOSITE_BINDING_COUNT];
    /* Counts composite_variants_bind calls; 0: resources holds nothing to bind. A variant is
     * pointed at new resources when next used, not at every call: a frame uses a few of the
     * variants created so far, and the updates of the others were most of the daemon's
     * allocations (heaptrack, soak). 64 bits: never wraps back to a variant's stamp. */
    uint64_t generation;
    bool warmed_up[2]; /* by output kind: sRGB8, linear */
};

/* Flags that make no difference in a pipeline collapse onto one: from space every pixel is
 * marched (ground included) and the sun is drawn by the march; the night sky is always
 * compiled in there, as before the split. Without clouds the ground costs nothing extra. */
static unsigned normalized(unsigned flags)
{
    if (flags & COMPOSITE_FROM_SPACE)
        flags = (flags & ~(unsigned)COMPOSITE_SUN_REGION) | COMPOSITE_NIGHT_SKY | COMPOSITE_GROUND;
    if (!(flags & COMPOSITE_CLOUDS))
        flags |= COMPOSITE_GROUND;
    return flags & (COMPOSITE_VARIANT_COUNT - 1);
}

bool composite_variants_claim_warm_up(struct composite_variants *cv, unsigned kind)
{
    bool *warmed = &cv->warmed_up[(kind & COMPOSITE_LINEAR) != 0];
    bool claimed = !*warmed;
    *warmed = true;
    return claimed;
}

int composite_variants_of_kind(unsigned kind, unsigned flags[COMPOSITE_VARIANT_COUNT])
{
    int count = 0;
    for (unsigned f = 0; f < COMPOSITE_VARIANT_COUNT; f++)
        if ((f & COMPOSITE_LINEAR) == (kind & COMPOSITE_LINEAR) && normalized(f) == f)
            flags[count++] = f;
    return count;
}

struct composite_variants *composite_variants_create(bool warm_up)
{
    struct composite_variants *cv = calloc(1, sizeof(struct composite_variants));
    if (cv && !warm_up)
        cv->warmed_up[0] = cv->warmed_up[1] = true;
    return cv;
}

void composite_variants_destroy(struct vk_context *ctx, struct composite_variants **cvp)
{
    struct composite_variants *cv = cvp ? *cvp : NULL;
    if (!cv)
        return;
    for (int i = 0; i < COMPOSITE_VARIANT_COUNT; i++)
        if (cv->variant[i].created)
            compute_pass_destroy(ctx, &cv->variant[i].pass);
    free(cv);
    *cvp = NULL;
}

void composite_variants_bind(struct composite_variants *cv,
                             const struct compute_resource *resources)
{
    for (int i = 0; i < COMPOSITE_BINDING_COUNT; i++)
        cv->resources[i] = resources[i];
    cv->generation++;
}

static const struct compute_pass *bound_pass(struct vk_context *ctx, struct composite_variants *cv,
                                             struct composite_variant *v)
{
    if (v->bound_generation != cv->generation) {
        compute_pass_bind(ctx, &v->pass, cv->resources);
        v->bound_generation = cv->generation;
    }
    return &v->pass;
}

const struct compute_pass *composite_variants_get(struct vk_context *ctx,
                                                  struct composite_variants *cv, unsigned flags)
{
    flags = normalized(flags);
    struct composite_variant *v = &cv->variant[flags];
    if (v->created)
        return bound_pass(ctx, cv, v);
    bool linear = flags & COMPOSITE_LINEAR;
    struct compute_pass_desc desc = {
        .name = (flags & COMPOSITE_SUN_REGION) ? "sun_disk" : "composite",
        .spirv = linear ? composite_linear_spv : composite_srgb_spv,
        .spirv_bytes = linear ? sizeof composite_linear_spv : sizeof composite_srgb_spv,
        SKY_PASS_LAYOUT(SKY_LAYOUT_COMPOSITE),
        .push_constant_bytes = sizeof(struct sky_region_push),
        .spec_count = SKY_CONST_GROUND + 1,
        .spec_values = { [SKY_CONST_FROM_SPACE] = (flags & COMPOSITE_FROM_SPACE) != 0,
                         [SKY_CONST_SUN_REGION] = (flags & COMPOSITE_SUN_REGION) != 0,
                         [SKY_CONST_NIGHT_SKY] = (flags & COMPOSITE_NIGHT_SKY) != 0,
                         [SKY_CONST_CLOUDS] = (flags & COMPOSITE_CLOUDS) != 0,
                         [SKY_CONST_GROUND] = (flags & COMPOSITE_GROUND) != 0 },
    };
    VkResult result = compute_pass_create(ctx, &desc, &v->pass);
    if (result != VK_SUCCESS) {
        vk_log(ctx, VK_LOG_ERROR, "render: cannot create composite variant %#x: %s", flags,
               vk_result_name(result));
        return NULL;
    }
    v->created = true;
    return bound_pass(ctx, cv, v);
}
