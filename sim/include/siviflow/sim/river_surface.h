// River Surface Generator (paper §2, Algorithm 1): from a plain triangle mesh, find the river's
// sections and banks from its topology, and give every vertex its section, bank flag, section
// width, in-river distances to both margins and the section's flow direction.
//
// The mesh is a strip: a triangulated band whose rows (sections) run from bank to bank, every
// triangle joining two neighbouring sections. Sections may differ in width and in vertex count.
// The strip may have holes, the islands: a section that meets an island goes on from its far
// side, so the island's shore is a border like the banks, between two arms of the river. An
// island vertex has no distance to either side (d_left = d_right = 0, both borders its own). The
// vertex order does not matter, except that the upstream end is the end section holding vertex
// `RiverSurfaceOptions::upstream_vertex` (vertex 0 by default: the paper's "first vertex is a
// corner"). The left bank is on the left looking downstream with +Y up (glTF).
//
// Or the mesh is a network (river_network.cpp): more than two ends, found at the corners of its
// outer border, arms parting and joining about tongues of land (a confluence: several inflows
// and one outflow; a fork: one inflow and several outflows), islands anywhere. Its sections are
// counted from that single end, each a row's arms from border to border; a tongue's vertices
// have no distance to either side, as an island's.
//
// Vertices at exactly the same position are welded (a glTF export splits vertices along UV
// seams and sharp edges, and a non-indexed mesh repeats every vertex): the topology is built on
// the welded "nodes" and every input vertex reads its node's data.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <iterator>
#include <ranges>
#include <span>
#include <vector>

#include <glm/vec3.hpp>

#include "siviflow/sim/triangles_around.h"
#include "siviflow/status.h"

namespace siviflow {

// Which margin a vertex lies on. The values are those of the `bank` column of `siviflow flow`.
enum class Bank : int8_t { kLeft = -1, kNone = 0, kRight = 1 };

// One end of the river named by the caller: a vertex on it (or the end nearest a point), and
// which way the water crosses it.
struct RiverEndMark {
  uint32_t vertex = 0;
  bool inflow = true;
  bool at_point = false;   // the end nearest `point` instead of the one holding `vertex`
  glm::vec3 point{0.0f};
};

struct RiverSurfaceOptions {
  // An input vertex on the upstream end section (a corner, in the paper's meshes).
  uint32_t upstream_vertex = 0;
  // Every end of the river, each named once by one of its vertices, in any order. Empty: the end
  // holding upstream_vertex is the only inflow and every other end an outflow (a fork, or a
  // strip). Given, upstream_vertex is not read. A network takes a single inflow or a single
  // outflow.
  std::vector<RiverEndMark> ends;
  // Called once, as soon as build() has read `positions` and `indices` for the last time (it
  // holds its own nodes and triangles then, before it finds sections and banks), with whether
  // it welded vertices: a caller may free the arrays there, or copy what it keeps of them. Not
  // called when build() fails before. May be empty.
  std::function<void(bool welded)> inputs_read;
  // Where given, set by a build that succeeds to one flag per triangle in triangles() order, true
  // where it reversed the winding (swapped the last two corners): what a caller that freed an
  // unwelded mesh's indices at inputs_read needs to give them back. Unspecified on a failure.
  std::vector<bool>* rewound = nullptr;
};

// The nodes of one section, from the left shore to the right shore: a run of the surface's list,
// or, where the surface numbers its nodes section after section, consecutive nodes (either way
// round), which a long river then keeps no list of. Its iterators stay valid while the surface
// does, whatever becomes of the range (a borrowed range).
class SectionNodes {
 public:
  class Iterator {
   public:
    using iterator_category = std::forward_iterator_tag;
    using value_type = uint32_t;
    using difference_type = std::ptrdiff_t;
    using pointer = void;
    using reference = uint32_t;

    Iterator() = default;
    Iterator(const uint32_t* list, int64_t first, int step, size_t i)
        : list_(list), first_(first), step_(step), i_(i) {}
    uint32_t operator*() const {
      return list_ != nullptr ? list_[i_] : static_cast<uint32_t>(first_ + step_ * int64_t(i_));
    }
    Iterator& operator++() {
      ++i_;
      return *this;
    }
    Iterator operator++(int) {
      const Iterator before = *this;
      ++i_;
      return before;
    }
    bool operator==(const Iterator& other) const = default;

   private:
    const uint32_t* list_ = nullptr;
    int64_t first_ = 0;
    int step_ = 0;
    size_t i_ = 0;
  };

