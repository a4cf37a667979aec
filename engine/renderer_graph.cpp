// The water renderer's frame graph and the resources it wires: the per-configuration graph
// (upload, reflection, flow tiles, flow, readback), the images it declares, and per frame the
// bindings of the host's images, the static data, the readback buffers and the frame's data.
#include <algorithm>
#include <cmath>
#include <string>

#include "renderer_impl.h"
#include "vk/pipeline.h"
#include "vk/vk_text.h"

namespace siviflow {
VkExtent2D reflection_extent(VkExtent2D extent) {
  return {std::max(1u, static_cast<uint32_t>(std::lround(extent.width * kDefaultReflectionScale))),
          std::max(1u, static_cast<uint32_t>(std::lround(extent.height * kDefaultReflectionScale)))};
}

VkRect2D sampled_area(const glm::vec4& water, float distortion, VkExtent2D size) {
  if (!(water.x <= water.z && water.y <= water.w)) return VkRect2D{};
  const auto edge = [distortion](float uv, float sign, uint32_t texels) {
    const float at = std::floor((uv + sign * distortion) * float(texels) + sign * 0.5f) + sign;
    return static_cast<uint32_t>(std::clamp(at, 0.0f, float(texels)));
  };
  const uint32_t x0 = edge(water.x, -1.0f, size.width), x1 = edge(water.z, 1.0f, size.width);
  const uint32_t y0 = edge(water.y, -1.0f, size.height), y1 = edge(water.w, 1.0f, size.height);
  return {{static_cast<int32_t>(x0), static_cast<int32_t>(y0)}, {x1 - x0, y1 - y0}};
}

VkFormat reflection_format(VkFormat color_format) {
  if (color_channel_count(color_format) < 3) return VK_FORMAT_UNDEFINED;
  // Without alpha there is no "nothing reflected here, show the sky"; 32-bit floats add nothing
  // to a half-size, filtered reflection and are not filterable on every device.
  if (!color_has_alpha(color_format) || color_format == VK_FORMAT_R32G32B32A32_SFLOAT) {
    return VK_FORMAT_R16G16B16A16_SFLOAT;
  }
  return color_format;
}

ImageHandle Renderer::Impl::frame_image(ImageHandle handle, bool persistent) {
  frame_images.push_back({handle, Image{}, persistent});
  return handle;
}

Status Renderer::Impl::declare_graph() {
  const VkExtent2D extent = info.extent;
  const VkExtent2D reflection_size = reflection_extent(extent);
  frame_images.clear();
  river_assets = river->assets.import_into(graph);
  VkClearValue transparent{};

  // upload: this frame's flow texture and particle aux data, through the slot's staging block.
  const FlowTextureLayout& layout = simulation.layout();
  const VkExtent2D flow_extent{layout.flow_extent.x, layout.flow_extent.y};
  const VkExtent2D aux_extent{layout.aux_extent.x, layout.aux_extent.y};
  frame_staging = graph.import_buffer({"frame staging", 0}, ResourceState{});
  const ImageHandle flow_texture = frame_image(
      graph.create_persistent_image({"flow texture", kFlowTextureFormat, flow_extent, {}}), true);
  const ImageHandle particle_aux = frame_image(
      graph.create_persistent_image({"particle aux", kParticleAuxFormat, aux_extent, {}}), true);
  frame_uploads.buffers.clear();
  frame_uploads.images = {{0, flow_texture, flow_extent, 0}, {0, particle_aux, aux_extent, 0}};
  uploads_data = add_upload_pass(graph, frame_staging, &frame_uploads);

  // reflection: the host's world mirrored about the water plane, clipped below it.
  ImageHandle reflection =
      frame_image(graph.create_image(
          {"reflection", reflection_format(info.color_format), reflection_size, transparent}));
  reflection_depth = frame_image(
      graph.create_image({"reflection depth", kReflectionDepthFormat, reflection_size, {}}));
  reflection_data = add_reflection_pass(graph, &reflection, &reflection_depth, info.reflection,
                                        info.reflection_user);
  reflection_view.format = reflection_format(info.color_format);

  // The host's images, in the states the host states per frame (record()); their declared
  // extent is the view's, the viewport is placed inside them when recording.
  host_color = graph.import_image({"host colour", info.color_format, extent, {}}, ResourceState{},
                                  state_of(Access::SampledFragment));
  host_depth = graph.import_image({"host depth", info.depth_format, extent, {}}, ResourceState{},
                                  state_of(Access::DepthAttachmentRead));
  host_motion = host_reactive = ImageHandle{};
  if (info.motion_format != VK_FORMAT_UNDEFINED) {
    host_motion = graph.import_image({"host motion", info.motion_format, extent, {}},
                                     ResourceState{}, state_of(Access::ColorAttachmentWrite));
  }
  if (info.reactive_format != VK_FORMAT_UNDEFINED) {
    host_reactive = graph.import_image({"host reactive", info.reactive_format, extent, {}},
                                       ResourceState{}, state_of(Access::ColorAttachmentWrite));
  }

  // refraction copy: what the host drew, for the water to see through.
  ImageHandle refraction =
      frame_image(graph.create_image({"refraction copy", info.color_format, extent, {}}));
  refraction_data = add_refraction_copy_pass(graph, host_color, &refraction);

  // flow: the water material over the host's colour.
  FlowPass::Handles water;
  water.color = host_color;
  water.depth = host_depth;
  water.flow = frame_uploads.images[0].destination;
  water.aux = frame_uploads.images[1].destination;
  water.reflection = reflection;
  water.normal_map = river_assets.images[SharedRiver::kNormalMap];
  water.vertices = river_assets.buffers[SharedRiver::kRiverVertices];
  water.indices = river_assets.buffers[SharedRiver::kRiverIndices];
  water.motion = host_motion;
  water.reactive = host_reactive;
  if ((info.readback_images & kAovReadbackImages) != 0) {
    water.mask = frame_image(graph.create_image({"water mask", FlowPass::kMaskFormat, extent, transparent}));
    water.normal = frame_image(graph.create_image({"water normal", FlowPass::kNormalFormat, extent, transparent}));
    water.reflection_sample = frame_image(
        graph.create_image({"reflection sample", FlowPass::kReflectionFormat, extent, transparent}));
    water.foam = frame_image(graph.create_image({"foam", FlowPass::kFoamFormat, extent, transparent}));
  }
  water.water_heights = river_assets.images[SharedRiver::kWaterHeights];
  water.refraction = refraction;
  water.tile_table = frame_image(graph.create_image(
      {"tile table", FlowPass::kTileTableFormat,
       {tile_lattice.layout().width, tile_lattice.layout().height}, {}}));
  flow_pass.declare_tiles(graph, &water);
  water_frame.draws = &water_draws;
  flow_pass.declare(graph, &water);
  if (info.write_depth) flow_pass.declare_depth(graph, &water);
  if (info.enable_timing && info.measure_flow_floor) {
    const ImageHandle floor =
        frame_image(graph.create_image({"flow floor", info.color_format, extent, {}}));
    flow_pass.declare_floor(graph, water, floor);
  }

  if (info.readback_images != 0) {
    const ImageHandle images[kReadbackImageCount] = {water.color,
                                                     water.depth,
                                                     water.mask,
                                                     frame_uploads.images[0].destination,
                                                     frame_uploads.images[1].destination,
                                                     water.normal,
                                                     water.reflection_sample,
                                                     water.tile_table,
                                                     water.foam};
    readbacks.clear();
    readback_kinds.clear();
    for (uint32_t i = 0; i < kReadbackImageCount; ++i) {
      const auto kind = static_cast<ReadbackImage>(i);
      if ((info.readback_images & readback_bit(kind)) == 0) continue;
      const BufferHandle buffer = graph.import_buffer({readback_image_name(kind), 0},
                                                      ResourceState{}, state_of(Access::HostRead));
      readbacks.push_back({images[i], buffer, {}});
      readback_kinds.push_back(kind);
    }
    readbacks_data = add_readback_pass(graph, &readbacks);
  }
  SIVIFLOW_TRY(graph.compile());
  SIVIFLOW_TRY(create_frame_images());

  FlowPass::Textures textures;
  textures.flow = find_frame_image(flow_texture)->view;
  textures.aux = find_frame_image(particle_aux)->view;
  textures.reflection = find_frame_image(reflection)->view;
  textures.normal_map = river->assets.image(SharedRiver::kNormalMap).view;
  textures.tile_table = find_frame_image(water.tile_table)->view;
  textures.water_heights = river->assets.image(SharedRiver::kWaterHeights).view;
  textures.refraction = find_frame_image(refraction)->view;
  return flow_pass.bind_textures(gpu, textures, [this](VkDescriptorPool pool) {
    ring.defer_deletion_until_all_slots([gpu_context = gpu, pool] {
      gpu_context.table->vkDestroyDescriptorPool(gpu_context.table->device, pool,
                                                 gpu_context.allocation_callbacks);
    });
  });
}

Status Renderer::Impl::create_frame_images() {
  for (FrameImage& f : frame_images) {
    const ImageDesc* desc = graph.image_desc(f.handle);
    const VkImageUsageFlags usage = graph.image_usage(f.handle);
    if (usage == 0) continue;  // no surviving pass uses it
    SIVIFLOW_TRY(create_image(gpu, desc->format, desc->extent, usage, desc->name.c_str(), &f.image));
  }
  frame_images_new = true;
  return Status::success();
}

const Image* Renderer::Impl::find_frame_image(ImageHandle handle) const {
  for (const FrameImage& f : frame_images) {
    if (f.handle.id == handle.id) return &f.image;
  }
  return nullptr;
}

void Renderer::Impl::retire_frame_images() {
  // Frames of any slot still in flight may use them: free them once every slot came round.
  for (FrameImage& f : frame_images) {
    ring.defer_deletion_until_all_slots(
        [gpu_context = gpu, retired = f.image]() mutable { destroy_image(gpu_context, &retired); });
  }
  frame_images.clear();
}

// Binds this frame's resources: the static assets, the frame images, the host's images with
// their states, a view of the host depth's depth aspect for sampling, the readback buffers.
Status Renderer::Impl::bind_frame(const FrameInputs& inputs) {
  FrameBindings& b = bindings;
  b.reset();
  river->assets.bind(b, river_assets);
  for (const FrameImage& f : frame_images) {
    b.bind_image(f.handle, f.image.image, f.image.view);
    // Persistent images start without contents (only the upload writes them, whole).
    if (frame_images_new && f.persistent) b.set_incoming(f.handle, ResourceState{});
  }
  VkClearValue far{};
  far.depthStencil = {far_depth(view.reverse_z), 0};
  b.set_clear(reflection_depth, far);
  const auto bind_host = [&b](ImageHandle handle, const ExternalImage& image) {
    b.bind_image(handle, image.image, image.view);
    b.set_incoming(handle, {image.current.stage, image.current.access, image.current.layout});
    b.set_outgoing(handle, {image.final.stage, image.final.access, image.final.layout});
  };
  bind_host(host_color, inputs.color);
  bind_host(host_depth, inputs.depth);
  if (host_motion.valid()) bind_host(host_motion, inputs.motion);
  if (host_reactive.valid()) bind_host(host_reactive, inputs.reactive);
  // The water renders over the view's part of the host's images only.
  b.set_render_area(host_color, viewport);
  b.set_render_area(host_depth, viewport);
  b.bind_buffer(frame_staging, ring.staging_buffer());
  for (size_t i = 0; i < readbacks.size(); ++i) {
    const ReadbackImage kind = readback_kinds[i];
    b.bind_buffer(readbacks[i].buffer, inputs.readback.buffers[static_cast<uint32_t>(kind)]);
    // The host's images are read back over the view's viewport only.
    const bool host_image = kind == ReadbackImage::kColor || kind == ReadbackImage::kDepth;
    readbacks[i].region = host_image ? viewport : VkRect2D{};
  }

  // The host's view may cover stencil too: the material samples depth alone, through a view of
  // its own, freed when this slot comes round again.
  VkImageViewCreateInfo view_info{VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO};
  view_info.image = inputs.depth.image;
  view_info.viewType = VK_IMAGE_VIEW_TYPE_2D;
  view_info.format = info.depth_format;
  view_info.subresourceRange = {VK_IMAGE_ASPECT_DEPTH_BIT, 0, 1, 0, 1};
  VkImageView depth_view = VK_NULL_HANDLE;
  SIVIFLOW_TRY(vk_status(
      table.vkCreateImageView(table.device, &view_info, gpu.allocation_callbacks, &depth_view),
      "vkCreateImageView (host depth)"));
  const auto destroy_view = [gpu_context = gpu, depth_view] {
    gpu_context.table->vkDestroyImageView(gpu_context.table->device, depth_view,
                                          gpu_context.allocation_callbacks);
  };
  try {
    ring.defer_deletion(destroy_view);
  } catch (...) {  // not queued: nothing has used the view yet
    destroy_view();
    throw;
  }
  water_frame.slot = current_slot;
  water_frame.host_depth = depth_view;
  water_frame.reverse_z = view.reverse_z;
  water_frame.viewport = viewport;
  water_frame.scissor = scissor;
  flow_pass.prepare_frame(gpu, water_frame);
  // What the passes read as they record: this frame's, through the graph's data handles.
  b.bind_data(flow_pass.frame_data(), &water_frame);
  b.bind_data(uploads_data, &frame_uploads);
  b.bind_data(reflection_data, &reflection_view);
  b.bind_data(refraction_data, &refraction_copy);
  if (readbacks_data.valid()) b.bind_data(readbacks_data, &readbacks);
  return Status::success();
}

VkDeviceSize Renderer::readback_bytes(ReadbackImage image) const {
  const VkDeviceSize pixels = VkDeviceSize{impl_->info.extent.width} * impl_->info.extent.height;
  switch (image) {
    case ReadbackImage::kColor:
      return pixels * color_texel_bytes(impl_->info.color_format);
    case ReadbackImage::kDepth:
    case ReadbackImage::kWaterMask:
    case ReadbackImage::kFoam:
      return pixels * sizeof(float);
    case ReadbackImage::kFlowTexture:
      return impl_->simulation.layout().flow_bytes;
    case ReadbackImage::kParticleAux:
      return impl_->simulation.layout().aux_bytes;
    case ReadbackImage::kNormal:
    case ReadbackImage::kReflection:
      return pixels * 4 * sizeof(float);
    case ReadbackImage::kTileTable:
      return VkDeviceSize{impl_->tile_lattice.layout().width} * impl_->tile_lattice.layout().height * 4 *
             sizeof(uint32_t);
  }
  return 0;
}

const char* readback_image_name(ReadbackImage image) {
  switch (image) {
    case ReadbackImage::kColor:
      return "readback colour";
    case ReadbackImage::kDepth:
      return "readback depth";
    case ReadbackImage::kWaterMask:
      return "readback water mask";
    case ReadbackImage::kFlowTexture:
      return "readback flow texture";
    case ReadbackImage::kParticleAux:
      return "readback particle aux";
    case ReadbackImage::kNormal:
      return "readback water normal";
    case ReadbackImage::kReflection:
      return "readback reflection sample";
    case ReadbackImage::kTileTable:
      return "readback tile table";
    case ReadbackImage::kFoam:
      return "readback foam";
  }
  return "readback";
}

}  // namespace siviflow
