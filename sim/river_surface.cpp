#include "siviflow/sim/river_surface.h"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstring>
#include <limits>
#include <numeric>
#include <string>

#include <glm/common.hpp>
#include <glm/geometric.hpp>
#include <glm/vec3.hpp>

#include "siviflow/sim/river_tuning.h"
#include "river_welded.h"
#include "strip_layering.h"
#include "siviflow/text_format.h"

namespace siviflow {
namespace {

using DVec3 = glm::dvec3;

DVec3 to_d(const glm::vec3& v) { return DVec3(v); }

uint32_t float_key(float f) {
  if (f == 0.0f) f = 0.0f;  // -0 and +0 weld together
  uint32_t u = 0;
  std::memcpy(&u, &f, sizeof(u));
  return u;
}

uint64_t hash_position(const glm::vec3& p) {
  uint64_t h = 0x9e3779b97f4a7c15ull;
  for (const float c : {p.x, p.y, p.z}) {
    h ^= float_key(c);
    h *= 0xbf58476d1ce4e5b9ull;
    h ^= h >> 31;
  }
  return h;
}

// The water's angle at each node of a border loop, the sum of its triangles' angles there in
// triangle order: about 90 degrees at the four corners of a strip, about 180 along its banks and
// ends. Kept for the loop only: a long river's every node would hold 8 bytes at the build's peak.
std::vector<double> loop_angles(const std::vector<glm::vec3>& pos,
                                const std::vector<uint32_t>& tris, const TrianglesAround& node_tris,
                                const std::vector<uint32_t>& loop) {
  std::vector<double> sum(loop.size(), 0.0);
  for (size_t k = 0; k < loop.size(); ++k) {
    const uint32_t n = loop[k];
    const DVec3 p = to_d(pos[n]);
    for (const uint32_t t : node_tris.of(n)) {
      const int i = tris[3 * t] == n ? 0 : tris[3 * t + 1] == n ? 1 : 2;
      const DVec3 u = glm::normalize(to_d(pos[tris[3 * t + (i + 1) % 3]]) - p);
      const DVec3 v = glm::normalize(to_d(pos[tris[3 * t + (i + 2) % 3]]) - p);
      sum[k] += std::acos(std::clamp(glm::dot(u, v), -1.0, 1.0));
    }
  }
  return sum;
}

// The border node nearest a point (kNoNode where the mesh has no border).
uint32_t nearest_on_border(const std::vector<glm::vec3>& pos, const std::vector<uint8_t>& on_border,
                           const glm::vec3& point) {
  uint32_t best = kNoNode;
  double best_d = std::numeric_limits<double>::max();
  for (uint32_t n = 0; n < pos.size(); ++n) {
    if (!on_border[n]) continue;
    const double d = glm::distance(to_d(pos[n]), to_d(point));
    if (d < best_d) {
      best_d = d;
      best = n;
    }
  }
  return best;
}

// The named ends' own checks: at least two, each vertex in the mesh and each point finite, and a
// strip's two one of each kind.
Status check_end_marks(const RiverSurfaceOptions& options, size_t vertex_count) {
  if (options.ends.size() == 1) {
    return Status::error("ends: a single end is named, where a river has at least two");
  }
  for (size_t m = 0; m < options.ends.size(); ++m) {
    const RiverEndMark& mark = options.ends[m];
    const glm::vec3& p = mark.point;
    if (mark.at_point && !(std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z))) {
      return Status::error(text_format("ends[%zu]: the point (%g, %g, %g) is not finite", m, p.x, p.y, p.z));
    }
    if (!mark.at_point && mark.vertex >= vertex_count) {
      return Status::error(text_format("ends[%zu]: vertex %u is not in the river mesh (%zu vertices)",
                                       m, mark.vertex, vertex_count));
    }
  }
  if (options.ends.size() == 2 && options.ends[0].inflow == options.ends[1].inflow) {
    return Status::error(text_format(
        "ends: both named ends are %s, where a strip has one inflow and one outflow",
        options.ends[0].inflow ? "inflows" : "outflows"));
  }
  return Status::success();
}

// A strip's named outflow lies on its last section.
Status check_named_outflow(const RiverSurfaceOptions& options, const std::vector<glm::vec3>& pos,
                           const std::vector<uint8_t>& on_border, const std::vector<uint32_t>& node_of_vertex,
                           const std::vector<uint32_t>& node_vertex, const std::vector<uint32_t>& node_section,
                           uint32_t last_section, uint32_t upstream_vertex) {
  for (size_t m = 0; m < options.ends.size(); ++m) {
    const RiverEndMark& mark = options.ends[m];
    if (mark.inflow) continue;
    const uint32_t n = mark.at_point ? nearest_on_border(pos, on_border, mark.point) : node_of_vertex[mark.vertex];
    if (node_section[n] == last_section) continue;
    const std::string what = mark.at_point ? text_format("the border's vertex %u nearest (%g, %g, %g)", node_vertex[n],
                                                         mark.point.x, mark.point.y, mark.point.z)
                                           : text_format("vertex %u", mark.vertex);
    return Status::error(text_format(
        "ends[%zu]: %s is not on the downstream end of the river (the end across from the inflow "
        "at vertex %u)",
        m, what.c_str(), upstream_vertex));
  }
  return Status::success();
}


}  // namespace

