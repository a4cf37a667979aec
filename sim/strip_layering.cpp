#include "strip_layering.h"

#include <algorithm>
#include <array>
#include <deque>
#include <glm/geometric.hpp>
#include <glm/vec3.hpp>
#include <tuple>

#include "siviflow/text_format.h"

namespace siviflow {
namespace {

// The island border edges that run across the flow (more across it than along it), as each
// island node's (at most two) neighbours over such an edge. The flow's direction near a node
// is that of the bank midpoints about the section its hop count from the upstream end names
// (which going around an island overestimates by a little; the direction turns slowly).
std::vector<std::array<uint32_t, 2>> across_island_edges(const MeshView& mesh,
                                                         const std::vector<uint32_t>& up,
                                                         const std::vector<uint32_t>& bank_1,
                                                         const std::vector<uint32_t>& bank_2) {
  const std::vector<glm::vec3>& pos = *mesh.positions;
  const auto midpoint = [&](size_t k) {
    return 0.5 * (glm::dvec3(pos[bank_1[k]]) + glm::dvec3(pos[bank_2[k]]));
  };
  const size_t last = bank_1.size() - 1;
  std::vector<std::array<uint32_t, 2>> across(up.size(), {kNoNode, kNoNode});
  for (const std::vector<uint32_t>& loop : *mesh.islands) {
    for (size_t i = 0; i < loop.size(); ++i) {
      const uint32_t a = loop[i], b = loop[(i + 1) % loop.size()];
      const size_t k = std::min<size_t>(up[a], last);
      const glm::dvec3 flow = midpoint(std::min(k + 1, last)) - midpoint(k == 0 ? 0 : k - 1);
      const glm::dvec3 edge = glm::dvec3(pos[b]) - glm::dvec3(pos[a]);
      const double along = std::abs(flow.x * edge.x + flow.z * edge.z);
      const double across_flow = std::abs(flow.x * edge.z - flow.z * edge.x);
      if (!(across_flow > along)) continue;
      for (const auto& [x, y] : {std::pair{a, b}, std::pair{b, a}}) {
        (across[x][0] == kNoNode ? across[x][0] : across[x][1]) = y;
      }
    }
  }
  return across;
}

// Island nodes by (island, layer): where a section that meets an island goes on.
struct IslandRows {
  std::vector<std::tuple<uint32_t, uint32_t, uint32_t>> sorted;  // island, layer, node