  // `size` nodes listed at `list`, or (list null) first, first + step, ... (step +1 or -1).
  SectionNodes(const uint32_t* list, int64_t first, int step, size_t size)
      : list_(list), first_(first), step_(step), size_(size) {}
  uint32_t operator[](size_t i) const { return *Iterator(list_, first_, step_, i); }
  size_t size() const { return size_; }
  uint32_t front() const { return (*this)[0]; }
  uint32_t back() const { return (*this)[size_ - 1]; }
  Iterator begin() const { return {list_, first_, step_, 0}; }
  Iterator end() const { return {list_, first_, step_, size_}; }

 private:
  const uint32_t* list_;
  int64_t first_;
  int step_;
  size_t size_;
};

}  // namespace siviflow

template <>
inline constexpr bool std::ranges::enable_borrowed_range<siviflow::SectionNodes> = true;

namespace siviflow {

// One cross-section of the river, from the left shore to the right shore.
struct RiverSection {
  uint32_t first_node = 0;  // offset into the surface's nodes listed section by section
  uint32_t node_count = 0;  // >= 2: the left shore, interior vertices, the right shore
  float width = 0.0f;       // length of the section polyline, metres
  float along = 0.0f;       // distance of the shore midpoint from the upstream end, along the river
  glm::vec3 midpoint{0.0f};        // midpoint of the two shore vertices
  glm::vec3 flow_direction{0.0f};  // unit, horizontal, downstream (paper §2.1)
};

// The section of every node: listed, or, where the surface numbers its nodes section after
// section, found from the sections' first nodes, which a long river then keeps no list for. A
// view: valid while the list, or the surface, it reads is.
class NodeSections {
 public:
  // Runs are searched from the section of every 2^kBlockBits-th node: 0.25 bytes a node, and a
  // search among a few sections.
  static constexpr int kBlockBits = 4;

  NodeSections() = default;
  // Node n's section is list[n] (a view, as a span is).
  NodeSections(std::span<const uint32_t> list) : list_(list) {}  // NOLINT: a list is its sections
  NodeSections(const std::vector<uint32_t>& list) : list_(list) {}  // NOLINT
  // Node n lies in the section whose run [first_node, first_node + node_count) holds it;
  // `block_sections[b]` is the section of node b * 2^kBlockBits.
  NodeSections(std::span<const RiverSection> runs, std::span<const uint32_t> block_sections)
      : runs_(runs), block_sections_(block_sections) {}

  uint32_t operator[](size_t n) const {
    if (runs_.empty()) return list_[n];
    const size_t b = n >> kBlockBits;
    const auto lo = runs_.begin() + block_sections_[b];
    const auto hi =
        b + 1 < block_sections_.size() ? runs_.begin() + block_sections_[b + 1] + 1 : runs_.end();
    const auto after = std::upper_bound(
        lo, hi, n, [](size_t node, const RiverSection& run) { return node < run.first_node; });
    return static_cast<uint32_t>(after - runs_.begin() - 1);
  }
  size_t size() const {
    return runs_.empty() ? list_.size() : size_t{runs_.back().first_node} + runs_.back().node_count;
  }

 private:
  std::span<const uint32_t> list_;
  std::span<const RiverSection> runs_;
  std::span<const uint32_t> block_sections_;
};

// The borders of the water: the two banks beside the upstream end (a network's root end), the
// islands' shores, then a network's other banks (the tongues between its arms). Every vertex
// lies between a border on its left and one on its right along its section (the two banks,
// where no island parts the river).
using BorderId = uint16_t;
inline constexpr BorderId kLeftBankBorder = 0;
inline constexpr BorderId kRightBankBorder = 1;
inline constexpr BorderId island_border(size_t island) { return static_cast<BorderId>(2 + island); }

// One island: a hole in the river mesh, its shore a closed loop of nodes.
struct RiverIsland {
  uint32_t first_node = 0;  // offset into RiverSurface::island_nodes()
  uint32_t node_count = 0;  // the shore's nodes in border order
};

inline constexpr uint32_t kNoEndMark = 0xffffffffu;

// An open end of the river, where water enters or leaves: one section's water between the two
// borders at its corners.
struct RiverEnd {
  uint32_t first_node = 0;  // offset into RiverSurface::end_nodes(), left to right downstream
  uint32_t node_count = 0;
  bool inflow = true;
  uint32_t section = 0;
  BorderId left_border = kLeftBankBorder;  // looking downstream
  BorderId right_border = kRightBankBorder;
  float width = 0.0f;
  uint32_t mark = kNoEndMark;  // the index in RiverSurfaceOptions::ends that named it
};

// A bank of a river network: a border between two ends, its nodes in border order.
struct RiverBank {
  BorderId border = kLeftBankBorder;
  uint32_t first_node = 0;  // offset into RiverSurface::bank_nodes()
  uint32_t node_count = 0;
};

// What Algorithm 1 stores per vertex.
struct RiverVertex {
  uint32_t section = 0;
  Bank bank = Bank::kNone;
  float width = 0.0f;    // width of the vertex's section (the sum of its arms around islands)
  float d_left = 0.0f;   // distance along the section to the border on the left
  float d_right = 0.0f;  // distance along the section to the border on the right
  BorderId left_border = kLeftBankBorder;
  BorderId right_border = kRightBankBorder;
  glm::vec3 flow_direction{0.0f};  // the section's flow direction
};

class RiverSurface {
 public:
  // Builds the surface. `indices` holds three vertex indices per triangle; when empty the mesh is
  // non-indexed (every three positions make a triangle). Fails, naming the vertex, triangle or
  // section, on: no or too many vertices, non-finite positions, indices out of range or not a
  // multiple of three, degenerate triangles, unused vertices, non-manifold edges or vertices,
  // several pieces, anything that is not a strip of >= 2 sections (with islands, each crossed by
  // a section once), zero-width sections, islands touching a bank or each other.
  // `out` is left untouched on failure.
  static Status build(std::span<const glm::vec3> positions, std::span<const uint32_t> indices,
                      const RiverSurfaceOptions& options, RiverSurface* out);

