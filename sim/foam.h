// Foam on the river, per vertex, from its flow (issue "water that shows its flow").
//
// Which quantity, and why: foam is air the water took in where its flow was disturbed, and it
// drifts with the current until it bursts. So
//   - the sources: the flow's velocity gradient |grad u| (Frobenius norm of the 2x2 horizontal
//     gradient, 1/s) over its section's mean speed, large where the flow speeds up or turns
//     sharply for its speed, i.e. at the shoulders of every obstacle and in tight bends, small in
//     open water however fast (relative, so a fast river is not all foam); the velocity deficit
//     1 - speed / (its section's mean speed), large in the still water in an obstacle's lee
//     (where a real rock's eddies churn: the stream function is irrotational and has no eddies
//     of its own, and is as slow in front of the rock as behind it, so the deficit counts a
//     quarter where the water slows along the flow, before the rock); and a line along the banks
//     as fast as the section flows (the stream function slips at the banks, so the gradient
//     alone would miss the shear a real bank makes);
//   - the foam is then carried downstream along the flow, thinning as exp(-t / lifetime): the
//     steady state of that transport, max(source, foam upstream one step earlier, decayed),
//     makes the wake, strongest just behind an obstacle and fading with distance.
// No Vulkan: the renderer hands the values to the GPU with the particles' data.
#pragma once

#include <algorithm>
#include <cstdint>
#include <span>
#include <vector>

#include <glm/vec3.hpp>

#include "sim/triangle_bvh.h"
#include "siviflow/sim/river_surface.h"
#include "siviflow/sim/triangles_around.h"
#include "siviflow/sim/xz_box.h"
#include "siviflow/status.h"

namespace siviflow {

struct FoamParams {
  // |grad u| relative to the section's mean speed, 1/m (1 over the length over which the flow
  // changes by its own speed): where foam starts (open water, and the shear across a fast
  // narrow channel, stay below) and where it is full (a boulder's shoulders).
  float gradient_onset = 0.28f;
  float gradient_full = 0.75f;
  float min_section_speed = 0.3f;  // m/s: slower sections count as this fast
  float deficit_onset = 0.5f;    // velocity deficit where foam starts (banks' own slow water
                                 // stays below)
  float deficit_full = 0.9f;     // where it is full (nearly still water)
  // The deficit's foam where the water slows towards an obstacle, as a share of that in its lee
  // (where it gathers speed again): the cushion a rock pushes up is smoother than its eddies.
  float front_share = 0.25f;
  float lee_acceleration = 0.1f;  // 1/s of speed change along the flow that tells front from lee
  float bank_width_m = 0.5f;     // the bank line's width (falls off as exp(-distance / width))
  float bank_speed_full = 1.0f;  // m/s past the bank at which its line is full
  float bank_strength = 0.6f;    // the bank line's foam at full speed
  float lifetime_s = 8.0f;       // foam decays as exp(-t / lifetime) while carried
  float step_s = 0.4f;           // transport step
  uint32_t steps = 30;           // transport steps: the wake is followed for steps * step_s
};

// Each vertex's distance along its section to the nearer margin: the smaller of its river
// surface node's two, read when needed, so a long river keeps no copy a vertex.
struct MarginDistances {
  std::span<const float> left;        // per node (RiverSurface::node_d_left)
  std::span<const float> right;       // per node
  std::span<const uint32_t> node_of;  // per vertex; empty when the vertices are the nodes
  float operator()(size_t v) const {
    const size_t n = node_of.empty() ? v : node_of[v];
    return std::min(left[n], right[n]);
  }
};
// The surface's, for the vertices of the mesh it was built from.
MarginDistances margin_distances(const RiverSurface& surface);

class FoamField {
 public:
  // For the mesh (indices: 3 per triangle; empty, every 3 positions are one). `section`: each
  // vertex's cross-section (river_surface.h). `bvh` is built on the same positions and indices.
  // `around`: the triangles around each vertex where the caller keeps them (a river surface's,
  // when its nodes are the vertices); null, the field builds its own. The spans, `bvh` and
  // `around` outlive this object, and `around` stays where it is (the field keeps its address).
  // Every vertex must be a corner of a triangle.
  static Status create(std::span<const glm::vec3> positions, std::span<const uint32_t> indices,
                       NodeSections section, const TriangleBvh* bvh, const FoamParams& params,
                       FoamField* out, const TrianglesAround* around = nullptr);
  FoamField() = default;
  FoamField(FoamField&&) = default;
  FoamField& operator=(FoamField&&) = default;
  FoamField(const FoamField&) = delete;
  FoamField& operator=(const FoamField&) = delete;

