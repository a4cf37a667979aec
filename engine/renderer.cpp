#include "siviflow/renderer.h"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstring>
#include <string>

#include <glm/gtc/matrix_transform.hpp>

#include "passes/passes.h"
#include "scene/default_scene.h"
#include "scene/detail_texture.h"
#include "scene/river_simulation.h"
#include "scene/scene_objects.h"
#include "scene/water_normal_map.h"
#include "siviflow/scene_file.h"
#include "siviflow/scene_river.h"
#include "sim/water_heights.h"
#include "vk/device_table.h"
#include "vk/frame_graph.h"
#include "vk/frame_ring.h"
#include "vk/gpu_resources.h"
#include "vk/pipeline.h"

namespace siviflow {
namespace {

constexpr uint32_t kDefaultFramesInFlight = 2;
constexpr uint32_t kMaxFramesInFlight = 8;
constexpr VkFormat kDefaultColorFormat = VK_FORMAT_R16G16B16A16_SFLOAT;
constexpr VkFormat kDepthFormat = VK_FORMAT_D32_SFLOAT;
constexpr VkDeviceSize kDefaultStagingBytes = 8ull << 20;
constexpr VkDeviceSize kStagingAlignment = 16;  // covers every texel size we copy
// Layouts documented in shaders/shared.h.
constexpr VkFormat kFlowTextureFormat = VK_FORMAT_R16G16B16A16_UINT;
constexpr VkFormat kParticleAuxFormat = VK_FORMAT_R32G32B32A32_SFLOAT;
constexpr VkFormat kNormalMapFormat = VK_FORMAT_R8G8B8A8_UNORM;
constexpr VkFormat kDetailFormat = VK_FORMAT_R8G8B8A8_UNORM;
constexpr VkFormat kBaseColorFormat = VK_FORMAT_R8G8B8A8_SRGB;
constexpr float kDefaultReflectionScale = 0.5f;
constexpr uint32_t kMaxTimedPasses = 16;  // reflection target size relative to the output

// Tunables of the water's look, in one place.
constexpr float kReflectionDistortion = 0.04f;    // screen uv offset per unit of normal tilt
constexpr float kTdfTileMetres = 3.0f;            // Tiled Directional Flow tile size on the water
constexpr uint32_t kMaxWaterHeightSamples = 2048;  // per axis: 16 MiB at most, samples widen beyond
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


// The constants that draw a model placed at `offset` with the scene shaders, which work in the
// model's coordinates: clip and fog see the same distances as for the translated model.
gpu::SceneConstants translated(const gpu::SceneConstants& constants, glm::vec3 offset) {
  gpu::SceneConstants moved = constants;
  moved.view_proj = constants.view_proj * glm::translate(glm::mat4(1.0f), offset);
  moved.camera_position = constants.camera_position - glm::vec4(offset, 0.0f);
  moved.clip_plane.w += glm::dot(glm::vec3(constants.clip_plane), offset);
  moved.fog.z += offset.y;  // height fog needs the world height, not the model's
  return moved;
}

Status invalid(const std::string& message) {
  return Status::error("siviflow::Renderer: " + message, VK_ERROR_INITIALIZATION_FAILED);
}

// The bytes of a contiguous container, for the static upload.
template <typename Items>
std::vector<uint8_t> bytes_of(const Items& items) {
  const auto* first = reinterpret_cast<const uint8_t*>(items.data());
  return std::vector<uint8_t>(first, first + items.size() * sizeof(items[0]));
}

// The longest triangle edge of a mesh, seen from above.
float longest_edge_xz(const std::vector<glm::vec3>& positions,
                      const std::vector<uint32_t>& indices) {
  float longest = 0.0f;
  for (size_t t = 0; t + 2 < indices.size(); t += 3) {
    for (int e = 0; e < 3; ++e) {
      const glm::vec3 d = positions[indices[t + e]] - positions[indices[t + (e + 1) % 3]];
      longest = std::max(longest, glm::length(glm::vec2(d.x, d.z)));
    }
  }
  return longest;
}

}  // namespace

const char* version_string() { return "siviflow 0.1.0"; }

struct Renderer::Impl {
  CreateInfo info;
  DeviceTable table;
  GpuContext gpu;
  FrameRing ring;
  ProceduralRiver river{default_river_params()};  // the default scene's, or the scene file's
  bool river_from_file = false;  // a glTF river: no valley, its bed drawn from its own depth
  RiverInput river_input;         // handed to the simulation by create_static_resources
  std::vector<float> particle_heights;  // this frame's live particles' heights
  FlowParams flow_params{kDefaultSceneDischarge, kDefaultShepardPower, 0.0f};
  std::vector<Obstacle> obstacles;  // each drawn as a boulder where it is this frame
  SceneObjects objects;             // the scene file's glTF objects, drawn where they stand
  std::vector<Obstacle> object_obstacles;  // footprints of the objects marked obstacle
  SceneCamera camera_path;          // keys empty: the default camera gliding downstream
  SceneLook look = default_scene_look();
  RiverSimulation simulation;  // the river's flow, particles and flow textures, on the CPU
  double last_time = 0.0;

