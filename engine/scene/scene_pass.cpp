#include "scene/scene_pass.h"

#include <cstddef>

#include "vk/device_table.h"
#include "vk/pipeline.h"

namespace siviflow {

Status ScenePass::create(const GpuContext& gpu, VkPipelineCache cache, VkFormat color_format,
                         VkFormat depth_format) {
  SIVIFLOW_TRY(create_pass_layout(gpu, 1, sizeof(gpu::SceneConstants), &set_layout_, &layout_));
  // The detail texture has one level: linear filtering, repeated over the terrain.
  SIVIFLOW_TRY(create_sampler(gpu, VK_FILTER_LINEAR, VK_SAMPLER_ADDRESS_MODE_REPEAT, false, &detail_sampler_));
  // glTF's default sampler: linear, mipmapped, repeat.
  SIVIFLOW_TRY(create_sampler(gpu, VK_FILTER_LINEAR, VK_SAMPLER_ADDRESS_MODE_REPEAT, true, &base_color_sampler_));

  GraphicsPipelineDesc sky;
  sky.vertex_shader = "sky.vert";
  sky.fragment_shader = "sky.frag";
  sky.layout = layout_;
  sky.color_format = color_format;
  sky.depth_format = depth_format;
  sky.depth_write = false;
  sky.dynamic_depth_compare = true;  // drawn at the far plane over the clear: less or equal
  SIVIFLOW_TRY(create_graphics_pipeline(gpu, cache, sky, &sky_pipeline_));

  GraphicsPipelineDesc scene;
  scene.vertex_shader = "scene.vert";
  scene.fragment_shader = "scene.frag";
  scene.layout = layout_;
  scene.color_format = color_format;
  scene.depth_format = depth_format;
  scene.dynamic_depth_compare = true;  // the view's depth convention
  scene.dynamic_culling = true;        // the terrain's back faces in the main view only
  scene.bindings = {{0, sizeof(gpu::SceneVertex), VK_VERTEX_INPUT_RATE_VERTEX}};
  scene.attributes = {
      {SIVIFLOW_ATTR_POSITION, 0, VK_FORMAT_R32G32B32_SFLOAT, offsetof(gpu::SceneVertex, position)},
      {SIVIFLOW_ATTR_NORMAL, 0, VK_FORMAT_R32G32B32_SFLOAT, offsetof(gpu::SceneVertex, normal)},
      {SIVIFLOW_ATTR_COLOR, 0, VK_FORMAT_R32G32B32A32_SFLOAT, offsetof(gpu::SceneVertex, color)},
      {SIVIFLOW_ATTR_TEXCOORD, 0, VK_FORMAT_R32G32_SFLOAT, offsetof(gpu::SceneVertex, texcoord)}};
  SIVIFLOW_TRY(create_graphics_pipeline(gpu, cache, scene, &scene_pipeline_));
  GraphicsPipelineDesc object = scene;
  object.fragment_shader = "object.frag";
  object.vertex_constants = {1};  // scene.vert's kTextured
  return create_graphics_pipeline(gpu, cache, object, &object_pipeline_);
}

void ScenePass::destroy(const GpuContext& gpu) {
  const DeviceTable& vk = *gpu.table;
  const VkAllocationCallbacks* callbacks = gpu.allocation_callbacks;
  for (VkPipeline pipeline : {object_pipeline_, scene_pipeline_, sky_pipeline_}) {
    if (pipeline != VK_NULL_HANDLE) vk.vkDestroyPipeline(vk.device, pipeline, callbacks);
  }
  for (VkSampler sampler : {detail_sampler_, base_color_sampler_}) {
    if (sampler != VK_NULL_HANDLE) vk.vkDestroySampler(vk.device, sampler, callbacks);
  }
  if (pool_ != VK_NULL_HANDLE) vk.vkDestroyDescriptorPool(vk.device, pool_, callbacks);
  if (layout_ != VK_NULL_HANDLE) vk.vkDestroyPipelineLayout(vk.device, layout_, callbacks);
  if (set_layout_ != VK_NULL_HANDLE) vk.vkDestroyDescriptorSetLayout(vk.device, set_layout_, callbacks);
  *this = ScenePass{};
}

Status ScenePass::set_textures(const GpuContext& gpu, VkImageView detail,
                               const std::vector<VkImageView>& base_colors) {
  sets_.resize(1 + base_colors.size());
  SIVIFLOW_TRY(allocate_sampler_sets(gpu, set_layout_, 1, static_cast<uint32_t>(sets_.size()), &pool_,
                                     sets_.data()));
  std::vector<VkDescriptorImageInfo> images;
  images.push_back({detail_sampler_, detail, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL});
  for (VkImageView view : base_colors) {
    images.push_back({base_color_sampler_, view, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL});
  }
  std::vector<VkWriteDescriptorSet> writes(sets_.size(), {VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET});
  for (size_t i = 0; i < writes.size(); ++i) {
    writes[i].dstSet = sets_[i];
    writes[i].dstBinding = 0;
    writes[i].descriptorCount = 1;
    writes[i].descriptorType = VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER;
    writes[i].pImageInfo = &images[i];
  }
  gpu.table->vkUpdateDescriptorSets(gpu.table->device, static_cast<uint32_t>(writes.size()),
                                    writes.data(), 0, nullptr);
  return Status::success();
}

ScenePass::FrameData ScenePass::declare(FrameGraph& graph, const char* pass_name,
                                        Handles* handles) {
  const FrameData data{graph.declare_data<std::vector<SceneDraw>>("world draws"),
                       graph.declare_data<Frame>("world view")};
  PassBuilder pass = graph.add_pass(pass_name, PassKind::Graphics);
  // Not cleared: the sky, drawn last over the cleared depth, writes every pixel nothing else did
  // (lavapipe spent 1.5-2 ms of a 720p frame clearing a half-float target).
  handles->color = pass.color_write(handles->color, LoadOp::DontCare);
  handles->depth = pass.depth_write(handles->depth, LoadOp::Clear);
  pass.vertex_read(handles->vertices);
  pass.index_read(handles->indices);
  pass.sampled_fragment(handles->detail);
  for (ImageHandle base_color : handles->base_colors) pass.sampled_fragment(base_color);
  const Handles h = *handles;
  pass.record([this, h, data](const PassContext& ctx) {
    const Frame& frame = ctx.data(data.view);
    set_viewport(ctx.table(), ctx.cmd(), frame.viewport);
    draw(ctx.table(), ctx.cmd(), ctx.buffer(h.vertices), ctx.buffer(h.indices),
         ctx.data(data.draws), *frame.sky, frame);
    return Status::success();
  });
  return data;
}

void ScenePass::draw(const DeviceTable& vk, VkCommandBuffer cmd, VkBuffer vertices,
                     VkBuffer indices, const std::vector<SceneDraw>& draws,
                     const gpu::SceneConstants& sky, const Frame& view) const {
  constexpr VkShaderStageFlags kStages = VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT;
  // Terrain and objects first, so the sky's fragments are depth-tested away behind them.
  const VkDeviceSize offset = 0;
  vk.vkCmdBindVertexBuffers(cmd, 0, 1, &vertices, &offset);
  vk.vkCmdBindIndexBuffer(cmd, indices, 0, VK_INDEX_TYPE_UINT32);
  VkPipeline bound = VK_NULL_HANDLE;
  VkDescriptorSet bound_set = VK_NULL_HANDLE;
  bool culling = false;
  const gpu::SceneConstants* pushed = nullptr;
  for (const SceneDraw& d : draws) {
    const VkPipeline pipeline = d.material == 0 ? scene_pipeline_ : object_pipeline_;
    const bool cull = view.cull_back_faces && d.one_sided;
    const bool rebound = pipeline != bound;
    if (rebound) {
      vk.vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, pipeline);
      vk.vkCmdSetDepthCompareOp(cmd, view.reverse_z ? VK_COMPARE_OP_GREATER : VK_COMPARE_OP_LESS);
      vk.vkCmdSetFrontFace(cmd, view.outside_clockwise ? VK_FRONT_FACE_CLOCKWISE
                                                       : VK_FRONT_FACE_COUNTER_CLOCKWISE);
      bound = pipeline;
    }
    if (rebound || cull != culling) {
      vk.vkCmdSetCullMode(cmd, cull ? VK_CULL_MODE_BACK_BIT : VK_CULL_MODE_NONE);
      culling = cull;
    }
    if (sets_[d.material] != bound_set) {
      bound_set = sets_[d.material];
      vk.vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, layout_, 0, 1, &bound_set, 0, nullptr);
    }
    // Pushed again only when they change: the terrain's chunks share the view's.
    if (d.constants != pushed) {
      vk.vkCmdPushConstants(cmd, layout_, kStages, 0, sizeof(gpu::SceneConstants), d.constants);
      pushed = d.constants;
    }
    vk.vkCmdDrawIndexed(cmd, d.index_count, 1, d.first_index, 0, 0);
  }
  vk.vkCmdPushConstants(cmd, layout_, kStages, 0, sizeof(gpu::SceneConstants), &sky);
  vk.vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, sky_pipeline_);
  vk.vkCmdSetDepthCompareOp(cmd, view.reverse_z ? VK_COMPARE_OP_GREATER_OR_EQUAL
                                           : VK_COMPARE_OP_LESS_OR_EQUAL);
  vk.vkCmdDraw(cmd, 3, 1, 0, 0);
}

}  // namespace siviflow
