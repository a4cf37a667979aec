#include "network_layering.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <glm/geometric.hpp>
#include <glm/vec2.hpp>

#include "siviflow/text_format.h"

namespace siviflow {
namespace {

glm::dvec2 xz(const glm::vec3& p) { return {p.x, p.z}; }

// The area-weighted mean gradient (in x/z) of the layer index at every node: the direction the
// layers grow in, which is along the flow.
std::vector<glm::dvec2> layer_gradients(const MeshView& mesh, const std::vector<uint32_t>& layer) {
  const std::vector<glm::vec3>& pos = *mesh.positions;
  const std::vector<uint32_t>& tris = *mesh.tris;
  std::vector<glm::dvec2> grad(pos.size(), glm::dvec2(0.0));
  for (size_t t = 0; t < tris.size() / 3; ++t) {
    const uint32_t a = tris[3 * t], b = tris[3 * t + 1], c = tris[3 * t + 2];
    const glm::dvec2 pa = xz(pos[a]), ab = xz(pos[b]) - pa, ac = xz(pos[c]) - pa;
    const double det = ab.x * ac.y - ab.y * ac.x;
    if (det == 0.0) continue;  // vertical in x/z: no say in the horizontal direction
    const double lb = double(layer[b]) - double(layer[a]);
    const double lc = double(layer[c]) - double(layer[a]);
    // Solve [ab; ac] g = [lb; lc]; weighted by the area, |det| / 2.
    const glm::dvec2 g((lb * ac.y - lc * ab.y) / det, (lc * ab.x - lb * ac.x) / det);
    const glm::dvec2 weighted = 0.5 * std::abs(det) * g;
    for (const uint32_t n : {a, b, c}) grad[n] += weighted;
  }
  return grad;
}

// Border edges between a node and its neighbour along a bank or a shore (never an end's edges:
// an end is a section).
struct BorderNeighbours {
  std::vector<std::array<uint32_t, 2>> of;
  explicit BorderNeighbours(size_t nodes) : of(nodes, {kNoNode, kNoNode}) {}
  void add(uint32_t a, uint32_t b) {
    for (const auto& [x, y] : {std::pair{a, b}, std::pair{b, a}}) {
      (of[x][0] == kNoNode || of[x][0] == y ? of[x][0] : of[x][1]) = y;
    }
  }
  bool joined(uint32_t a, uint32_t b) const { return of[a][0] == b || of[a][1] == b; }
};

}  // namespace

Status layer_network(const MeshView& mesh, const NetworkSides& sides, NetworkLayering* out) {
  const Csr& adj = *mesh.adjacency;
  const std::vector<glm::vec3>& pos = *mesh.positions;
  const std::vector<uint32_t>& tris = *mesh.tris;
  const size_t node_count = pos.size();
  const size_t side_count = sides.sides.size();

  // --- Borders: the banks in side order, then the islands; a corner belongs to its bank.
  NetworkLayering net;
  net.border.assign(node_count, kNoNode);
  net.side_bank.assign(side_count, kNoNode);
  BorderNeighbours along_border(node_count);
  for (size_t i = 0; i < side_count; ++i) {
    if (sides.is_end[i]) continue;
    net.side_bank[i] = net.bank_count++;
    const std::vector<uint32_t>& bank = sides.sides[i];
    for (size_t j = 0; j < bank.size(); ++j) {
      net.border[bank[j]] = net.side_bank[i];
      if (j > 0) along_border.add(bank[j - 1], bank[j]);
    }
  }
  for (uint32_t i = 0; i < mesh.islands->size(); ++i) {
    const std::vector<uint32_t>& loop = (*mesh.islands)[i];
    for (size_t j = 0; j < loop.size(); ++j) {
      net.border[loop[j]] = net.bank_count + i;
      along_border.add(loop[j], loop[(j + 1) % loop.size()]);
    }
  }

  // --- Layers: hops from the root end, where the edges of a shore or a tongue that run across
  // the flow cost nothing, so a row stays one row around an island's head or a tongue's tip.
  // The flow's direction at a hop count is that of the midpoints of the root end's two banks
  // there (the river's middle; a tongue or an island bends the hop count's own fronts).
  const std::vector<uint32_t>& root = sides.sides[sides.root];
  const std::vector<uint32_t> hops = hops_from(adj, root);
  uint32_t max_hops = 0;
  for (const uint32_t h : hops) max_hops = std::max(max_hops, h);
  const uint32_t root_left_bank = net.side_bank[(sides.root + side_count - 1) % side_count];
  const uint32_t root_right_bank = net.side_bank[(sides.root + 1) % side_count];
  std::vector<uint32_t> left_at(max_hops + 1, kNoNode), right_at(max_hops + 1, kNoNode);
  for (const size_t side :
       {(sides.root + side_count - 1) % side_count, (sides.root + 1) % side_count}) {
    std::vector<uint32_t>& at = net.side_bank[side] == root_left_bank ? left_at : right_at;
    for (const uint32_t n : sides.sides[side]) {
      if (at[hops[n]] == kNoNode) at[hops[n]] = n;
    }
  }
  for (std::vector<uint32_t>* at : {&left_at, &right_at}) {  // a bank that ends holds its last
    uint32_t last = kNoNode;
    for (uint32_t& n : *at) last = n = n == kNoNode ? last : n;
    for (size_t k = at->size(); k-- > 0;) last = (*at)[k] = (*at)[k] == kNoNode ? last : (*at)[k];
  }
  auto middle = [&](size_t k) {
    return 0.5 * (xz(pos[left_at[std::min<size_t>(k, max_hops)]]) +
                  xz(pos[right_at[std::min<size_t>(k, max_hops)]]));
  };
  std::vector<std::array<uint32_t, 2>> across(node_count, {kNoNode, kNoNode});
  for (uint32_t a = 0; a < node_count; ++a) {
    for (const uint32_t b : along_border.of[a]) {
      if (b == kNoNode || b < a) continue;
      if (net.border[a] == root_left_bank || net.border[a] == root_right_bank) continue;
      const size_t k = hops[a];
      const glm::dvec2 g = middle(k + 1) - middle(k == 0 ? 0 : k - 1);
      const glm::dvec2 e = xz(pos[b]) - xz(pos[a]);
      if (!(std::abs(e.x * g.y - e.y * g.x) > std::abs(glm::dot(e, g)))) continue;
      for (const auto& [x, y] : {std::pair{a, b}, std::pair{b, a}}) {
        (across[x][0] == kNoNode ? across[x][0] : across[x][1]) = y;
      }
    }
  }
  net.layer = layers_with_free_edges(adj, root, across);
  for (const uint32_t l : net.layer) net.max_layer = std::max(net.max_layer, l);
  const std::vector<uint32_t>& layer = net.layer;
  // Messages count sections from upstream, as the surface does (a confluence's root is downstream).
  auto section_of = [&](uint32_t l) { return sides.root_is_inflow ? l : net.max_layer - l; };

  for (size_t t = 0; t < tris.size() / 3; ++t) {
    const uint32_t a = tris[3 * t], b = tris[3 * t + 1], c = tris[3 * t + 2];
    if (layer[a] == layer[b] && layer[b] == layer[c]) {
      return Status::error(text_format(
          "the river network is not made of sections: triangle %zu (vertices %s, %s, %s) lies "
          "inside section %u instead of joining two neighbouring sections (where arms meet, "
          "they meet at a shallow angle, their sections turning gradually)",
          t, vertex_name(mesh, a).c_str(), vertex_name(mesh, b).c_str(),
          vertex_name(mesh, c).c_str(), section_of(layer[a])));
    }
  }
  for (size_t i = 0; i < side_count; ++i) {
    if (!sides.is_end[i]) continue;
    const std::vector<uint32_t>& end = sides.sides[i];
    for (const uint32_t n : end) {
      if (layer[n] != layer[end.front()]) {
        return Status::error(text_format(
            "the river network's end from vertex %s to vertex %s does not run across the flow: "
            "its vertices %s and %s lie in sections %u and %u, %u and %u hops from the end at "
            "vertex %s",
            vertex_name(mesh, end.front()).c_str(), vertex_name(mesh, end.back()).c_str(),
            vertex_name(mesh, end.front()).c_str(), vertex_name(mesh, n).c_str(),
            section_of(layer[end.front()]), section_of(layer[n]), layer[end.front()], layer[n],
            vertex_name(mesh, root.front()).c_str()));
      }
    }
  }

  // --- Arm segments: within a layer, the edges that are not along a border make paths from
  // border to border; every water node has exactly two of them.
  auto same_layer = [&](uint32_t n, auto&& visit) {
    for (const uint32_t m : adj.of(n)) {
      if (layer[m] == layer[n] && !along_border.joined(n, m)) visit(m);
    }
  };
  for (uint32_t n = 0; n < node_count; ++n) {
    if (net.border[n] != kNoNode) continue;
    uint32_t count = 0;
    same_layer(n, [&](uint32_t) { ++count; });
    if (count > 2) {
      return Status::error(text_format(
          "the river network is not made of sections: section %u branches at vertex %s (%u "
          "neighbours in the same section)",
          section_of(layer[n]), vertex_name(mesh, n).c_str(), count));
    }
    if (count < 2) {
      return Status::error(text_format(
          "the river network is not made of sections: section %u stops at vertex %s in the "
          "water (a section runs from one border to another)",
          section_of(layer[n]), vertex_name(mesh, n).c_str()));
    }
  }
  const std::vector<glm::dvec2> grad = layer_gradients(mesh, layer);
  const double downstream_sign = sides.root_is_inflow ? 1.0 : -1.0;
  std::vector<uint8_t> walked(node_count, 0);
  std::vector<uint32_t> path;
  for (uint32_t b = 0; b < node_count; ++b) {
    if (net.border[b] == kNoNode) continue;
    Status failed;
    same_layer(b, [&](uint32_t m) {
      if (!failed.ok() || walked[m] || (net.border[m] != kNoNode && m < b)) return;
      path.assign({b});
      uint32_t prev = b, cur = m;
      while (net.border[cur] == kNoNode) {
        walked[cur] = 1;
        path.push_back(cur);
        uint32_t next = kNoNode;
        same_layer(cur, [&](uint32_t x) {
          if (x != prev && next == kNoNode) next = x;
        });
        prev = cur;
        cur = next;
      }
      path.push_back(cur);
      if (net.border[cur] == net.border[b]) {
        failed = Status::error(text_format(
            "the river network is not made of sections: section %u meets one border twice, at "
            "vertices %s and %s (a bay?): each section runs from one border to another",
            section_of(layer[b]), vertex_name(mesh, b).c_str(), vertex_name(mesh, cur).c_str()));
        return;
      }
      glm::dvec2 g(0.0);
      for (const uint32_t n : path) g += grad[n];
      const glm::dvec2 d = downstream_sign * g;
      const glm::dvec2 chord = xz(pos[path.front()]) - xz(pos[path.back()]);
      const double score = chord.x * d.y - chord.y * d.x;  // chord . (+Y x downstream)
      if (!(std::abs(score) > 1e-9 * glm::length(chord) * glm::length(d))) {
        failed = Status::error(text_format(
            "cannot tell left from right in section %u of the river network: from vertex %s to "
            "vertex %s it does not run across the flow",
            section_of(layer[b]), vertex_name(mesh, path.front()).c_str(),
            vertex_name(mesh, path.back()).c_str()));
        return;
      }
      if (score < 0.0) std::reverse(path.begin(), path.end());
      ArmSegment seg;
      seg.layer = layer[b];
      seg.first = static_cast<uint32_t>(net.segment_nodes.size());
      seg.count = static_cast<uint32_t>(path.size());
      seg.left_border = net.border[path.front()];
      seg.right_border = net.border[path.back()];
      seg.downstream = glm::vec3(glm::normalize(glm::dvec3(d.x, 0.0, d.y)));
      net.segment_nodes.insert(net.segment_nodes.end(), path.begin(), path.end());
      net.segments.push_back(seg);
    });
    SIVIFLOW_TRY(std::move(failed));
  }
  for (uint32_t n = 0; n < node_count; ++n) {
    if (net.border[n] == kNoNode && !walked[n]) {
      return Status::error(text_format(
          "the river network is not made of sections: section %u has a ring of vertices (vertex "
          "%s among them) that meets no border",
          section_of(layer[n]), vertex_name(mesh, n).c_str()));
    }
  }
  std::stable_sort(net.segments.begin(), net.segments.end(),
                   [](const ArmSegment& a, const ArmSegment& b) { return a.layer < b.layer; });
  *out = std::move(net);
  return Status::success();
}

}  // namespace siviflow
