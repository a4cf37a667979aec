#include "passes/passes.h"

#include <cstddef>

#include "vk/device_table.h"
#include "vk/pipeline.h"

namespace siviflow {
namespace {

Status check(VkResult result, const char* call) {
  if (result == VK_SUCCESS) return Status::success();
  return Status::error(std::string("scene pass: ") + call + " failed: " + result_name(result), result);
}

}  // namespace

Status ScenePass::create(const GpuContext& gpu, VkPipelineCache cache, VkFormat color_format,
                         VkFormat depth_format) {
  const DeviceTable& vk = *gpu.table;
  const VkAllocationCallbacks* callbacks = gpu.allocation_callbacks;

  VkDescriptorSetLayoutBinding binding{};
  binding.binding = 0;
  binding.descriptorType = VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER;
  binding.descriptorCount = 1;
  binding.stageFlags = VK_SHADER_STAGE_FRAGMENT_BIT;
  VkDescriptorSetLayoutCreateInfo set_info{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO};
  set_info.bindingCount = 1;
  set_info.pBindings = &binding;
  SIVIFLOW_TRY(check(vk.vkCreateDescriptorSetLayout(vk.device, &set_info, callbacks, &set_layout_),
                     "vkCreateDescriptorSetLayout"));

  VkPushConstantRange range{VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT, 0,
                            sizeof(gpu::SceneConstants)};
  VkPipelineLayoutCreateInfo layout_info{VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO};
  layout_info.setLayoutCount = 1;
  layout_info.pSetLayouts = &set_layout_;
  layout_info.pushConstantRangeCount = 1;
  layout_info.pPushConstantRanges = &range;
  SIVIFLOW_TRY(check(vk.vkCreatePipelineLayout(vk.device, &layout_info, callbacks, &layout_),
                     "vkCreatePipelineLayout"));

  VkDescriptorPoolSize pool_size{VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, 1};
  VkDescriptorPoolCreateInfo pool_info{VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO};
  pool_info.maxSets = 1;
  pool_info.poolSizeCount = 1;
  pool_info.pPoolSizes = &pool_size;
  SIVIFLOW_TRY(check(vk.vkCreateDescriptorPool(vk.device, &pool_info, callbacks, &pool_),
                     "vkCreateDescriptorPool"));
  VkDescriptorSetAllocateInfo alloc{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO};
  alloc.descriptorPool = pool_;
  alloc.descriptorSetCount = 1;
  alloc.pSetLayouts = &set_layout_;
  SIVIFLOW_TRY(check(vk.vkAllocateDescriptorSets(vk.device, &alloc, &set_), "vkAllocateDescriptorSets"));

  VkSamplerCreateInfo sampler_info{VK_STRUCTURE_TYPE_SAMPLER_CREATE_INFO};
  sampler_info.magFilter = VK_FILTER_LINEAR;
  sampler_info.minFilter = VK_FILTER_LINEAR;
  sampler_info.mipmapMode = VK_SAMPLER_MIPMAP_MODE_NEAREST;
  sampler_info.addressModeU = VK_SAMPLER_ADDRESS_MODE_REPEAT;
  sampler_info.addressModeV = VK_SAMPLER_ADDRESS_MODE_REPEAT;
  sampler_info.addressModeW = VK_SAMPLER_ADDRESS_MODE_REPEAT;
  sampler_info.maxLod = 0.0f;
  SIVIFLOW_TRY(check(vk.vkCreateSampler(vk.device, &sampler_info, callbacks, &sampler_), "vkCreateSampler"));

  GraphicsPipelineDesc sky;
  sky.vertex_shader = "sky.vert";
  sky.fragment_shader = "sky.frag";
  sky.layout = layout_;
  sky.color_format = color_format;
  sky.depth_format = depth_format;
  sky.depth_write = false;
  sky.depth_compare = VK_COMPARE_OP_LESS_OR_EQUAL;  // drawn at the far plane over the clear
  SIVIFLOW_TRY(create_graphics_pipeline(gpu, cache, sky, &sky_pipeline_));

  GraphicsPipelineDesc scene;
  scene.vertex_shader = "scene.vert";
  scene.fragment_shader = "scene.frag";
  scene.layout = layout_;
  scene.color_format = color_format;
  scene.depth_format = depth_format;
  scene.bindings = {{0, sizeof(SceneVertex), VK_VERTEX_INPUT_RATE_VERTEX}};
  scene.attributes = {
      {SIVIFLOW_ATTR_POSITION, 0, VK_FORMAT_R32G32B32_SFLOAT, offsetof(SceneVertex, position)},
      {SIVIFLOW_ATTR_NORMAL, 0, VK_FORMAT_R32G32B32_SFLOAT, offsetof(SceneVertex, normal)},
      {SIVIFLOW_ATTR_COLOR, 0, VK_FORMAT_R32G32B32A32_SFLOAT, offsetof(SceneVertex, color)}};
  SIVIFLOW_TRY(create_graphics_pipeline(gpu, cache, scene, &scene_pipeline_));
  return Status::success();
}

void ScenePass::destroy(const GpuContext& gpu) {
  const DeviceTable& vk = *gpu.table;
  const VkAllocationCallbacks* callbacks = gpu.allocation_callbacks;
  if (scene_pipeline_ != VK_NULL_HANDLE) vk.vkDestroyPipeline(vk.device, scene_pipeline_, callbacks);
  if (sky_pipeline_ != VK_NULL_HANDLE) vk.vkDestroyPipeline(vk.device, sky_pipeline_, callbacks);
  if (sampler_ != VK_NULL_HANDLE) vk.vkDestroySampler(vk.device, sampler_, callbacks);
  if (pool_ != VK_NULL_HANDLE) vk.vkDestroyDescriptorPool(vk.device, pool_, callbacks);
  if (layout_ != VK_NULL_HANDLE) vk.vkDestroyPipelineLayout(vk.device, layout_, callbacks);
  if (set_layout_ != VK_NULL_HANDLE) vk.vkDestroyDescriptorSetLayout(vk.device, set_layout_, callbacks);
  *this = ScenePass{};
}

void ScenePass::set_detail_texture(const GpuContext& gpu, VkImageView view) {
  VkDescriptorImageInfo image{sampler_, view, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL};
  VkWriteDescriptorSet write{VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET};
  write.dstSet = set_;
  write.dstBinding = 0;
  write.descriptorCount = 1;
  write.descriptorType = VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER;
  write.pImageInfo = &image;
  gpu.table->vkUpdateDescriptorSets(gpu.table->device, 1, &write, 0, nullptr);
}

void ScenePass::declare(FrameGraph& graph, const char* pass_name,
                        const std::vector<SceneDraw>* draws, Handles* handles) {
  PassBuilder pass = graph.add_pass(pass_name, PassKind::Graphics);
  handles->color = pass.color_write(handles->color, LoadOp::Clear);
  handles->depth = pass.depth_write(handles->depth, LoadOp::Clear);
  pass.vertex_read(handles->vertices);
  pass.index_read(handles->indices);
  pass.sampled_fragment(handles->detail);
  const Handles h = *handles;
  pass.record([this, h, draws](const PassContext& ctx) {
    const DeviceTable& vk = ctx.table();
    const VkCommandBuffer cmd = ctx.cmd();
    const VkExtent2D extent = ctx.extent(h.color);
    const VkViewport viewport{0.0f, 0.0f, static_cast<float>(extent.width),
                              static_cast<float>(extent.height), 0.0f, 1.0f};
    const VkRect2D scissor{{0, 0}, extent};
    constexpr VkShaderStageFlags kStages = VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT;
    vk.vkCmdSetViewport(cmd, 0, 1, &viewport);
    vk.vkCmdSetScissor(cmd, 0, 1, &scissor);
    vk.vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, layout_, 0, 1, &set_, 0, nullptr);
    // Terrain and objects first, so the sky's fragments are depth-tested away behind them.
    vk.vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, scene_pipeline_);
    const VkBuffer vertices = ctx.buffer(h.vertices);
    const VkDeviceSize offset = 0;
    vk.vkCmdBindVertexBuffers(cmd, 0, 1, &vertices, &offset);
    vk.vkCmdBindIndexBuffer(cmd, ctx.buffer(h.indices), 0, VK_INDEX_TYPE_UINT32);
    for (const SceneDraw& draw : *draws) {
      vk.vkCmdPushConstants(cmd, layout_, kStages, 0, sizeof(gpu::SceneConstants), draw.constants);
      vk.vkCmdDrawIndexed(cmd, draw.index_count, 1, draw.first_index, 0, 0);
    }
    // The sky with the view's own constants: those of the first, untranslated draw.
    vk.vkCmdPushConstants(cmd, layout_, kStages, 0, sizeof(gpu::SceneConstants), draws->front().constants);
    vk.vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, sky_pipeline_);
    vk.vkCmdDraw(cmd, 3, 1, 0, 0);
    return Status::success();
  });
}

}  // namespace siviflow
