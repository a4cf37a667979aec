#include "passes/passes.h"

#include <cstddef>

#include "vk/device_table.h"
#include "vk/pipeline.h"

namespace siviflow {

Status ScenePass::create(const GpuContext& gpu, VkPipelineCache cache, VkFormat color_format,
                         VkFormat depth_format) {
  SIVIFLOW_TRY(create_pass_layout(gpu, 1, sizeof(gpu::SceneConstants), &set_layout_, &layout_));
  SIVIFLOW_TRY(allocate_sampler_set(gpu, set_layout_, 1, &pool_, &set_));
  // The detail texture has one level: linear filtering, repeated over the terrain.
  SIVIFLOW_TRY(create_sampler(gpu, VK_FILTER_LINEAR, VK_SAMPLER_ADDRESS_MODE_REPEAT, false, &sampler_));

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
    constexpr VkShaderStageFlags kStages = VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT;
    set_viewport(vk, cmd, ctx.extent(h.color));
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
