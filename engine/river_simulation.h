// The simulation half of a frame for a river, on the CPU: the river surface and its
// stream-function flow (solved once, shared by every view of the river), and per view the
// screen-space particles and flow textures (kept every frame). No Vulkan: the renderer copies
// pack()'s bytes into its staging block.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <span>
#include <vector>

#include <glm/mat4x4.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include "siviflow/sim/river_surface.h"
#include "siviflow/water_river.h"
#include "sim/flow_textures.h"
#include "sim/foam.h"
#include "sim/particles.h"
#include "sim/triangle_bvh.h"
#include "sim/water_query.h"
#include "siviflow/sim/obstacle.h"
#include "siviflow/sim/procedural_river.h"
#include "siviflow/sim/river_surface.h"
#include "siviflow/sim/stream_function.h"
#include "siviflow/status.h"
#include "siviflow/water_river.h"

namespace siviflow {

// What the simulation runs on: the river's mesh (positions, indices), the water depth and the
// riverbed slope under each vertex, and the surface built from the mesh (built once). The mesh
// has no positions and indices when the surface's are the same (it welded nothing and kept the
// winding): one copy of a long river, not two.
struct RiverInput {
  RiverMesh mesh;               // its depth and slope empty: they are below
  std::vector<uint16_t> depth;  // metres, binary16 (sim/half_float.h)
  std::vector<uint16_t> slope;  // rise over run, binary16
  RiverSurface surface;
  std::vector<float> end_discharges;  // FlowParams::end_discharges: per surface end, or none
};

// The solver's parameters for a host's flow: with named ends, their discharges (in the order of
// `input`'s surface) and their inflows' sum as the discharge.
FlowParams river_flow_params(const RiverFlowParams& flow, const RiverInput& input);
// The surface options that name a river's ends (none: vertex 0's end is the upstream one).
RiverSurfaceOptions river_surface_options(std::span<const WaterRiverEnd> ends);
// Their discharges in the order of `surface`'s ends (built with those options), or none.
std::vector<float> surface_end_discharges(const RiverSurface& surface,
                                          std::span<const WaterRiverEnd> ends);

// The generated river's ends (a confluence's), the outflow carrying `discharge` and the
// tributaries sharing it by width; none for a strip.
std::vector<WaterRiverEnd> procedural_river_ends(const RiverMesh& mesh, float discharge);
// The procedural river's mesh with its surface built.
Status procedural_river_input(const ProceduralRiver& river, RiverInput* out);
// A host's river (CreateInfo::river): its arrays checked (sizes, finite, depth and slope from 0
// to 65504) and copied, its surface built. `copied` (may be empty) is called as soon as none of the
// river's arrays is read any more, before the surface finds its sections. Errors name the field
// and the vertex.
Status river_input_from(const WaterRiver& river, const std::function<void()>& copied,
                        RiverInput* out);

// The flow's obstacle for a host's: the polygon turned about +Y (x' = x cos + z sin,
// z' = -x sin + z cos, as glm::rotate turns +X towards -Z), the keys as they are.
Obstacle flow_obstacle(const WaterObstacle& placed);
// A host's obstacle checked as the flow would check it; the message names it by `index`.
Status check_obstacle(const WaterObstacle& placed, size_t index);

// The river every view of it shares: its mesh, its flow (solved once, then re-solved only
// around obstacles that move, come or go) and the ray-cast structure of its surface. Its
// per-vertex arrays change in place, so the views' particles see every new flow.
class RiverFlow {
 public:
  // Where the mesh the GPU draws lives once the GPU has it. Given the positions and indices to
  // draw, a home makes its buffers of them and, where the host reads those as fast as its own
  // memory (a unified-memory device's), returns them; else leaves `placed` empty.
  struct PlacedMesh {
    std::span<const glm::vec3> positions;
    std::span<const uint32_t> indices;
  };
  using MeshHome = std::function<Status(std::span<const glm::vec3> positions,
                                        std::span<const uint32_t> indices, PlacedMesh* placed)>;

  // Solves the flow of `river` with the obstacles, and hands the mesh to `home` (if any) before
  // anything reads it: a mesh placed there, alive while anything reads this flow, is then read
  // from there and the flow's own copy freed (only a mesh read from the surface, see per_node_).
  // Must not be moved after create(): the views keep spans into its per-vertex arrays, and the
  // foam the address of its surface's triangles around each node.
  Status create(RiverInput river, const FlowParams& flow, std::vector<Obstacle> obstacles,
                const MeshHome& home = {});

