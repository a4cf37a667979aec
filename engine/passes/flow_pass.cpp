#include "passes/passes.h"

#include <array>
#include <string>

#include "vk/device_table.h"
#include "vk/pipeline.h"

namespace siviflow {
namespace {

// Bindings 0..3 as in shaders/flow_material.glsl: flow texture, particle aux, reflection,
// normal map.
constexpr uint32_t kBindingCount = 4;

}  // namespace

Status FlowPass::create(const GpuContext& gpu, VkPipelineCache cache, VkFormat color_format,
                        VkFormat depth_format, bool with_aovs, bool with_floor) {
  with_aovs_ = with_aovs;
  SIVIFLOW_TRY(create_pass_layout(gpu, kBindingCount, sizeof(gpu::FlowConstants), &set_layout_, &layout_));
  // Flow and aux are integer or exact data read with texelFetch: nearest, never filtered.
  SIVIFLOW_TRY(create_sampler(gpu, VK_FILTER_NEAREST, VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE, false, &nearest_));
  SIVIFLOW_TRY(create_sampler(gpu, VK_FILTER_LINEAR, VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE, false, &linear_clamp_));
  SIVIFLOW_TRY(create_sampler(gpu, VK_FILTER_LINEAR, VK_SAMPLER_ADDRESS_MODE_REPEAT, true, &linear_repeat_));

  GraphicsPipelineDesc desc;
  desc.vertex_shader = "flow.vert";
  desc.fragment_shader = with_aovs ? "flow_aovs.frag" : "flow.frag";
  desc.layout = layout_;
  desc.color_format = color_format;
  if (with_aovs) desc.extra_color_formats = {kMaskFormat, kNormalFormat, kReflectionFormat};
  desc.depth_format = depth_format;
  desc.depth_write = false;
  desc.depth_compare = VK_COMPARE_OP_LESS_OR_EQUAL;
  desc.alpha_blend = true;
  desc.bindings = {{0, sizeof(float) * 3, VK_VERTEX_INPUT_RATE_VERTEX},
                   {1, sizeof(float), VK_VERTEX_INPUT_RATE_VERTEX}};
  desc.attributes = {{SIVIFLOW_ATTR_POSITION, 0, VK_FORMAT_R32G32B32_SFLOAT, 0},
                     {SIVIFLOW_ATTR_WATER_DEPTH, 1, VK_FORMAT_R32_SFLOAT, 0}};
  SIVIFLOW_TRY(create_graphics_pipeline(gpu, cache, desc, &pipeline_));
  if (!with_floor) return Status::success();
  // The same geometry and depth test as the water, so the floor shades exactly its pixels.
  GraphicsPipelineDesc floor = desc;
  floor.fragment_shader = "flow_floor.frag";
  floor.color_format = kFloorFormat;
  floor.extra_color_formats.clear();
  floor.alpha_blend = false;
  return create_graphics_pipeline(gpu, cache, floor, &floor_pipeline_);
}

void FlowPass::destroy(const GpuContext& gpu) {
  const DeviceTable& vk = *gpu.table;
  const VkAllocationCallbacks* callbacks = gpu.allocation_callbacks;
  if (pipeline_ != VK_NULL_HANDLE) vk.vkDestroyPipeline(vk.device, pipeline_, callbacks);
  if (floor_pipeline_ != VK_NULL_HANDLE) vk.vkDestroyPipeline(vk.device, floor_pipeline_, callbacks);
  if (pool_ != VK_NULL_HANDLE) vk.vkDestroyDescriptorPool(vk.device, pool_, callbacks);
  for (VkSampler sampler : {nearest_, linear_clamp_, linear_repeat_}) {
    if (sampler != VK_NULL_HANDLE) vk.vkDestroySampler(vk.device, sampler, callbacks);
  }
  if (layout_ != VK_NULL_HANDLE) vk.vkDestroyPipelineLayout(vk.device, layout_, callbacks);
  if (set_layout_ != VK_NULL_HANDLE) vk.vkDestroyDescriptorSetLayout(vk.device, set_layout_, callbacks);
  *this = FlowPass{};
}

Status FlowPass::bind_textures(const GpuContext& gpu, const Textures& textures,
                               const std::function<void(VkDescriptorPool)>& retire) {
  const DeviceTable& vk = *gpu.table;
  // A new set first: on failure the current one stays valid.
  VkDescriptorPool pool = VK_NULL_HANDLE;
  VkDescriptorSet set = VK_NULL_HANDLE;
  const Status allocated = allocate_sampler_sets(gpu, set_layout_, kBindingCount, 1, &pool, &set);
  if (!allocated.ok()) {
    if (pool != VK_NULL_HANDLE) vk.vkDestroyDescriptorPool(vk.device, pool, gpu.allocation_callbacks);
    return allocated;
  }
  if (pool_ != VK_NULL_HANDLE) retire(pool_);
  pool_ = pool;
  set_ = set;
  const VkImageLayout read = VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL;
  const std::array<VkDescriptorImageInfo, kBindingCount> images{{
      {nearest_, textures.flow, read},
      {nearest_, textures.aux, read},
      {linear_clamp_, textures.reflection, textures.reflection_layout},
      {linear_repeat_, textures.normal_map, read}}};
  std::array<VkWriteDescriptorSet, kBindingCount> writes{};
  for (uint32_t i = 0; i < kBindingCount; ++i) {
    writes[i] = {VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET};
    writes[i].dstSet = set_;
    writes[i].dstBinding = i;
    writes[i].descriptorCount = 1;
    writes[i].descriptorType = VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER;
    writes[i].pImageInfo = &images[i];
  }
  vk.vkUpdateDescriptorSets(vk.device, kBindingCount, writes.data(), 0, nullptr);
  return Status::success();
}

void FlowPass::declare(FrameGraph& graph, const gpu::FlowConstants* constants, uint32_t index_count,
                       Handles* handles) {
  PassBuilder pass = graph.add_pass("flow", PassKind::Graphics);
  handles->color = pass.color_write(handles->color, LoadOp::Load);
  if (with_aovs_) {
    handles->mask = pass.color_write(handles->mask, LoadOp::Clear);
    handles->normal = pass.color_write(handles->normal, LoadOp::Clear);
    handles->reflection_sample = pass.color_write(handles->reflection_sample, LoadOp::Clear);
  }
  pass.depth_read(handles->depth);
  pass.sampled_fragment(handles->flow);
  pass.sampled_fragment(handles->aux);
  pass.sampled_fragment(handles->reflection);
  pass.sampled_fragment(handles->normal_map);
  pass.vertex_read(handles->vertices);
  pass.vertex_read(handles->depths);
  pass.index_read(handles->indices);
  const Handles h = *handles;
  pass.record([this, h, constants, index_count](const PassContext& ctx) {
    draw_river(ctx, pipeline_, h, ctx.extent(h.color), constants, index_count);
    return Status::success();
  });
}

void FlowPass::declare_floor(FrameGraph& graph, const gpu::FlowConstants* constants,
                             uint32_t index_count, const Handles& inputs, ImageHandle target) {
  PassBuilder pass = graph.add_pass("flow floor", PassKind::Graphics);
  const ImageHandle written = pass.color_write(target, LoadOp::DontCare);
  pass.depth_read(inputs.depth);
  pass.sampled_fragment(inputs.flow);
  pass.sampled_fragment(inputs.aux);
  pass.sampled_fragment(inputs.reflection);
  pass.sampled_fragment(inputs.normal_map);
  pass.vertex_read(inputs.vertices);
  pass.vertex_read(inputs.depths);
  pass.index_read(inputs.indices);
  pass.side_effect();
  const Handles h = inputs;
  pass.record([this, h, written, constants, index_count](const PassContext& ctx) {
    draw_river(ctx, floor_pipeline_, h, ctx.extent(written), constants, index_count);
    return Status::success();
  });
}

void FlowPass::draw_river(const PassContext& ctx, VkPipeline pipeline, const Handles& h,
                          VkExtent2D extent, const gpu::FlowConstants* constants,
                          uint32_t index_count) const {
  const DeviceTable& vk = ctx.table();
  const VkCommandBuffer cmd = ctx.cmd();
  set_viewport(vk, cmd, extent);
  vk.vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, layout_, 0, 1, &set_, 0, nullptr);
  vk.vkCmdPushConstants(cmd, layout_, VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT, 0,
                        sizeof(gpu::FlowConstants), constants);
  vk.vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, pipeline);
  const VkBuffer streams[2] = {ctx.buffer(h.vertices), ctx.buffer(h.depths)};
  const VkDeviceSize offsets[2] = {0, 0};
  vk.vkCmdBindVertexBuffers(cmd, 0, 2, streams, offsets);
  vk.vkCmdBindIndexBuffer(cmd, ctx.buffer(h.indices), 0, VK_INDEX_TYPE_UINT32);
  vk.vkCmdDrawIndexed(cmd, index_count, 1, 0, 0, 0);
}

}  // namespace siviflow