  IslandRows(const MeshView& mesh, const std::vector<uint32_t>& layer) {
    for (uint32_t i = 0; i < mesh.islands->size(); ++i) {
      for (const uint32_t n : (*mesh.islands)[i]) sorted.emplace_back(i, layer[n], n);
    }
    std::sort(sorted.begin(), sorted.end());
  }
  std::span<const std::tuple<uint32_t, uint32_t, uint32_t>> of(uint32_t island,
                                                               uint32_t layer) const {
    const auto lo = std::lower_bound(sorted.begin(), sorted.end(), std::tuple{island, layer, 0u});
    const auto hi =
        std::lower_bound(sorted.begin(), sorted.end(), std::tuple{island, layer + 1, 0u});
    return {lo, hi};
  }
};

}  // namespace

std::vector<uint32_t> hops_from(const Csr& adj, const std::vector<uint32_t>& sources) {
  std::vector<uint32_t> hops(adj.start.size() - 1, kNoNode);
  std::vector<uint32_t> queue;
  queue.reserve(hops.size());
  for (const uint32_t n : sources) {
    hops[n] = 0;
    queue.push_back(n);
  }
  for (size_t head = 0; head < queue.size(); ++head) {
    const uint32_t n = queue[head];
    for (const uint32_t m : adj.of(n)) {
      if (hops[m] == kNoNode) {
        hops[m] = hops[n] + 1;
        queue.push_back(m);
      }
    }
  }
  return hops;
}

std::vector<uint32_t> layers_with_free_edges(const Csr& adj, const std::vector<uint32_t>& sources,
                                             const std::vector<std::array<uint32_t, 2>>& free_edges) {
  std::vector<uint32_t> layer(adj.start.size() - 1, kNoNode);
  std::deque<uint32_t> queue;
  for (const uint32_t n : sources) {
    layer[n] = 0;
    queue.push_back(n);
  }
  while (!queue.empty()) {
    const uint32_t n = queue.front();
    queue.pop_front();
    for (const uint32_t m : adj.of(n)) {
      const bool free = free_edges[n][0] == m || free_edges[n][1] == m;
      const uint32_t d = layer[n] + (free ? 0 : 1);
      if (d >= layer[m]) continue;
      layer[m] = d;
      if (free) {
        queue.push_front(m);
      } else {
        queue.push_back(m);
      }
    }
  }
  return layer;
}

std::string vertex_name(const MeshView& mesh, uint32_t node) {
  return std::to_string((*mesh.node_vertex)[node]);
}

double path_length(const std::vector<glm::vec3>& pos, const std::vector<uint32_t>& path) {
  double length = 0.0;
  for (size_t i = 1; i < path.size(); ++i) {
    length += glm::distance(glm::dvec3(pos[path[i - 1]]), glm::dvec3(pos[path[i]]));
  }
  return length;
}

Status layer_strip(const MeshView& mesh, const std::vector<uint32_t>& end_a,
                   const std::vector<uint32_t>& end_b, const std::vector<uint32_t>& bank_1,
                   const std::vector<uint32_t>& bank_2, Layering* out) {
  const Csr& adj = *mesh.adjacency;
  const std::vector<uint32_t>& tris = *mesh.tris;
  const size_t node_count = adj.start.size() - 1;
  const bool has_islands = !mesh.islands->empty();
  const std::vector<glm::vec3>& pos = *mesh.positions;

  if (bank_1.size() != bank_2.size()) {
    return Status::error(text_format(
        "the river mesh is not a strip of sections: its banks have different vertex counts "
        "(%zu from vertex %s and %zu from vertex %s)",
        bank_1.size(), vertex_name(mesh, bank_1.front()).c_str(), bank_2.size(),
        vertex_name(mesh, bank_2.front()).c_str()));
  }

  std::vector<uint32_t> layer = hops_from(adj, end_a);
  if (has_islands) {
    layer = layers_with_free_edges(adj, end_a, across_island_edges(mesh, layer, bank_1, bank_2));
  }
  uint32_t max_layer = 0;
  for (const uint32_t l : layer) max_layer = std::max(max_layer, l);  // connected: all set
  const size_t section_count = size_t{max_layer} + 1;
  if (section_count < 2) {
    return Status::error("the river mesh has a single section: a river needs at least two");
  }

  for (size_t t = 0; t < tris.size() / 3; ++t) {
    const uint32_t a = tris[3 * t], b = tris[3 * t + 1], c = tris[3 * t + 2];
    if (layer[a] == layer[b] && layer[b] == layer[c]) {
      return Status::error(text_format(
          "the river mesh is not a strip of sections: triangle %zu (vertices %s, %s, %s) lies "
          "inside section %u instead of joining two neighbouring sections",
          t, vertex_name(mesh, a).c_str(), vertex_name(mesh, b).c_str(),
          vertex_name(mesh, c).c_str(), layer[a]));
    }
  }

  for (size_t i = 0; i < bank_1.size(); ++i) {
    for (const uint32_t n : {bank_1[i], bank_2[i]}) {
      if (layer[n] != i) {
        return Status::error(text_format(
            "the river mesh is not a strip of sections: bank vertex %s is the bank's vertex %zu "
            "but lies in section %u",
            vertex_name(mesh, n).c_str(), i, layer[n]));
      }
    }
  }
  if (bank_1.size() != section_count) {
    return Status::error(text_format(
        "the river mesh is not a strip of sections: it has %zu sections but %zu vertices on each "
        "bank",
        section_count, bank_1.size()));
  }
  for (const uint32_t n : end_b) {
    if (layer[n] != max_layer) {
      return Status::error(text_format(
          "the river mesh is not a strip of sections: vertex %s on the downstream end lies in "
          "section %u, not in the last section %u",
          vertex_name(mesh, n).c_str(), layer[n], max_layer));
    }
  }

  std::vector<uint32_t> layer_size(section_count, 0);
  for (const uint32_t l : layer) ++layer_size[l];
  const IslandRows island_rows(mesh, layer);  // empty without islands
  std::vector<uint32_t> walked_in(has_islands ? node_count : 0, kNoNode);

  out->chain_start.assign(section_count + 1, 0);
  out->chain_nodes.clear();
  out->chain_nodes.reserve(node_count);
  for (uint32_t k = 0; k < section_count; ++k) {
    const uint32_t size = layer_size[k];
    if (size < 2) {
      return Status::error(text_format(
          "section %u of the river has a single vertex (%s): a section needs a non-zero width", k,
          vertex_name(mesh, bank_1[k]).c_str()));
    }
    // Walk the chain of same-section edges from one shore to the other, going on from an
    // island's far side where the chain ends on it.
    uint32_t prev = kNoNode;
    uint32_t cur = bank_1[k];
    std::vector<uint32_t> crossed;  // the islands this section went across
    for (uint32_t steps = 0; cur != kNoNode; ++steps) {
      if (steps >= size) break;  // a cycle: reported below as an incomplete chain
      out->chain_nodes.push_back(cur);
      if (has_islands) walked_in[cur] = k;
      uint32_t next = kNoNode;
      uint32_t same = 0;
      for (const uint32_t m : adj.of(cur)) {
        if (layer[m] != k) continue;
        ++same;
        if (m != prev && next == kNoNode) next = m;
      }
      const uint32_t allowed =
          (prev == kNoNode) ? 1 : 2;  // a shore has one neighbour in its section
      if (same > allowed) {
        return Status::error(text_format(
            "the river mesh is not a strip of sections: section %u branches at vertex %s "
            "(%u neighbours in the same section)",
            k, vertex_name(mesh, cur).c_str(), same));
      }
      prev = cur;
      if (next == kNoNode && has_islands && (*mesh.node_island)[cur] != kNoNode) {
        const uint32_t island = (*mesh.node_island)[cur];
        if (std::find(crossed.begin(), crossed.end(), island) != crossed.end()) {
          return Status::error(text_format(
              "the river mesh is not a strip of sections: section %u meets the island at vertex "
              "%s a second time (a bay?): each section must cross an island once",
              k, vertex_name(mesh, cur).c_str()));
        }
        crossed.push_back(island);
        // The far side: the nearest of the island's other nodes in this section.
        uint32_t far_side = kNoNode;
        double nearest = 0.0;
        for (const auto& [i, l, n] : island_rows.of(island, k)) {
          if (walked_in[n] == k) continue;
          const double d = glm::distance(glm::dvec3(pos[cur]), glm::dvec3(pos[n]));
          if (far_side == kNoNode || d < nearest) {
            far_side = n;
            nearest = d;
          }
        }
        next = far_side;
        prev = kNoNode;  // the far side starts a run of the chain, as a shore does
      }
      cur = next;
    }
    const uint32_t walked = static_cast<uint32_t>(out->chain_nodes.size()) - out->chain_start[k];
    if (walked != size || out->chain_nodes.back() != bank_2[k]) {
      return Status::error(text_format(
          "the river mesh is not a strip of sections: section %u is not one chain of edges "
          "from bank vertex %s to bank vertex %s (%u of its %u vertices reached)",
          k, vertex_name(mesh, bank_1[k]).c_str(), vertex_name(mesh, bank_2[k]).c_str(), walked,
          size));
    }
    out->chain_start[k + 1] = static_cast<uint32_t>(out->chain_nodes.size());
  }
  out->layer = std::move(layer);
  out->bank_a = bank_1;
  out->bank_b = bank_2;
  return Status::success();
}

}  // namespace siviflow
