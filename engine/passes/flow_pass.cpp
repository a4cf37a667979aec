#include "passes/passes.h"

#include <array>
#include <span>
#include <string>

#include "vk/device_table.h"
#include "vk/pipeline.h"

namespace siviflow {
namespace {

// Bindings 0..4 as in shaders/flow_material.glsl: flow texture, particle aux, reflection,
// normal map, tile table.
constexpr uint32_t kBindingCount = 5;
constexpr std::array<VkDescriptorType, kBindingCount> kMaterialBindings = {
    VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER,
    VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER,
    VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER};
// Bindings of shaders/flow_tiles.comp: flow texture, water heights, tile table.
constexpr std::array<VkDescriptorType, 3> kTileBindings = {
    VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER,
    VK_DESCRIPTOR_TYPE_STORAGE_IMAGE};
constexpr uint32_t kTileGroupSide = 8;  // flow_tiles.comp's local size

}  // namespace

Status FlowPass::create(const GpuContext& gpu, VkPipelineCache cache, VkFormat color_format,
                        VkFormat depth_format, bool with_aovs, bool with_floor) {
  with_aovs_ = with_aovs;
  SIVIFLOW_TRY(create_layouts(gpu, kMaterialBindings,
                              VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT,
                              sizeof(gpu::FlowConstants), &set_layout_, &layout_));
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
  SIVIFLOW_TRY(create_layouts(gpu, kTileBindings, VK_SHADER_STAGE_COMPUTE_BIT,
                              sizeof(gpu::FlowTileConstants), &tiles_set_layout_, &tiles_layout_));
  SIVIFLOW_TRY(
      create_compute_pipeline(gpu, cache, "flow_tiles.comp", tiles_layout_, &tiles_pipeline_));
  if (!with_floor) return Status::success();
  // The same geometry, depth test, colour format and blending as the water, so the floor shades
  // exactly its pixels and writes them as the water does.
  GraphicsPipelineDesc floor = desc;
  floor.fragment_shader = "flow_floor.frag";
  floor.extra_color_formats.clear();
  return create_graphics_pipeline(gpu, cache, floor, &floor_pipeline_);
}

void FlowPass::destroy(const GpuContext& gpu) {
  const DeviceTable& vk = *gpu.table;
  const VkAllocationCallbacks* callbacks = gpu.allocation_callbacks;
  for (VkPipeline pipeline : {pipeline_, tiles_pipeline_, floor_pipeline_}) {
    if (pipeline != VK_NULL_HANDLE) vk.vkDestroyPipeline(vk.device, pipeline, callbacks);
  }
  for (VkDescriptorPool pool : {pool_, tiles_pool_}) {
    if (pool != VK_NULL_HANDLE) vk.vkDestroyDescriptorPool(vk.device, pool, callbacks);
  }
  for (VkSampler sampler : {nearest_, linear_clamp_, linear_repeat_}) {
    if (sampler != VK_NULL_HANDLE) vk.vkDestroySampler(vk.device, sampler, callbacks);
  }
  for (VkPipelineLayout layout : {layout_, tiles_layout_}) {
    if (layout != VK_NULL_HANDLE) vk.vkDestroyPipelineLayout(vk.device, layout, callbacks);
  }
  for (VkDescriptorSetLayout layout : {set_layout_, tiles_set_layout_}) {
    if (layout != VK_NULL_HANDLE) vk.vkDestroyDescriptorSetLayout(vk.device, layout, callbacks);
  }
  *this = FlowPass{};
}

Status FlowPass::bind_textures(const GpuContext& gpu, const Textures& textures,
                               const std::function<void(VkDescriptorPool)>& retire) {
  const DeviceTable& vk = *gpu.table;
  // New sets first: on failure the current ones stay valid.
  std::array<VkDescriptorPool, 2> pools{};
  std::array<VkDescriptorSet, 2> sets{};
  Status allocated = allocate_sets(gpu, set_layout_, kMaterialBindings, 1, &pools[0], &sets[0]);
  if (allocated.ok())
    allocated = allocate_sets(gpu, tiles_set_layout_, kTileBindings, 1, &pools[1], &sets[1]);
  if (!allocated.ok()) {
    for (VkDescriptorPool pool : pools) {
      if (pool != VK_NULL_HANDLE)
        vk.vkDestroyDescriptorPool(vk.device, pool, gpu.allocation_callbacks);
    }
    return allocated;
  }
  for (VkDescriptorPool pool : {pool_, tiles_pool_}) {
    if (pool != VK_NULL_HANDLE) retire(pool);
  }
  pool_ = pools[0];
  tiles_pool_ = pools[1];
  set_ = sets[0];
  tiles_set_ = sets[1];
  const VkImageLayout read = VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL;
  const std::array<VkDescriptorImageInfo, kBindingCount> material{
      {{nearest_, textures.flow, read},
       {nearest_, textures.aux, read},
       {linear_clamp_, textures.reflection, textures.reflection_layout},
       {linear_repeat_, textures.normal_map, read},
       {nearest_, textures.tile_table, read}}};
  const std::array<VkDescriptorImageInfo, kTileBindings.size()> tiles{
      {{nearest_, textures.flow, read},
       {nearest_, textures.water_heights, read},
       {VK_NULL_HANDLE, textures.tile_table, VK_IMAGE_LAYOUT_GENERAL}}};
  std::vector<VkWriteDescriptorSet> writes;
  const auto write = [&writes](VkDescriptorSet set, std::span<const VkDescriptorType> types,
                               std::span<const VkDescriptorImageInfo> images) {
    for (uint32_t i = 0; i < types.size(); ++i) {
      VkWriteDescriptorSet w{VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET};
      w.dstSet = set;
      w.dstBinding = i;
      w.descriptorCount = 1;
      w.descriptorType = types[i];
      w.pImageInfo = &images[i];
      writes.push_back(w);
    }
  };
  write(set_, kMaterialBindings, material);
  write(tiles_set_, kTileBindings, tiles);
  vk.vkUpdateDescriptorSets(vk.device, static_cast<uint32_t>(writes.size()), writes.data(), 0,
                            nullptr);
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
  pass.sampled_fragment(handles->tile_table);
  pass.vertex_read(handles->vertices);
  pass.vertex_read(handles->depths);
  pass.index_read(handles->indices);
  const Handles h = *handles;
  pass.record([this, h, constants, index_count](const PassContext& ctx) {
    draw_river(ctx, pipeline_, h, ctx.extent(h.color), constants, index_count);
    return Status::success();
  });
}

void FlowPass::declare_tiles(FrameGraph& graph, const gpu::FlowTileConstants* constants,
                             Handles* handles) {
  PassBuilder pass = graph.add_pass("flow tiles", PassKind::Compute);
  handles->tile_table = pass.storage_write(handles->tile_table);  // every texel written
  pass.sampled(handles->flow, ShaderStage::Compute);
  pass.sampled(handles->water_heights, ShaderStage::Compute);
  const ImageHandle table = handles->tile_table;
  pass.record([this, table, constants](const PassContext& ctx) {
    const DeviceTable& vk = ctx.table();
    const VkCommandBuffer cmd = ctx.cmd();
    vk.vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, tiles_pipeline_);
    vk.vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, tiles_layout_, 0, 1,
                               &tiles_set_, 0, nullptr);
    vk.vkCmdPushConstants(cmd, tiles_layout_, VK_SHADER_STAGE_COMPUTE_BIT, 0,
                          sizeof(gpu::FlowTileConstants), constants);
    const VkExtent2D extent = ctx.extent(table);
    vk.vkCmdDispatch(cmd, (extent.width + kTileGroupSide - 1) / kTileGroupSide,
                     (extent.height + kTileGroupSide - 1) / kTileGroupSide, 1);
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
  pass.sampled_fragment(inputs.tile_table);
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