RiverVertex RiverSurface::node(uint32_t n) const {
  RiverVertex v;
  v.section = node_section()[n];
  v.bank = node_bank_[n];
  v.width = sections_[v.section].width;
  v.d_left = node_d_left_[n];
  v.d_right = node_d_right_[n];
  v.left_border = node_left_border(n);
  v.right_border = node_right_border(n);
  v.flow_direction = sections_[v.section].flow_direction;
  return v;
}

size_t RiverSurface::memory_bytes() const {
  const auto bytes = [](const auto& v) { return v.capacity() * sizeof(v[0]); };
  return bytes(node_of_vertex_) + bytes(node_vertex_) + bytes(node_positions_) +
         bytes(node_section_) + bytes(node_bank_) + bytes(node_d_left_) + bytes(node_d_right_) +
         bytes(triangles_) + node_triangles_.memory_bytes() + bytes(sections_) +
         bytes(section_nodes_) + bytes(block_sections_) + bytes(node_left_border_) +
         bytes(node_right_border_) + bytes(islands_) + bytes(island_nodes_) + bytes(ends_) +
         bytes(end_nodes_) + bytes(banks_) + bytes(bank_nodes_);
}

void RiverSurface::drop_section_list_of_runs() {
  bool ascending = true, descending = true;
  for (const RiverSection& sec : sections_) {
    for (uint32_t i = 0; i < sec.node_count && (ascending || descending); ++i) {
      const uint32_t n = section_nodes_[sec.first_node + i];
      ascending = ascending && n == sec.first_node + i;
      descending = descending && n == sec.first_node + sec.node_count - 1 - i;
    }
  }
  if (!ascending && !descending) return;
  section_step_ = ascending ? 1 : -1;
  section_nodes_ = std::vector<uint32_t>();
  const size_t blocks = (node_section_.size() + (size_t{1} << NodeSections::kBlockBits) - 1) >>
                        NodeSections::kBlockBits;
  block_sections_.resize(blocks);
  for (size_t b = 0; b < blocks; ++b)
    block_sections_[b] = node_section_[b << NodeSections::kBlockBits];
  node_section_ = std::vector<uint32_t>();
}

Status RiverSurface::share_mesh(std::span<const glm::vec3> positions,
                               std::span<const uint32_t> triangles) {
  const std::span<const glm::vec3> own_positions = node_positions();
  const std::span<const uint32_t> own_triangles = this->triangles();
  if (positions.size() != own_positions.size() || triangles.size() != own_triangles.size()) {
    return Status::error(text_format(
        "share_mesh: %zu positions and %zu indices given for a surface of %zu and %zu",
        positions.size(), triangles.size(), own_positions.size(), own_triangles.size()));
  }
  if (!std::equal(positions.begin(), positions.end(), own_positions.begin()) ||
      !std::equal(triangles.begin(), triangles.end(), own_triangles.begin())) {
    return Status::error("share_mesh: the shared positions or triangles differ from the surface's");
  }
  shared_positions_ = positions;
  shared_triangles_ = triangles;
  node_positions_ = std::vector<glm::vec3>();
  triangles_ = std::vector<uint32_t>();
  return Status::success();
}

