// Stream-function flow on the river surface (paper §2.2.1, eq. 2.1-2.3; algorithms.md §1.1, §1.6).
//
// psi(P) = sum_i w(d_i) psi_i / sum_i w(d_i),  w(d) = d^-p f(1 - d/s) for d < s, else 0,
// f(t) = 6t^5 - 15t^4 + 10t^3 (t clamped to [0, 1]).
//
// Boundaries: the left bank (psi = Q), the right bank (psi = 0), each island's shore (the psi
// of zero circulation about it, island_circulation.h), with in-river distances measured along
// each vertex's section to the border on either side of it, and the obstacles in the water, at the XZ distance to their
// footprint, each with psi = the obstacle-free field at its centre (so the total discharge is
// kept). An obstacle whose footprint crosses one bank is part of that bank: it takes the bank's
// psi (no water passes between them) and the bank's distance becomes the nearer of the two, so
// an object entering the water from the shore does not make the flow pop.
// Velocity: per triangle v = grad(psi) x n (P1, tangent to the surface, divergence-free, pointing
// downstream); per vertex the area-weighted mean of its triangles, slid along the bank on a bank
// vertex (a bank is a streamline), zero on a dry vertex (inside an obstacle).
#pragma once

#include <cstdint>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>
#include <span>
#include <utility>
#include <vector>

#include "siviflow/sim/obstacle.h"
#include "siviflow/sim/river_surface.h"
#include "siviflow/sim/river_tuning.h"
#include "siviflow/sim/spatial_grid.h"
#include "siviflow/sim/xz_box.h"
#include "siviflow/status.h"

namespace siviflow {

struct FlowParams {
  float discharge = 1.0f;              // Q = psi_left - psi_right, m^2/s (speed Q/W when uniform)
  float p = kDefaultShepardPower;      // Shepard power, in (0, 16]
  float search_radius = 0.0f;          // s in metres; 0: kDefaultSearchRadiusFactor x widest section
  // Per end of the river (RiverSurface::ends() order), m^2/s in or out: the ends must balance and
  // bring in `discharge`. Empty: the upstream end carries `discharge` and the ends of the other
  // kind share it by width (end_discharges.h).
  std::vector<float> end_discharges;
};

// What the last update re-solved (a full solve counts everything).
struct FlowUpdateStats {
  size_t nodes_resolved = 0;     // psi re-solved (within reach of an obstacle that moved)
  size_t triangles_updated = 0;  // triangle velocities recomputed
  size_t nodes_velocity = 0;     // vertex velocities recomputed
  // Boxes holding every node whose velocity was recomputed, one about each place an obstacle
  // left or reached (none when nothing changed; one box everywhere after a full solve): what
  // depends on the velocity re-derives only there.
  std::vector<XzBox> velocity_changed;
};

class StreamFunction {
 public:
  // Takes the surface and solves the obstacle-free field. Fails on bad parameters, or naming the
  // section and vertex, when an interior vertex does not have both banks within s.
  static Status create(RiverSurface surface, const FlowParams& params, StreamFunction* out);
  // The checks of create() that need no surface: a finite discharge, p in (0, 16], a search
  // radius >= 0. A caller with costly work before create() makes them first.
  static Status validate_params(const FlowParams& params);

  const RiverSurface& surface() const { return surface_; }
  const FlowParams& params() const { return params_; }  // search_radius resolved
  float search_radius() const { return params_.search_radius; }