  // --- Per input vertex (the accessor order of the mesh) ---
  size_t vertex_count() const { return welded() ? node_of_vertex_.size() : node_count(); }
  uint32_t node_of(size_t vertex) const {
    return welded() ? node_of_vertex_[vertex] : static_cast<uint32_t>(vertex);
  }
  RiverVertex vertex(size_t vertex) const { return node(node_of(vertex)); }
  // Whether some input vertices were welded; if not, node n is input vertex n.
  bool welded() const { return !node_of_vertex_.empty(); }
  // Every input vertex's node; empty when nothing was welded.
  std::span<const uint32_t> node_of_vertex() const { return node_of_vertex_; }

  // --- Per node (welded vertex); every index below is a node index ---
  size_t node_count() const { return node_positions().size(); }
  RiverVertex node(uint32_t n) const;
  std::span<const glm::vec3> node_positions() const {
    return shared_positions_.data() != nullptr ? shared_positions_ : std::span(node_positions_);
  }
  NodeSections node_section() const {
    return node_section_.empty() ? NodeSections(sections_, block_sections_)
                                 : NodeSections(node_section_);
  }
  std::span<const Bank> node_bank() const { return node_bank_; }
  std::span<const float> node_d_left() const { return node_d_left_; }
  std::span<const float> node_d_right() const { return node_d_right_; }
  BorderId node_left_border(uint32_t n) const {
    return node_left_border_.empty() ? kLeftBankBorder : node_left_border_[n];
  }
  BorderId node_right_border(uint32_t n) const {
    return node_right_border_.empty() ? kRightBankBorder : node_right_border_[n];
  }
  // Whether node n lies on an island's shore, and which.
  bool on_island(uint32_t n) const {
    return !node_left_border_.empty() && is_island_border(node_left_border_[n]) &&
           node_d_left_[n] == 0.0f && node_d_right_[n] == 0.0f;
  }
  bool is_island_border(BorderId b) const {
    return b >= island_border(0) && b < island_border(islands_.size());
  }
  // Whether node n lies on a network's bank that is not one of the root end's two (a tongue).
  bool on_tongue(uint32_t n) const {
    return !node_left_border_.empty() && node_left_border_[n] >= island_border(islands_.size()) &&
           node_d_left_[n] == 0.0f && node_d_right_[n] == 0.0f;
  }
  size_t border_count() const { return 2 + islands_.size() + (banks_.empty() ? 0 : banks_.size() - 2); }
  size_t island_of(uint32_t n) const { return node_left_border_[n] - island_border(0); }

  std::span<const RiverIsland> islands() const { return islands_; }
  // The shore of island i, in border order (closed: the last node neighbours the first).
  std::span<const uint32_t> island_nodes(size_t i) const {
    return {island_nodes_.data() + islands_[i].first_node, islands_[i].node_count};
  }
  // The first input vertex welded into node n (what error messages call "vertex").
  uint32_t vertex_of_node(uint32_t n) const { return welded() ? node_vertex_[n] : n; }

