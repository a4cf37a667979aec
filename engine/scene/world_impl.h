// The built-in world's state (World::Impl), shared by world.cpp (creating it, recording its
// passes) and world_pieces.cpp (the boulders and floats a host moves, and what each view draws).
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <glm/mat4x4.hpp>
#include <glm/vec3.hpp>

#include "gpu_timer.h"
#include "index_range.h"
#include "scene/default_scene.h"
#include "scene/lod_culling.h"
#include "scene/scene_pass.h"
#include "siviflow/world.h"
#include "static_assets.h"
#include "vk/device_table.h"
#include "vk/frame_graph.h"
#include "vk/frame_ring.h"
#include "vk/gpu_resources.h"

namespace siviflow {

inline constexpr std::string_view kWorldErrorPrefix = "siviflow::World: ";

inline Status world_error(const std::string& message) {
  return Status::error(std::string(kWorldErrorPrefix) + message);
}

// A float the world draws where its host places it.
struct WorldFloat {
  FloatMesh mesh = FloatMesh::kLog;
  float radius = 0.0f;
  IndexRange triangles;
  bool shown = false;
  glm::vec3 centre{0.0f};
  float heading = 0.0f;
};

struct World::Impl {
  WorldCreateInfo info;
  DeviceTable table;
  GpuContext gpu;
  FrameRing ring;  // deletions only: the static upload's staging buffer
  ProceduralRiver river{default_river_params()};  // the default scene's, or the scene file's
  bool river_from_file = false;  // a glTF river: no valley, its bed drawn from its own depth
  RiverMesh river_mesh;          // for a glTF river's bed and overview camera
  std::vector<SceneGeometry> other_rivers;  // the scene's rivers after the first, until uploaded
  std::vector<RiverMesh> other_meshes;      // those from files, for the ground, until built
  std::vector<Obstacle> obstacles;  // each drawn as a boulder where it is at the frame's time
  // Per boulder: where the host stood it (overriding its obstacle's keys), and whether it is
  // drawn (spares start hidden).
  std::vector<std::optional<glm::vec3>> placed;
  std::vector<bool> shown;
  std::vector<LodPiece> pieces;       // the static world, culled and levelled per view
  std::vector<IndexRange> boulders;   // per obstacle, drawn translated to it
  std::vector<WorldFloat> floats;     // the scene's, then the spares
  SceneCamera camera_path;          // keys empty: the scene's default camera
  // The ground, beds and objects as World::occluders() gives them.
  std::vector<glm::vec3> occluder_positions;
  std::vector<uint32_t> occluder_indices;
  SceneLook look = default_scene_look();

  enum StaticBufferId : uint32_t { kVertices, kIndices };
  enum StaticImageId : uint32_t { kDetail, kFirstBaseColor };
  StaticAssets assets;
  StaticAssets::GraphHandles asset_handles;  // in `graph`
  ScenePass main_pass;        // host colour and depth formats
  ScenePass reflection_pass;  // the renderer's reflection target, when its formats differ
  bool own_reflection_pass = false;

  // What the passes draw, chosen per view: the static pieces it sees (nearest first, so the
  // depth test spares the far ones' shading), then each obstacle's boulder with its own
  // constants (translated to where the obstacle is). Per view: main, then mirrored.
  std::vector<SceneDraw> main_draws;
  std::vector<SceneDraw> reflection_draws;
  // Kept, so a steady frame allocates nothing: the draws by distance, each piece's level, the
  // ranges of one piece.
  std::vector<std::pair<float, SceneDraw>> sorted_pieces;
  std::vector<uint32_t> piece_levels;
  std::vector<IndexRange> piece_ranges;
  gpu::SceneConstants main_constants{};
  gpu::SceneConstants reflection_constants{};
  std::vector<gpu::SceneConstants> obstacle_constants;  // per obstacle: main, then mirrored
  std::vector<gpu::SceneConstants> float_constants;     // per float: main, then mirrored
  double time = 0.0;  // of the last record(), for the reflection
  glm::mat4 projection{1.0f};  // of the last record()'s view: the reflection's levels use it too
  WorldDrawStats stats;
  GpuTimer timer;  // with WorldCreateInfo::enable_timing
  uint32_t slot = 0;  // of the last begin_frame()
  ScenePass::Frame frame;  // the main view's depth convention and viewport
  ScenePass::FrameData frame_data;  // where `graph` reads the draws and `frame`

  FrameGraph graph;
  ImageHandle color;
  ImageHandle depth;
  FrameBindings bindings;

  Status load_scene();
  Status create_resources();
  Status declare_graph();
  gpu::SceneConstants view_constants(const glm::mat4& view_proj, const glm::vec3& camera,
                                     const glm::vec4& clip_plane, bool reverse) const;
  // Where boulder `i` stands at time `at`: where the host placed it, or where its keys put it.
  glm::vec3 boulder_centre(size_t i, double at) const {
    return placed[i] ? *placed[i] : obstacle_centre_at(obstacles[i], at);
  }
  void select_draws(const CullView& view, const gpu::SceneConstants& constants, size_t which,
                    std::vector<SceneDraw>* draws, uint32_t* triangles);
  void destroy();
  static Status create(const WorldCreateInfo& info, std::unique_ptr<World>* out);
  Status record(VkCommandBuffer cmd, const View& view, double time_seconds,
                const ExternalImage& host_color, const ExternalImage& host_depth);
};

}  // namespace siviflow
