// The water renderer's state, shared by the files that implement Renderer: renderer.cpp
// (creation, frame graph, frame recording) and water_controls.cpp (runtime obstacles and look).
#pragma once

#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <glm/mat4x4.hpp>
#include <glm/vec2.hpp>
#include <glm/vec4.hpp>

#include "entry_guard.h"
#include "gpu_timer.h"
#include "passes/passes.h"
#include "siviflow/renderer.h"
#include "shared_river.h"
#include "static_assets.h"
#include "tile_lattice.h"
#include "view_math.h"
#include "vk/device_table.h"
#include "vk/frame_graph.h"
#include "vk/frame_ring.h"
#include "vk/gpu_resources.h"

namespace siviflow {

struct Renderer::Impl {
  CreateInfo info;
  glm::mat4 river_from_world{1.0f};  // the inverse of info.world_from_river
  DeviceTable table;
  GpuContext gpu;
  FrameRing ring;
  std::vector<float> particle_heights;  // this frame's live particles' heights
  WaterLook look;                    // from the next update() on (set_look)
  DebugView debug_view = DebugView::kNone;  // likewise (set_debug_view)
  // The river, its flow and its static GPU data, shared with the other views of it.
  std::shared_ptr<SharedRiver> river;
  RiverView simulation;  // this view's particles and flow textures, on the CPU
  double last_time = 0.0;
  FlowPass flow_pass;

  // Images the frame graph declares; created after it compiles, with the usage it derived.
  struct FrameImage {
    ImageHandle handle;
    Image image;
    bool persistent = false;  // keeps its contents from frame to frame
  };
  std::vector<FrameImage> frame_images;
  bool frame_images_new = true;  // persistent ones have no previous contents yet

  FrameGraph graph;
  StaticAssets::GraphHandles river_assets;  // the shared river's static data in `graph`
  BufferHandle frame_staging;  // the slot's staging block: this frame's flow textures
  UploadList frame_uploads;    // flow texture and particle aux, every frame
  ImageHandle host_color;      // imported per frame: the host's colour and depth
  ImageHandle host_depth;
  ImageHandle host_motion;     // and its temporal filter's inputs, where configured
  ImageHandle host_reactive;
  ImageHandle reflection_depth;
  std::vector<ReadbackCopy> readbacks;  // one per image CreateInfo::readback_images asks for
  std::vector<ReadbackImage> readback_kinds;  // which image each of them copies
  FrameBindings bindings;
  FlowPass::Frame water_frame;  // of the frame being prepared: push constants, look, host depth
  std::vector<IndexRange> water_draws;  // the surface's runs the frame's view sees, joined
  glm::vec4 water_bounds{1.0f, 1.0f, 0.0f, 0.0f};  // their box_screen_bounds, joined (x0 > x1: none)
  // Where the graph's passes read this frame's upload list, readback copies, reflection view and
  // refraction copy.
  DataHandle<UploadList> uploads_data;
  DataHandle<std::vector<ReadbackCopy>> readbacks_data;
  DataHandle<ReflectionView> reflection_data;
  DataHandle<RefractionCopy> refraction_data;
  RefractionCopy refraction_copy;  // of the frame being prepared
  ViewMath view;        // of the frame being prepared, in river space, as drawn (jittered)
  glm::mat4 steady_view_proj{1.0f};  // river -> clip without the jitter: particles, motion
  glm::mat4 previous_view_proj{1.0f};  // what this frame's motion is measured from
  glm::mat4 shown_view_proj{1.0f};     // steady_view_proj of the last frame shown
  bool has_shown = false;              // false after create() and resize()
  VkRect2D viewport{};  // in the host's images
  VkRect2D scissor{};   // inside the viewport
  ReflectionView reflection_view{};
  TileLattice tile_lattice;  // the tile table's size and, per frame, its lattice and window

  GpuTimer timer;  // with CreateInfo::enable_timing
  uint32_t current_slot = 0;