  // Places the keyframed obstacles at `time_seconds` and re-solves the flow near those that
  // moved (nothing when they are already there).
  Status set_time(double time_seconds);
  glm::vec3 obstacle_centre(size_t index) const { return flow_.obstacle_centre(index); }
  size_t obstacle_count() const { return flow_.obstacles().size(); }
  // Every obstacle's footprint where it stands now (pointers into this object, valid until the
  // obstacles next change): where particles are not made.
  void dry_footprints(std::vector<DryFootprint>* out) const;

  // Obstacles placed at runtime, by their index in the flow's list (add appends): each re-solves
  // the flow only around the old and new footprint. A keyed one starts where its keys put it at
  // the last set_time()'s time, and moves with the later ones.
  Status add_obstacle(Obstacle obstacle);
  Status replace_obstacle(size_t index, Obstacle obstacle);
  Status move_obstacle(size_t index, const glm::vec3& centre);
  Status remove_obstacle(size_t index);

  // The water at each river-space point (sim/water_query.h), from the flow as it stands: each
  // sample's obstacle is the flow's obstacle index plus one, 0 outside every footprint. Reads
  // only; safe beside other reads, not beside a call that changes the obstacles or the time.
  void query(std::span<const glm::vec3> points, std::span<WaterSample> out) const;

  // The river's mesh, in the host's vertex order.
  std::span<const glm::vec3> positions() const { return field_.positions; }
  std::span<const uint32_t> indices() const { return field_.indices; }
  // The surface, its flow and what the particles read per vertex (spans into this object).
  const RiverFlowField& field() const { return field_; }
  std::shared_ptr<const TriangleBvh> bvh() const { return bvh_; }
  uint64_t full_solves() const { return full_solves_; }  // 1: the one at create

  // The host's geometry that can hide the water (Renderer::set_occluders): copied, with its
  // ray-cast structure, for every view's particles from their next frame; an empty mesh clears
  // it. Errors name the OccluderMesh field and index, and nothing changes then.
  Status set_occluders(std::span<const glm::vec3> positions, std::span<const uint32_t> indices);
  // Null when there are none.
  std::shared_ptr<const TriangleBvh> occluders() const { return occluders_; }

 private:
  // Re-reads the solved velocity per vertex and derives the foam from it.
  void refresh_velocity();

  // A mesh the surface welded nothing of and wound as it came (RiverInput) is read from the
  // surface: positions, indices, section and velocity per vertex are then its per-node arrays;
  // else mesh_, section_copy_ and velocity_copy_.
  bool per_node_ = false;
  RiverMesh mesh_;
  StreamFunction flow_;
  std::vector<glm::vec3> velocity_copy_;  // per vertex, m/s
  std::vector<uint16_t> depth_;           // RiverInput's
  std::vector<uint16_t> slope_;
  std::vector<uint32_t> section_copy_;
  std::vector<float> foam_;          // 0..1 per vertex (sim/foam.h)
  FoamField foam_field_;
  bool has_keys_ = false;            // some obstacle moves: re-solve as time goes
  double time_ = 0.0;                // the last set_time()'s
  RiverFlowField field_;
  std::shared_ptr<const TriangleBvh> bvh_;
  WaterQuery water_query_;
  std::shared_ptr<const TriangleBvh> occluders_;  // owns its mesh (aliasing)
  uint64_t full_solves_ = 0;
};

// One view of a river: its screen-space particles and the flow textures packed from them.
class RiverView {
 public:
  // Sizes the particles and flow textures for `viewport`. `river` outlives this view.
  Status create(const RiverFlow& river, uint64_t seed, glm::uvec2 viewport);

  // A new viewport: new particles (from frame 0) and flow textures, on the same river and
  // ray-cast structure. On failure nothing changes.
  Status resize(glm::uvec2 viewport);

  // One frame of Algorithm 2. Frames must come in order from 0; dt is the time since the last.
  Status simulate(const glm::mat4& view_proj, float dt_seconds);
  // Packs this frame's flow texture and auxiliary data into `staging` (layout().total_bytes).
  Status pack(std::span<std::byte> staging);

  uint64_t next_frame() const { return particles_.next_frame(); }
  const FlowTextureLayout& layout() const { return flow_textures_.layout(); }
  const ParticleField& particle_field() const { return particles_; }

 private:
  const RiverFlow* river_ = nullptr;
  ParticleField particles_;
  FlowTextures flow_textures_;
  glm::uvec2 viewport_{0u};
  std::vector<DryFootprint> dry_;  // scratch: the river's footprints this frame
};

}  // namespace siviflow
