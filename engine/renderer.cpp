#include "siviflow/renderer.h"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstring>
#include <limits>
#include <optional>
#include <string>
#include <string_view>

#include <glm/gtc/matrix_transform.hpp>

#include "renderer_impl.h"
#include "renderer_inspect.h"
#include "default_river.h"
#include "sim/text_format.h"
#include "vk/pipeline.h"

namespace siviflow {
namespace {

constexpr uint32_t kDefaultFramesInFlight = 2;
constexpr uint32_t kMaxFramesInFlight = 8;
constexpr VkFormat kDefaultColorFormat = VK_FORMAT_R16G16B16A16_SFLOAT;
constexpr VkFormat kDefaultDepthFormat = VK_FORMAT_D32_SFLOAT;
constexpr VkFormat kReflectionDepthFormat = VK_FORMAT_D32_SFLOAT;
constexpr VkDeviceSize kDefaultStagingBytes = 8ull << 20;
constexpr VkDeviceSize kStagingAlignment = 16;  // covers every texel size we copy
// Layouts documented in shaders/shared.h.
constexpr VkFormat kFlowTextureFormat = VK_FORMAT_R16G16B16A16_UINT;
constexpr VkFormat kParticleAuxFormat = VK_FORMAT_R32G32B32A32_SFLOAT;
constexpr float kDefaultReflectionScale = 0.5f;  // reflection target size relative to the view

constexpr float kTdfRepeatTiles = 3.5f;  // normal-map repeat in tiles at ripple scale 1 (van Hoesel 35/10)
constexpr float kReflectionClipBias = 0.02f;      // metres below the water kept, so no seam shows

uint32_t texel_bytes(VkFormat format) {
  switch (format) {
    case VK_FORMAT_R8G8B8A8_UNORM:
    case VK_FORMAT_R8G8B8A8_SRGB:
    case VK_FORMAT_B8G8R8A8_UNORM:
    case VK_FORMAT_B8G8R8A8_SRGB:
      return 4;
    case VK_FORMAT_R16G16B16A16_SFLOAT:
      return 8;
    case VK_FORMAT_R32G32B32A32_SFLOAT:
      return 16;
    default:
      return 0;
  }
}

bool is_host_depth_format(VkFormat format) {
  return format == VK_FORMAT_D32_SFLOAT || format == VK_FORMAT_D24_UNORM_S8_UINT ||
         format == VK_FORMAT_D32_SFLOAT_S8_UINT;
}

std::string extent_text(VkExtent2D extent) {
  return std::to_string(extent.width) + "x" + std::to_string(extent.height);
}

}  // namespace

Status argument_error(const std::string& message) {
  return Status::error(std::string(kRendererErrorPrefix) + message);
}

View camera_view(const Camera& camera, VkExtent2D extent) {
  View view;
  const float aspect = static_cast<float>(extent.width) / static_cast<float>(std::max(1u, extent.height));
  view.projection = glm::perspectiveRH_ZO(glm::radians(camera.fov_y_deg), aspect,
                                          camera.near_plane, camera.far_plane);
  view.projection[1][1] *= -1.0f;  // Vulkan's clip space has +Y down
  view.view = glm::lookAtRH(camera.position, camera.target, glm::vec3(0.0f, 1.0f, 0.0f));
  view.viewport = {{0, 0}, extent};
  return view;
}

const char* version_string() { return "siviflow 0.1.0"; }


Status Renderer::Impl::validate_info(const CreateInfo& create) {
  info = create;
  if (info.instance == VK_NULL_HANDLE || info.physical_device == VK_NULL_HANDLE ||
      info.device == VK_NULL_HANDLE || info.get_instance_proc_addr == nullptr) {
    return argument_error("CreateInfo needs instance, physical_device, device and get_instance_proc_addr");
  }
  if (info.extent.width == 0 || info.extent.height == 0) {
    return argument_error("CreateInfo::extent must be at least 1x1");
  }
  if (info.frames_in_flight == 0) info.frames_in_flight = kDefaultFramesInFlight;
  if (info.frames_in_flight > kMaxFramesInFlight) {
    return argument_error("CreateInfo::frames_in_flight " + std::to_string(info.frames_in_flight) +
                   " exceeds " + std::to_string(kMaxFramesInFlight));
  }
  if (info.color_format == VK_FORMAT_UNDEFINED) info.color_format = kDefaultColorFormat;
  if (texel_bytes(info.color_format) == 0) {
    return argument_error("CreateInfo::color_format " + std::to_string(info.color_format) +
                   " is not an RGBA8, RGBA16F or RGBA32F format");
  }
  if (info.depth_format == VK_FORMAT_UNDEFINED) info.depth_format = kDefaultDepthFormat;
  if (!is_host_depth_format(info.depth_format)) {
    return argument_error("CreateInfo::depth_format " + std::to_string(info.depth_format) +
                   " is not D32_SFLOAT, D24_UNORM_S8_UINT or D32_SFLOAT_S8_UINT");
  }
  if (info.staging_bytes_per_slot == 0) info.staging_bytes_per_slot = kDefaultStagingBytes;
  if ((info.readback_images & ~kAllReadbackImages) != 0) {
    return argument_error("CreateInfo::readback_images 0x" +
                          text_format("%x", info.readback_images) + " has bits past the " +
                          std::to_string(kReadbackImageCount) + " ReadbackImage values");
  }

  const char* missing_function = nullptr;
  const VkResult loaded = load_device_table(info.instance, info.physical_device, info.device,
                                            info.get_instance_proc_addr, info.get_device_proc_addr,
                                            info.debug_utils, &table, &missing_function);
  if (loaded != VK_SUCCESS) {
    return Status::error(std::string("siviflow::Renderer: cannot load ") + missing_function, loaded);
  }
  gpu = make_gpu_context(table, info.allocation_callbacks);
  if (info.enabled_features == nullptr) {
    return argument_error("CreateInfo::enabled_features must point to the feature chain the device was "
                   "created with");
  }
  const std::vector<std::string> missing = missing_device_features(info.enabled_features);
  if (!missing.empty()) {
    std::string names;
    for (const std::string& name : missing) names += (names.empty() ? "" : ", ") + name;
    return Status::error("siviflow::Renderer: the device was created without required features: " +
                             names + " (enable required_device_features())",
                         VK_ERROR_FEATURE_NOT_PRESENT);
  }
  uint32_t family_count = 0;
  table.vkGetPhysicalDeviceQueueFamilyProperties(info.physical_device, &family_count, nullptr);
  std::vector<VkQueueFamilyProperties> families(family_count);
  table.vkGetPhysicalDeviceQueueFamilyProperties(info.physical_device, &family_count, families.data());
  if (info.queue_family_index >= family_count ||
      (families[info.queue_family_index].queueFlags & VK_QUEUE_GRAPHICS_BIT) == 0) {
    return argument_error("CreateInfo::queue_family_index " + std::to_string(info.queue_family_index) +
                   " is not a graphics queue family of this device");
  }
  VkPhysicalDeviceProperties2 props{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2};
  table.vkGetPhysicalDeviceProperties2(info.physical_device, &props);
  const uint32_t limit = props.properties.limits.maxImageDimension2D;
  if (info.extent.width > limit || info.extent.height > limit) {
    return argument_error("extent " + std::to_string(info.extent.width) + "x" +
                   std::to_string(info.extent.height) + " exceeds the device limit of " +
                   std::to_string(limit));
  }
  VkFormatProperties format_props;
  table.vkGetPhysicalDeviceFormatProperties(info.physical_device, info.color_format, &format_props);
  if ((format_props.optimalTilingFeatures & VK_FORMAT_FEATURE_COLOR_ATTACHMENT_BIT) == 0) {
    return Status::error("siviflow::Renderer: color_format cannot be rendered to on this device",
                         VK_ERROR_FORMAT_NOT_SUPPORTED);
  }
  table.vkGetPhysicalDeviceFormatProperties(info.physical_device, info.depth_format, &format_props);
  const VkFormatFeatureFlags depth_needs =
      VK_FORMAT_FEATURE_DEPTH_STENCIL_ATTACHMENT_BIT | VK_FORMAT_FEATURE_SAMPLED_IMAGE_BIT;
  if ((format_props.optimalTilingFeatures & depth_needs) != depth_needs) {
    return Status::error("siviflow::Renderer: CreateInfo::depth_format " +
                             std::to_string(info.depth_format) +
                             " cannot be both a depth attachment and sampled on this device",
                         VK_ERROR_FORMAT_NOT_SUPPORTED);
  }
  return Status::success();
}

// The starting look: the host's, else the scene's, else the defaults.
Status Renderer::Impl::take_look() {
  look = info.look != nullptr ? *info.look : WaterLook{};
  std::string problem;
  const std::string field = water_look_error(look, &problem);
  if (!field.empty()) return argument_error("CreateInfo::look." + field + " " + problem);
  return Status::success();
}

// The river of the scene (or the default one) with its obstacles, solved, with its static data;
// or the one of the renderer this one shares it with.
Status Renderer::Impl::create_river() {
  if (info.share_river_with != nullptr) {
    const Impl& other = *info.share_river_with->impl_;
    if (other.info.device != info.device) {
      return argument_error("CreateInfo::share_river_with renders on another device");
    }
    river = other.river;
    return Status::success();
  }
  RiverInput input;
  RiverFlowParams flow;
  std::vector<Obstacle> obstacles;
  if (info.river == nullptr) {  // the built-in default river and its boulders
    const ProceduralRiver procedural(default_river_params());
    SIVIFLOW_TRY(procedural_river_input(procedural, &input));
    obstacles = default_scene_obstacles(procedural);
  } else {
    SIVIFLOW_TRY(river_input_from(*info.river, &input));
    flow = info.river->flow;
    for (size_t i = 0; i < info.river->obstacles.size(); ++i) {
      const Status valid = check_obstacle(info.river->obstacles[i], i);
      if (!valid.ok()) return argument_error("CreateInfo::river->obstacles: " + valid.message());
      obstacles.push_back(flow_obstacle(info.river->obstacles[i]));
    }
  }
  const FlowParams params{flow.discharge, flow.shepard_power, flow.search_radius};
  return SharedRiver::create(table, info.allocation_callbacks, std::move(input), params,
                             std::move(obstacles), &river);
}

// This view's particles and flow textures, tile table size, staging ring and water passes.
Status Renderer::Impl::create_view_resources() {
  SIVIFLOW_TRY(simulation.create(river->flow, info.seed, {info.extent.width, info.extent.height}));
  tile_lattice.size(river->water_lo, river->water_hi, look.tile_size_m);
  water_frame.tiles.heights =
      glm::vec4(river->heights_origin, river->heights_spacing, look.tile_size_m);
  // Every frame's flow textures must fit a slot's staging block.
  info.staging_bytes_per_slot = std::max(info.staging_bytes_per_slot,
                                         VkDeviceSize{simulation.layout().total_bytes} + kStagingAlignment);
  SIVIFLOW_TRY(ring.init(gpu, info.frames_in_flight, info.staging_bytes_per_slot));
  return flow_pass.create(gpu, info.pipeline_cache, info.color_format, info.depth_format,
                          info.frames_in_flight, (info.readback_images & kAovReadbackImages) != 0,
                          info.enable_timing);
}

ImageHandle Renderer::Impl::frame_image(ImageHandle handle, bool persistent) {
  frame_images.push_back({handle, Image{}, persistent});
  return handle;
}

Status Renderer::Impl::declare_graph() {
  const VkExtent2D extent = info.extent;
  const VkExtent2D reflection_extent{
      std::max(1u, static_cast<uint32_t>(std::lround(extent.width * kDefaultReflectionScale))),
      std::max(1u, static_cast<uint32_t>(std::lround(extent.height * kDefaultReflectionScale)))};
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
      frame_image(graph.create_image({"reflection", info.color_format, reflection_extent, transparent}));
  reflection_depth = frame_image(
      graph.create_image({"reflection depth", kReflectionDepthFormat, reflection_extent, {}}));
  reflection_data = add_reflection_pass(graph, &reflection, &reflection_depth, info.reflection,
                                        info.reflection_user);

  // The host's images, in the states the host states per frame (record()); their declared
  // extent is the view's, the viewport is placed inside them when recording.
  host_color = graph.import_image({"host colour", info.color_format, extent, {}}, ResourceState{},
                                  state_of(Access::SampledFragment));
  host_depth = graph.import_image({"host depth", info.depth_format, extent, {}}, ResourceState{},
                                  state_of(Access::DepthAttachmentRead));

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
  if ((info.readback_images & kAovReadbackImages) != 0) {
    water.mask = frame_image(graph.create_image({"water mask", FlowPass::kMaskFormat, extent, transparent}));
    water.normal = frame_image(graph.create_image({"water normal", FlowPass::kNormalFormat, extent, transparent}));
    water.reflection_sample = frame_image(
        graph.create_image({"reflection sample", FlowPass::kReflectionFormat, extent, transparent}));
  }
  water.water_heights = river_assets.images[SharedRiver::kWaterHeights];
  water.tile_table = frame_image(graph.create_image(
      {"tile table", FlowPass::kTileTableFormat,
       {tile_lattice.layout().width, tile_lattice.layout().height}, {}}));
  flow_pass.declare_tiles(graph, &water);
  flow_pass.declare(graph, river->index_count, &water);
  if (info.enable_timing) {
    const ImageHandle floor =
        frame_image(graph.create_image({"flow floor", info.color_format, extent, {}}));
    flow_pass.declare_floor(graph, river->index_count, water, floor);
  }

  if (info.readback_images != 0) {
    const ImageHandle images[kReadbackImageCount] = {water.color,
                                                     host_depth,
                                                     water.mask,
                                                     frame_uploads.images[0].destination,
                                                     frame_uploads.images[1].destination,
                                                     water.normal,
                                                     water.reflection_sample,
                                                     water.tile_table};
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

void Renderer::Impl::destroy() {
  if (gpu.table == nullptr) return;  // failed before any Vulkan object existed
  flow_pass.destroy(gpu);
  for (FrameImage& f : frame_images) destroy_image(gpu, &f.image);
  timer.destroy(gpu);
  ring.destroy();
  river.reset();  // the last view of the river frees its static data
}

Status Renderer::create(const CreateInfo& info, std::unique_ptr<Renderer>* out) {
  return guarded(info, [&]() -> Status {
    if (out == nullptr) return argument_error("create: out must not be null");
    auto impl = std::make_unique<Impl>();
    Status status;
    try {
      status = impl->validate_info(info);
      if (status.ok()) status = impl->take_look();
      if (status.ok()) status = impl->create_river();
      if (status.ok()) status = impl->create_view_resources();
      if (status.ok()) status = impl->declare_graph();
      if (status.ok() && info.enable_timing) {
        status = impl->timer.create(impl->gpu, info.physical_device, info.queue_family_index,
                                    impl->info.frames_in_flight);
      }
      if (status.ok()) out->reset(new Renderer(std::move(impl)));
    } catch (...) {
      impl->destroy();  // the Vulkan objects made so far
      throw;
    }
    if (!status.ok()) impl->destroy();
    return status;
  });
}

Renderer::Renderer(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
Renderer::~Renderer() { impl_->destroy(); }

Status Renderer::begin_frame(uint32_t slot) {
  Impl& r = *impl_;
  return guarded(r.info, [&]() -> Status {
    if (r.unusable) return argument_error("a resize failed; resize again before rendering");
    SIVIFLOW_TRY(r.ring.begin_slot(slot));
    r.current_slot = slot;
    r.frame_begun = true;
    r.frame_updated = false;
    return Status::success();
  });
}

Status Renderer::Impl::simulate(const View& host_view, double time_seconds) {
  if (!std::isfinite(time_seconds)) {
    return argument_error("time " + std::to_string(time_seconds) + " is not finite");
  }
  ViewMath math;
  SIVIFLOW_TRY(derive_view_math(host_view.view, host_view.projection, &math));
  VkRect2D rect = host_view.viewport;
  if (rect.extent.width == 0 && rect.extent.height == 0) rect.extent = info.extent;
  if (rect.extent.width != info.extent.width || rect.extent.height != info.extent.height) {
    return argument_error("View::viewport extent " + extent_text(rect.extent) +
                          " differs from the configured view size " + extent_text(info.extent) +
                          " (resize() first)");
  }
  if (rect.offset.x < 0 || rect.offset.y < 0) {
    return argument_error("View::viewport offset (" + std::to_string(rect.offset.x) + ", " +
                          std::to_string(rect.offset.y) + ") is negative");
  }
  const float dt = simulation.next_frame() == 0 ? 0.0f : static_cast<float>(time_seconds - last_time);
  if (dt < 0.0f) return argument_error("time went backwards");
  SIVIFLOW_TRY(river->flow.set_time(time_seconds));
  SIVIFLOW_TRY(simulation.simulate(math.view_proj, dt));
  view = math;
  viewport = rect;

  // The reflection is the world mirrored about the water plane y = h, seen from the real
  // camera, so the flow pass samples it at its own screen position; only what is above the
  // water stays.
  const float h = visible_water_level();
  const glm::mat4 mirrored = mirrored_view_proj(view.view_proj, h);
  const glm::vec3 mirrored_camera = mirrored_point(view.camera_position, h);
  const glm::vec4 clip_plane(0.0f, 1.0f, 0.0f, -h + kReflectionClipBias);
  std::memcpy(reflection_view.view_proj, &mirrored[0][0], sizeof(reflection_view.view_proj));
  std::memcpy(reflection_view.clip_plane, &clip_plane[0], sizeof(reflection_view.clip_plane));
  std::memcpy(reflection_view.camera_position, &mirrored_camera[0],
              sizeof(reflection_view.camera_position));
  reflection_view.reverse_z = view.reverse_z;

  const FlowTextureLayout& layout = simulation.layout();
  water_frame.flow.view_proj = view.view_proj;
  water_frame.flow.camera_position = glm::vec4(view.camera_position, view.depth_ratio_constant);
  water_frame.flow.sun_direction = glm::vec4(glm::normalize(look.sun_direction), 0.0f);
  water_frame.flow.water = glm::vec4(h, look.reflection_distortion, look.tile_size_m,
                                   static_cast<float>(layout.texel_px));
  const float repeat_tiles = kTdfRepeatTiles * look.ripple_scale;
  water_frame.look.water_color = glm::vec4(look.water_color, look.absorption_per_metre);
  water_frame.look.deep_color = glm::vec4(look.deep_color, look.opacity_per_metre);
  water_frame.look.sun_color = glm::vec4(look.sun_color, look.ripple_strength);
  water_frame.look.surface = glm::vec4(look.fresnel_f0, repeat_tiles, 0.0f, 0.0f);
  // The view looks down its -Z axis: that axis's world direction is the inverse's third column.
  const glm::vec3 forward = -glm::vec3(glm::inverse(host_view.view)[2]);
  tile_lattice.place(river->water_lo, river->water_hi, look.tile_size_m, view.camera_position,
                     forward);
  const TileTableLayout& tiles = tile_lattice.layout();
  water_frame.tiles.heights.w = look.tile_size_m;
  water_frame.tiles.ripples = glm::vec4(repeat_tiles, 0.0f, 0.0f, 0.0f);
  water_frame.flow.screen = glm::vec4(rect.offset.x, rect.offset.y,
                                    1.0f / static_cast<float>(info.extent.width),
                                    1.0f / static_cast<float>(info.extent.height));
  water_frame.tiles.view_proj = view.view_proj;
  water_frame.tiles.lattice = glm::vec4(tiles.corner_x, tiles.corner_z, tiles.width, tiles.height);
  water_frame.tiles.screen =
      glm::vec4(info.extent.width, info.extent.height, static_cast<float>(layout.texel_px),
                static_cast<float>(std::fmod(time_seconds, SIVIFLOW_TDF_TIME_PERIOD)));
  last_time = time_seconds;
  return Status::success();
}

// The plane of the visible reach: the median height of this frame's live particles. They are
// spread evenly over the water on screen, so this is the level of most of the water seen (a
// level river's own level); a descending river's reflection is right where most of it shows.
float Renderer::Impl::visible_water_level() {
  std::vector<float>& heights = particle_heights;  // kept: a steady frame allocates nothing
  heights.clear();
  for (const Particle& p : simulation.particle_field().particles()) {
    if (p.live()) heights.push_back(p.world.y);
  }
  if (heights.empty()) return river->flow.mesh().positions.front().y;  // no water on screen
  const auto middle = heights.begin() + static_cast<std::ptrdiff_t>(heights.size() / 2);
  std::nth_element(heights.begin(), middle, heights.end());
  return *middle;
}

Status Renderer::simulate(const View& view, double time_seconds) {
  Impl& r = *impl_;
  return guarded(r.info, [&]() -> Status {
    if (r.frame_begun) return argument_error("simulate called between begin_frame and record");
    return r.simulate(view, time_seconds);
  });
}

Status Renderer::update(const View& view, double time_seconds) {
  Impl& r = *impl_;
  return guarded(r.info, [&]() -> Status {
    if (!r.frame_begun) return argument_error("update called before begin_frame");
    if (r.frame_updated) return argument_error("update called twice for one frame");
    // Staging first: a failure there must not leave the particles one frame ahead.
    const FlowTextureLayout& layout = r.simulation.layout();
    StagingAllocation staging;
    SIVIFLOW_TRY(r.ring.allocate_staging(layout.total_bytes, kStagingAlignment, &staging));
    SIVIFLOW_TRY(r.simulate(view, time_seconds));
    SIVIFLOW_TRY(r.simulation.pack({static_cast<std::byte*>(staging.data), layout.total_bytes}));
    r.frame_uploads.images[0].staging_offset = staging.offset + layout.flow_offset;
    r.frame_uploads.images[1].staging_offset = staging.offset + layout.aux_offset;
    StaticAssets& assets = r.river->assets;  // staged by the first view of the river to update
    if (!assets.uploaded() && !assets.staged()) SIVIFLOW_TRY(assets.stage(r.river->gpu));
    r.frame_updated = true;
    return Status::success();
  });
}

// The host's word on an image against the configuration: an error names the image and the
// value, before any command is recorded.
Status Renderer::Impl::check_inputs(const FrameInputs& inputs) const {
  const auto check = [this](const ExternalImage& image, const char* name, VkFormat format) {
    const std::string field = std::string("FrameInputs::") + name;
    if (image.image == VK_NULL_HANDLE || image.view == VK_NULL_HANDLE) {
      return argument_error(field + " needs an image and a view");
    }
    if (image.final.layout == VK_IMAGE_LAYOUT_UNDEFINED) {
      return argument_error(field + ".final.layout must not be UNDEFINED");
    }
    if (image.format != format) {
      return argument_error(field + ".format " + std::to_string(image.format) +
                            " differs from the configured " + std::to_string(format));
    }
    const uint64_t right = uint64_t{static_cast<uint32_t>(viewport.offset.x)} + viewport.extent.width;
    const uint64_t bottom = uint64_t{static_cast<uint32_t>(viewport.offset.y)} + viewport.extent.height;
    if (image.extent.width < right || image.extent.height < bottom) {
      return argument_error(field + ".extent " + extent_text(image.extent) +
                            " does not contain the view's viewport (" +
                            std::to_string(viewport.offset.x) + ", " +
                            std::to_string(viewport.offset.y) + ") + " +
                            extent_text(viewport.extent));
    }
    return Status::success();
  };
  // The AOV attachments are the view's size: they cannot sit at an offset in the host's images.
  if ((info.readback_images & kAovReadbackImages) != 0 &&
      (viewport.offset.x != 0 || viewport.offset.y != 0)) {
    return argument_error("with the water mask, normal or reflection read back, View::viewport "
                          "must start at the images' origin");
  }
  SIVIFLOW_TRY(check(inputs.color, "color", info.color_format));
  SIVIFLOW_TRY(check(inputs.depth, "depth", info.depth_format));
  for (const ReadbackImage kind : readback_kinds) {
    if (inputs.readback.buffers[static_cast<uint32_t>(kind)] == VK_NULL_HANDLE) {
      return argument_error(std::string("CreateInfo::readback_images asks for the ") +
                            readback_image_name(kind) + " but FrameInputs::readback has no buffer for it");
    }
  }
  return Status::success();
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
  // The water renders over the view's part of the host's images only.
  b.set_render_area(host_color, viewport);
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
  flow_pass.prepare_frame(gpu, water_frame);
  // What the passes read as they record: this frame's, through the graph's data handles.
  b.bind_data(flow_pass.frame_data(), &water_frame);
  b.bind_data(uploads_data, &frame_uploads);
  b.bind_data(reflection_data, &reflection_view);
  if (readbacks_data.valid()) b.bind_data(readbacks_data, &readbacks);
  return Status::success();
}

Status Renderer::record(VkCommandBuffer cmd, const FrameInputs& inputs) {
  Impl& r = *impl_;
  return guarded(r.info, [&]() -> Status {
    if (!r.frame_updated) return argument_error("record called before begin_frame and update");
    SIVIFLOW_TRY(r.check_inputs(inputs));
    StaticAssets& assets = r.river->assets;  // uploaded by the first view of the river to record
    if (!assets.uploaded()) {
      if (!assets.staged()) SIVIFLOW_TRY(assets.stage(r.river->gpu));
      SIVIFLOW_TRY(assets.record_upload(r.table, cmd));
    }
    SIVIFLOW_TRY(r.bind_frame(inputs));
    FrameGraph::Timestamps timestamps;
    if (r.timer.enabled()) {
      const auto passes = static_cast<uint32_t>(r.graph.pass_order().size());
      SIVIFLOW_TRY(r.timer.begin(r.table, cmd, r.current_slot, passes, &timestamps));
    }
    SIVIFLOW_TRY(r.graph.execute(r.table, cmd, r.bindings, r.timer.enabled() ? &timestamps : nullptr));
    if (!assets.uploaded()) assets.finish_upload(r.ring, r.river->gpu);
    r.frame_images_new = false;
    r.frame_begun = false;
    r.frame_updated = false;
    return Status::success();
  });
}

Status Renderer::resize(VkExtent2D extent) {
  Impl& r = *impl_;
  return guarded(r.info, [&] { return r.resize(extent); });
}

Status Renderer::Impl::resize(VkExtent2D extent) {
  Impl& r = *this;
  if (r.frame_begun) return argument_error("resize called between begin_frame and record");
  if (extent.width == 0 || extent.height == 0) return argument_error("resize: extent must be at least 1x1");
  VkPhysicalDeviceProperties2 props{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2};
  r.table.vkGetPhysicalDeviceProperties2(r.info.physical_device, &props);
  const uint32_t limit = props.properties.limits.maxImageDimension2D;
  if (extent.width > limit || extent.height > limit) {
    return argument_error("resize: extent " + extent_text(extent) + " exceeds the device limit of " +
                   std::to_string(limit));
  }
  // The particles live in screen space: a new viewport starts them afresh at frame 0. This can
  // fail (a size the particles cannot cover); nothing has changed then.
  SIVIFLOW_TRY(r.simulation.resize({extent.width, extent.height}));
  // Past this point the old configuration is gone: a failure leaves nothing to record with,
  // until a resize succeeds.
  Status status = r.ring.ensure_staging_capacity(r.simulation.layout().total_bytes + kStagingAlignment);
  if (status.ok()) {
    r.retire_frame_images();
    r.info.extent = extent;
    r.graph = FrameGraph{};
    r.bindings.reset();
    status = r.declare_graph();
  }
  r.unusable = !status.ok();
  return status;
}

VkDeviceSize Renderer::readback_bytes(ReadbackImage image) const {
  const VkDeviceSize pixels = VkDeviceSize{impl_->info.extent.width} * impl_->info.extent.height;
  switch (image) {
    case ReadbackImage::kColor:
      return pixels * texel_bytes(impl_->info.color_format);
    case ReadbackImage::kDepth:
    case ReadbackImage::kWaterMask:
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
  }
  return "readback";
}

const TileTableLayout& Renderer::tile_table_layout() const { return impl_->tile_lattice.layout(); }
const ParticleField& RendererInspector::particle_field(const Renderer& renderer) {
  return renderer.impl_->simulation.particle_field();
}
const FlowTextureLayout& RendererInspector::flow_texture_layout(const Renderer& renderer) {
  return renderer.impl_->simulation.layout();
}
uint64_t Renderer::next_frame() const { return impl_->simulation.next_frame(); }
uint64_t Renderer::flow_solves() const { return impl_->river->flow.full_solves(); }

Status Renderer::pass_times(uint32_t slot, std::vector<PassTime>* out) const {
  const Impl& r = *impl_;
  return guarded(r.info, [&] { return r.pass_times(slot, out); });
}

Status Renderer::Impl::pass_times(uint32_t slot, std::vector<PassTime>* out) const {
  out->clear();
  if (!timer.enabled()) return argument_error("pass_times needs CreateInfo::enable_timing");
  if (slot >= info.frames_in_flight) return argument_error("pass_times: slot out of range");
  return timer.pass_times(table, slot, graph.pass_order(), out);
}

std::string Renderer::dump_frame_graph() const { return impl_->graph.dump_text(); }
std::string Renderer::dump_frame_graph_graphviz() const { return impl_->graph.dump_graphviz(); }

}  // namespace siviflow