  bool unusable = false;  // a resize failed half-way
  bool frame_begun = false;
  bool frame_updated = false;
  bool frame_recorded = false;  // since the last begin_frame
  bool record_failed = false;   // the last record of this frame failed

  Status validate_info(const CreateInfo& create);
  // An error naming the field, the format and the features it lacks (optimal tiling), and why
  // the water needs them.
  Status check_format_features(const char* field, VkFormat format, VkFormatFeatureFlags needs,
                               const char* why) const;
  Status take_look();
  Status create_river();
  Status create_view_resources();
  Status declare_graph();
  ImageHandle frame_image(ImageHandle handle, bool persistent = false);
  Status create_frame_images();
  const Image* find_frame_image(ImageHandle handle) const;
  size_t runtime_obstacle_index(uint32_t id) const;  // in runtime_obstacles; size() when unknown
  Status add_obstacle(const WaterObstacle& obstacle, uint32_t* id);
  Status move_obstacle(uint32_t id, const glm::vec3& centre, float rotation_rad);
  Status remove_obstacle(uint32_t id);
  Status set_occluders(const OccluderMesh& mesh);
  Status set_look(const WaterLook& new_look);
  Status query_water(std::span<const glm::vec3> points, std::span<WaterSample> out) const;
  Status simulate(const View& host_view, double time_seconds);
  // The frame prepared was recorded (or simulated without rendering): the next one's motion
  // starts from it.
  void show_frame() {
    shown_view_proj = steady_view_proj;
    has_shown = true;
  }
  float visible_water_level();
  void choose_water_draws();
  Status check_inputs(const FrameInputs& inputs) const;
  Status bind_frame(const FrameInputs& inputs);
  Status resize(VkExtent2D extent);
  Status pass_times(uint32_t slot, std::vector<PassTime>* out) const;
  void retire_frame_images();
  void destroy();
};

// An error in what the caller passed: no Vulkan result stands behind it.
Status argument_error(const std::string& message);

// What create() and view_memory() refuse of `info` without a device: sizes, formats, placement.
Status check_create_info(const CreateInfo& info);
inline constexpr VkDeviceSize kStagingAlignment = 16;  // covers every texel size we copy
// What CreateInfo's zeros stand for.
inline constexpr VkDeviceSize kDefaultStagingBytes = 8ull << 20;
inline constexpr uint32_t kDefaultFramesInFlight = 2;
// The view's own images (renderer_graph.cpp; view_memory.cpp counts them). Layouts of the flow
// texture and the particle aux data are documented in shaders/shared.h.
inline constexpr VkFormat kReflectionDepthFormat = VK_FORMAT_D32_SFLOAT;
inline constexpr VkFormat kFlowTextureFormat = VK_FORMAT_R16G16B16A16_UINT;
inline constexpr VkFormat kParticleAuxFormat = VK_FORMAT_R32G32B32A32_SFLOAT;
inline constexpr float kDefaultReflectionScale = 0.5f;  // reflection target size relative to the view
// The reflection target's size for a view of `extent`.
VkExtent2D reflection_extent(VkExtent2D extent);
// The texels of a view-covering target of `size` (the reflection, the refraction copy) that the
// water samples: `water` (box_screen_bounds of the water in view; x0 > x1 when none is) widened
// by `distortion` (texture coordinates per unit of ripple tilt, which stays under 1) and a texel
// for the filter. Empty when no water is.
VkRect2D sampled_area(const glm::vec4& water, float distortion, VkExtent2D size);

inline constexpr std::string_view kRendererErrorPrefix = "siviflow::Renderer: ";

// A public entry point's body, guarded (entry_guard.h) with the renderer's prefix and log.
template <typename Body>
Status guarded(const CreateInfo& info, Body&& body) noexcept {
  return guarded(kRendererErrorPrefix, info.log, info.log_user, std::forward<Body>(body));
}

}  // namespace siviflow
