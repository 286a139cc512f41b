#include "compute_pass.h"

#include <string.h>

#include "vk_check.h"
#include "vk_context.h"
#include "vk_resources.h"

/* The shader module lives only as long as it takes to make the pipeline. */
static VkResult create_pipeline(struct vk_context *ctx, const struct compute_pass_desc *desc,
                                VkPipelineLayout layout, VkPipeline *out)
{
    VkShaderModuleCreateInfo module_info = {
        .sType = VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO,
        .codeSize = desc->spirv_bytes,
        .pCode = desc->spirv,
    };
    VkShaderModule module;
    VK_CHECK_RETURN(vkCreateShaderModule(ctx->device, &module_info, NULL, &module));
    uint32_t spec_count = desc->spec_count < COMPUTE_PASS_MAX_SPEC ? desc->spec_count
                                                                   : COMPUTE_PASS_MAX_SPEC;
    VkSpecializationMapEntry entries[COMPUTE_PASS_MAX_SPEC];
    for (uint32_t i = 0; i < spec_count; i++)
        entries[i] = (VkSpecializationMapEntry){ i, i * sizeof(uint32_t), sizeof(uint32_t) };
    VkSpecializationInfo spec = {
        .mapEntryCount = spec_count,
        .pMapEntries = entries,
        .dataSize = spec_count * sizeof(uint32_t),
        .pData = desc->spec_values,
    };
    VkComputePipelineCreateInfo pipeline_info = {
        .sType = VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO,
        .stage = {
            .sType = VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO,
            .stage = VK_SHADER_STAGE_COMPUTE_BIT,
            .module = module,
            .pName = "main",
            .pSpecializationInfo = spec_count ? &spec : NULL,
        },
        .layout = layout,
    };
    VkResult result;
    VK_CHECK_KEEP_GOTO(
        vkCreateComputePipelines(ctx->device, VK_NULL_HANDLE, 1, &pipeline_info, NULL, out), result,
        destroy_module);
    vk_context_name_object(ctx, VK_OBJECT_TYPE_PIPELINE, (uint64_t)*out, desc->name);
destroy_module:
    vkDestroyShaderModule(ctx->device, module, NULL);
    return result;
}

VkResult compute_pass_create(struct vk_context *ctx, const struct compute_pass_desc *desc,
                             struct compute_pass *out)
{
    memset(out, 0, sizeof *out);
    out->name = desc->name;
    out->binding_count = desc->binding_count;
    memcpy(out->bindings, desc->bindings, sizeof out->bindings);
    out->push_constant_bytes = desc->push_constant_bytes;
    VkResult result;

    VkDescriptorSetLayoutBinding bindings[COMPUTE_PASS_MAX_BINDINGS];
    VkDescriptorPoolSize pool_sizes[COMPUTE_PASS_MAX_BINDINGS];
    for (uint32_t i = 0; i < desc->binding_count; i++) {
        bindings[i] = (VkDescriptorSetLayoutBinding){
            .binding = i,
            .descriptorType = desc->bindings[i],
            .descriptorCount = 1,
            .stageFlags = VK_SHADER_STAGE_COMPUTE_BIT,
        };
        pool_sizes[i] = (VkDescriptorPoolSize){ desc->bindings[i], 1 };
    }
    VkDescriptorSetLayoutCreateInfo set_info = {
        .sType = VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO,
        .bindingCount = desc->binding_count,
        .pBindings = bindings,
    };
    VK_CHECK_KEEP_GOTO(vkCreateDescriptorSetLayout(ctx->device, &set_info, NULL, &out->set_layout),
                       result, report);
    VkPushConstantRange range = {
        .stageFlags = VK_SHADER_STAGE_COMPUTE_BIT,
        .offset = 0,
        .size = desc->push_constant_bytes,
    };
    VkPipelineLayoutCreateInfo layout_info = {
        .sType = VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO,
        .setLayoutCount = 1,
        .pSetLayouts = &out->set_layout,
        .pushConstantRangeCount = desc->push_constant_bytes ? 1 : 0,
        .pPushConstantRanges = &range,
    };
    VK_CHECK_KEEP_GOTO(vkCreatePipelineLayout(ctx->device, &layout_info, NULL, &out->layout),
                       result, destroy_set_layout);
    result = create_pipeline(ctx, desc, out->layout, &out->pipeline);
    if (result != VK_SUCCESS)
        goto destroy_layout;