Status RiverSurface::measure_arms(std::span<const uint32_t> chain,
                                  std::span<const glm::vec3> pos,
                                  const std::vector<uint32_t>& node_island,
                                  const std::vector<uint32_t>& node_vertex, size_t section,
                                  double min_arm, double* width) {
  auto border_of = [&](size_t i) -> int {
    if (i == 0) return kLeftBankBorder;
    if (i + 1 == chain.size()) return kRightBankBorder;
    const uint32_t island = node_island[chain[i]];
    return island == kNoNode ? -1 : static_cast<int>(island_border(island));
  };
  // Forward: the border last passed and the distance from it; the water between two borders
  // is an arm, and the section's width is the sum of its arms.
  *width = 0.0;
  int last = kLeftBankBorder;
  size_t last_at = 0;
  double from_last = 0.0;
  for (size_t i = 1; i < chain.size(); ++i) {
    const int border = border_of(i);
    const bool along_one_border = border >= 0 && border == border_of(i - 1);
    if (!along_one_border) {  // over water (a jump across an island joins two nodes of one border)
      from_last += glm::distance(glm::dvec3(pos[chain[i - 1]]), glm::dvec3(pos[chain[i]]));
    }
    if (border < 0) {
      node_left_border_[chain[i]] = static_cast<uint16_t>(last);
      node_d_left_[chain[i]] = static_cast<float>(from_last);
      continue;
    }
    if (!along_one_border) {
      if (!(from_last > min_arm)) {
        return Status::error(text_format(
            "section %zu of the river has a zero-width neck (%g m of water between vertices %u "
            "and %u): an island touches a bank or another island there",
            section, from_last, node_vertex[chain[last_at]], node_vertex[chain[i]]));
      }
      *width += from_last;
    }
    if (i + 1 == chain.size()) {  // the right shore: its far side is the last arm away
      node_left_border_[chain[i]] = static_cast<uint16_t>(last);
      node_d_left_[chain[i]] = static_cast<float>(from_last);
    } else {
      node_left_border_[chain[i]] = node_right_border_[chain[i]] = static_cast<uint16_t>(border);
    }
    last = border;
    last_at = i;
    from_last = 0.0;
  }
  // Backward: the next border and the distance to it.
  int next = kRightBankBorder;
  double to_next = 0.0;
  for (size_t i = chain.size() - 1; i-- > 0;) {
    const int border = border_of(i);
    if (!(border >= 0 && border == border_of(i + 1))) {
      to_next += glm::distance(glm::dvec3(pos[chain[i + 1]]), glm::dvec3(pos[chain[i]]));
    }
    if (border < 0 || i == 0) {
      node_right_border_[chain[i]] = static_cast<uint16_t>(next);
      node_d_right_[chain[i]] = static_cast<float>(to_next);
    }
    if (border >= 0) {
      next = border;
      to_next = 0.0;
    }
  }
  return Status::success();
}

