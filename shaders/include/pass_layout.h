/* How a compute pass's interface is declared once, for the shader and for the C that makes its
 * pipeline (render/vk/compute_pass.h):
 *
 * - binding indices, specialization-constant ids and workgroup sizes are #defines that the GLSL
 *   (`layout(binding = SKY_TRANSMITTANCE_OUT)`, `layout(constant_id = ...)`,
 *   `layout(local_size_x = ...)`) and the C (descriptor writes, specialization values,
 *   dispatch sizes) both use;
 * - each pass's layout is an X-macro listing (index, kind) per binding, kind one of BLOCK (a
 *   parameter block: a storage buffer, see SKY_PARAMETER_BLOCK), SAMPLED (combined image
 *   sampler), IMAGE (storage image) and BUFFER (storage buffer); SKY_PASS_LAYOUT(layout) turns
 *   it into compute_pass_desc's binding_count and bindings. GLSL reads the X-macros' names only
 *   and never expands them.
 *
 * The layouts themselves are in sky_layouts.h (atmosphere, sky, composite) and cloud_layouts.h
 * (clouds). Validation layers (on in the tests) reject a pipeline whose shader and layout
 * disagree. */
#ifndef SKY_PASS_LAYOUT_H
#define SKY_PASS_LAYOUT_H

#if !(defined(VULKAN) || defined(GL_core_profile))
#include <vulkan/vulkan.h>

#define SKY_KIND_BLOCK VK_DESCRIPTOR_TYPE_STORAGE_BUFFER
#define SKY_KIND_SAMPLED VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER
#define SKY_KIND_IMAGE VK_DESCRIPTOR_TYPE_STORAGE_IMAGE
#define SKY_KIND_BUFFER VK_DESCRIPTOR_TYPE_STORAGE_BUFFER

#define SKY_LAYOUT_DESCRIPTOR_(index, kind) [index] = SKY_KIND_##kind,
#define SKY_LAYOUT_COUNT_(index, kind) +1
/* compute_pass_desc members for a layout X-macro: its bindings at their indices, and their
 * count (the indices run from 0 without gaps). */
#define SKY_PASS_LAYOUT(layout)                                                            \
    .binding_count = 0 layout(SKY_LAYOUT_COUNT_), .bindings = { layout(SKY_LAYOUT_DESCRIPTOR_) }
/* The number of bindings of a layout, a constant expression. */
#define SKY_LAYOUT_COUNT(layout) (0 layout(SKY_LAYOUT_COUNT_))
#endif

#endif