    VkDescriptorPoolCreateInfo pool_info = {
        .sType = VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO,
        .maxSets = 1,
        .poolSizeCount = desc->binding_count,
        .pPoolSizes = pool_sizes,
    };
    VK_CHECK_KEEP_GOTO(vkCreateDescriptorPool(ctx->device, &pool_info, NULL, &out->pool), result,
                       destroy_pipeline);
    VkDescriptorSetAllocateInfo alloc = {
        .sType = VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO,
        .descriptorPool = out->pool,
        .descriptorSetCount = 1,
        .pSetLayouts = &out->set_layout,
    };
    VK_CHECK_KEEP_GOTO(vkAllocateDescriptorSets(ctx->device, &alloc, &out->set), result,
                       destroy_pool);
    return VK_SUCCESS;

destroy_pool:
    vkDestroyDescriptorPool(ctx->device, out->pool, NULL);
destroy_pipeline:
    vkDestroyPipeline(ctx->device, out->pipeline, NULL);
destroy_layout:
    vkDestroyPipelineLayout(ctx->device, out->layout, NULL);
destroy_set_layout:
    vkDestroyDescriptorSetLayout(ctx->device, out->set_layout, NULL);
report:
    vk_log(ctx, VK_LOG_ERROR, "vulkan: cannot create compute pass %s", desc->name);
    vk_context_note_failure(ctx, result, "creating compute pass %s", desc->name);
    memset(out, 0, sizeof *out);
    return result;
}

void compute_pass_destroy(struct vk_context *ctx, struct compute_pass *pass)
{
    if (!ctx || !pass)
        return;
    if (pass->pool)
        vkDestroyDescriptorPool(ctx->device, pass->pool, NULL);
    if (pass->pipeline)
        vkDestroyPipeline(ctx->device, pass->pipeline, NULL);
    if (pass->layout)
        vkDestroyPipelineLayout(ctx->device, pass->layout, NULL);
    if (pass->set_layout)
        vkDestroyDescriptorSetLayout(ctx->device, pass->set_layout, NULL);
    memset(pass, 0, sizeof *pass);
}

void compute_pass_bind(struct vk_context *ctx, struct compute_pass *pass,
                       const struct compute_resource *resources)
{
    VkWriteDescriptorSet writes[COMPUTE_PASS_MAX_BINDINGS];
    VkDescriptorImageInfo images[COMPUTE_PASS_MAX_BINDINGS];
    VkDescriptorBufferInfo buffers[COMPUTE_PASS_MAX_BINDINGS];
    for (uint32_t i = 0; i < pass->binding_count; i++) {
        const struct compute_resource *r = &resources[i];
        writes[i] = (VkWriteDescriptorSet){
            .sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET,
            .dstSet = pass->set,
            .dstBinding = i,
            .descriptorCount = 1,
            .descriptorType = pass->bindings[i],
        };
        switch (pass->bindings[i]) {
        case VK_DESCRIPTOR_TYPE_STORAGE_IMAGE:
        case VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER:
            images[i] = (VkDescriptorImageInfo){
                .sampler = r->sampler,
                .imageView = r->image->view,
                .imageLayout = VK_IMAGE_LAYOUT_GENERAL,
            };
            writes[i].pImageInfo = &images[i];
            break;
        default:
            buffers[i] = (VkDescriptorBufferInfo){ r->buffer->buffer, 0, VK_WHOLE_SIZE };
            writes[i].pBufferInfo = &buffers[i];
            break;
        }
    }
    vkUpdateDescriptorSets(ctx->device, pass->binding_count, writes, 0, NULL);
}

void compute_pass_record(VkCommandBuffer cmd, const struct compute_pass *pass, const void *push,
                         const uint32_t size[3], const uint32_t local[3])
{
    vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, pass->pipeline);
    vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, pass->layout, 0, 1, &pass->set, 0,
                            NULL);
    if (pass->push_constant_bytes)
        vkCmdPushConstants(cmd, pass->layout, VK_SHADER_STAGE_COMPUTE_BIT, 0,
                           pass->push_constant_bytes, push);
    vkCmdDispatch(cmd, (size[0] + local[0] - 1) / local[0], (size[1] + local[1] - 1) / local[1],
                  (size[2] + local[2] - 1) / local[2]);
    gpu_barrier_compute_to_compute(cmd);
}
