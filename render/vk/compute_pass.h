/* A compute pipeline with its own descriptor set: made from embedded SPIR-V and a list of
 * binding types, bound to resources once (and again when they change), then recorded with
 * push constants and a dispatch rounded up to cover the whole domain. */
#ifndef SKYD_COMPUTE_PASS_H
#define SKYD_COMPUTE_PASS_H

#include <stddef.h>
#include <stdint.h>
#include <vulkan/vulkan.h>

struct vk_context;
struct gpu_image;
struct gpu_buffer;

#define COMPUTE_PASS_MAX_BINDINGS 20
#define COMPUTE_PASS_MAX_SPEC 8

struct compute_pass_desc {
    const char *name;
    const uint32_t *spirv;
    size_t spirv_bytes;
    uint32_t binding_count;
    VkDescriptorType bindings[COMPUTE_PASS_MAX_BINDINGS];
    uint32_t push_constant_bytes;
    /* Specialization constants: constant_id i takes spec_values[i] (booleans as 0/1). */
    uint32_t spec_count;
    uint32_t spec_values[COMPUTE_PASS_MAX_SPEC];
};

struct compute_pass {
    const char *name;
    VkDescriptorSetLayout set_layout;
    VkPipelineLayout layout;
    VkPipeline pipeline;
    VkDescriptorPool pool;
    VkDescriptorSet set;
    uint32_t binding_count;
    VkDescriptorType bindings[COMPUTE_PASS_MAX_BINDINGS];
    uint32_t push_constant_bytes;
};

/* One resource per binding, in binding order: an image (storage, or sampled with `sampler`)
 * or a buffer (uniform or storage). */
struct compute_resource {
    const struct gpu_image *image;
    VkSampler sampler;
    const struct gpu_buffer *buffer;
};

VkResult compute_pass_create(struct vk_context *ctx, const struct compute_pass_desc *desc,
                             struct compute_pass *out);
void compute_pass_destroy(struct vk_context *ctx, struct compute_pass *pass);

/* Points every binding at its resource; `resources` has pass->binding_count entries. */
void compute_pass_bind(struct vk_context *ctx, struct compute_pass *pass,
                       const struct compute_resource *resources);

/* Binds, pushes constants (push_constant_bytes of them), dispatches ceil(size / local)
 * workgroups per axis, then a barrier so later passes see the writes. */
void compute_pass_record(VkCommandBuffer cmd, const struct compute_pass *pass, const void *push,
                         const uint32_t size[3], const uint32_t local[3]);

#endif
