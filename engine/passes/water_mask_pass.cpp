#include "passes/passes.h"

#include <string>

#include "vk/device_table.h"
#include "vk/pipeline.h"

namespace siviflow {

Status WaterMaskPass::create(const GpuContext& gpu, VkPipelineCache cache, VkFormat depth_format) {
  const DeviceTable& vk = *gpu.table;
  VkPushConstantRange range{VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT, 0,
                            sizeof(gpu::SceneConstants)};
  VkPipelineLayoutCreateInfo layout_info{VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO};
  layout_info.pushConstantRangeCount = 1;
  layout_info.pPushConstantRanges = &range;
  const VkResult result =
      vk.vkCreatePipelineLayout(vk.device, &layout_info, gpu.allocation_callbacks, &layout_);
  if (result != VK_SUCCESS) {
    return Status::error(std::string("water mask pass: vkCreatePipelineLayout failed: ") +
                             result_name(result),
                         result);
  }
  GraphicsPipelineDesc desc;
  desc.vertex_shader = "water_mask.vert";
  desc.fragment_shader = "water_mask.frag";
  desc.layout = layout_;
  desc.color_format = kFormat;
  desc.depth_format = depth_format;
  desc.depth_write = false;
  desc.depth_compare = VK_COMPARE_OP_LESS_OR_EQUAL;
  desc.bindings = {{0, sizeof(float) * 3, VK_VERTEX_INPUT_RATE_VERTEX}};
  desc.attributes = {{SIVIFLOW_ATTR_POSITION, 0, VK_FORMAT_R32G32B32_SFLOAT, 0}};
  return create_graphics_pipeline(gpu, cache, desc, &pipeline_);
}

void WaterMaskPass::destroy(const GpuContext& gpu) {
  const DeviceTable& vk = *gpu.table;
  if (pipeline_ != VK_NULL_HANDLE) vk.vkDestroyPipeline(vk.device, pipeline_, gpu.allocation_callbacks);
  if (layout_ != VK_NULL_HANDLE) vk.vkDestroyPipelineLayout(vk.device, layout_, gpu.allocation_callbacks);
  *this = WaterMaskPass{};
}

void WaterMaskPass::declare(FrameGraph& graph, const gpu::SceneConstants* constants,
                            uint32_t index_count, Handles* handles) {
  PassBuilder pass = graph.add_pass("water mask", PassKind::Graphics);
  handles->mask = pass.color_write(handles->mask, LoadOp::Clear);
  pass.depth_read(handles->depth);
  pass.vertex_read(handles->vertices);
  pass.index_read(handles->indices);
  const Handles h = *handles;
  pass.record([this, h, constants, index_count](const PassContext& ctx) {
    const DeviceTable& vk = ctx.table();
    const VkCommandBuffer cmd = ctx.cmd();
    const VkExtent2D extent = ctx.extent(h.mask);
    const VkViewport viewport{0.0f, 0.0f, static_cast<float>(extent.width),
                              static_cast<float>(extent.height), 0.0f, 1.0f};
    const VkRect2D scissor{{0, 0}, extent};
    vk.vkCmdSetViewport(cmd, 0, 1, &viewport);
    vk.vkCmdSetScissor(cmd, 0, 1, &scissor);
    vk.vkCmdPushConstants(cmd, layout_, VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT,
                          0, sizeof(gpu::SceneConstants), constants);
    vk.vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, pipeline_);
    const VkBuffer vertices = ctx.buffer(h.vertices);
    const VkDeviceSize offset = 0;
    vk.vkCmdBindVertexBuffers(cmd, 0, 1, &vertices, &offset);
    vk.vkCmdBindIndexBuffer(cmd, ctx.buffer(h.indices), 0, VK_INDEX_TYPE_UINT32);
    vk.vkCmdDrawIndexed(cmd, index_count, 1, 0, 0, 0);
    return Status::success();
  });
}

}  // namespace siviflow
