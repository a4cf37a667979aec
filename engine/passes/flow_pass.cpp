#include "passes/passes.h"

#include <array>
#include <cstring>
#include <span>
#include <string>

#include "siviflow/water_look.h"
#include "vk/device_table.h"
#include "vk/pipeline.h"

namespace siviflow {
namespace {

// Bindings 0..7 as in shaders/flow_material.glsl: flow texture, particle aux, reflection,
// normal map, tile table, host depth, the look's uniform buffer, the refraction copy.
constexpr uint32_t kBindingCount = 8;
constexpr uint32_t kHostDepthBinding = 5;
constexpr uint32_t kLookBinding = 6;
constexpr uint32_t kRefractionBinding = 7;
constexpr std::array<VkDescriptorType, kBindingCount> kMaterialBindings = {
    VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER,
    VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER,
    VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER,
    VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER};
// Each slot's look block starts at a multiple of this: the largest minUniformBufferOffsetAlignment
// the specification allows, so no device query is needed.
constexpr VkDeviceSize kLookStride = 256;
static_assert(sizeof(gpu::WaterLookConstants) <= kLookStride);
// Bindings of shaders/flow_tiles.comp: flow texture, water heights, tile table, particle aux.
constexpr std::array<VkDescriptorType, 4> kTileBindings = {
    VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER,
    VK_DESCRIPTOR_TYPE_STORAGE_IMAGE, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER};
constexpr uint32_t kTileGroupSide = 8;  // flow_tiles.comp's local size

// The material's variant with the outputs a configuration asks for (shaders/CMakeLists.txt).
const char* material_shader(const FlowPass::Config& config) {
  const bool motion = config.motion_format != VK_FORMAT_UNDEFINED;
  const bool reactive = config.reactive_format != VK_FORMAT_UNDEFINED;
  const char* const names[2][4] = {
      {"flow.frag", "flow_motion.frag", "flow_reactive.frag", "flow_temporal.frag"},
      {"flow_aovs.frag", "flow_aovs_motion.frag", "flow_aovs_reactive.frag",
       "flow_aovs_temporal.frag"}};
  return names[config.with_aovs ? 1 : 0][(motion ? 1 : 0) + (reactive ? 2 : 0)];
}

}  // namespace

Status FlowPass::create(const GpuContext& gpu, VkPipelineCache cache, const Config& config) {
  config_ = config;
  const uint32_t slot_count = config.slot_count;
  SIVIFLOW_TRY(create_layouts(gpu, kMaterialBindings,
                              VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT,
                              sizeof(gpu::FlowConstants), &set_layout_, &layout_));
  // Flow and aux are integer or exact data read with texelFetch: nearest, never filtered.
  SIVIFLOW_TRY(create_buffer(gpu, kLookStride * slot_count, VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT,
                             true, "water look", &look_buffer_));
  SIVIFLOW_TRY(create_sampler(gpu, VK_FILTER_NEAREST, VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE, false, &nearest_));
  SIVIFLOW_TRY(create_sampler(gpu, VK_FILTER_LINEAR, VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE, false, &linear_clamp_));
  SIVIFLOW_TRY(create_sampler(gpu, VK_FILTER_LINEAR, VK_SAMPLER_ADDRESS_MODE_REPEAT, true, &linear_repeat_));

  GraphicsPipelineDesc desc;
  desc.vertex_shader = "flow.vert";
  desc.fragment_shader = material_shader(config);
  desc.layout = layout_;
  desc.color_format = config.color_format;
  for (VkFormat format : {config.motion_format, config.reactive_format}) {
    if (format != VK_FORMAT_UNDEFINED) desc.extra_color_formats.push_back(format);
  }
  if (config.with_aovs) {
    desc.extra_color_formats.insert(desc.extra_color_formats.end(),
                                    {kMaskFormat, kNormalFormat, kReflectionFormat, kFoamFormat});
  }
  desc.depth_format = config.depth_format;
  desc.depth_write = false;
  desc.dynamic_depth_compare = true;  // the host's depth convention, per frame
  desc.alpha_blend = true;
  desc.bindings = {{0, sizeof(float) * 3, VK_VERTEX_INPUT_RATE_VERTEX}};
  desc.attributes = {{SIVIFLOW_ATTR_POSITION, 0, VK_FORMAT_R32G32B32_SFLOAT, 0}};
  cache_ = cache;
  material_desc_ = desc;
  // Each pipeline holds its compiled shaders (on lavapipe about 2 MB): the first frame's is made
  // now, a material or debug view switched to later when a frame first draws with it.
  SIVIFLOW_TRY(ensure_material_pipeline(gpu, config.material, false));
  SIVIFLOW_TRY(create_layouts(gpu, kTileBindings, VK_SHADER_STAGE_COMPUTE_BIT,
                              sizeof(gpu::FlowTileConstants), &tiles_set_layout_, &tiles_layout_));
  SIVIFLOW_TRY(
      create_compute_pipeline(gpu, cache, "flow_tiles.comp", tiles_layout_, &tiles_pipeline_));
  if (config.with_depth) {
    // The material's geometry and depth test, writing depth alone.
    GraphicsPipelineDesc depth = desc;
    depth.fragment_shader = "flow_depth.frag";
    depth.fragment_constants.clear();
    depth.color_format = VK_FORMAT_UNDEFINED;
    depth.extra_color_formats.clear();
    depth.alpha_blend = false;
    depth.depth_write = true;
    SIVIFLOW_TRY(create_graphics_pipeline(gpu, cache, depth, &depth_pipeline_));
  }
  if (!config.with_floor) return Status::success();
  // The same geometry, depth test, colour format and blending as the water, so the floor shades
  // exactly its pixels and writes its colour as the water does (not the temporal outputs).
  GraphicsPipelineDesc floor = desc;
  floor.fragment_shader = "flow_floor.frag";
  floor.fragment_constants.clear();
  floor.extra_color_formats.clear();
  return create_graphics_pipeline(gpu, cache, floor, &floor_pipeline_);
}

void FlowPass::destroy(const GpuContext& gpu) {
  const DeviceTable& vk = *gpu.table;
  const VkAllocationCallbacks* callbacks = gpu.allocation_callbacks;
  for (const auto& variants : pipelines_) {
    for (VkPipeline pipeline : variants) {
      if (pipeline != VK_NULL_HANDLE) vk.vkDestroyPipeline(vk.device, pipeline, callbacks);
    }
  }
  for (VkPipeline pipeline : {tiles_pipeline_, floor_pipeline_, depth_pipeline_}) {
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
  destroy_buffer(gpu, &look_buffer_);
  *this = FlowPass{};
}

Status FlowPass::bind_textures(const GpuContext& gpu, const Textures& textures,
                               const std::function<void(VkDescriptorPool)>& retire) {
  const DeviceTable& vk = *gpu.table;
  // New sets first: on failure the current ones stay valid.
  std::array<VkDescriptorPool, 2> pools{};
  std::vector<VkDescriptorSet> sets(config_.slot_count);
  VkDescriptorSet tiles_set = VK_NULL_HANDLE;
  Status allocated = allocate_sets(gpu, set_layout_, kMaterialBindings, config_.slot_count, &pools[0],
                                   sets.data());
  if (allocated.ok())
    allocated = allocate_sets(gpu, tiles_set_layout_, kTileBindings, 1, &pools[1], &tiles_set);
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
  sets_ = std::move(sets);
  tiles_set_ = tiles_set;
  const VkImageLayout read = VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL;
  // The host depth (binding 5) is written per frame, into the slot's own set.
  const std::array<VkDescriptorImageInfo, kHostDepthBinding> material{
      {{nearest_, textures.flow, read},
       {nearest_, textures.aux, read},
       {linear_clamp_, textures.reflection, textures.reflection_layout},
       {linear_repeat_, textures.normal_map, read},
       {nearest_, textures.tile_table, read}}};
  const std::array<VkDescriptorImageInfo, kTileBindings.size()> tiles{
      {{nearest_, textures.flow, read},
       {nearest_, textures.water_heights, read},
       {VK_NULL_HANDLE, textures.tile_table, VK_IMAGE_LAYOUT_GENERAL},
       {nearest_, textures.aux, read}}};
  std::vector<VkWriteDescriptorSet> writes;
  // Bindings first, first + 1, ... of `set` to `images`.
  const auto write = [&writes](VkDescriptorSet set, uint32_t first,
                               std::span<const VkDescriptorType> types,
                               std::span<const VkDescriptorImageInfo> images) {
    for (uint32_t i = 0; i < images.size(); ++i) {
      VkWriteDescriptorSet w{VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET};
      w.dstSet = set;
      w.dstBinding = first + i;
      w.descriptorCount = 1;
      w.descriptorType = types[first + i];
      w.pImageInfo = &images[i];
      writes.push_back(w);
    }
  };
  const VkDescriptorImageInfo refraction{nearest_, textures.refraction, read};
  for (VkDescriptorSet set : sets_) {
    write(set, 0, kMaterialBindings, material);
    write(set, kRefractionBinding, kMaterialBindings, {&refraction, 1});
  }
  write(tiles_set_, 0, kTileBindings, tiles);
  std::vector<VkDescriptorBufferInfo> looks(config_.slot_count);
  for (uint32_t slot = 0; slot < config_.slot_count; ++slot) {
    looks[slot] = {look_buffer_.buffer, kLookStride * slot, sizeof(gpu::WaterLookConstants)};
    VkWriteDescriptorSet w{VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET};
    w.dstSet = sets_[slot];
    w.dstBinding = kLookBinding;
    w.descriptorCount = 1;
    w.descriptorType = kMaterialBindings[kLookBinding];
    w.pBufferInfo = &looks[slot];
    writes.push_back(w);
  }
  vk.vkUpdateDescriptorSets(vk.device, static_cast<uint32_t>(writes.size()), writes.data(), 0,
                            nullptr);
  return Status::success();
}

Status FlowPass::ensure_material_pipeline(const GpuContext& gpu, WaterMaterial material,
                                          bool debug_views) {
  const auto m = static_cast<uint32_t>(material);
  VkPipeline* pipeline = &pipelines_[m][debug_views ? 1 : 0];
  if (*pipeline != VK_NULL_HANDLE) return Status::success();
  GraphicsPipelineDesc desc = material_desc_;
  desc.fragment_constants = {m, debug_views ? 1u : 0u};
  const Status made = create_graphics_pipeline(gpu, cache_, desc, pipeline);
  if (made.ok()) return made;
  return Status::error(std::string("the pipeline of the water material ") +
                           water_material_name(material) +
                           (debug_views ? " with the debug views: " : ": ") + made.message(),
                       made.code());
}

Status FlowPass::prepare_pipeline(const GpuContext& gpu, const Frame& frame) {
  return ensure_material_pipeline(gpu, frame.material, frame.debug_view != DebugView::kNone);
}

void FlowPass::prepare_frame(const GpuContext& gpu, const Frame& frame) {
  // The slot's previous frame is done (the host waited on it), so its set and its look block
  // may change; host-coherent writes are visible to the commands submitted after them.
  std::memcpy(static_cast<std::byte*>(look_buffer_.mapped) + kLookStride * frame.slot, &frame.look,
              sizeof(frame.look));
  const VkDescriptorImageInfo image{nearest_, frame.host_depth,
                                    VK_IMAGE_LAYOUT_DEPTH_STENCIL_READ_ONLY_OPTIMAL};
  VkWriteDescriptorSet w{VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET};
  w.dstSet = sets_[frame.slot];
  w.dstBinding = kHostDepthBinding;
  w.descriptorCount = 1;
  w.descriptorType = kMaterialBindings[kHostDepthBinding];
  w.pImageInfo = &image;
  gpu.table->vkUpdateDescriptorSets(gpu.table->device, 1, &w, 0, nullptr);
}

void FlowPass::declare(FrameGraph& graph, Handles* handles) {
  PassBuilder pass = graph.add_pass("flow", PassKind::Graphics);
  handles->color = pass.color_write(handles->color, LoadOp::Load);
  // In the material's output order (flow_material.glsl): motion, reactive, then the AOVs.
  if (config_.motion_format != VK_FORMAT_UNDEFINED) {
    handles->motion = pass.color_write(handles->motion, LoadOp::Load);
  }
  if (config_.reactive_format != VK_FORMAT_UNDEFINED) {
    handles->reactive = pass.color_write(handles->reactive, LoadOp::Load);
  }
  if (config_.with_aovs) {
    handles->mask = pass.color_write(handles->mask, LoadOp::Clear);
    handles->normal = pass.color_write(handles->normal, LoadOp::Clear);
    handles->reflection_sample = pass.color_write(handles->reflection_sample, LoadOp::Clear);
    handles->foam = pass.color_write(handles->foam, LoadOp::Clear);
  }
  pass.depth_read(handles->depth);
  pass.sampled_fragment(handles->depth);
  pass.sampled_fragment(handles->flow);
  pass.sampled_fragment(handles->aux);
  pass.sampled_fragment(handles->reflection);
  pass.sampled_fragment(handles->normal_map);
  pass.sampled_fragment(handles->tile_table);
  pass.sampled_fragment(handles->refraction);
  pass.vertex_read(handles->vertices);
  pass.index_read(handles->indices);
  const Handles h = *handles;
  pass.record([this, h](const PassContext& ctx) {
    const Frame& frame = ctx.data(frame_data_);
    const VkPipeline pipeline = pipelines_[static_cast<uint32_t>(frame.material)]
                                          [frame.debug_view != DebugView::kNone ? 1 : 0];
    draw_river(ctx, pipeline, h);
    return Status::success();
  });
}

void FlowPass::declare_depth(FrameGraph& graph, Handles* handles) {
  PassBuilder pass = graph.add_pass("water depth", PassKind::Graphics);
  handles->depth = pass.depth_write(handles->depth, LoadOp::Load);
  pass.vertex_read(handles->vertices);
  pass.index_read(handles->indices);
  const Handles h = *handles;
  pass.record([this, h](const PassContext& ctx) {
    draw_river(ctx, depth_pipeline_, h);
    return Status::success();
  });
}

void FlowPass::declare_tiles(FrameGraph& graph, Handles* handles) {
  frame_data_ = graph.declare_data<Frame>("water frame");
  PassBuilder pass = graph.add_pass("flow tiles", PassKind::Compute);
  handles->tile_table = pass.storage_write(handles->tile_table);  // every texel written
  pass.sampled(handles->flow, ShaderStage::Compute);
  pass.sampled(handles->water_heights, ShaderStage::Compute);
  pass.sampled(handles->aux, ShaderStage::Compute);
  const ImageHandle table = handles->tile_table;
  const DataHandle<Frame> frame = frame_data_;
  pass.record([this, table, frame](const PassContext& ctx) {
    const DeviceTable& vk = ctx.table();
    const VkCommandBuffer cmd = ctx.cmd();
    vk.vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, tiles_pipeline_);
    vk.vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, tiles_layout_, 0, 1,
                               &tiles_set_, 0, nullptr);
    vk.vkCmdPushConstants(cmd, tiles_layout_, VK_SHADER_STAGE_COMPUTE_BIT, 0,
                          sizeof(gpu::FlowTileConstants), &ctx.data(frame).tiles);
    const VkExtent2D extent = ctx.extent(table);
    vk.vkCmdDispatch(cmd, (extent.width + kTileGroupSide - 1) / kTileGroupSide,
                     (extent.height + kTileGroupSide - 1) / kTileGroupSide, 1);
    return Status::success();
  });
}