  // Triangles in node indices, wound counter-clockwise seen from the river's upper side
  // (downstream x (left shore - right shore)), whatever the input winding was.
  std::span<const uint32_t> triangles() const {  // 3 per triangle
    return shared_triangles_.data() != nullptr ? shared_triangles_ : std::span(triangles_);
  }
  size_t triangle_count() const { return triangles().size() / 3; }
  // Triangles around node n, ascending.
  TrianglesAround::Range node_triangles(uint32_t n) const { return node_triangles_.of(n); }
  // The same for every node at once.
  const TrianglesAround& triangles_around() const { return node_triangles_; }

  // The ends: the upstream end first, then the rest in border order (a strip's second is its
  // downstream end). A network has more than two.
  std::span<const RiverEnd> ends() const { return ends_; }
  std::span<const uint32_t> end_nodes(size_t e) const {
    return {end_nodes_.data() + ends_[e].first_node, ends_[e].node_count};
  }
  bool network() const { return ends_.size() > 2; }
  // A network's banks (empty for a strip, whose banks are its sections' shores).
  std::span<const RiverBank> banks() const { return banks_; }
  std::span<const uint32_t> bank_nodes(size_t b) const {
    return {bank_nodes_.data() + banks_[b].first_node, banks_[b].node_count};
  }

  std::span<const RiverSection> sections() const { return sections_; }
  // Nodes of section k, from the left shore to the right shore.
  SectionNodes section_nodes(size_t k) const {
    const RiverSection& sec = sections_[k];
    if (section_step_ == 0) return {section_nodes_.data() + sec.first_node, 0, 0, sec.node_count};
    const int64_t first = section_step_ > 0 ? sec.first_node : sec.first_node + sec.node_count - 1;
    return {nullptr, first, section_step_, sec.node_count};
  }
  float widest_section() const { return widest_; }
  // Length of the bounding-box diagonal: the scale the geometric tolerances are relative to.
  float extent() const { return extent_; }
  // Bytes of its arrays: what a long river costs to keep.
  size_t memory_bytes() const;

  // From now on reads its node positions and triangles from `positions` and `triangles` (a
  // unified-memory device's vertex and index buffers), which hold the same values and stay
  // alive while anything reads the surface, and frees its own: a long river's mesh is then held
  // once. Fails, changing nothing, when they differ from its own.
  Status share_mesh(std::span<const glm::vec3> positions, std::span<const uint32_t> triangles);

 private:
  // Everything past the welded mesh's checks for a mesh with more than two ends: its corners,
  // ends, layers, arms and borders (river_network.cpp).
  struct Welded;
  static Status build_network(const Welded& mesh, const RiverSurfaceOptions& options,
                              RiverSurface* out);
  // With islands: the distances, borders and arms of section `section` (`chain`, left to right);
  // its width, the sum of its arms, in `width`. Fails on an arm narrower than `min_arm`.
  Status measure_arms(std::span<const uint32_t> chain, std::span<const glm::vec3> pos,
                      const std::vector<uint32_t>& node_island,
                      const std::vector<uint32_t>& node_vertex, size_t section, double min_arm,
                      double* width);
  // Once built: frees the list of the sections' nodes, and of the nodes' sections, where every
  // section is a run of consecutive nodes, all ascending or all descending (section_step_).
  void drop_section_list_of_runs();

  std::vector<uint32_t> node_of_vertex_;  // both empty when nothing was welded
  std::vector<uint32_t> node_vertex_;
  std::vector<glm::vec3> node_positions_;
  std::vector<uint32_t> node_section_;
  std::vector<Bank> node_bank_;
  std::vector<float> node_d_left_;
  std::vector<float> node_d_right_;
  std::vector<uint32_t> triangles_;
  TrianglesAround node_triangles_;
  std::vector<RiverSection> sections_;
  std::vector<uint32_t> section_nodes_;  // empty where the sections are runs
  int section_step_ = 0;                 // runs' step: +1, -1; 0: listed
  std::vector<uint32_t> block_sections_;  // where the sections are runs: NodeSections'
  // Only with islands: the border on each side of every node, and the islands' shores.
  std::vector<BorderId> node_left_border_;
  std::vector<BorderId> node_right_border_;
  std::vector<RiverIsland> islands_;
  std::vector<uint32_t> island_nodes_;
  std::vector<RiverEnd> ends_;
  std::vector<uint32_t> end_nodes_;
  std::vector<RiverBank> banks_;  // only in a network
  std::vector<uint32_t> bank_nodes_;
  // After share_mesh: where the positions and triangles are read instead of the vectors above.
  std::span<const glm::vec3> shared_positions_;
  std::span<const uint32_t> shared_triangles_;
  float widest_ = 0.0f;
  float extent_ = 0.0f;
};

}  // namespace siviflow