  // Geometry and textures that never change: copied to the GPU once by the static graph, then
  // only read by the frame graph, so later frames carry no upload barriers for them.
  enum StaticBufferId {
    kSceneVertices, kSceneIndices, kRiverVertices, kRiverDepths, kRiverIndices, kStaticBufferCount
  };
  struct StaticBuffer {
    const char* name;
    Access read_as;  // how the frame graph reads it
    VkBufferUsageFlags usage;
    std::vector<uint8_t> bytes;  // kept until staged for the first frame
    Buffer buffer;
    BufferHandle in_frame_graph;
  };
  std::array<StaticBuffer, kStaticBufferCount> static_buffers{{
      {"scene vertices", Access::VertexBufferRead, VK_BUFFER_USAGE_VERTEX_BUFFER_BIT, {}, {}, {}},
      {"scene indices", Access::IndexBufferRead, VK_BUFFER_USAGE_INDEX_BUFFER_BIT, {}, {}, {}},
      {"river vertices", Access::VertexBufferRead, VK_BUFFER_USAGE_VERTEX_BUFFER_BIT, {}, {}, {}},
      {"river depths", Access::VertexBufferRead, VK_BUFFER_USAGE_VERTEX_BUFFER_BIT, {}, {}, {}},
      {"river indices", Access::IndexBufferRead, VK_BUFFER_USAGE_INDEX_BUFFER_BIT, {}, {}, {}}}};
  enum StaticImageId { kDetail, kNormalMap, kWaterHeights, kFirstBaseColor };
  struct StaticImage {
    const char* name;
    VkFormat format;
    VkExtent2D extent;
    std::vector<uint8_t> texels;         // every mip level, kept until staged
    std::vector<size_t> mip_offsets;     // into texels
    Image image;
    ImageHandle in_frame_graph;
    Access read_as = Access::SampledFragment;  // how the frame graph reads it
  };
  // The detail texture, the water normal map, the water heights, then the objects' base-colour
  // textures.
  std::vector<StaticImage> static_images{
      {"ground detail", kDetailFormat, {}, {}, {}, {}, {}},
      {"water normal map", kNormalMapFormat, {}, {}, {}, {}, {}},
      {"water heights", FlowPass::kWaterHeightsFormat, {}, {}, {}, {}, {}, Access::SampledCompute}};
  // What the scene and reflection passes draw: the static scene, and the moving boulder with
  // its own constants (translated to where its obstacle is this frame).
  std::vector<SceneDraw> scene_draws;
  std::vector<SceneDraw> reflection_draws;
  std::vector<glm::vec3> obstacle_offsets;  // this frame's obstacle centres
  std::vector<gpu::SceneConstants> obstacle_constants;  // per obstacle: main view, then mirrored
  uint32_t river_index_count = 0;
  ScenePass scene_pass;
  FlowPass flow_pass;

  FrameGraph static_graph;
  BufferHandle static_staging;
  UploadList static_uploads;
  Buffer static_staging_buffer;  // sized for the static data; freed when its slot comes round

  // Images the frame graph declares; created after it compiles, with the usage it derived.
  struct FrameImage {
    ImageHandle handle;
    Image image;
    bool persistent = false;  // keeps its contents from frame to frame
  };
  std::vector<FrameImage> frame_images;
  bool frame_images_new = true;  // persistent ones have no previous contents yet

  FrameGraph graph;
  BufferHandle frame_staging;  // the slot's staging block: this frame's flow textures
  UploadList frame_uploads;    // flow texture and particle aux, every frame
  ImageHandle output;
  std::vector<ReadbackCopy> readbacks;  // one per ReadbackImage when readback is enabled
  FrameBindings bindings;
  gpu::SceneConstants constants{};
  gpu::SceneConstants reflection_constants{};
  gpu::FlowConstants flow_constants{};
  gpu::FlowTileConstants tile_constants{};
  // The tile table's lattice (shaders/shared.h): the points the water heights cover, and the
  // table's size, a power of two per axis.
  glm::ivec2 lattice_lo{0};
  glm::ivec2 lattice_hi{0};
  TileTableLayout tile_table;  // its corner moves with the camera when the river is larger

  // With CreateInfo::enable_timing: per slot, two timestamps around each pass of the graph.
  std::vector<VkQueryPool> query_pools;
  std::vector<uint32_t> timed_passes;  // per slot: passes recorded with timestamps
  uint32_t current_slot = 0;
  float timestamp_period_ns = 1.0f;
  uint64_t timestamp_mask = ~uint64_t{0};  // the queue's valid timestamp bits

  bool static_data_uploaded = false;
  bool unusable = false;  // a resize failed half-way
  bool frame_begun = false;
  bool frame_updated = false;

