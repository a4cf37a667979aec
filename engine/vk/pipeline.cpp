#include "vk/pipeline.h"

#include <algorithm>
#include <string>
#include <vector>

#include "shader_registry.h"

namespace siviflow {
namespace {

Status create_module(const GpuContext& gpu, std::string_view name, VkShaderModule* out) {
  const ShaderBlob* blob = find_shader(name);
  if (blob == nullptr) {
    return Status::error("no embedded shader named '" + std::string(name) + "'");
  }
  VkShaderModuleCreateInfo info{VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO};
  info.codeSize = blob->word_count * sizeof(uint32_t);
  info.pCode = blob->words;
  const VkResult result =
      gpu.table->vkCreateShaderModule(gpu.table->device, &info, gpu.allocation_callbacks, out);
  if (result != VK_SUCCESS) {
    return Status::error("vkCreateShaderModule for '" + std::string(name) +
                             "' failed: " + result_name(result),
                         result);
  }
  return Status::success();
}

}  // namespace

Status create_graphics_pipeline(const GpuContext& gpu, VkPipelineCache cache,
                                const GraphicsPipelineDesc& desc, VkPipeline* out) {
  const DeviceTable& vk = *gpu.table;
  VkShaderModule vertex = VK_NULL_HANDLE;
  VkShaderModule fragment = VK_NULL_HANDLE;
  Status status = create_module(gpu, desc.vertex_shader, &vertex);
  if (status.ok()) status = create_module(gpu, desc.fragment_shader, &fragment);

  if (status.ok()) {
    VkPipelineShaderStageCreateInfo stages[2] = {
        {VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO},
        {VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO}};
    stages[0].stage = VK_SHADER_STAGE_VERTEX_BIT;
    stages[0].module = vertex;
    stages[0].pName = "main";
    stages[1].stage = VK_SHADER_STAGE_FRAGMENT_BIT;
    stages[1].module = fragment;
    stages[1].pName = "main";
    // Constant i at offset 4 i, in either stage.
    std::vector<VkSpecializationMapEntry> entries;
    const size_t most = std::max(desc.vertex_constants.size(), desc.fragment_constants.size());
    for (uint32_t i = 0; i < most; ++i) {
      entries.push_back({i, i * static_cast<uint32_t>(sizeof(uint32_t)), sizeof(uint32_t)});
    }
    const auto specialization = [&entries](const std::vector<uint32_t>& constants) {
      return VkSpecializationInfo{static_cast<uint32_t>(constants.size()), entries.data(),
                                  constants.size() * sizeof(uint32_t), constants.data()};
    };
    const VkSpecializationInfo vertex_specialization = specialization(desc.vertex_constants);
    const VkSpecializationInfo fragment_specialization = specialization(desc.fragment_constants);
    if (!desc.vertex_constants.empty()) stages[0].pSpecializationInfo = &vertex_specialization;
    if (!desc.fragment_constants.empty()) stages[1].pSpecializationInfo = &fragment_specialization;

    VkPipelineVertexInputStateCreateInfo vertex_input{
        VK_STRUCTURE_TYPE_PIPELINE_VERTEX_INPUT_STATE_CREATE_INFO};
    vertex_input.vertexBindingDescriptionCount = static_cast<uint32_t>(desc.bindings.size());
    vertex_input.pVertexBindingDescriptions = desc.bindings.data();
    vertex_input.vertexAttributeDescriptionCount = static_cast<uint32_t>(desc.attributes.size());
    vertex_input.pVertexAttributeDescriptions = desc.attributes.data();

    VkPipelineInputAssemblyStateCreateInfo assembly{
        VK_STRUCTURE_TYPE_PIPELINE_INPUT_ASSEMBLY_STATE_CREATE_INFO};
    assembly.topology = VK_PRIMITIVE_TOPOLOGY_TRIANGLE_LIST;

    VkPipelineViewportStateCreateInfo viewport{VK_STRUCTURE_TYPE_PIPELINE_VIEWPORT_STATE_CREATE_INFO};
    viewport.viewportCount = 1;
    viewport.scissorCount = 1;

    VkPipelineRasterizationStateCreateInfo raster{
        VK_STRUCTURE_TYPE_PIPELINE_RASTERIZATION_STATE_CREATE_INFO};
    raster.polygonMode = VK_POLYGON_MODE_FILL;
    raster.cullMode = desc.cull_mode;
    raster.frontFace = desc.front_face;
    raster.lineWidth = 1.0f;

    VkPipelineMultisampleStateCreateInfo multisample{
        VK_STRUCTURE_TYPE_PIPELINE_MULTISAMPLE_STATE_CREATE_INFO};
    multisample.rasterizationSamples = VK_SAMPLE_COUNT_1_BIT;

    VkPipelineDepthStencilStateCreateInfo depth{
        VK_STRUCTURE_TYPE_PIPELINE_DEPTH_STENCIL_STATE_CREATE_INFO};
    depth.depthTestEnable = desc.depth_test ? VK_TRUE : VK_FALSE;
    depth.depthWriteEnable = desc.depth_write ? VK_TRUE : VK_FALSE;
    depth.depthCompareOp = desc.depth_compare;

    VkPipelineColorBlendAttachmentState blend_attachment{};
    blend_attachment.colorWriteMask = VK_COLOR_COMPONENT_R_BIT | VK_COLOR_COMPONENT_G_BIT |
                                      VK_COLOR_COMPONENT_B_BIT | VK_COLOR_COMPONENT_A_BIT;
    if (desc.alpha_blend) {
      blend_attachment.blendEnable = VK_TRUE;
      blend_attachment.srcColorBlendFactor = VK_BLEND_FACTOR_SRC_ALPHA;
      blend_attachment.dstColorBlendFactor = VK_BLEND_FACTOR_ONE_MINUS_SRC_ALPHA;
      blend_attachment.colorBlendOp = VK_BLEND_OP_ADD;
      blend_attachment.srcAlphaBlendFactor = VK_BLEND_FACTOR_ONE;
      blend_attachment.dstAlphaBlendFactor = VK_BLEND_FACTOR_ONE_MINUS_SRC_ALPHA;
      blend_attachment.alphaBlendOp = VK_BLEND_OP_ADD;
    }
    std::vector<VkFormat> color_formats;
    if (desc.color_format != VK_FORMAT_UNDEFINED) color_formats.push_back(desc.color_format);
    color_formats.insert(color_formats.end(), desc.extra_color_formats.begin(),
                         desc.extra_color_formats.end());
    std::vector<VkPipelineColorBlendAttachmentState> blend_attachments(
        color_formats.size(), VkPipelineColorBlendAttachmentState{});
    for (size_t i = 0; i < blend_attachments.size(); ++i) {
      blend_attachments[i].colorWriteMask = blend_attachment.colorWriteMask;
    }
    if (!blend_attachments.empty()) blend_attachments[0] = blend_attachment;
    VkPipelineColorBlendStateCreateInfo blend{VK_STRUCTURE_TYPE_PIPELINE_COLOR_BLEND_STATE_CREATE_INFO};
    blend.attachmentCount = static_cast<uint32_t>(blend_attachments.size());
    blend.pAttachments = blend_attachments.data();

    std::vector<VkDynamicState> dynamic_states = {VK_DYNAMIC_STATE_VIEWPORT,
                                                  VK_DYNAMIC_STATE_SCISSOR};
    if (desc.dynamic_depth_compare) dynamic_states.push_back(VK_DYNAMIC_STATE_DEPTH_COMPARE_OP);
    if (desc.dynamic_culling) {
      dynamic_states.push_back(VK_DYNAMIC_STATE_CULL_MODE);
      dynamic_states.push_back(VK_DYNAMIC_STATE_FRONT_FACE);
    }
    VkPipelineDynamicStateCreateInfo dynamic{VK_STRUCTURE_TYPE_PIPELINE_DYNAMIC_STATE_CREATE_INFO};
    dynamic.dynamicStateCount = static_cast<uint32_t>(dynamic_states.size());
    dynamic.pDynamicStates = dynamic_states.data();

    VkPipelineRenderingCreateInfo rendering{VK_STRUCTURE_TYPE_PIPELINE_RENDERING_CREATE_INFO};
    rendering.colorAttachmentCount = static_cast<uint32_t>(color_formats.size());
    rendering.pColorAttachmentFormats = color_formats.data();
    rendering.depthAttachmentFormat = desc.depth_format;

    VkGraphicsPipelineCreateInfo info{VK_STRUCTURE_TYPE_GRAPHICS_PIPELINE_CREATE_INFO};
    info.pNext = &rendering;
    info.stageCount = 2;
    info.pStages = stages;
    info.pVertexInputState = &vertex_input;
    info.pInputAssemblyState = &assembly;
    info.pViewportState = &viewport;
    info.pRasterizationState = &raster;
    info.pMultisampleState = &multisample;
    info.pDepthStencilState = desc.depth_format != VK_FORMAT_UNDEFINED ? &depth : nullptr;
    info.pColorBlendState = &blend;
    info.pDynamicState = &dynamic;
    info.layout = desc.layout;
    const VkResult result = vk.vkCreateGraphicsPipelines(vk.device, cache, 1, &info,
                                                         gpu.allocation_callbacks, out);
    if (result != VK_SUCCESS) {
      status = Status::error("vkCreateGraphicsPipelines (" + std::string(desc.vertex_shader) + ", " +
                                 std::string(desc.fragment_shader) + ") failed: " + result_name(result),
                             result);
    }
  }
  if (vertex != VK_NULL_HANDLE) vk.vkDestroyShaderModule(vk.device, vertex, gpu.allocation_callbacks);
  if (fragment != VK_NULL_HANDLE) {
    vk.vkDestroyShaderModule(vk.device, fragment, gpu.allocation_callbacks);
  }
  return status;
}

Status vk_status(VkResult result, const char* call) {
  if (result == VK_SUCCESS) return Status::success();
  return Status::error(std::string(call) + " failed: " + result_name(result), result);
}

Status create_compute_pipeline(const GpuContext& gpu, VkPipelineCache cache,
                               std::string_view shader, VkPipelineLayout layout, VkPipeline* out) {
  const DeviceTable& vk = *gpu.table;
  VkShaderModule module = VK_NULL_HANDLE;
  SIVIFLOW_TRY(create_module(gpu, shader, &module));
  VkComputePipelineCreateInfo info{VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO};
  info.stage = {VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO};
  info.stage.stage = VK_SHADER_STAGE_COMPUTE_BIT;
  info.stage.module = module;
  info.stage.pName = "main";
  info.layout = layout;
  const VkResult result =
      vk.vkCreateComputePipelines(vk.device, cache, 1, &info, gpu.allocation_callbacks, out);
  vk.vkDestroyShaderModule(vk.device, module, gpu.allocation_callbacks);
  if (result != VK_SUCCESS) {
    return Status::error(
        "vkCreateComputePipelines (" + std::string(shader) + ") failed: " + result_name(result),
        result);
  }
  return Status::success();
}

Status create_layouts(const GpuContext& gpu, std::span<const VkDescriptorType> bindings,
                      VkShaderStageFlags stages, uint32_t push_constant_bytes,
                      VkDescriptorSetLayout* set_layout, VkPipelineLayout* layout) {
  const DeviceTable& vk = *gpu.table;
  std::vector<VkDescriptorSetLayoutBinding> set_bindings(bindings.size());
  for (uint32_t i = 0; i < bindings.size(); ++i)
    set_bindings[i] = {i, bindings[i], 1, stages, nullptr};
  VkDescriptorSetLayoutCreateInfo set_info{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO};
  set_info.bindingCount = static_cast<uint32_t>(set_bindings.size());
  set_info.pBindings = set_bindings.data();
  SIVIFLOW_TRY(vk_status(vk.vkCreateDescriptorSetLayout(vk.device, &set_info, gpu.allocation_callbacks, set_layout),
                         "vkCreateDescriptorSetLayout"));
  const VkPushConstantRange range{stages, 0, push_constant_bytes};
  VkPipelineLayoutCreateInfo layout_info{VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO};
  layout_info.setLayoutCount = 1;
  layout_info.pSetLayouts = set_layout;
  layout_info.pushConstantRangeCount = 1;
  layout_info.pPushConstantRanges = &range;
  return vk_status(vk.vkCreatePipelineLayout(vk.device, &layout_info, gpu.allocation_callbacks, layout),
                   "vkCreatePipelineLayout");
}

Status create_pass_layout(const GpuContext& gpu, uint32_t sampler_count,
                          uint32_t push_constant_bytes, VkDescriptorSetLayout* set_layout,
                          VkPipelineLayout* layout) {
  const std::vector<VkDescriptorType> samplers(sampler_count,
                                               VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER);
  return create_layouts(gpu, samplers, VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT,
                        push_constant_bytes, set_layout, layout);
}

Status allocate_sets(const GpuContext& gpu, VkDescriptorSetLayout set_layout,
                     std::span<const VkDescriptorType> bindings, uint32_t set_count,
                     VkDescriptorPool* pool, VkDescriptorSet* sets) {
  const DeviceTable& vk = *gpu.table;
  std::vector<VkDescriptorPoolSize> sizes;
  for (VkDescriptorType type : bindings) {
    const auto same =
        std::find_if(sizes.begin(), sizes.end(),
                     [type](const VkDescriptorPoolSize& size) { return size.type == type; });
    if (same != sizes.end()) {
      same->descriptorCount += set_count;
    } else {
      sizes.push_back({type, set_count});
    }
  }
  VkDescriptorPoolCreateInfo pool_info{VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO};
  pool_info.maxSets = set_count;
  pool_info.poolSizeCount = static_cast<uint32_t>(sizes.size());
  pool_info.pPoolSizes = sizes.data();
  SIVIFLOW_TRY(vk_status(vk.vkCreateDescriptorPool(vk.device, &pool_info, gpu.allocation_callbacks, pool),
                         "vkCreateDescriptorPool"));
  VkDescriptorSetAllocateInfo alloc{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO};
  alloc.descriptorPool = *pool;
  const std::vector<VkDescriptorSetLayout> layouts(set_count, set_layout);
  alloc.descriptorSetCount = set_count;
  alloc.pSetLayouts = layouts.data();
  return vk_status(vk.vkAllocateDescriptorSets(vk.device, &alloc, sets), "vkAllocateDescriptorSets");
}

Status allocate_sampler_sets(const GpuContext& gpu, VkDescriptorSetLayout set_layout,
                             uint32_t sampler_count, uint32_t set_count, VkDescriptorPool* pool,
                             VkDescriptorSet* sets) {
  const std::vector<VkDescriptorType> samplers(sampler_count,
                                               VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER);
  return allocate_sets(gpu, set_layout, samplers, set_count, pool, sets);
}

Status create_sampler(const GpuContext& gpu, VkFilter filter, VkSamplerAddressMode address,
                      bool mipmapped, VkSampler* out) {
  VkSamplerCreateInfo info{VK_STRUCTURE_TYPE_SAMPLER_CREATE_INFO};
  info.magFilter = filter;
  info.minFilter = filter;
  info.mipmapMode = mipmapped ? VK_SAMPLER_MIPMAP_MODE_LINEAR : VK_SAMPLER_MIPMAP_MODE_NEAREST;
  info.addressModeU = address;
  info.addressModeV = address;
  info.addressModeW = address;
  info.maxLod = mipmapped ? VK_LOD_CLAMP_NONE : 0.0f;
  return vk_status(gpu.table->vkCreateSampler(gpu.table->device, &info, gpu.allocation_callbacks, out),
                   "vkCreateSampler");
}

void set_viewport(const DeviceTable& vk, VkCommandBuffer cmd, VkExtent2D extent) {
  set_viewport(vk, cmd, VkRect2D{{0, 0}, extent});
}

void set_viewport(const DeviceTable& vk, VkCommandBuffer cmd, VkRect2D area) {
  const VkViewport viewport{static_cast<float>(area.offset.x), static_cast<float>(area.offset.y),
                            static_cast<float>(area.extent.width),
                            static_cast<float>(area.extent.height), 0.0f, 1.0f};
  vk.vkCmdSetViewport(cmd, 0, 1, &viewport);
  vk.vkCmdSetScissor(cmd, 0, 1, &area);
}

}  // namespace siviflow
