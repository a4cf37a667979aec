#include "siviflow/world.h"

#include <algorithm>
#include <cstring>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "entry_guard.h"
#include "scene/detail_texture.h"
#include "scene/float_meshes.h"
#include "scene/scene_objects.h"
#include "scene/world_impl.h"
#include "siviflow/scene_river.h"
#include "view_culling.h"
#include "view_math.h"
#include "vk/pipeline.h"
#include "vk/vk_text.h"

namespace siviflow {
namespace {

constexpr uint32_t kDefaultFramesInFlight = 2;
constexpr VkFormat kDefaultColorFormat = VK_FORMAT_R16G16B16A16_SFLOAT;
constexpr VkFormat kDefaultDepthFormat = VK_FORMAT_D32_SFLOAT;
constexpr VkFormat kReflectionDepthFormat = VK_FORMAT_D32_SFLOAT;  // the renderer's
constexpr VkFormat kDetailFormat = VK_FORMAT_R8G8B8A8_UNORM;
constexpr VkFormat kBaseColorFormat = VK_FORMAT_R8G8B8A8_SRGB;

// The most a terrain level's height error may look, in pixels: the reflection, rippled and
// faded by Fresnel, takes coarser ground than the main view.
constexpr float kMainErrorPixels = 1.0f;
constexpr float kReflectionErrorPixels = 2.0f;

}  // namespace

Status World::Impl::load_scene() {
  SceneRiverData first;
  SIVIFLOW_TRY(scene_river_shape(info.scene, 0, &first));
  river_from_file = !first.procedural.has_value();
  if (first.procedural) river = *first.procedural;
  river_mesh = std::move(first.mesh);
  // The scene's other rivers: their valleys (procedural) or beds (glTF), without boulders.
  const size_t rivers = info.scene != nullptr ? info.scene->rivers.size() : 1;
  for (size_t i = 1; i < rivers; ++i) {
    SceneRiverData other;
    SIVIFLOW_TRY(scene_river_shape(info.scene, i, &other));
    SceneGeometry geometry;
    if (other.procedural) {
      geometry = build_scene_geometry(*other.procedural, {});
    } else {
      SIVIFLOW_TRY(build_riverbed_geometry(other.mesh, {}, {}, &geometry));
      other_meshes.push_back(std::move(other.mesh));
    }
    other_rivers.push_back(std::move(geometry));
  }
  obstacles = info.scene != nullptr ? info.scene->obstacles : default_scene_obstacles(river);
  shown.assign(obstacles.size(), true);
  for (uint32_t i = 0; i < info.spare_boulders; ++i) {
    Obstacle spare;
    spare.radius = info.spare_boulder_radius;
    obstacles.push_back(spare);
    shown.push_back(false);
  }
  placed.assign(obstacles.size(), std::nullopt);
  if (info.scene != nullptr) {
    for (const SceneFloat& f : info.scene->floats) floats.push_back({f.mesh, f.radius});
  }
  const float log_radius = scene_float_defaults(FloatMesh::kLog).radius;
  const float leaf_radius = scene_float_defaults(FloatMesh::kLeaf).radius;
  for (uint32_t i = 0; i < info.spare_logs; ++i) floats.push_back({FloatMesh::kLog, log_radius});
  for (uint32_t i = 0; i < info.spare_leaves; ++i) floats.push_back({FloatMesh::kLeaf, leaf_radius});
  if (info.scene != nullptr) camera_path = info.scene->camera;
  return Status::success();
}

Status World::Impl::create_resources() {
  SceneGeometry geometry;
  if (river_from_file) {
    other_meshes.insert(other_meshes.begin(), river_mesh);
    SIVIFLOW_TRY(build_riverbed_geometry(river_mesh, obstacles, other_meshes, &geometry));
    other_meshes.clear();
  } else {
    geometry = build_scene_geometry(river, obstacles);
    other_meshes.clear();
  }
  SceneObjects objects;
  if (info.scene != nullptr) SIVIFLOW_TRY(load_scene_objects(*info.scene, &objects));
  obstacle_constants.resize(2 * obstacles.size());  // sized once: the draws point into it
  boulders = geometry.obstacle_boulders;
  float_constants.resize(2 * floats.size());
  for (size_t i = 0; i < floats.size(); ++i) {
    floats[i].triangles = add_float_mesh(floats[i].mesh, floats[i].radius, float(i), &geometry);
  }
  // The other rivers' valleys or beds, static like the first's.
  for (SceneGeometry& other : other_rivers) append_geometry(std::move(other), &geometry);
  other_rivers.clear();
  // The objects after the valley, in world space: drawn with the view's own constants.
  const auto first_object_vertex = static_cast<uint32_t>(geometry.vertices.size());
  const auto first_object_index = static_cast<uint32_t>(geometry.indices.size());
  geometry.vertices.insert(geometry.vertices.end(), objects.vertices.begin(), objects.vertices.end());
  for (uint32_t index : objects.indices) geometry.indices.push_back(first_object_vertex + index);
  for (const SceneObjects::Draw& draw : objects.draws) {
    geometry.pieces.push_back(object_piece(geometry, first_object_index + draw.first_index,
                                           draw.index_count, draw.texture + 1));
  }
  pieces = std::move(geometry.pieces);
  // Every piece is static; the boulders stand for the renderer's obstacles, which it knows
  // itself. The finest level stops particles (its ground: the skirts lie under it).
  occluder_positions.reserve(geometry.vertices.size());
  for (const SceneVertex& v : geometry.vertices) occluder_positions.push_back(v.position);
  for (const LodPiece& piece : pieces) {
    const IndexRange& finest = piece.levels.front();
    const auto begin = geometry.indices.begin() + finest.first_index;
    occluder_indices.insert(occluder_indices.end(), begin, begin + finest.index_count);
  }
  assets.add_buffer({"world vertices", Access::VertexBufferRead, VK_BUFFER_USAGE_VERTEX_BUFFER_BIT,
                     bytes_of(geometry.vertices)});
  assets.add_buffer({"world indices", Access::IndexBufferRead, VK_BUFFER_USAGE_INDEX_BUFFER_BIT,
                     bytes_of(geometry.indices)});
  DetailTexture detail = make_detail_texture();
  assets.add_image({"ground detail", kDetailFormat, {detail.size, detail.size},
                    std::move(detail.texels), {0}});
  for (BaseColorTexture& texture : objects.textures) {
    assets.add_image({"base colour", kBaseColorFormat, {texture.width, texture.height},
                      std::move(texture.texels), std::move(texture.mip_offsets)});
  }
  SIVIFLOW_TRY(ring.init(gpu, info.frames_in_flight, 0));
  if (info.enable_timing) {
    SIVIFLOW_TRY(timer.create(gpu, info.physical_device, info.queue_family_index,
                              info.frames_in_flight));
  }
  SIVIFLOW_TRY(assets.create(gpu));
  std::vector<VkImageView> base_colors;
  for (uint32_t n = kFirstBaseColor; n < assets.image_count(); ++n) {
    base_colors.push_back(assets.image(n).view);
  }
  SIVIFLOW_TRY(main_pass.create(gpu, info.pipeline_cache, info.color_format, info.depth_format));
  SIVIFLOW_TRY(main_pass.set_textures(gpu, assets.image(kDetail).view, base_colors));
  // The reflection target has the renderer's formats, which may differ from the host's.
  const VkFormat mirrored_format = reflection_format(info.color_format);
  own_reflection_pass =
      info.depth_format != kReflectionDepthFormat || mirrored_format != info.color_format;
  if (!own_reflection_pass) return Status::success();
  SIVIFLOW_TRY(reflection_pass.create(gpu, info.pipeline_cache, mirrored_format,
                                      kReflectionDepthFormat));
  return reflection_pass.set_textures(gpu, assets.image(kDetail).view, base_colors);
}

Status World::Impl::declare_graph() {
  asset_handles = assets.import_into(graph);
  // The host's images: their states and clear depth come per frame.
  color = graph.import_image({"host colour", info.color_format, {1, 1}, {}}, ResourceState{},
                             state_of(Access::SampledFragment));
  depth = graph.import_image({"host depth", info.depth_format, {1, 1}, {}}, ResourceState{},
                             state_of(Access::DepthAttachmentRead));
  ScenePass::Handles handles;
  handles.color = color;
  handles.depth = depth;
  handles.vertices = asset_handles.buffers[kVertices];
  handles.indices = asset_handles.buffers[kIndices];
  handles.detail = asset_handles.images[kDetail];
  for (uint32_t n = kFirstBaseColor; n < assets.image_count(); ++n) {
    handles.base_colors.push_back(asset_handles.images[n]);
  }
  frame_data = main_pass.declare(graph, "world", &handles);
  return graph.compile();
}

gpu::SceneConstants World::Impl::view_constants(const glm::mat4& view_proj,
                                                 const glm::vec3& camera,
                                                 const glm::vec4& clip_plane, bool reverse) const {
  gpu::SceneConstants c{};
  c.view_proj = view_proj;
  c.camera_position = glm::vec4(camera, 1.0f);
  c.sun_direction = glm::vec4(glm::normalize(look.sun_direction), look.sun_disc_intensity);
  c.clip_plane = clip_plane;
  c.fog = glm::vec4(look.fog_density, look.fog_height_falloff, 0.0f, far_depth(reverse));
  return c;
}


void World::Impl::destroy() {
  if (gpu.table == nullptr) return;
  main_pass.destroy(gpu);
  reflection_pass.destroy(gpu);
  assets.destroy(gpu);
  timer.destroy(gpu);
  ring.destroy();
}

Status World::create(const WorldCreateInfo& info, std::unique_ptr<World>* out) {
  return guarded(kWorldErrorPrefix, nullptr, nullptr, [&] { return Impl::create(info, out); });
}

Status World::Impl::create(const WorldCreateInfo& info, std::unique_ptr<World>* out) {
  if (out == nullptr) return world_error("create: out must not be null");
  auto impl = std::make_unique<Impl>();
  Impl& w = *impl;
  w.info = info;
  if (info.instance == VK_NULL_HANDLE || info.physical_device == VK_NULL_HANDLE ||
      info.device == VK_NULL_HANDLE || info.get_instance_proc_addr == nullptr) {
    return world_error("WorldCreateInfo needs instance, physical_device, device and "
                       "get_instance_proc_addr");
  }
  if (w.info.frames_in_flight == 0) w.info.frames_in_flight = kDefaultFramesInFlight;
  if (w.info.color_format == VK_FORMAT_UNDEFINED) w.info.color_format = kDefaultColorFormat;
  if (w.info.depth_format == VK_FORMAT_UNDEFINED) w.info.depth_format = kDefaultDepthFormat;
  const char* missing = nullptr;
  const VkResult loaded =
      load_device_table(info.instance, info.physical_device, info.device,
                        info.get_instance_proc_addr, info.get_device_proc_addr, info.debug_utils,
                        &w.table, &missing);
  if (loaded != VK_SUCCESS) {
    return Status::error(std::string(kWorldErrorPrefix) + "cannot load " + missing, loaded);
  }
  w.gpu = make_gpu_context(w.table, info.allocation_callbacks);
  Status status;
  try {
    status = w.load_scene();
    if (status.ok()) status = w.create_resources();
    if (status.ok()) status = w.declare_graph();
  } catch (...) {
    w.destroy();  // the Vulkan objects made so far
    throw;
  }
  if (!status.ok()) {
    w.destroy();
    return status;
  }
  out->reset(new World(std::move(impl)));
  return Status::success();
}

World::World(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
World::~World() { impl_->destroy(); }

Camera World::scene_camera(double time_seconds) const {
  const Impl& w = *impl_;
  const SceneCamera& path = w.camera_path;
  if (path.keys.empty()) {
    Camera camera = w.river_from_file ? river_overview_camera(w.river_mesh.positions)
                                      : default_camera(w.river, time_seconds);
    if (w.info.scene != nullptr) camera.fov_y_deg = path.fov_y_deg;
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

OccluderMesh World::occluders() const {
  return {impl_->occluder_positions, impl_->occluder_indices};
}


Status World::begin_frame(uint32_t slot) {
  return guarded(kWorldErrorPrefix, nullptr, nullptr, [&] {
    SIVIFLOW_TRY(impl_->ring.begin_slot(slot));
    impl_->slot = slot;
    return Status::success();
  });
}

Status World::record(VkCommandBuffer cmd, const View& view, double time_seconds,
                     const ExternalImage& color, const ExternalImage& depth) {
  return guarded(kWorldErrorPrefix, nullptr, nullptr,
                 [&] { return impl_->record(cmd, view, time_seconds, color, depth); });
}

Status World::Impl::record(VkCommandBuffer cmd, const View& view,
                           double time_seconds, const ExternalImage& host_color,
                           const ExternalImage& host_depth) {
  Impl& w = *this;
  if (host_color.format != w.info.color_format) {
    return world_error("the colour image's format " + format_name(host_color.format) +
                       " differs from WorldCreateInfo's " + format_name(w.info.color_format));
  }
  if (host_depth.format != w.info.depth_format) {
    return world_error("the depth image's format " + format_name(host_depth.format) +
                       " differs from WorldCreateInfo's " + format_name(w.info.depth_format));
  }
  ViewMath math;
  SIVIFLOW_TRY(derive_view_math(view.view, view.projection, &math));
  if (!w.assets.uploaded()) {
    if (!w.assets.staged()) SIVIFLOW_TRY(w.assets.stage(w.gpu));
    SIVIFLOW_TRY(w.assets.record_upload(w.table, cmd));
  }
  w.time = time_seconds;
  w.frame.reverse_z = math.reverse_z;
  // Back faces of the ground are hidden behind its front faces in the main view. Not in the
  // reflection: the water's edge, a little under the bank, reflects the bank's underside there.
  w.frame.cull_back_faces = true;
  w.frame.outside_clockwise = outside_lands_clockwise(view.view, view.projection);
  // Nothing clipped in the main view.
  w.main_constants = w.view_constants(math.view_proj, math.camera_position,
                                      glm::vec4(0.0f, 0.0f, 0.0f, 1.0f), math.reverse_z);
  w.frame.viewport = view.viewport;
  if (w.frame.viewport.extent.width == 0 && w.frame.viewport.extent.height == 0) {
    w.frame.viewport.extent = host_color.extent;
  }
  w.frame.sky = &w.main_constants;
  CullView cull;
  cull.view_proj = math.view_proj;
  cull.camera = math.camera_position;
  w.projection = view.projection;
  cull.focal_pixels = focal_pixels(view.projection, float(w.frame.viewport.extent.height));
  cull.max_error_pixels = kMainErrorPixels;
  w.select_draws(cull, w.main_constants, 0, &w.main_draws, &w.stats.main_triangles);

  FrameBindings& b = w.bindings;
  b.reset();
  w.assets.bind(b, w.asset_handles);
  const auto bind_host = [&b](ImageHandle handle, const ExternalImage& image) {
    b.bind_image(handle, image.image, image.view);
    b.set_incoming(handle, {image.current.stage, image.current.access, image.current.layout});
    b.set_outgoing(handle, {image.final.stage, image.final.access, image.final.layout});
  };
  bind_host(w.color, host_color);
  bind_host(w.depth, host_depth);
  b.bind_data(w.frame_data.draws, &w.main_draws);
  b.bind_data(w.frame_data.view, &w.frame);
  b.set_render_area(w.color, w.frame.viewport);  // the view's part only: drawn whole
  VkClearValue far{};
  far.depthStencil = {far_depth(math.reverse_z), 0};
  b.set_clear(w.depth, far);
  FrameGraph::Timestamps timestamps;
  if (w.timer.enabled()) {
    SIVIFLOW_TRY(w.timer.begin(w.table, cmd, w.slot,
                               static_cast<uint32_t>(w.graph.pass_order().size()), &timestamps));
  }
  SIVIFLOW_TRY(w.graph.execute(w.table, cmd, b, w.timer.enabled() ? &timestamps : nullptr));
  if (!w.assets.uploaded()) w.assets.finish_upload(w.ring, w.gpu);
  return Status::success();
}

Status World::pass_times(uint32_t slot, std::vector<PassTime>* out) const {
  return guarded(kWorldErrorPrefix, nullptr, nullptr, [&] {
    const Impl& w = *impl_;
    if (out == nullptr) return world_error("pass_times: out must not be null");
    if (!w.timer.enabled()) return world_error("pass_times needs WorldCreateInfo::enable_timing");
    if (slot >= w.info.frames_in_flight) return world_error("pass_times: slot out of range");
    return w.timer.pass_times(w.table, slot, w.graph.pass_order(), out);
  });
}

WorldDrawStats World::draw_stats() const { return impl_->stats; }

void World::draw_reflection(VkCommandBuffer cmd, const ReflectionView& view, void* world) {
  Impl& w = *static_cast<World*>(world)->impl_;
  glm::mat4 view_proj;
  glm::vec4 clip_plane;
  glm::vec3 camera;
  std::memcpy(&view_proj[0][0], view.view_proj, sizeof(view.view_proj));
  std::memcpy(&clip_plane[0], view.clip_plane, sizeof(view.clip_plane));
  std::memcpy(&camera[0], view.camera_position, sizeof(view.camera_position));
  w.reflection_constants = w.view_constants(view_proj, camera, clip_plane, view.reverse_z);
  // Only what the water samples (the scissor): the frustum narrowed to it.
  const bool sampled = view.area.extent.width > 0 && view.area.extent.height > 0;
  const glm::vec2 size(view.extent.width, view.extent.height);
  const glm::vec2 lo = glm::vec2(view.area.offset.x, view.area.offset.y) / size;
  const glm::vec2 hi = lo + glm::vec2(view.area.extent.width, view.area.extent.height) / size;
  CullView cull;
  cull.view_proj = sampled ? narrowed_view(view_proj, glm::vec4(lo, hi)) : view_proj;
  cull.camera = camera;
  cull.clip_plane = clip_plane;
  cull.focal_pixels = focal_pixels(w.projection, float(view.extent.height));
  cull.max_error_pixels = kReflectionErrorPixels;
  if (sampled) {
    w.select_draws(cull, w.reflection_constants, 1, &w.reflection_draws,
                   &w.stats.reflection_triangles);
  } else {  // no water in view: nothing of the world is seen in it
    w.reflection_draws.clear();
    w.stats.reflection_triangles = 0;
  }
  const ScenePass& pass = w.own_reflection_pass ? w.reflection_pass : w.main_pass;
  ScenePass::Frame mirrored;
  mirrored.reverse_z = view.reverse_z;
  pass.draw(w.table, cmd, w.assets.buffer(Impl::kVertices).buffer,
            w.assets.buffer(Impl::kIndices).buffer, w.reflection_draws, w.reflection_constants,
            mirrored);
}

}  // namespace siviflow
