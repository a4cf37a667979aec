#include "siviflow/renderer.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <optional>
#include <string>

#include <glm/gtc/matrix_transform.hpp>

#include "default_river.h"
#include "renderer_impl.h"
#include "renderer_inspect.h"
#include "siviflow/text_format.h"
#include "view_culling.h"
#include "vk/pipeline.h"
#include "vk/vk_text.h"

namespace siviflow {
namespace {

constexpr VkFormat kDefaultDepthFormat = VK_FORMAT_D32_SFLOAT;
constexpr float kTdfRepeatTiles = 3.5f;  // normal-map repeat in tiles at ripple scale 1 (van Hoesel 35/10)
constexpr float kReflectionClipBias = 0.02f;      // metres below the water kept, so no seam shows
// A TAA or upscaler jitter is under a pixel; an upscaler's (in output pixels of a 3x upscale)
// a few. Past this it is a mistake, not a jitter.
constexpr float kMaxJitterPixels = 64.0f;

std::string extent_text(VkExtent2D extent) {
  return std::to_string(extent.width) + "x" + std::to_string(extent.height);
}

std::string rect_text(const VkRect2D& rect) {
  return "(" + std::to_string(rect.offset.x) + ", " + std::to_string(rect.offset.y) + ") + " +
         extent_text(rect.extent);
}

bool rect_inside(const VkRect2D& inner, const VkRect2D& outer) {
  const int64_t right = int64_t{inner.offset.x} + inner.extent.width;
  const int64_t bottom = int64_t{inner.offset.y} + inner.extent.height;
  return inner.offset.x >= outer.offset.x && inner.offset.y >= outer.offset.y &&
         right <= int64_t{outer.offset.x} + outer.extent.width &&
         bottom <= int64_t{outer.offset.y} + outer.extent.height && inner.extent.width > 0 &&
         inner.extent.height > 0;
}

std::string api_version_text(uint32_t version) {
  return std::to_string(VK_API_VERSION_MAJOR(version)) + "." +
         std::to_string(VK_API_VERSION_MINOR(version));
}

// A command the table could not load. Vulkan 1.3 core commands are missing when the device or
// the instance (VkApplicationInfo::apiVersion) is older: say which, not only the command.
Status missing_function_error(const CreateInfo& info, const char* function, VkResult result) {
  std::string message = std::string("cannot load ") + function;
  const auto properties = reinterpret_cast<PFN_vkGetPhysicalDeviceProperties>(
      info.get_instance_proc_addr(info.instance, "vkGetPhysicalDeviceProperties"));
  if (properties != nullptr) {
    VkPhysicalDeviceProperties props{};
    properties(info.physical_device, &props);
    if (props.apiVersion < VK_API_VERSION_1_3) {
      message += ": the device supports Vulkan " + api_version_text(props.apiVersion) +
                 " and SiViFlow needs 1.3";
    } else {
      message += ", a Vulkan 1.3 command: create the instance with VkApplicationInfo::apiVersion "
                 "VK_API_VERSION_1_3 or later (the device supports " +
                 api_version_text(props.apiVersion) + ")";
    }
  }
  return Status::error(std::string(kRendererErrorPrefix) + message, result);
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

Status Renderer::Impl::validate_info(const CreateInfo& create) {
  info = create;
  if (info.instance == VK_NULL_HANDLE || info.physical_device == VK_NULL_HANDLE ||
      info.device == VK_NULL_HANDLE || info.get_instance_proc_addr == nullptr) {
    return argument_error("CreateInfo needs instance, physical_device, device and get_instance_proc_addr");
  }
  SIVIFLOW_TRY(check_create_info(info));
  river_from_world = glm::inverse(info.world_from_river);
  if (info.frames_in_flight == 0) info.frames_in_flight = kDefaultFramesInFlight;
  if (info.depth_format == VK_FORMAT_UNDEFINED) info.depth_format = kDefaultDepthFormat;
  if (info.staging_bytes_per_slot == 0) info.staging_bytes_per_slot = kDefaultStagingBytes;

  const char* missing_function = nullptr;
  const VkResult loaded = load_device_table(info.instance, info.physical_device, info.device,
                                            info.get_instance_proc_addr, info.get_device_proc_addr,
                                            info.debug_utils, &table, &missing_function);
  if (loaded != VK_SUCCESS) return missing_function_error(info, missing_function, loaded);
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
  // The water pass draws its temporal outputs and the AOVs it reads back beside the colour.
  const uint32_t attachments =
      1 + (info.motion_format != VK_FORMAT_UNDEFINED ? 1 : 0) +
      (info.reactive_format != VK_FORMAT_UNDEFINED ? 1 : 0) +
      ((info.readback_images & kAovReadbackImages) != 0 ? FlowPass::kAovAttachmentCount : 0);
  if (props.properties.limits.maxColorAttachments < attachments) {
    return Status::error("siviflow::Renderer: the motion and reactive outputs and the AOVs of "
                         "CreateInfo::readback_images make the water pass draw " +
                         std::to_string(attachments) +
                         " colour attachments, and this device draws at most " +
                         std::to_string(props.properties.limits.maxColorAttachments),
                         VK_ERROR_FEATURE_NOT_PRESENT);
  }
  // Drawn to with blending; and, as the refraction's copy, copied into, out of and sampled.
  SIVIFLOW_TRY(check_format_features(
      "color_format", info.color_format,
      VK_FORMAT_FEATURE_COLOR_ATTACHMENT_BIT | VK_FORMAT_FEATURE_COLOR_ATTACHMENT_BLEND_BIT |
          VK_FORMAT_FEATURE_SAMPLED_IMAGE_BIT | VK_FORMAT_FEATURE_TRANSFER_SRC_BIT |
          VK_FORMAT_FEATURE_TRANSFER_DST_BIT,
      "the water blends into it, copies it and samples the copy"));
  SIVIFLOW_TRY(check_format_features(
      "color_format's reflection target", reflection_format(info.color_format),
      VK_FORMAT_FEATURE_COLOR_ATTACHMENT_BIT | VK_FORMAT_FEATURE_SAMPLED_IMAGE_BIT |
          VK_FORMAT_FEATURE_SAMPLED_IMAGE_FILTER_LINEAR_BIT,
      "the reflection is drawn to and sampled filtered"));
  SIVIFLOW_TRY(check_format_features(
      "depth_format", info.depth_format,
      VK_FORMAT_FEATURE_DEPTH_STENCIL_ATTACHMENT_BIT | VK_FORMAT_FEATURE_SAMPLED_IMAGE_BIT,
      "the water tests against it and samples it"));
  if (info.motion_format != VK_FORMAT_UNDEFINED) {
    SIVIFLOW_TRY(check_format_features("motion_format", info.motion_format,
                                       VK_FORMAT_FEATURE_COLOR_ATTACHMENT_BIT,
                                       "the water draws its motion into it"));
  }
  if (info.reactive_format != VK_FORMAT_UNDEFINED) {
    SIVIFLOW_TRY(check_format_features("reactive_format", info.reactive_format,
                                       VK_FORMAT_FEATURE_COLOR_ATTACHMENT_BIT,
                                       "the water draws its reactive mask into it"));
  }
  return Status::success();
}

Status Renderer::Impl::check_format_features(const char* field, VkFormat format,
                                             VkFormatFeatureFlags needs, const char* why) const {
  VkFormatProperties props{};
  table.vkGetPhysicalDeviceFormatProperties(info.physical_device, format, &props);
  const VkFormatFeatureFlags missing = needs & ~props.optimalTilingFeatures;
  if (missing == 0) return Status::success();
  return Status::error(std::string(kRendererErrorPrefix) + "CreateInfo::" + field + " " +
                           format_name(format) + " lacks " + format_feature_text(missing) +
                           " on this device (" + why + ")",
                       VK_ERROR_FORMAT_NOT_SUPPORTED);
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
    if (other.info.world_from_river != info.world_from_river) {
      return argument_error("CreateInfo::world_from_river differs from that of the renderer in "
                            "CreateInfo::share_river_with (one river lies in one place)");
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
    flow = info.river->flow;
    for (size_t i = 0; i < info.river->obstacles.size(); ++i) {
      const Status valid = check_obstacle(info.river->obstacles[i], i);
      if (!valid.ok()) return argument_error("CreateInfo::river->obstacles: " + valid.message());
      obstacles.push_back(flow_obstacle(info.river->obstacles[i]));
    }
    // Called as soon as the surface holds its own nodes and triangles: a long river's mesh is not
    // held twice while its topology is found.
    const auto copied = [this] {
      if (info.river_copied != nullptr) info.river_copied(info.river_copied_user);
    };
    SIVIFLOW_TRY(river_input_from(*info.river, copied, &input));
  }
  const FlowParams params = river_flow_params(flow, input);
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
  FlowPass::Config config;
  config.color_format = info.color_format;
  config.depth_format = info.depth_format;
  config.motion_format = info.motion_format;
  config.reactive_format = info.reactive_format;
  config.slot_count = info.frames_in_flight;
  config.with_aovs = (info.readback_images & kAovReadbackImages) != 0;
  config.with_floor = info.enable_timing && info.measure_flow_floor;
  config.with_depth = info.write_depth;
  config.material = look.material;
  return flow_pass.create(gpu, info.pipeline_cache, config);
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
    // An updated frame's particles moved on: skipping its record would drop a frame of them.
    if (r.frame_updated && !r.record_failed) {
      return argument_error("begin_frame called again before record: record the updated frame, "
                            "or abandon_frame() it");
    }
    SIVIFLOW_TRY(r.ring.begin_slot(slot));
    r.frame_recorded = false;
    r.record_failed = false;
    r.current_slot = slot;
    r.frame_begun = true;
    r.frame_updated = false;
    return Status::success();
  });
}

Status Renderer::abandon_frame() {
  Impl& r = *impl_;
  return guarded(r.info, [&]() -> Status {
    if (!r.frame_begun) {
      return argument_error("abandon_frame called without a frame begun and not recorded (a "
                            "recorded frame is submitted)");
    }
    r.frame_begun = false;
    r.frame_updated = false;
    return Status::success();
  });
}

Status Renderer::Impl::simulate(const View& host_view, double time_seconds) {
  if (!std::isfinite(time_seconds)) {
    return argument_error("time " + std::to_string(time_seconds) + " is not finite");
  }
  const glm::vec2 jitter = host_view.jitter;
  if (!std::isfinite(jitter.x) || !std::isfinite(jitter.y) ||
      std::max(std::abs(jitter.x), std::abs(jitter.y)) > kMaxJitterPixels) {
    return argument_error("View::jitter (" + text_format("%g, %g", jitter.x, jitter.y) +
                          ") is not a finite offset within " +
                          text_format("%g", kMaxJitterPixels) + " pixels");
  }
  // The renderer works in river space: the host's view of the river is its view of the world
  // after world_from_river.
  ViewMath math;
  SIVIFLOW_TRY(
      derive_view_math(host_view.view * info.world_from_river, host_view.projection, &math));
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
  VkRect2D clip = host_view.scissor;
  if (clip.extent.width == 0 && clip.extent.height == 0) clip = rect;
  if (!rect_inside(clip, rect)) {
    return argument_error("View::scissor " + rect_text(clip) + " is not inside the viewport " +
                          rect_text(rect));
  }
  const float dt = simulation.next_frame() == 0 ? 0.0f : static_cast<float>(time_seconds - last_time);
  if (dt < 0.0f) return argument_error("time went backwards");
  // Particles are placed and kept in the unjittered view: jitter churns none of them.
  const glm::mat4 steady = shifted_by_pixels(
      math.view_proj, -jitter, glm::vec2(info.extent.width, info.extent.height));
  SIVIFLOW_TRY(river->flow.set_time(time_seconds));
  SIVIFLOW_TRY(simulation.simulate(steady, dt));
  view = math;
  viewport = rect;
  scissor = clip;
  // Motion is measured from the last frame the host was shown (recorded, or simulated in its
  // place), not from one it dropped.
  previous_view_proj = has_shown && !host_view.camera_cut ? shown_view_proj : steady;
  steady_view_proj = steady;

  // The reflection is the world mirrored about the water plane y = h of river space, seen from
  // the real camera, so the flow pass samples it at its own screen position; only what is above
  // the water stays. The host draws it in its world: river space is left again on both sides.
  const float h = visible_water_level();
  const glm::mat4 mirrored =
      mirrored_view_proj(host_view.jitter_reflection ? view.view_proj : steady, h) *
      river_from_world;
  const glm::vec3 mirrored_camera =
      glm::vec3(info.world_from_river * glm::vec4(mirrored_point(view.camera_position, h), 1.0f));
  const glm::vec4 clip_plane = glm::transpose(river_from_world) *
                               glm::vec4(0.0f, 1.0f, 0.0f, -h + kReflectionClipBias);
  std::memcpy(reflection_view.view_proj, &mirrored[0][0], sizeof(reflection_view.view_proj));
  std::memcpy(reflection_view.clip_plane, &clip_plane[0], sizeof(reflection_view.clip_plane));
  std::memcpy(reflection_view.camera_position, &mirrored_camera[0],
              sizeof(reflection_view.camera_position));
  reflection_view.reverse_z = view.reverse_z;

  choose_water_draws();
  reflection_view.area = sampled_area(water_bounds, look.reflection_distortion,
                                      reflection_extent(info.extent));
  refraction_copy = {rect.offset,
                     sampled_area(water_bounds, look.refraction_distortion, info.extent)};
  const FlowTextureLayout& layout = simulation.layout();
  water_frame.flow.view_proj = view.view_proj;
  water_frame.flow.camera_position = glm::vec4(view.camera_position, view.depth_ratio_constant);
  water_frame.flow.sun_direction = glm::vec4(glm::normalize(look.sun_direction), 0.0f);
  water_frame.flow.water = glm::vec4(h, look.reflection_distortion, look.tile_size_m,
                                   static_cast<float>(layout.texel_px));
  const float repeat_tiles = kTdfRepeatTiles * look.ripple_scale;
  water_frame.look.water_color = glm::vec4(look.water_color, look.absorption_per_metre);
  water_frame.look.deep_color = glm::vec4(look.deep_color, 0.0f);
  water_frame.look.sun_color = glm::vec4(look.sun_color, look.ripple_strength);
  water_frame.look.foam = glm::vec4(look.foam_color, look.foam_amount);
  water_frame.look.surface = glm::vec4(look.fresnel_f0, repeat_tiles, look.sun_glint,
                                         static_cast<float>(debug_view));
  const float wrapped_time = static_cast<float>(std::fmod(time_seconds, SIVIFLOW_TDF_TIME_PERIOD));
  water_frame.look.clock = glm::vec4(wrapped_time, 0.0f, 0.0f, 0.0f);
  water_frame.material = look.material;
  water_frame.debug_view = debug_view;
  water_frame.look.refraction =
      glm::vec4(look.opacity_per_metre * look.opacity_tint, look.refraction_distortion);
  water_frame.look.temporal = glm::vec4(look.reactive_strength, 0.0f, 0.0f, 0.0f);
  water_frame.look.motion_now = steady_view_proj;
  water_frame.look.motion_before = previous_view_proj;
  tile_lattice.place(river->water_lo, river->water_hi, look.tile_size_m, view.camera_position,
                     view.forward);
  const TileTableLayout& tiles = tile_lattice.layout();
  water_frame.tiles.heights.w = look.tile_size_m;
  water_frame.tiles.ripples = glm::vec4(repeat_tiles, 0.0f, 0.0f, 0.0f);
  water_frame.flow.screen = glm::vec4(rect.offset.x, rect.offset.y,
                                    1.0f / static_cast<float>(info.extent.width),
                                    1.0f / static_cast<float>(info.extent.height));
  // The tiles pick their particles where the particles were placed: in the unjittered view.
  water_frame.tiles.view_proj = steady_view_proj;
  water_frame.tiles.lattice = glm::vec4(tiles.corner_x, tiles.corner_z, tiles.width, tiles.height);
  water_frame.tiles.screen =
      glm::vec4(info.extent.width, info.extent.height, static_cast<float>(layout.texel_px),
                wrapped_time);
  last_time = time_seconds;
  return Status::success();
}

// The chunks of the surface inside the view, neighbours joined into one draw: a river's GPU cost
// follows what is on screen, not its length.
void Renderer::Impl::choose_water_draws() {
  water_draws.clear();
  water_bounds = glm::vec4(1.0f, 1.0f, 0.0f, 0.0f);
  for (const SharedRiver::Chunk& chunk : river->chunks) {
    if (box_outside_view(chunk.lo, chunk.hi, view.view_proj)) continue;
    const glm::vec4 bounds = box_screen_bounds(chunk.lo, chunk.hi, view.view_proj);
    water_bounds = glm::vec4(glm::min(glm::vec2(water_bounds), glm::vec2(bounds)),
                             glm::max(glm::vec2(water_bounds.z, water_bounds.w),
                                      glm::vec2(bounds.z, bounds.w)));
    if (!water_draws.empty() && water_draws.back().first_index + water_draws.back().index_count ==
                                    chunk.indices.first_index) {
      water_draws.back().index_count += chunk.indices.index_count;
    } else {
      water_draws.push_back(chunk.indices);
    }
  }
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
  if (heights.empty()) return river->flow.positions().front().y;  // no water on screen
  const auto middle = heights.begin() + static_cast<std::ptrdiff_t>(heights.size() / 2);
  std::nth_element(heights.begin(), middle, heights.end());
  return *middle;
}

Status Renderer::simulate(const View& view, double time_seconds) {
  Impl& r = *impl_;
  return guarded(r.info, [&]() -> Status {
    if (r.frame_begun) return argument_error("simulate called between begin_frame and record");
    SIVIFLOW_TRY(r.simulate(view, time_seconds));
    r.show_frame();  // a frame advanced in place of a rendered one
    return Status::success();
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
  const auto check = [this](const ExternalImage& image, const char* name, VkFormat format,
                            VkImageUsageFlags needs, std::optional<ReadbackImage> copy) {
    const std::string field = std::string("FrameInputs::") + name;
    if (copy && (info.readback_images & readback_bit(*copy)) != 0) {
      needs |= VK_IMAGE_USAGE_TRANSFER_SRC_BIT;
    }
    if (image.image == VK_NULL_HANDLE || image.view == VK_NULL_HANDLE) {
      return argument_error(field + " needs an image and a view");
    }
    if (image.final.layout == VK_IMAGE_LAYOUT_UNDEFINED) {
      return argument_error(field + ".final.layout must not be UNDEFINED");
    }
    if (image.format != format) {
      return argument_error(field + ".format " + format_name(image.format) +
                            " differs from the configured " + format_name(format));
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
    if ((image.usage & needs) != needs) {
      return argument_error(field + ".usage " + image_usage_text(image.usage) + " lacks " +
                            image_usage_text(needs & ~image.usage));
    }
    return Status::success();
  };
  // The AOV attachments are the view's size: they cannot sit at an offset in the host's images.
  if ((info.readback_images & kAovReadbackImages) != 0 &&
      (viewport.offset.x != 0 || viewport.offset.y != 0)) {
    return argument_error("with the water mask, normal, reflection or foam read back, View::viewport "
                          "must start at the images' origin");
  }
  SIVIFLOW_TRY(check(inputs.color, "color", info.color_format,
                     VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT,
                     ReadbackImage::kColor));
  SIVIFLOW_TRY(check(inputs.depth, "depth", info.depth_format,
                     VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT | VK_IMAGE_USAGE_SAMPLED_BIT,
                     ReadbackImage::kDepth));
  if (info.motion_format != VK_FORMAT_UNDEFINED) {
    SIVIFLOW_TRY(check(inputs.motion, "motion", info.motion_format,
                       VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT, std::nullopt));
  }
  if (info.reactive_format != VK_FORMAT_UNDEFINED) {
    SIVIFLOW_TRY(check(inputs.reactive, "reactive", info.reactive_format,
                       VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT, std::nullopt));
  }
  for (const ReadbackImage kind : readback_kinds) {
    if (inputs.readback.buffers[static_cast<uint32_t>(kind)] == VK_NULL_HANDLE) {
      return argument_error(std::string("CreateInfo::readback_images asks for the ") +
                            readback_image_name(kind) + " but FrameInputs::readback has no buffer for it");
    }
  }
  return Status::success();
}

Status Renderer::record(VkCommandBuffer cmd, const FrameInputs& inputs) {
  Impl& r = *impl_;
  const Status status = guarded(r.info, [&]() -> Status {
    if (r.frame_recorded) {
      return argument_error("record called twice for one frame: begin_frame and update start "
                            "the next");
    }
    if (!r.frame_begun) return argument_error("record called before begin_frame and update");
    if (!r.frame_updated) return argument_error("record called before update");
    SIVIFLOW_TRY(r.check_inputs(inputs));
    // A pipeline the frame's material needs is compiled before anything is recorded.
    SIVIFLOW_TRY(r.flow_pass.prepare_pipeline(r.gpu, r.water_frame));
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
    r.frame_recorded = true;
    r.show_frame();
    return Status::success();
  });
  // The host may record again, or begin the next frame and drop this one.
  if (!status.ok()) r.record_failed = true;
  return status;
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
  r.has_shown = false;  // the particles start afresh: no motion from the old size
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

Renderer::Bounds Renderer::river_bounds() const {
  const Impl& r = *impl_;
  const glm::vec3 lo = r.river->surface_min;
  const glm::vec3 hi = r.river->surface_max;
  // The box of the river-space box's corners in the host's world.
  Bounds bounds{glm::vec3(std::numeric_limits<float>::max()),
                glm::vec3(-std::numeric_limits<float>::max())};
  for (int corner = 0; corner < 8; ++corner) {
    const glm::vec3 p((corner & 1) != 0 ? hi.x : lo.x, (corner & 2) != 0 ? hi.y : lo.y,
                      (corner & 4) != 0 ? hi.z : lo.z);
    const glm::vec3 world = glm::vec3(r.info.world_from_river * glm::vec4(p, 1.0f));
    bounds.min = glm::min(bounds.min, world);
    bounds.max = glm::max(bounds.max, world);
  }
  return bounds;
}

const TileTableLayout& Renderer::tile_table_layout() const { return impl_->tile_lattice.layout(); }
const ParticleField& RendererInspector::particle_field(const Renderer& renderer) {
  return renderer.impl_->simulation.particle_field();
}
const FlowTextureLayout& RendererInspector::flow_texture_layout(const Renderer& renderer) {
  return renderer.impl_->simulation.layout();
}
const RiverFlowField& RendererInspector::flow_field(const Renderer& renderer) {
  return renderer.impl_->river->flow.field();
}
uint32_t RendererInspector::drawn_water_triangles(const Renderer& renderer) {
  uint32_t indices = 0;
  for (const IndexRange& run : renderer.impl_->water_draws) indices += run.index_count;
  return indices / 3;
}
bool RendererInspector::flow_reads_gpu_mesh(const Renderer& renderer) {
  const SharedRiver& river = *renderer.impl_->river;
  return river.flow.positions().data() ==
             river.assets.buffer(SharedRiver::kRiverVertices).mapped &&
         river.flow.indices().data() == river.assets.buffer(SharedRiver::kRiverIndices).mapped;
}
VkRect2D RendererInspector::reflection_area(const Renderer& renderer) {
  return renderer.impl_->reflection_view.area;
}
VkExtent2D RendererInspector::reflection_extent(const Renderer& renderer) {
  return siviflow::reflection_extent(renderer.impl_->info.extent);
}
VkRect2D RendererInspector::refraction_area(const Renderer& renderer) {
  return renderer.impl_->refraction_copy.area;
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