  // Replaces the obstacles, places the keyframed ones at `time`, and re-solves everything (where
  // there were none and are none, the field already is that solve). On failure (naming the
  // obstacle) the previous obstacles stay.
  Status set_obstacles(std::vector<Obstacle> obstacles, double time = 0.0);
  std::span<const Obstacle> obstacles() const { return obstacles_; }
  // Moves obstacle `index` to `centre` and re-solves only the vertices within s of its old or
  // new footprint (and the triangles and vertex velocities around them). The result equals a
  // full re-solve, bit for bit. The obstacle keeps its keys: the next set_time() uses them.
  Status move_obstacle(size_t index, const glm::vec3& centre);
  // Appends an obstacle (keyframed ones placed at `time`) and re-solves only the vertices within
  // s of its footprint; it takes index obstacles().size() - 1. The result equals a full re-solve.
  Status add_obstacle(Obstacle obstacle, double time = 0.0);
  // Gives obstacle `index` a new footprint and centre (a turned polygon, a new radius), re-solving
  // around the old and the new footprint. On failure nothing changes.
  Status replace_obstacle(size_t index, Obstacle obstacle, double time = 0.0);
  // Removes obstacle `index` (later ones move down one) and re-solves around where it was.
  Status remove_obstacle(size_t index);
  // Places every keyframed obstacle at time t, incrementally.
  Status set_time(double t);
  // Re-solves every vertex for the obstacles where they are now.
  void solve_full();
  const FlowUpdateStats& last_update() const { return stats_; }
  // Bytes of its arrays, the surface's included (the obstacle grids only once obstacles came).
  size_t memory_bytes() const;

  // --- Per input vertex.
  double psi(size_t vertex) const { return node_psi(surface_.node_of(vertex)); }
  glm::vec3 velocity(size_t vertex) const { return node_velocity_[surface_.node_of(vertex)]; }
  bool wet(size_t vertex) const { return wet_[surface_.node_of(vertex)]; }

  // --- Per node (RiverSurface node indices) and per triangle (RiverSurface::triangles()).
  // Evaluated when asked, under the obstacles where they are (a long river cannot keep 8 bytes
  // per node for it): the value the last solve used, bit for bit.
  double node_psi(uint32_t n) const;
  double node_psi_free(uint32_t n) const;  // without obstacles
  std::span<const glm::vec3> node_velocity() const { return node_velocity_; }
  const std::vector<bool>& node_wet() const { return wet_; }
  // Computed when asked (a long river cannot keep 12 bytes per triangle for it), psi at each
  // corner evaluated too.
  glm::vec3 triangle_velocity(uint32_t t) const;

  // --- Per island: psi on its shore. The discharge passing on its left is psi_left_border -
  // island_psi, on its right island_psi - psi_right_border.
  double island_psi(size_t i) const { return border_psi_[island_border(i)]; }
  // Q on the left bank, 0 on the right, island_psi on an island's shore; a network's other banks
  // as its ends' discharges set them.
  double border_psi(BorderId border) const { return border_psi_[border]; }
  // The discharge through end e (RiverSurface::ends() order), m^2/s.
  double end_discharge(size_t e) const { return end_discharge_[e]; }

  // --- Per obstacle.
  glm::vec3 obstacle_centre(size_t i) const { return state_[i].centre; }
  bool obstacle_in_water(size_t i) const { return state_[i].in_water; }
  // The bank an obstacle is merged into (it crosses that bank), or kNone.
  Bank obstacle_bank(size_t i) const { return state_[i].merged; }
  double obstacle_psi(size_t i) const { return state_[i].psi; }

 private:
  struct ObstacleState {
    glm::vec3 centre{0.0f};
    glm::dvec2 lo{0.0}, hi{0.0};     // footprint bounds, XZ
    bool in_water = false;           // the footprint overlaps a river triangle
    double psi = 0.0;                // psi_free at the centre (or the nearest wet point)
    float along_lo = 0.0f, along_hi = 0.0f;  // along-river span of the wet footprint
    // The bank the footprint crosses, if one (not both): the obstacle is then part of that bank,
    // with its psi, and enters the interpolation as the nearer of the two.
    Bank merged = Bank::kNone;
  };