  Status validate_info(const CreateInfo& create);
  Status take_scene();
  Status create_static_resources();
  Status declare_static_graph();
  Status declare_graph();
  ImageHandle frame_image(ImageHandle handle, bool persistent = false);
  Status create_frame_images();
  const Image* find_frame_image(ImageHandle handle) const;
  Status stage_static_data();
  void make_tile_lattice(const std::vector<glm::vec3>& surface,
                         const std::vector<uint32_t>& indices);
  glm::ivec2 tile_window(const Camera& camera) const;
  Status simulate(const Camera& camera, double time_seconds);
  float visible_water_level();
  Status record_static_upload(VkCommandBuffer cmd);
  Status create_query_pools();
  void declare_host_reflection(ScenePass::Handles* mirrored);
  void retire_frame_images();
  void destroy();
};

Status Renderer::Impl::validate_info(const CreateInfo& create) {
  info = create;
  if (info.instance == VK_NULL_HANDLE || info.physical_device == VK_NULL_HANDLE ||
      info.device == VK_NULL_HANDLE || info.get_instance_proc_addr == nullptr) {
    return invalid("CreateInfo needs instance, physical_device, device and get_instance_proc_addr");
  }
  if (info.extent.width == 0 || info.extent.height == 0) {
    return invalid("CreateInfo::extent must be at least 1x1");
  }
  if (info.frames_in_flight == 0) info.frames_in_flight = kDefaultFramesInFlight;
  if (info.frames_in_flight > kMaxFramesInFlight) {
    return invalid("CreateInfo::frames_in_flight " + std::to_string(info.frames_in_flight) +
                   " exceeds " + std::to_string(kMaxFramesInFlight));
  }
  if (info.color_format == VK_FORMAT_UNDEFINED) info.color_format = kDefaultColorFormat;
  if (texel_bytes(info.color_format) == 0) {
    return invalid("CreateInfo::color_format " + std::to_string(info.color_format) +
                   " is not an RGBA8, RGBA16F or RGBA32F format");
  }
  if (info.staging_bytes_per_slot == 0) info.staging_bytes_per_slot = kDefaultStagingBytes;

  const char* missing_function = nullptr;
  const VkResult loaded = load_device_table(info.instance, info.physical_device, info.device,
                                            info.get_instance_proc_addr, info.get_device_proc_addr,
                                            info.debug_utils, &table, &missing_function);
  if (loaded != VK_SUCCESS) {
    return Status::error(std::string("siviflow::Renderer: cannot load ") + missing_function, loaded);
  }
  gpu = make_gpu_context(table, info.allocation_callbacks);
  if (info.enabled_features == nullptr) {
    return invalid("CreateInfo::enabled_features must point to the feature chain the device was "
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
    return invalid("CreateInfo::queue_family_index " + std::to_string(info.queue_family_index) +
                   " is not a graphics queue family of this device");
  }
  VkPhysicalDeviceProperties2 props{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2};
  table.vkGetPhysicalDeviceProperties2(info.physical_device, &props);
  const uint32_t limit = props.properties.limits.maxImageDimension2D;
  if (info.extent.width > limit || info.extent.height > limit) {
    return invalid("extent " + std::to_string(info.extent.width) + "x" +
                   std::to_string(info.extent.height) + " exceeds the device limit of " +
                   std::to_string(limit));
  }
  VkFormatProperties format_props;
  table.vkGetPhysicalDeviceFormatProperties(info.physical_device, info.color_format, &format_props);
  if ((format_props.optimalTilingFeatures & VK_FORMAT_FEATURE_COLOR_ATTACHMENT_BIT) == 0) {
    return Status::error("siviflow::Renderer: color_format cannot be rendered to on this device",
                         VK_ERROR_FORMAT_NOT_SUPPORTED);
  }
  return Status::success();
}

Status Renderer::Impl::take_scene() {
  if (info.scene == nullptr) {
    obstacles = default_scene_obstacles(river);
    return procedural_river_input(river, &river_input);
  }
  const SceneFile& scene = *info.scene;
  const auto in_scene = [&scene](const Status& status) {
    return status.ok() ? status : Status::error(scene.path + ": " + status.message(), status.code());
  };
  if (scene.river.source == SceneRiver::Source::kGltf) {
    TriangleMesh gltf;
    SIVIFLOW_TRY(in_scene(load_river_mesh(scene.river.gltf, scene.river.mesh, &gltf)));
    SIVIFLOW_TRY(in_scene(gltf_river_input(std::move(gltf), &river_input)));
    river_from_file = true;
  } else {
    SIVIFLOW_TRY(in_scene(ProceduralRiver::validate(scene.river.procedural)));
    river = ProceduralRiver(scene.river.procedural);
    SIVIFLOW_TRY(in_scene(procedural_river_input(river, &river_input)));
  }
  flow_params = scene.flow;
  obstacles = scene.obstacles;
  camera_path = scene.camera;
  SIVIFLOW_TRY(load_scene_objects(scene, &objects));
  return scene_object_obstacles(scene, river_input.mesh.positions, &object_obstacles);
}

Status Renderer::Impl::create_static_resources() {
  SceneGeometry geometry = river_from_file ? build_riverbed_geometry(river_input.mesh, obstacles)
                                           : build_scene_geometry(river, obstacles);
  // Sized once: the draws point into it.
  obstacle_constants.resize(2 * obstacles.size());
  scene_draws = {{0, geometry.static_index_count, &constants}};
  reflection_draws = {{0, geometry.static_index_count, &reflection_constants}};
  for (size_t i = 0; i < geometry.obstacle_boulders.size(); ++i) {
    const SceneGeometry::Instance& boulder = geometry.obstacle_boulders[i];
    scene_draws.push_back({boulder.first_index, boulder.index_count, &obstacle_constants[2 * i]});
    reflection_draws.push_back({boulder.first_index, boulder.index_count, &obstacle_constants[2 * i + 1]});
  }
  // The objects after the valley, in world space: drawn with the view's own constants.
  const auto first_object_vertex = static_cast<uint32_t>(geometry.vertices.size());
  const auto first_object_index = static_cast<uint32_t>(geometry.indices.size());
  geometry.vertices.insert(geometry.vertices.end(), objects.vertices.begin(), objects.vertices.end());
  for (uint32_t index : objects.indices) geometry.indices.push_back(first_object_vertex + index);
  for (const SceneObjects::Draw& draw : objects.draws) {
    scene_draws.push_back({first_object_index + draw.first_index, draw.index_count, &constants, draw.texture + 1});
    reflection_draws.push_back(
        {first_object_index + draw.first_index, draw.index_count, &reflection_constants, draw.texture + 1});
  }
  for (BaseColorTexture& texture : objects.textures) {
    static_images.push_back({"base colour", kBaseColorFormat, {texture.width, texture.height},
                             std::move(texture.texels), std::move(texture.mip_offsets), {}, {}});
  }
  objects = SceneObjects{};  // copied into the static data
  static_buffers[kSceneVertices].bytes = bytes_of(geometry.vertices);
  static_buffers[kSceneIndices].bytes = bytes_of(geometry.indices);
  std::vector<Obstacle> flow_obstacles = obstacles;
  flow_obstacles.insert(flow_obstacles.end(), object_obstacles.begin(), object_obstacles.end());
  SIVIFLOW_TRY(simulation.create(std::move(river_input), flow_params, std::move(flow_obstacles),
                                 info.seed, {info.extent.width, info.extent.height}));
  const RiverMesh& surface = simulation.mesh();
  river_index_count = static_cast<uint32_t>(surface.indices.size());
  static_buffers[kRiverVertices].bytes = bytes_of(surface.positions);
  static_buffers[kRiverDepths].bytes = bytes_of(surface.depth);
  static_buffers[kRiverIndices].bytes = bytes_of(surface.indices);
  make_tile_lattice(surface.positions, surface.indices);

  DetailTexture detail = make_detail_texture();
  static_images[kDetail].extent = {detail.size, detail.size};
  static_images[kDetail].texels = std::move(detail.texels);
  static_images[kDetail].mip_offsets = {0};
  WaterNormalMap normal_map = make_water_normal_map();
  static_images[kNormalMap].extent = {normal_map.size, normal_map.size};
  static_images[kNormalMap].texels = std::move(normal_map.texels);
  static_images[kNormalMap].mip_offsets = std::move(normal_map.mip_offsets);

  // Every frame's flow textures must fit a slot's staging block.
  info.staging_bytes_per_slot = std::max(info.staging_bytes_per_slot,
                                         VkDeviceSize{simulation.layout().total_bytes} + kStagingAlignment);
  SIVIFLOW_TRY(ring.init(gpu, info.frames_in_flight, info.staging_bytes_per_slot));
  for (StaticBuffer& b : static_buffers) {
    SIVIFLOW_TRY(create_buffer(gpu, b.bytes.size(), b.usage | VK_BUFFER_USAGE_TRANSFER_DST_BIT,
                               false, b.name, &b.buffer));
  }
  return Status::success();
}

// The water heights around the river, and the tile table that covers their lattice points (or
// as many as SIVIFLOW_TILE_TABLE_MAX allows, then a window around the camera).
void Renderer::Impl::make_tile_lattice(const std::vector<glm::vec3>& surface,
                                       const std::vector<uint32_t>& indices) {
  const float half_tile = 0.5f * kTdfTileMetres;
  // A tile reaches half a tile beyond the water it covers; the margin keeps its centre inside.
  const WaterHeights heights =
      water_heights(surface, half_tile, kTdfTileMetres, kMaxWaterHeightSamples);
  const glm::vec2 far_corner =
      heights.origin + heights.spacing * glm::vec2(heights.columns - 1, heights.rows - 1);
  lattice_lo = glm::ivec2(glm::floor(heights.origin / half_tile));
  lattice_hi = glm::ivec2(glm::ceil(far_corner / half_tile));
  const auto table_side = [](int points) {
    return std::min(std::bit_ceil(static_cast<uint32_t>(points)), SIVIFLOW_TILE_TABLE_MAX);
  };
  tile_table.width = table_side(lattice_hi.x - lattice_lo.x + 1);
  tile_table.height = table_side(lattice_hi.y - lattice_lo.y + 1);
  tile_table.tile_size_m = kTdfTileMetres;
  tile_constants.heights = glm::vec4(heights.origin, heights.spacing, kTdfTileMetres);
  StaticImage& image = static_images[kWaterHeights];
  image.extent = {heights.columns, heights.rows};
  // A tile centre is within a tile of water it covers, and water within its longest triangle
  // edge of a vertex: samples farther than both are no tile's. Steps go along the axes, so a
  // distance d takes up to d sqrt(2) / spacing of them, plus one for the vertex's own sample.
  const float reach = (kTdfTileMetres + longest_edge_xz(surface, indices)) * std::sqrt(2.0f);
  const auto reach_steps = static_cast<uint32_t>(std::ceil(reach / heights.spacing)) + 1;
  std::vector<float> texels(heights.heights.size());
  for (size_t i = 0; i < texels.size(); ++i) {
    texels[i] = heights.steps[i] <= reach_steps ? heights.heights[i]
                                                : static_cast<float>(SIVIFLOW_FAR_FROM_WATER);
  }
  image.texels = bytes_of(texels);
  image.mip_offsets = {0};
}

// The lattice point of the tile table's window corner: the river's first point when the table
// holds them all, else a window reaching as far ahead of the camera as it can (what lies behind
// is not seen), kept over the river. Water beyond the window, farther than the table's reach
// (768 m at SIVIFLOW_TILE_TABLE_MAX), takes the tiles of points a table size away.
glm::ivec2 Renderer::Impl::tile_window(const Camera& camera) const {
  const glm::ivec2 size(tile_table.width, tile_table.height);
  const float half_tile = 0.5f * kTdfTileMetres;
  const glm::vec2 position = glm::vec2(camera.position.x, camera.position.z) / half_tile;
  glm::vec2 forward(camera.target.x - camera.position.x, camera.target.z - camera.position.z);
  forward = glm::length(forward) > 0.0f ? glm::normalize(forward) : glm::vec2(0.0f);
  // The window's centre half a window ahead, less a tile, so the camera's own tiles stay in it.
  const glm::vec2 ahead = forward * (0.5f * glm::vec2(size) - 2.0f);
  const glm::ivec2 centre(glm::round(position + ahead));
  return glm::clamp(centre - size / 2, lattice_lo, glm::max(lattice_lo, lattice_hi - size + 1));
}

Status Renderer::Impl::declare_static_graph() {
  static_staging = static_graph.import_buffer({"static staging", 0}, ResourceState{});
  for (const StaticBuffer& b : static_buffers) {
    const BufferHandle handle = static_graph.import_buffer({b.name, b.buffer.size}, ResourceState{},
                                                           state_of(b.read_as));
    static_uploads.buffers.push_back({0, handle, b.buffer.size});
  }
  std::vector<ImageHandle> image_handles;
  for (const StaticImage& i : static_images) {
    const ImageHandle handle = static_graph.import_image({i.name, i.format, i.extent, {}},
                                                         ResourceState{}, state_of(i.read_as));
    image_handles.push_back(handle);
    for (uint32_t level = 0; level < i.mip_offsets.size(); ++level) {
      const VkExtent2D extent{std::max(1u, i.extent.width >> level), std::max(1u, i.extent.height >> level)};
      static_uploads.images.push_back({0, handle, extent, level});
    }
  }
  add_upload_pass(static_graph, static_staging, &static_uploads);
  SIVIFLOW_TRY(static_graph.compile());
  for (size_t n = 0; n < static_images.size(); ++n) {
    StaticImage& i = static_images[n];
    // The frame graph only samples the static images.
    const VkImageUsageFlags usage = static_graph.image_usage(image_handles[n]) | VK_IMAGE_USAGE_SAMPLED_BIT;
    SIVIFLOW_TRY(create_image(gpu, i.format, i.extent, usage, i.name, &i.image,
                              static_cast<uint32_t>(i.mip_offsets.size())));
  }
  SIVIFLOW_TRY(scene_pass.create(gpu, info.pipeline_cache, info.color_format, kDepthFormat));
  SIVIFLOW_TRY(flow_pass.create(gpu, info.pipeline_cache, info.color_format, kDepthFormat,
                                info.enable_readback, info.enable_timing));
  std::vector<VkImageView> base_colors;
  for (size_t n = kFirstBaseColor; n < static_images.size(); ++n) base_colors.push_back(static_images[n].image.view);
  return scene_pass.set_textures(gpu, static_images[kDetail].image.view, base_colors);
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
  for (StaticBuffer& b : static_buffers) {
    b.in_frame_graph = graph.import_buffer({b.name, b.buffer.size}, state_of(b.read_as),
                                           state_of(b.read_as));
  }
  for (StaticImage& i : static_images) {
    i.in_frame_graph = graph.import_image({i.name, i.format, i.extent, {}}, state_of(i.read_as),
                                          state_of(i.read_as));
  }
  VkClearValue transparent{};
  VkClearValue far_depth{};
  far_depth.depthStencil = {1.0f, 0};

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
  add_upload_pass(graph, frame_staging, &frame_uploads);

  // reflection: the scene mirrored about the water plane, clipped below it.
  ScenePass::Handles mirrored;
  mirrored.color = frame_image(graph.create_image({"reflection", info.color_format, reflection_extent, transparent}));
  mirrored.depth = frame_image(graph.create_image({"reflection depth", kDepthFormat, reflection_extent, far_depth}));
  mirrored.vertices = static_buffers[kSceneVertices].in_frame_graph;
  mirrored.indices = static_buffers[kSceneIndices].in_frame_graph;
  mirrored.detail = static_images[kDetail].in_frame_graph;
  for (size_t n = kFirstBaseColor; n < static_images.size(); ++n) {
    mirrored.base_colors.push_back(static_images[n].in_frame_graph);
  }
  if (info.reflection != nullptr) {
    declare_host_reflection(&mirrored);
  } else {
    scene_pass.declare(graph, "reflection", &reflection_draws, &mirrored);
  }

  // scene: sky, terrain, riverbed and objects into the host's output.
  // The host states the output's real states per frame; these are overridden in record().
  output = graph.import_image({"output", info.color_format, extent, transparent}, ResourceState{},
                              state_of(Access::SampledFragment));
  ScenePass::Handles scene;
  scene.color = output;
  scene.depth = frame_image(graph.create_image({"depth", kDepthFormat, extent, far_depth}));
  scene.vertices = static_buffers[kSceneVertices].in_frame_graph;
  scene.indices = static_buffers[kSceneIndices].in_frame_graph;
  scene.detail = static_images[kDetail].in_frame_graph;
  scene.base_colors = mirrored.base_colors;
  scene_pass.declare(graph, "scene", &scene_draws, &scene);

  // flow: the water material over the scene.
  FlowPass::Handles water;
  water.color = scene.color;
  water.depth = scene.depth;
  water.flow = frame_uploads.images[0].destination;
  water.aux = frame_uploads.images[1].destination;
  water.reflection = mirrored.color;
  water.normal_map = static_images[kNormalMap].in_frame_graph;
  water.vertices = static_buffers[kRiverVertices].in_frame_graph;
  water.depths = static_buffers[kRiverDepths].in_frame_graph;
  water.indices = static_buffers[kRiverIndices].in_frame_graph;
  if (info.enable_readback) {
    water.mask = frame_image(graph.create_image({"water mask", FlowPass::kMaskFormat, extent, transparent}));
    water.normal = frame_image(graph.create_image({"water normal", FlowPass::kNormalFormat, extent, transparent}));
    water.reflection_sample = frame_image(
        graph.create_image({"reflection sample", FlowPass::kReflectionFormat, extent, transparent}));
  }
  water.water_heights = static_images[kWaterHeights].in_frame_graph;
  water.tile_table = frame_image(graph.create_image(
      {"tile table", FlowPass::kTileTableFormat, {tile_table.width, tile_table.height}, {}}));
  flow_pass.declare_tiles(graph, &tile_constants, &water);
  flow_pass.declare(graph, &flow_constants, river_index_count, &water);
  if (info.enable_timing) {
    const ImageHandle floor =
        frame_image(graph.create_image({"flow floor", info.color_format, extent, {}}));
    flow_pass.declare_floor(graph, &flow_constants, river_index_count, water, floor);
  }

  if (info.enable_readback) {
    const ImageHandle images[kReadbackImageCount] = {water.color,
                                                     scene.depth,
                                                     water.mask,
                                                     frame_uploads.images[0].destination,
                                                     frame_uploads.images[1].destination,
                                                     water.normal,
                                                     water.reflection_sample,
                                                     water.tile_table};
    readbacks.clear();
    for (uint32_t i = 0; i < kReadbackImageCount; ++i) {
      const BufferHandle buffer = graph.import_buffer(
          {readback_image_name(static_cast<ReadbackImage>(i)), 0}, ResourceState{},
          state_of(Access::HostRead));
      readbacks.push_back({images[i], buffer});
    }
    add_readback_pass(graph, &readbacks);
  }
  SIVIFLOW_TRY(graph.compile());
  SIVIFLOW_TRY(create_frame_images());

  FlowPass::Textures textures;
  textures.flow = find_frame_image(flow_texture)->view;
  textures.aux = find_frame_image(particle_aux)->view;
  textures.reflection = find_frame_image(mirrored.color)->view;
  textures.normal_map = static_images[kNormalMap].image.view;
  textures.tile_table = find_frame_image(water.tile_table)->view;
  textures.water_heights = static_images[kWaterHeights].image.view;
  return flow_pass.bind_textures(gpu, textures, [this](VkDescriptorPool pool) {
    ring.defer_deletion_until_all_slots([gpu_context = gpu, pool] {
      gpu_context.table->vkDestroyDescriptorPool(gpu_context.table->device, pool,
                                                 gpu_context.allocation_callbacks);
    });
  });
}

void Renderer::Impl::declare_host_reflection(ScenePass::Handles* mirrored) {
  PassBuilder pass = graph.add_pass("reflection", PassKind::Graphics);
  mirrored->color = pass.color_write(mirrored->color, LoadOp::Clear);
  mirrored->depth = pass.depth_write(mirrored->depth, LoadOp::Clear);
  const ImageHandle color = mirrored->color;
  pass.record([this, color](const PassContext& ctx) {
    ReflectionView view{};
    std::memcpy(view.view_proj, &reflection_constants.view_proj[0][0], sizeof(view.view_proj));
    std::memcpy(view.clip_plane, &reflection_constants.clip_plane[0], sizeof(view.clip_plane));
    std::memcpy(view.camera_position, &reflection_constants.camera_position[0], sizeof(view.camera_position));
    view.extent = ctx.extent(color);
    set_viewport(ctx.table(), ctx.cmd(), view.extent);
    info.reflection(ctx.cmd(), view, info.reflection_user);
    return Status::success();
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

Status Renderer::Impl::stage_static_data() {
  VkDeviceSize total = 0;
  for (const StaticImage& i : static_images) total += i.texels.size();
  for (const StaticBuffer& b : static_buffers) total += b.bytes.size();
  SIVIFLOW_TRY(create_buffer(gpu, total, VK_BUFFER_USAGE_TRANSFER_SRC_BIT, /*host_visible=*/true,
                             "static staging", &static_staging_buffer));
  auto* bytes = static_cast<uint8_t*>(static_staging_buffer.mapped);
  // Images first: every copy offset into them stays a multiple of their 4-byte texels.
  VkDeviceSize offset = 0;
  size_t upload = 0;
  for (StaticImage& i : static_images) {
    std::memcpy(bytes + offset, i.texels.data(), i.texels.size());
    for (size_t level = 0; level < i.mip_offsets.size(); ++level) {
      static_uploads.images[upload++].staging_offset = offset + i.mip_offsets[level];
    }
    offset += i.texels.size();
    i.texels = std::vector<uint8_t>();  // the staging copy is the only one needed from now on
  }
  for (size_t n = 0; n < static_buffers.size(); ++n) {
    std::vector<uint8_t>& source = static_buffers[n].bytes;
    std::memcpy(bytes + offset, source.data(), source.size());
    static_uploads.buffers[n].staging_offset = offset;
    offset += source.size();
    source = std::vector<uint8_t>();
  }
  return Status::success();
}

Status Renderer::Impl::record_static_upload(VkCommandBuffer cmd) {
  FrameBindings static_bindings;
  static_bindings.bind_buffer(static_staging, static_staging_buffer.buffer);
  for (size_t n = 0; n < static_buffers.size(); ++n) {
    static_bindings.bind_buffer(static_uploads.buffers[n].destination, static_buffers[n].buffer.buffer);
  }
  size_t upload = 0;
  for (const StaticImage& i : static_images) {
    static_bindings.bind_image(static_uploads.images[upload].destination, i.image.image, i.image.view);
    upload += i.mip_offsets.size();
  }
  SIVIFLOW_TRY(static_graph.execute(table, cmd, static_bindings));
  // The GPU reads the staging buffer until this slot's frame completes; free it after that.
  Buffer retired = static_staging_buffer;
  static_staging_buffer = Buffer{};
  ring.defer_deletion([gpu_context = gpu, retired]() mutable { destroy_buffer(gpu_context, &retired); });
  return Status::success();
}

void Renderer::Impl::destroy() {
  if (gpu.table == nullptr) return;  // failed before any Vulkan object existed
  scene_pass.destroy(gpu);
  flow_pass.destroy(gpu);
  for (FrameImage& f : frame_images) destroy_image(gpu, &f.image);
  for (StaticImage& i : static_images) destroy_image(gpu, &i.image);
  for (StaticBuffer& b : static_buffers) destroy_buffer(gpu, &b.buffer);
  destroy_buffer(gpu, &static_staging_buffer);
  for (VkQueryPool pool : query_pools) table.vkDestroyQueryPool(table.device, pool, gpu.allocation_callbacks);
  ring.destroy();
}

Status Renderer::Impl::create_query_pools() {
  VkPhysicalDeviceProperties2 props{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2};
  table.vkGetPhysicalDeviceProperties2(info.physical_device, &props);
  timestamp_period_ns = props.properties.limits.timestampPeriod;
  uint32_t family_count = 0;
  table.vkGetPhysicalDeviceQueueFamilyProperties(info.physical_device, &family_count, nullptr);
  std::vector<VkQueueFamilyProperties> families(family_count);
  table.vkGetPhysicalDeviceQueueFamilyProperties(info.physical_device, &family_count, families.data());
  const uint32_t bits = families[info.queue_family_index].timestampValidBits;
  if (bits == 0) return invalid("enable_timing: the queue family has no timestamps");
  timestamp_mask = bits >= 64 ? ~uint64_t{0} : (uint64_t{1} << bits) - 1;
  VkQueryPoolCreateInfo pool_info{VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO};
  pool_info.queryType = VK_QUERY_TYPE_TIMESTAMP;
  pool_info.queryCount = 2 * kMaxTimedPasses;
  query_pools.assign(info.frames_in_flight, VK_NULL_HANDLE);
  timed_passes.assign(info.frames_in_flight, 0);
  for (VkQueryPool& pool : query_pools) {
    SIVIFLOW_TRY(vk_status(table.vkCreateQueryPool(table.device, &pool_info, gpu.allocation_callbacks, &pool),
                           "vkCreateQueryPool"));
  }
  return Status::success();
}

Status Renderer::create(const CreateInfo& info, std::unique_ptr<Renderer>* out) {
  auto impl = std::make_unique<Impl>();
  Status status = impl->validate_info(info);
  if (status.ok()) status = impl->take_scene();
  if (status.ok()) status = impl->create_static_resources();
  if (status.ok()) status = impl->declare_static_graph();
  if (status.ok()) status = impl->declare_graph();
  if (status.ok() && info.enable_timing) status = impl->create_query_pools();
  if (!status.ok()) {
    if (info.log != nullptr) info.log(LogLevel::kError, status.message().c_str(), info.log_user);
    impl->destroy();
    return status;
  }
  out->reset(new Renderer(std::move(impl)));
  return Status::success();
}

Renderer::Renderer(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
Renderer::~Renderer() { impl_->destroy(); }

Status Renderer::begin_frame(uint32_t slot) {
  Impl& r = *impl_;
  if (r.unusable) return Status::error("Renderer: a resize failed; resize again before rendering");
  SIVIFLOW_TRY(r.ring.begin_slot(slot));
  r.current_slot = slot;
  r.frame_begun = true;
  r.frame_updated = false;
  return Status::success();
}

Status Renderer::Impl::simulate(const Camera& camera, double time_seconds) {
  if (!std::isfinite(time_seconds) || camera.near_plane <= 0.0f ||
      camera.far_plane <= camera.near_plane || camera.fov_y_deg <= 0.0f ||
      camera.fov_y_deg >= 180.0f || camera.position == camera.target) {
    return Status::error("Renderer: invalid camera or time");
  }
  const float dt = simulation.next_frame() == 0 ? 0.0f : static_cast<float>(time_seconds - last_time);
  if (dt < 0.0f) return Status::error("Renderer: time went backwards");
  const float aspect = static_cast<float>(info.extent.width) / static_cast<float>(info.extent.height);
  glm::mat4 projection = glm::perspectiveRH_ZO(glm::radians(camera.fov_y_deg), aspect,
                                               camera.near_plane, camera.far_plane);
  projection[1][1] *= -1.0f;  // Vulkan's clip space has +Y down
  const glm::mat4 view = glm::lookAtRH(camera.position, camera.target, glm::vec3(0.0f, 1.0f, 0.0f));
  const glm::vec4 sun(glm::normalize(look.sun_direction), look.sun_disc_intensity);
  const glm::vec4 fog(look.fog_density, look.fog_height_falloff, 0.0f, 0.0f);
  constants.view_proj = projection * view;
  constants.camera_position = glm::vec4(camera.position, 1.0f);
  constants.sun_direction = sun;
  constants.clip_plane = glm::vec4(0.0f, 0.0f, 0.0f, 1.0f);  // main view: nothing clipped
  constants.fog = fog;

  SIVIFLOW_TRY(simulation.set_time(time_seconds));
  SIVIFLOW_TRY(simulation.simulate(constants.view_proj, dt));

  // The reflection renders the scene mirrored about the water plane y = h from the real camera,
  // so the flow pass samples it at its own screen position; only what is above the water stays.
  const float h = visible_water_level();
  glm::mat4 mirror(1.0f);
  mirror[1][1] = -1.0f;
  mirror[3][1] = 2.0f * h;
  reflection_constants = constants;
  reflection_constants.view_proj = constants.view_proj * mirror;
  reflection_constants.camera_position = glm::vec4(camera.position.x, 2.0f * h - camera.position.y,
                                                   camera.position.z, 1.0f);
  reflection_constants.clip_plane = glm::vec4(0.0f, 1.0f, 0.0f, -h + kReflectionClipBias);

  const FlowTextureLayout& layout = simulation.layout();
  flow_constants.view_proj = constants.view_proj;
  flow_constants.camera_position = glm::vec4(camera.position, 0.0f);
  flow_constants.sun_direction = sun;
  flow_constants.water = glm::vec4(h, kReflectionDistortion, kTdfTileMetres,
                                   static_cast<float>(layout.texel_px));
  flow_constants.screen = glm::vec4(info.extent.width, info.extent.height,
                                    1.0f / static_cast<float>(info.extent.width),
                                    1.0f / static_cast<float>(info.extent.height));
  tile_constants.view_proj = constants.view_proj;
  const glm::ivec2 corner = tile_window(camera);
  tile_table.corner_x = corner.x;
  tile_table.corner_z = corner.y;
  tile_constants.lattice = glm::vec4(corner, tile_table.width, tile_table.height);
  tile_constants.screen =
      glm::vec4(info.extent.width, info.extent.height, static_cast<float>(layout.texel_px),
                static_cast<float>(std::fmod(time_seconds, SIVIFLOW_TDF_TIME_PERIOD)));
  // The obstacles where they are this frame, each drawn as a translated boulder.
  for (size_t i = 0; i < obstacles.size(); ++i) {
    const glm::vec3 offset = simulation.obstacle_centre(i);
    obstacle_constants[2 * i] = translated(constants, offset);
    obstacle_constants[2 * i + 1] = translated(reflection_constants, offset);
  }
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
  if (heights.empty()) return simulation.mesh().positions.front().y;  // no water on screen
  const auto middle = heights.begin() + static_cast<std::ptrdiff_t>(heights.size() / 2);
  std::nth_element(heights.begin(), middle, heights.end());
  return *middle;
}

Status Renderer::simulate(const Camera& camera, double time_seconds) {
  if (impl_->frame_begun) return Status::error("Renderer::simulate called between begin_frame and record");
  return impl_->simulate(camera, time_seconds);
}

Status Renderer::update(const Camera& camera, double time_seconds) {
  Impl& r = *impl_;
  if (!r.frame_begun) return Status::error("Renderer::update called before begin_frame");
  if (r.frame_updated) return Status::error("Renderer::update called twice for one frame");
  // Staging first: a failure there must not leave the particles one frame ahead.
  const FlowTextureLayout& layout = r.simulation.layout();
  StagingAllocation staging;
  SIVIFLOW_TRY(r.ring.allocate_staging(layout.total_bytes, kStagingAlignment, &staging));
  SIVIFLOW_TRY(r.simulate(camera, time_seconds));
  SIVIFLOW_TRY(r.simulation.pack({static_cast<std::byte*>(staging.data), layout.total_bytes}));
  r.frame_uploads.images[0].staging_offset = staging.offset + layout.flow_offset;
  r.frame_uploads.images[1].staging_offset = staging.offset + layout.aux_offset;
  if (!r.static_data_uploaded && r.static_staging_buffer.buffer == VK_NULL_HANDLE) {
    SIVIFLOW_TRY(r.stage_static_data());
  }
  r.frame_updated = true;
  return Status::success();
}

Status Renderer::record(VkCommandBuffer cmd, const FrameInputs& inputs) {
  Impl& r = *impl_;
  if (!r.frame_updated) return Status::error("Renderer::record called before begin_frame and update");
  if (inputs.output.image == VK_NULL_HANDLE || inputs.output.view == VK_NULL_HANDLE) {
    return Status::error("Renderer::record: FrameInputs::output needs an image and a view");
  }
  if (inputs.output.final.layout == VK_IMAGE_LAYOUT_UNDEFINED) {
    return Status::error("Renderer::record: FrameInputs::output.final.layout must not be UNDEFINED");
  }
  for (uint32_t i = 0; i < r.readbacks.size(); ++i) {
    if (inputs.readback.buffers[i] == VK_NULL_HANDLE) {
      return Status::error(std::string("Renderer::record: readback is enabled but FrameInputs::readback has no ") +
                           readback_image_name(static_cast<ReadbackImage>(i)) + " buffer");
    }
  }
  if (!r.static_data_uploaded) SIVIFLOW_TRY(r.record_static_upload(cmd));
  FrameBindings& b = r.bindings;
  b.reset();
  for (const Impl::StaticBuffer& sb : r.static_buffers) b.bind_buffer(sb.in_frame_graph, sb.buffer.buffer);
  for (const Impl::StaticImage& si : r.static_images) b.bind_image(si.in_frame_graph, si.image.image, si.image.view);
  for (const Impl::FrameImage& f : r.frame_images) {
    b.bind_image(f.handle, f.image.image, f.image.view);
    // Persistent images start without contents (only the upload writes them, whole).
    if (r.frame_images_new && f.persistent) b.set_incoming(f.handle, ResourceState{});
  }
  b.bind_image(r.output, inputs.output.image, inputs.output.view);
  b.set_incoming(r.output, {inputs.output.current.stage, inputs.output.current.access,
                            inputs.output.current.layout});
  b.set_outgoing(r.output, {inputs.output.final.stage, inputs.output.final.access,
                            inputs.output.final.layout});
  b.bind_buffer(r.frame_staging, r.ring.staging_buffer());
  for (uint32_t i = 0; i < r.readbacks.size(); ++i) b.bind_buffer(r.readbacks[i].buffer, inputs.readback.buffers[i]);
  FrameGraph::Timestamps timestamps;
  if (!r.query_pools.empty()) {
    const uint32_t passes = static_cast<uint32_t>(r.graph.pass_order().size());
    if (passes > kMaxTimedPasses) return Status::error("Renderer::record: too many passes to time");
    timestamps.pool = r.query_pools[r.current_slot];
    r.table.vkCmdResetQueryPool(cmd, timestamps.pool, 0, 2 * passes);
    r.timed_passes[r.current_slot] = passes;
  }
  const Status status = r.graph.execute(r.table, cmd, b, r.query_pools.empty() ? nullptr : &timestamps);
  if (!status.ok()) {
    if (r.info.log != nullptr) r.info.log(LogLevel::kError, status.message().c_str(), r.info.log_user);
    return status;
  }
  r.static_data_uploaded = true;
  r.frame_images_new = false;
  r.frame_begun = false;
  r.frame_updated = false;
  return Status::success();
}

Status Renderer::resize(VkExtent2D extent) {
  Impl& r = *impl_;
  if (r.frame_begun) return Status::error("Renderer::resize called between begin_frame and record");
  if (extent.width == 0 || extent.height == 0) return invalid("resize: extent must be at least 1x1");
  VkPhysicalDeviceProperties2 props{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2};
  r.table.vkGetPhysicalDeviceProperties2(r.info.physical_device, &props);
  const uint32_t limit = props.properties.limits.maxImageDimension2D;
  if (extent.width > limit || extent.height > limit) {
    return invalid("resize: extent " + std::to_string(extent.width) + "x" +
                   std::to_string(extent.height) + " exceeds the device limit of " +
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

Camera Renderer::scene_camera(double time_seconds) const {
  const SceneCamera& path = impl_->camera_path;
  if (path.keys.empty()) {
    Camera camera = impl_->river_from_file ? river_overview_camera(impl_->simulation.mesh().positions)
                                           : default_camera(impl_->river, time_seconds);
    if (impl_->info.scene != nullptr) camera.fov_y_deg = path.fov_y_deg;
    return camera;
  }
  // Linear between keys, held before the first and after the last.
  Camera camera;
  camera.fov_y_deg = path.fov_y_deg;
  const auto after = std::find_if(path.keys.begin(), path.keys.end(),
                                  [&](const CameraKey& key) { return key.t > time_seconds; });
  if (after == path.keys.begin() || after == path.keys.end()) {
    const CameraKey& key = after == path.keys.begin() ? path.keys.front() : path.keys.back();
    camera.position = key.position;
    camera.target = key.target;
    return camera;
  }
  const CameraKey& a = *(after - 1);
  const float u = static_cast<float>((time_seconds - a.t) / (after->t - a.t));
  camera.position = glm::mix(a.position, after->position, u);
  camera.target = glm::mix(a.target, after->target, u);
  return camera;
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
      return VkDeviceSize{impl_->tile_table.width} * impl_->tile_table.height * 4 *
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

const ParticleField& Renderer::particle_field() const { return impl_->simulation.particle_field(); }
const TileTableLayout& Renderer::tile_table_layout() const { return impl_->tile_table; }
const FlowTextureLayout& Renderer::flow_texture_layout() const { return impl_->simulation.layout(); }
uint64_t Renderer::next_frame() const { return impl_->simulation.next_frame(); }

Status Renderer::pass_times(uint32_t slot, std::vector<PassTime>* out) const {
  const Impl& r = *impl_;
  out->clear();
  if (r.query_pools.empty()) return Status::error("Renderer::pass_times needs CreateInfo::enable_timing");
  if (slot >= r.query_pools.size()) return Status::error("Renderer::pass_times: slot out of range");
  const uint32_t passes = r.timed_passes[slot];
  if (passes == 0) return Status::success();
  std::vector<uint64_t> ticks(2 * passes);
  SIVIFLOW_TRY(vk_status(r.table.vkGetQueryPoolResults(r.table.device, r.query_pools[slot], 0, 2 * passes,
                                                       ticks.size() * sizeof(uint64_t), ticks.data(),
                                                       sizeof(uint64_t),
                                                       VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_WAIT_BIT),
                         "vkGetQueryPoolResults"));
  const std::vector<std::string> names = r.graph.pass_order();
  for (uint32_t i = 0; i < passes && i < names.size(); ++i) {
    // Differences modulo the valid bits, so a counter that wrapped still gives the right span.
    const auto span = [&](uint64_t from, uint64_t to) {
      return static_cast<double>((to - from) & r.timestamp_mask) * r.timestamp_period_ns;
    };
    const double begin_ns = span(ticks[0], ticks[2 * i]);
    const double ns = span(ticks[2 * i], ticks[2 * i + 1]);
    out->push_back({names[i], begin_ns * 1e-6, ns * 1e-6});
  }
  return Status::success();
}

std::string Renderer::dump_frame_graph() const { return impl_->graph.dump_text(); }
std::string Renderer::dump_frame_graph_graphviz() const { return impl_->graph.dump_graphviz(); }

}  // namespace siviflow