Status RiverSurface::build(std::span<const glm::vec3> positions, std::span<const uint32_t> indices,
                           const RiverSurfaceOptions& options, RiverSurface* out) {
  // --- Sizes, before anything is allocated or read.
  const size_t vertex_count = positions.size();
  if (vertex_count == 0) return Status::error("the river mesh has no vertices");
  if (vertex_count > kMaxRiverVertices) {
    return Status::error(text_format("the river mesh has %zu vertices, more than the limit of %zu",
                                     vertex_count, kMaxRiverVertices));
  }
  const bool indexed = !indices.empty();
  const size_t index_count = indexed ? indices.size() : vertex_count;
  if (indexed && index_count > 3 * kMaxRiverTriangles) {
    return Status::error(text_format(
        "the river mesh has %zu indices, more than the limit of %zu triangles", index_count,
        kMaxRiverTriangles));
  }
  if (index_count % 3 != 0) {
    return Status::error(text_format(
        indexed ? "the river mesh has %zu indices, not a multiple of 3: it is not a triangle list"
                : "the non-indexed river mesh has %zu vertices, not a multiple of 3",
        index_count));
  }
  const size_t tri_count = index_count / 3;
  auto index_at = [&](size_t i) { return indexed ? indices[i] : static_cast<uint32_t>(i); };

  for (size_t v = 0; v < vertex_count; ++v) {
    const glm::vec3& p = positions[v];
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) {
      return Status::error(text_format("river vertex %zu has a non-finite position (%g, %g, %g)",
                                       v, p.x, p.y, p.z));
    }
  }
  for (size_t i = 0; i < index_count; ++i) {
    if (index_at(i) >= vertex_count) {
      return Status::error(text_format(
          "river triangle %zu refers to vertex %u, but the mesh has only %zu vertices", i / 3,
          index_at(i), vertex_count));
    }
  }
  SIVIFLOW_TRY(check_end_marks(options, vertex_count));
  // The upstream end: the named inflow of a strip's two named ends (a vertex, or a point whose
  // nearest border node is found with the border), else upstream_vertex; a network with named
  // ends reads neither.
  const bool read_upstream = options.ends.size() <= 2;
  const RiverEndMark* named_inflow =
      options.ends.size() == 2 ? &options.ends[options.ends[0].inflow ? 0 : 1] : nullptr;
  const uint32_t upstream_vertex = named_inflow != nullptr ? named_inflow->vertex : options.upstream_vertex;
  const bool upstream_at_point = named_inflow != nullptr && named_inflow->at_point;
  if (read_upstream && !upstream_at_point && upstream_vertex >= vertex_count) {
    return Status::error(text_format("the upstream vertex %u is not in the river mesh (%zu vertices)",
                                     upstream_vertex, vertex_count));
  }

  // --- Weld vertices at exactly the same position (open addressing on the position bits).
  std::vector<uint32_t> node_of_vertex(vertex_count);
  std::vector<uint32_t> node_vertex;
  std::vector<glm::vec3> pos;
  pos.reserve(vertex_count);  // kept: grown by doubling, it held up to twice its size
  {
    const size_t table_size = std::bit_ceil(2 * vertex_count);
    std::vector<uint32_t> table(table_size, kNoNode);
    for (size_t v = 0; v < vertex_count; ++v) {
      const glm::vec3& p = positions[v];
      size_t slot = hash_position(p) & (table_size - 1);
      while (table[slot] != kNoNode && pos[table[slot]] != p) slot = (slot + 1) & (table_size - 1);
      if (table[slot] == kNoNode) {
        table[slot] = static_cast<uint32_t>(pos.size());
        pos.push_back(p);
        node_vertex.push_back(static_cast<uint32_t>(v));
      }
      node_of_vertex[v] = table[slot];
    }
  }
  const size_t node_count = pos.size();
  const MeshView view_for_names{nullptr, nullptr, nullptr, &node_vertex, nullptr, nullptr};

  // --- Triangles on nodes; reject degenerate ones (they have no normal and no gradient).
  std::vector<uint32_t> tris(index_count);
  for (size_t t = 0; t < tri_count; ++t) {
    const uint32_t raw[3] = {index_at(3 * t), index_at(3 * t + 1), index_at(3 * t + 2)};
    uint32_t n[3];
    for (int i = 0; i < 3; ++i) n[i] = tris[3 * t + i] = node_of_vertex[raw[i]];
    for (int i = 0; i < 3; ++i) {
      const int j = (i + 1) % 3;
      if (n[i] != n[j]) continue;
      if (raw[i] == raw[j]) {
        return Status::error(text_format(
            "river triangle %zu (vertices %u, %u, %u) is degenerate: it uses vertex %u twice", t,
            raw[0], raw[1], raw[2], raw[i]));
      }
      return Status::error(text_format(
          "river triangle %zu (vertices %u, %u, %u) is degenerate: vertices %u and %u are at the "
          "same position (%g, %g, %g) - a zero-width section or a collapsed edge",
          t, raw[0], raw[1], raw[2], raw[i], raw[j], positions[raw[i]].x, positions[raw[i]].y,
          positions[raw[i]].z));
    }
    const DVec3 a = to_d(pos[n[0]]), b = to_d(pos[n[1]]), c = to_d(pos[n[2]]);
    const double area2 = glm::length(glm::cross(b - a, c - a));
    const double longest2 =
        std::max({glm::dot(b - a, b - a), glm::dot(c - b, c - b), glm::dot(a - c, a - c)});
    if (!(area2 > kDegenerateTriangleRatio * longest2)) {
      return Status::error(text_format(
          "river triangle %zu (vertices %u, %u, %u) is degenerate: it has zero area (its corners "
          "are collinear)",
          t, raw[0], raw[1], raw[2]));
    }
  }

  // The input is not read past this point.
  if (options.inputs_read) options.inputs_read(node_count != vertex_count);

  // --- Node -> triangles.
  TrianglesAround node_tris = TrianglesAround::of_mesh(node_count, tris);
  for (uint32_t n = 0; n < node_count; ++n) {
    if (node_tris.of(n).size() == 0) {
      return Status::error(text_format("river vertex %u is not used by any triangle",
                                       node_vertex[n]));
    }
  }

  // --- Node adjacency (sorted, unique), manifold edges and the border.
  Csr adj;
  adj.start.assign(node_count + 1, 0);
  // Each edge twice: a disc with h holes has V + T - 1 + h edges. Too small a reserve doubles
  // at the end and holds both copies (65 MB at once for a 100 km river); pages never written
  // cost nothing.
  adj.list.reserve(2 * (node_count + tri_count + kMaxRiverIslands));
  std::vector<std::array<uint32_t, 2>> border_next(node_count, {kNoNode, kNoNode});
  std::vector<uint8_t> on_border(node_count, 0);
  size_t edge_count = 0;
  {
    std::vector<uint32_t> scratch;
    for (uint32_t n = 0; n < node_count; ++n) {
      scratch.clear();
      for (const uint32_t t : node_tris.of(n)) {
        for (int i = 0; i < 3; ++i) {
          if (tris[3 * t + i] != n) scratch.push_back(tris[3 * t + i]);
        }
      }
      std::sort(scratch.begin(), scratch.end());
      scratch.erase(std::unique(scratch.begin(), scratch.end()), scratch.end());
      adj.list.insert(adj.list.end(), scratch.begin(), scratch.end());
      adj.start[n + 1] = static_cast<uint32_t>(adj.list.size());
      for (const uint32_t m : scratch) {
        if (m < n) continue;
        ++edge_count;
        uint32_t shared = 0;
        for (const uint32_t t : node_tris.of(n)) {
          shared += (tris[3 * t] == m || tris[3 * t + 1] == m || tris[3 * t + 2] == m) ? 1 : 0;
        }
        if (shared > 2) {
          return Status::error(text_format(
              "the river mesh is non-manifold: the edge between vertices %u and %u is shared by "
              "%u triangles",
              node_vertex[n], node_vertex[m], shared));
        }
        if (shared == 1) {
          for (const auto& [x, y] : {std::pair{n, m}, std::pair{m, n}}) {
            auto& slots = border_next[x];
            if (slots[0] == kNoNode) {
              slots[0] = y;
            } else if (slots[1] == kNoNode) {
              slots[1] = y;
            } else {
              return Status::error(text_format(
                  "the river mesh is non-manifold at vertex %u: more than two border edges meet "
                  "there (two parts of the mesh, an island and a bank, or a border and itself touch at a "
                  "single vertex)",
                  node_vertex[x]));
            }
            on_border[x] = 1;
          }
        }
      }
    }
  }

  // --- One piece.
  {
    std::vector<uint32_t> piece(node_count, kNoNode);
    std::vector<uint32_t> stack;
    uint32_t pieces = 0;
    uint32_t second_piece_node = kNoNode;
    for (uint32_t s = 0; s < node_count; ++s) {
      if (piece[s] != kNoNode) continue;
      if (pieces == 1) second_piece_node = s;
      piece[s] = pieces;
      stack.push_back(s);
      while (!stack.empty()) {
        const uint32_t n = stack.back();
        stack.pop_back();
        for (const uint32_t m : adj.of(n)) {
          if (piece[m] == kNoNode) {
            piece[m] = pieces;
            stack.push_back(m);
          }
        }
      }
      ++pieces;
    }
    if (pieces > 1) {
      return Status::error(text_format(
          "the river mesh is in %u disconnected pieces (vertices %u and %u are in different "
          "pieces): a river is one strip",
          pieces, node_vertex[0], node_vertex[second_piece_node]));
    }
  }

  // --- The border: the outer loop, holding the upstream vertex, and one loop per island.
  if (std::find(on_border.begin(), on_border.end(), 1) == on_border.end()) {
    return Status::error("the river mesh is closed (it has no border): a river is an open strip");
  }
  const uint32_t upstream_node = !read_upstream     ? kNoNode
                                 : upstream_at_point ? nearest_on_border(pos, on_border, named_inflow->point)
                                                     : node_of_vertex[upstream_vertex];
  if (read_upstream && !on_border[upstream_node]) {
    return Status::error(text_format(
        "river vertex %u marks the upstream end but is not on the border of the mesh: the "
        "upstream end is the end section holding it (a corner, in the paper's meshes)",
        upstream_vertex));
  }
  std::vector<uint32_t> loop;
  std::vector<std::vector<uint32_t>> island_loops;
  {
    // With named ends: the outer border is the one that holds the first.
    const uint32_t first_end_node =
        read_upstream ? kNoNode
        : options.ends[0].at_point ? nearest_on_border(pos, on_border, options.ends[0].point)
                                   : node_of_vertex[options.ends[0].vertex];
    auto is_outer_loop = [&](const std::vector<uint32_t>& walked) {
      return std::find(walked.begin(), walked.end(), first_end_node) != walked.end();
    };
    std::vector<uint8_t> seen(node_count, 0);
    for (uint32_t s = 0; s < node_count; ++s) {
      if (!on_border[s] || seen[s]) continue;
      if (border_next[s][1] == kNoNode) {
        return Status::error(text_format(
            "the river mesh is non-manifold at vertex %u: a single border edge ends there",
            node_vertex[s]));
      }
      std::vector<uint32_t> walked;
      uint32_t prev = kNoNode, cur = s;
      do {
        walked.push_back(cur);
        seen[cur] = 1;
        const uint32_t next = border_next[cur][0] != prev ? border_next[cur][0] : border_next[cur][1];
        prev = cur;
        cur = next;
      } while (cur != s && cur != kNoNode && !seen[cur]);
      if (read_upstream ? std::find(walked.begin(), walked.end(), upstream_node) != walked.end()
                        : is_outer_loop(walked)) {
        loop = std::move(walked);
      } else {
        island_loops.push_back(std::move(walked));
      }
    }
    if (loop.empty()) {  // only a named vertex can miss the border
      return Status::error(text_format(
          "ends[0]: vertex %u is not on the border of the river mesh, so not on an end",
          options.ends[0].vertex));
    }
    if (island_loops.size() > kMaxRiverIslands) {
      return Status::error(text_format(
          "the river mesh has %zu holes (islands), more than the limit of %zu",
          island_loops.size(), kMaxRiverIslands));
    }
  }
  const long euler = static_cast<long>(node_count) - static_cast<long>(edge_count) +
                     static_cast<long>(tri_count);
  if (euler != 1 - static_cast<long>(island_loops.size())) {
    return Status::error(text_format(
        "the river mesh is not a disc with holes (Euler characteristic %ld, a strip with %zu "
        "islands has %ld): it has handles",
        euler, island_loops.size(), 1 - static_cast<long>(island_loops.size())));
  }
  if (loop.size() < 4) {
    return Status::error(text_format(
        "the river mesh has only %zu border vertices: a river needs at least two sections of two "
        "vertices each",
        loop.size()));
  }
  border_next = std::vector<std::array<uint32_t, 2>>();  // walked: what follows holds more
  std::vector<uint32_t> node_island;
  if (!island_loops.empty()) {
    node_island.assign(node_count, kNoNode);
    for (uint32_t i = 0; i < island_loops.size(); ++i) {
      for (const uint32_t n : island_loops[i]) node_island[n] = i;
    }
  }

  std::vector<double> angles = loop_angles(pos, tris, node_tris, loop);
  Welded welded{pos,         tris,         node_tris, adj,  node_vertex, node_of_vertex,
                island_loops, node_island, loop,      angles, vertex_count};
  if (options.ends.size() > 2) return build_network(welded, options, out);

  // --- Corners: the four sharpest border vertices (about 90 degrees; banks and ends are about
  // 180). Ties go to the lower node, so the choice is deterministic.
  std::vector<uint32_t> corner_at(loop.size());  // positions in the loop
  std::iota(corner_at.begin(), corner_at.end(), 0u);
  std::partial_sort(corner_at.begin(), corner_at.begin() + 4, corner_at.end(),
                    [&](uint32_t i, uint32_t j) {
                      const double ai = angles[i], aj = angles[j];
                      return ai != aj ? ai < aj : loop[i] < loop[j];
                    });
  corner_at.resize(4);
  std::sort(corner_at.begin(), corner_at.end());
  auto side = [&](int i) {
    std::vector<uint32_t> path;
    size_t p = corner_at[i];
    const size_t end = corner_at[(i + 1) % 4];
    for (;;) {
      path.push_back(loop[p]);
      if (p == end) break;
      p = (p + 1) % loop.size();
    }
    return path;
  };
  const std::array<std::vector<uint32_t>, 4> sides = {side(0), side(1), side(2), side(3)};

  // Candidate upstream ends: the sides holding the marker, shortest first (a river is longer
  // than it is wide, so when the marker is a corner the short side is the end).
  std::vector<int> candidates;
  for (int i = 0; i < 4; ++i) {
    if (std::find(sides[i].begin(), sides[i].end(), upstream_node) != sides[i].end()) {
      candidates.push_back(i);
    }
  }
  std::stable_sort(candidates.begin(), candidates.end(), [&](int i, int j) {
    return path_length(pos, sides[i]) < path_length(pos, sides[j]);
  });

  const MeshView mesh{&pos, &tris, &adj, &node_vertex, &island_loops, &node_island};
  Layering layering;
  Status first_error;
  bool found = false;
  for (const int a : candidates) {
    const std::vector<uint32_t>& end_a = sides[a];
    const std::vector<uint32_t>& end_b = sides[(a + 2) % 4];
    const std::vector<uint32_t> bank_1 = sides[(a + 1) % 4];
    std::vector<uint32_t> bank_2 = sides[(a + 3) % 4];
    std::reverse(bank_2.begin(), bank_2.end());
    Status status = layer_strip(mesh, end_a, end_b, bank_1, bank_2, &layering);
    if (status.ok()) {
      found = true;
      break;
    }
    if (first_error.ok()) first_error = std::move(status);
  }
  if (!found) {
    // More corners than a strip's four, and no ends named: a network whose ends are found.
    const size_t sharp = static_cast<size_t>(std::count_if(
        angles.begin(), angles.end(), [](double a) { return a < kNetworkCornerMaxAngle; }));
    std::string corners;
    for (const uint32_t c : corner_at) {
      corners += (corners.empty() ? "" : ", ") + vertex_name(view_for_names, loop[c]);
    }
    const std::string as_strip = first_error.message() + " (corners taken at vertices " + corners + ")";
    if (options.ends.empty() && sharp >= 6) {
      const Status network = build_network(welded, options, out);
      if (network.ok()) return network;
      return Status::error(as_strip + "; nor is it a network of " + std::to_string(sharp / 2) +
                           " ends with vertex " + std::to_string(node_vertex[upstream_node]) +
                           "'s the only inflow: " + network.message() +
                           " (a confluence takes its ends named, each an inflow or an outflow)");
    }
    if (sharp >= 6) {
      return Status::error(text_format(
          "%s; it has %zu corners, as a network of %zu ends has: name every end, or none",
          as_strip.c_str(), sharp, sharp / 2));
    }
    return Status::error(as_strip);
  }
  const size_t section_count = layering.chain_start.size() - 1;
  adj = Csr();  // layered: not read again

  // --- Left and right: the left bank is on the +Y x downstream side.
  std::vector<DVec3> mid(section_count);
  for (size_t k = 0; k < section_count; ++k) {
    mid[k] = 0.5 * (to_d(pos[layering.bank_a[k]]) + to_d(pos[layering.bank_b[k]]));
  }
  auto downstream_at = [&](size_t k) {
    return mid[std::min(k + 1, section_count - 1)] - mid[k == 0 ? 0 : k - 1];
  };
  double side_score = 0.0;
  double chord_scale = 0.0;
  for (size_t k = 0; k < section_count; ++k) {
    const DVec3 chord = to_d(pos[layering.bank_a[k]]) - to_d(pos[layering.bank_b[k]]);
    const DVec3 left = glm::cross(DVec3(0, 1, 0), downstream_at(k));
    side_score += glm::dot(left, chord);
    chord_scale += glm::length(left) * glm::length(chord);
  }
  if (!(std::abs(side_score) > 1e-6 * chord_scale)) {
    return Status::error(
        "cannot tell the river's left bank from its right: seen from +Y (up) its sections do not "
        "run across the flow");
  }
  const bool a_is_left = side_score > 0.0;

  // --- Bounding box, for relative tolerances.
  DVec3 lo(std::numeric_limits<double>::max()), hi(-std::numeric_limits<double>::max());
  for (const glm::vec3& p : pos) {
    lo = glm::min(lo, to_d(p));
    hi = glm::max(hi, to_d(p));
  }
  const double extent = glm::length(hi - lo);

  // --- Sections and per-node data.
  RiverSurface s;
  s.sections_.resize(section_count);
  s.section_nodes_.reserve(node_count);
  s.node_section_ = std::move(layering.layer);
  s.node_bank_.assign(node_count, Bank::kNone);
  s.node_d_left_.assign(node_count, 0.0f);
  s.node_d_right_.assign(node_count, 0.0f);
  if (!island_loops.empty()) {
    s.node_left_border_.assign(node_count, kLeftBankBorder);
    s.node_right_border_.assign(node_count, kRightBankBorder);
    for (const std::vector<uint32_t>& island : island_loops) {
      s.islands_.push_back({static_cast<uint32_t>(s.island_nodes_.size()),
                            static_cast<uint32_t>(island.size())});
      s.island_nodes_.insert(s.island_nodes_.end(), island.begin(), island.end());
    }
  }
  double along = 0.0;
  for (size_t k = 0; k < section_count; ++k) {
    RiverSection& sec = s.sections_[k];
    sec.first_node = static_cast<uint32_t>(s.section_nodes_.size());
    const auto begin = layering.chain_nodes.begin() + layering.chain_start[k];
    const auto end = layering.chain_nodes.begin() + layering.chain_start[k + 1];
    if (a_is_left) {
      s.section_nodes_.insert(s.section_nodes_.end(), begin, end);
    } else {
      s.section_nodes_.insert(s.section_nodes_.end(), std::make_reverse_iterator(end),
                              std::make_reverse_iterator(begin));
    }
    sec.node_count = static_cast<uint32_t>(end - begin);
    const std::span<const uint32_t> chain(s.section_nodes_.data() + sec.first_node, sec.node_count);

    const uint32_t left = chain.front(), right = chain.back();
    double width = 0.0;
    if (island_loops.empty()) {
      std::vector<double> arc(chain.size(), 0.0);
      for (size_t i = 1; i < chain.size(); ++i) {
        arc[i] = arc[i - 1] + glm::distance(to_d(pos[chain[i - 1]]), to_d(pos[chain[i]]));
      }
      width = arc.back();
      for (size_t i = 0; i < chain.size(); ++i) {
        s.node_d_left_[chain[i]] = static_cast<float>(arc[i]);
        s.node_d_right_[chain[i]] = static_cast<float>(width - arc[i]);
      }
    } else {
      SIVIFLOW_TRY(s.measure_arms(chain, pos, node_island, node_vertex, k,
                                  kMinSectionWidthRelative * extent, &width));
    }
    if (!(width > kMinSectionWidthRelative * extent)) {
      return Status::error(text_format(
          "section %zu of the river has zero width (%g m between its shore vertices %u and %u)",
          k, width, node_vertex[left], node_vertex[right]));
    }
    s.node_bank_[left] = Bank::kLeft;
    s.node_bank_[right] = Bank::kRight;

    // Flow direction: normal of the plane through both shores and their midpoint raised along
    // +Y, i.e. +Y x (right - left), oriented downstream.
    const DVec3 chord = to_d(pos[right]) - to_d(pos[left]);
    DVec3 flow(chord.z, 0.0, -chord.x);
    const double flow_len = glm::length(flow);
    if (!(flow_len > kMinHorizontalChordRelative * glm::length(chord))) {
      return Status::error(text_format(
          "section %zu of the river runs vertically (shore vertices %u and %u are above each "
          "other): it has no horizontal flow direction",
          k, node_vertex[left], node_vertex[right]));
    }
    flow /= flow_len;
    if (glm::dot(flow, downstream_at(k)) < 0.0) flow = -flow;
    sec.width = static_cast<float>(width);
    sec.midpoint = glm::vec3(mid[k]);
    sec.flow_direction = glm::vec3(flow);
    if (k > 0) along += glm::distance(mid[k - 1], mid[k]);
    sec.along = static_cast<float>(along);
    s.widest_ = std::max(s.widest_, sec.width);
  }

  // --- Wind every triangle counter-clockwise about the river's up: downstream x (left - right).
  if (options.rewound != nullptr) options.rewound->assign(tri_count, false);
  for (size_t t = 0; t < tri_count; ++t) {
    uint32_t* tri = &tris[3 * t];
    const uint32_t k = std::min({s.node_section_[tri[0]], s.node_section_[tri[1]],
                                 s.node_section_[tri[2]]});
    const RiverSection& sec = s.sections_[k];
    const std::span<const uint32_t> chain(s.section_nodes_.data() + sec.first_node, sec.node_count);
    const DVec3 across = to_d(pos[chain.front()]) - to_d(pos[chain.back()]);
    const DVec3 up = glm::cross(mid[k + 1] - mid[k], across);
    const DVec3 a = to_d(pos[tri[0]]);
    const DVec3 normal = glm::cross(to_d(pos[tri[1]]) - a, to_d(pos[tri[2]]) - a);
    if (glm::dot(normal, up) < 0.0) {
      std::swap(tri[1], tri[2]);
      if (options.rewound != nullptr) (*options.rewound)[t] = true;
    }
  }

  // --- The two ends; a named outflow must lie on the downstream one.
  for (const size_t k : {size_t{0}, section_count - 1}) {
    const RiverSection& sec = s.sections_[k];
    RiverEnd end;
    end.first_node = static_cast<uint32_t>(s.end_nodes_.size());
    end.node_count = sec.node_count;
    end.inflow = k == 0;
    end.section = static_cast<uint32_t>(k);
    end.width = sec.width;
    for (size_t m = 0; m < options.ends.size(); ++m) {
      if (options.ends[m].inflow == end.inflow) end.mark = static_cast<uint32_t>(m);
    }
    s.end_nodes_.insert(s.end_nodes_.end(), s.section_nodes_.begin() + sec.first_node,
                        s.section_nodes_.begin() + sec.first_node + sec.node_count);
    s.ends_.push_back(end);
  }
  SIVIFLOW_TRY(check_named_outflow(options, pos, on_border, node_of_vertex, node_vertex, s.node_section_,
                                   section_count - 1, node_vertex[upstream_node]));

  if (node_count != vertex_count) {  // else both maps are the identity: not worth 8 bytes a vertex
    s.node_of_vertex_ = std::move(node_of_vertex);
    s.node_vertex_ = std::move(node_vertex);
  }
  pos.shrink_to_fit();  // a copy only where vertices were welded
  s.node_positions_ = std::move(pos);
  s.triangles_ = std::move(tris);
  s.node_triangles_ = std::move(node_tris);
  s.extent_ = static_cast<float>(extent);
  s.drop_section_list_of_runs();
  *out = std::move(s);
  return Status::success();
}

}  // namespace siviflow