void FlowPass::declare_floor(FrameGraph& graph, const Handles& inputs, ImageHandle target) {
  PassBuilder pass = graph.add_pass("flow floor", PassKind::Graphics);
  pass.color_write(target, LoadOp::DontCare);  // its new version: nothing reads it
  pass.depth_read(inputs.depth);
  pass.sampled_fragment(inputs.depth);
  pass.sampled_fragment(inputs.flow);
  pass.sampled_fragment(inputs.aux);
  pass.sampled_fragment(inputs.reflection);
  pass.sampled_fragment(inputs.normal_map);
  pass.sampled_fragment(inputs.tile_table);
  pass.sampled_fragment(inputs.refraction);
  pass.vertex_read(inputs.vertices);
  pass.index_read(inputs.indices);
  pass.side_effect();
  const Handles h = inputs;
  pass.record([this, h](const PassContext& ctx) {
    draw_river(ctx, floor_pipeline_, h);
    return Status::success();
  });
}

void FlowPass::draw_river(const PassContext& ctx, VkPipeline pipeline, const Handles& h) const {
  const DeviceTable& vk = ctx.table();
  const VkCommandBuffer cmd = ctx.cmd();
  const Frame& frame = ctx.data(frame_data_);
  set_viewport(vk, cmd, frame.viewport);
  vk.vkCmdSetScissor(cmd, 0, 1, &frame.scissor);
  vk.vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, layout_, 0, 1,
                             &sets_[frame.slot], 0, nullptr);
  vk.vkCmdPushConstants(cmd, layout_, VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT, 0,
                        sizeof(gpu::FlowConstants), &frame.flow);
  vk.vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, pipeline);
  // Tested (written only by the depth pass's own pipeline): water in front of (or level with)
  // what the host drew.
  vk.vkCmdSetDepthCompareOp(cmd, frame.reverse_z ? VK_COMPARE_OP_GREATER_OR_EQUAL
                                                 : VK_COMPARE_OP_LESS_OR_EQUAL);
  const VkBuffer vertices = ctx.buffer(h.vertices);
  const VkDeviceSize offset = 0;
  vk.vkCmdBindVertexBuffers(cmd, 0, 1, &vertices, &offset);
  vk.vkCmdBindIndexBuffer(cmd, ctx.buffer(h.indices), 0, VK_INDEX_TYPE_UINT32);
  for (const IndexRange& run : *frame.draws) {
    vk.vkCmdDrawIndexed(cmd, run.index_count, 1, run.first_index, 0, 0);
  }
}

}  // namespace siviflow