  // Foam per vertex in [0, 1] for the flow `velocity` (m/s per vertex); `bank_distance`: each
  // vertex's distance to the nearer margin along its section (metres), read during the call
  // only. Writes `foam` (sized to the vertices). Its scratch (32 bytes a vertex) lives only
  // during the call.
  void compute(std::span<const glm::vec3> velocity, const MarginDistances& bank_distance,
               std::span<float> foam);
  // The same, after the velocity changed only at vertices inside the `changed` boxes
  // (StreamFunction's FlowUpdateStats), `foam` holding what compute() or update() last wrote:
  // re-derives only the vertices whose foam can have changed and leaves the rest, so `foam`
  // ends equal to compute()'s bit for bit. Its scratch is sized by the vertices re-derived (and
  // a bit a vertex and a word a section of the river). Falls back to compute() where they are
  // most of the river, for a box that is not finite, and before the first compute().
  void update(std::span<const glm::vec3> velocity, const MarginDistances& bank_distance,
              std::span<const XzBox> changed, std::span<float> foam);
  // Vertices the last compute() or update() re-derived (all of them for compute()).
  size_t last_rederived() const { return last_rederived_; }

  const FoamParams& params() const { return params_; }

 private:
  // Where a vertex's water was one step earlier: the triangle there and its corners' weights
  // (all 0 where that point is off the river).
  struct Upstream {
    uint32_t triangle = 0;
    float weight[3] = {0.0f, 0.0f, 0.0f};
  };
  // Vertex v's foam source and upstream point; `ring` is scratch.
  float source_of(size_t v, std::span<const glm::vec3> velocity,
                  const MarginDistances& bank_distance, std::vector<uint32_t>* ring) const;
  Upstream upstream_of(size_t v, std::span<const glm::vec3> velocity) const;
  // Adds vertex v's share to its section's mean speed.
  void add_speed(size_t v, std::span<const glm::vec3> velocity);
  // update()'s halves: the sections about the changed boxes summed again (and the fastest speed
  // raised), giving the boxes whose sources can have changed; then the transport re-run on the
  // window's vertices (ascending), written back where inside `changed_foam`.
  std::vector<XzBox> resum_sections(std::span<const glm::vec3> velocity,
                                    std::span<const XzBox> changed);
  void rederive(std::span<const uint32_t> window, std::span<const XzBox> changed_foam,
                std::span<const glm::vec3> velocity, const MarginDistances& bank_distance,
                std::span<float> foam);
  // The vertices inside the boxes, each once, ascending.
  std::vector<uint32_t> vertices_in(std::span<const XzBox> boxes) const;
  uint32_t corner(size_t i) const { return indices_.empty() ? uint32_t(i) : indices_[i]; }

  std::span<const glm::vec3> positions_;
  std::span<const uint32_t> indices_;
  NodeSections section_;
  const TriangleBvh* bvh_ = nullptr;
  FoamParams params_;
  // The one-ring of a vertex is gathered from its triangles when needed: a long river keeps no
  // neighbour lists.
  const TrianglesAround& around() const {
    return shared_around_ != nullptr ? *shared_around_ : own_around_;
  }
  const TrianglesAround* shared_around_ = nullptr;
  TrianglesAround own_around_;        // when the caller gave none
  std::vector<float> section_speed_;  // per section: its vertices' mean speed
  std::vector<uint32_t> section_size_;
  float longest_edge_ = 0.0f;    // x/z: how far a triangle's corner lies from a point in it
  float rounding_ = 0.0f;        // how far a rounded upstream point can lie from the true one
  double widest_section_ = 0.0;  // x/z: how far apart two vertices of one section lie at most
  // At least every vertex's squared speed: set by compute(), only raised by update() (a bound
  // kept from a faster moment widens later windows, never wrongs them).
  float fastest2_ = 0.0f;
  bool computed_ = false;  // section_speed_ holds the last velocity's
  size_t last_rederived_ = 0;
};

}  // namespace siviflow