  double evaluate(uint32_t node, bool use_obstacles, bool* wet) const;
  bool influences(const ObstacleState& state, size_t obstacle, uint32_t node) const;
  // The velocity first: returned in two registers, (x, y) and (z, area2), which the caller reads
  // back whole (area2 first, x and y straddled them, and each read waited on both).
  struct TriangleFlow {
    glm::vec3 velocity;  // grad(psi) x n
    float area2;         // 2 x area
  };
  float triangle_area2(uint32_t t) const;
  // From psi at the triangle's corners. Out of line: inlined into the velocity's sum, GCC 12 at
  // -O3 kept the velocity's x and y in double (the disassembly multiplies g / area2 by area2 with
  // no rounding to float between; likely a compiler bug, not reduced), so a node's velocity hung
  // on its caller, a full solve against an update. Returned, the rounding is kept.
  [[gnu::noinline]] TriangleFlow triangle_flow(uint32_t t, double psi_a, double psi_b,
                                               double psi_c) const;
  // `psi_of(node)` gives psi at a node (the triangle's corners, a node's triangles' corners).
  template <class PsiOf>
  TriangleFlow triangle_flow(uint32_t t, const PsiOf& psi_of) const;
  template <class PsiOf>
  void update_node_velocity(uint32_t n, const PsiOf& psi_of);
  // psi at every node from `evaluate(n, use_obstacles)` (and each node's wet), then every node's
  // velocity from it; the psi is dropped after.
  void solve_all(bool use_obstacles);
  // Unit, downstream, on a bank node (its section's shore); zero elsewhere.
  glm::vec3 bank_tangent(uint32_t n) const;
  void build_grids();
  ObstacleState place(size_t obstacle, const glm::vec3& centre) const;
  void refresh_active();
  // Gives obstacle `obstacle` its new state and re-solves the vertices either state reaches.
  void move_incremental(size_t obstacle, const ObstacleState& new_state);

  RiverSurface surface_;
  FlowParams params_;
  // Only what a re-solve cannot cheaply recompute is kept per node: psi (evaluated per node
  // from the margin distances), the triangles' areas and velocities, the node areas and bank
  // tangents are derived when needed.
  std::vector<bool> wet_;  // a bit a node
  std::vector<glm::vec3> node_velocity_;
  // Where arms of a network meet: the tips of the tongues between them in one section, and the
  // water beyond, between the outermost arms' outer borders. Beyond it the streamlines parting
  // the arms leave from the tips (evaluate()).
  struct Junction {
    double along = 0.0;  // the tips' section's
    BorderId left = 0, right = 0;  // the outer borders of the water beyond
    // Each tip's place across the water, as the arms' share of the width left of it at the tips'
    // section, and its tongue's psi; from the left.
    std::vector<std::pair<double, double>> dividers;
  };
  // The junctions of a network (none for a strip), from border_psi_ (network_junctions.cpp).
  void find_junctions();
  std::vector<Junction> junctions_;
  std::vector<double> border_psi_;  // by BorderId
  std::vector<double> end_discharge_;
  // Every island shore node's tangent, and in a network every bank node's (a shore is a
  // streamline, as a bank is), by node.
  std::vector<std::pair<uint32_t, glm::vec3>> shore_tangent_;
  std::vector<Obstacle> obstacles_;
  std::vector<ObstacleState> state_;
  std::vector<uint32_t> active_;             // obstacles in the water, ascending
  XzGrid node_grid_;
  XzGrid triangle_grid_;
  // Scratch for incremental updates: generation stamps avoid clearing per update; an update's
  // last stamps also place each corner's psi in psi_values_.
  std::vector<uint32_t> node_stamp_;
  std::vector<uint32_t> triangle_stamp_;
  uint32_t stamp_ = 0;
  std::vector<uint32_t> scratch_nodes_;
  std::vector<uint32_t> scratch_triangles_;
  // An update's psi at the corners of the triangles around the nodes whose velocity it
  // recomputes (each corner's found by its stamp).
  std::vector<double> psi_values_;
  FlowUpdateStats stats_;
};

}  // namespace siviflow
