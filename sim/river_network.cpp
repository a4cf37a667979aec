// RiverSurface::build for a mesh with more than two ends: its corners and ends, its layers from
// the root end, and per node the two borders of its arm and the distances to them.
#include <algorithm>
#include <cmath>
#include <glm/geometric.hpp>
#include <limits>
#include <string>

#include "network_layering.h"
#include "river_welded.h"
#include "siviflow/sim/river_tuning.h"
#include "siviflow/text_format.h"

namespace siviflow {
namespace {

using DVec3 = glm::dvec3;


// The outer border split at its corners; is_end left for the caller.
std::vector<std::vector<uint32_t>> sides_between(const std::vector<uint32_t>& loop,
                                                 const std::vector<size_t>& corners) {
  std::vector<std::vector<uint32_t>> sides;
  for (size_t i = 0; i < corners.size(); ++i) {
    std::vector<uint32_t> side;
    for (size_t p = corners[i];; p = (p + 1) % loop.size()) {
      side.push_back(loop[p]);
      if (p == corners[(i + 1) % corners.size()]) break;
    }
    sides.push_back(std::move(side));
  }
  return sides;
}

}  // namespace

Status RiverSurface::build_network(const Welded& w, const RiverSurfaceOptions& options,
                                   RiverSurface* out) {
  const std::vector<glm::vec3>& pos = w.pos;
  const size_t node_count = pos.size();
  const MeshView mesh{&w.pos, &w.tris, &w.adj, &w.node_vertex, &w.island_loops, &w.node_island};
  auto name = [&](uint32_t n) { return vertex_name(mesh, n); };

  // --- Corners and sides.
  std::vector<size_t> corners;
  for (size_t i = 0; i < w.loop.size(); ++i) {
    if (w.angles[i] < kNetworkCornerMaxAngle) corners.push_back(i);
  }
  std::string corner_names;
  for (const size_t c : corners)
    corner_names += (corner_names.empty() ? "" : ", ") + name(w.loop[c]);
  if (!options.ends.empty() && corners.size() <= 4) {
    return Status::error(
        text_format("ends: %zu ends are named, but the river mesh has 2 (a strip: its corners are "
                    "at vertices %s)",
                    options.ends.size(), corner_names.c_str()));
  }
  if (corners.size() < 6 || corners.size() % 2 != 0) {
    return Status::error(text_format(
        "the river mesh is neither a strip nor a network: its outer border has %zu corners "
        "(vertices %s), where a strip has 4 and a network of n ends 2n",
        corners.size(), corner_names.c_str()));
  }
  const size_t end_count = corners.size() / 2;
  if (!options.ends.empty() && options.ends.size() != end_count) {
    return Status::error(text_format(
        "ends: %zu ends are named, but the river mesh has %zu (its corners are at vertices %s)",
        options.ends.size(), end_count, corner_names.c_str()));
  }
  NetworkSides sides;
  sides.sides = sides_between(w.loop, corners);
  const size_t side_count = sides.sides.size();
  // Where each named end lies: the sides holding its vertex (two at a corner), or the end side
  // nearest its point.
  std::vector<uint32_t> mark_node;
  for (size_t m = 0; m < options.ends.size(); ++m) {
    const uint32_t v = options.ends[m].vertex;
    if (!options.ends[m].at_point && v >= w.vertex_count) {
      return Status::error(text_format(
          "ends[%zu]: vertex %u is not in the river mesh (%zu vertices)", m, v, w.vertex_count));
    }
    mark_node.push_back(options.ends[m].at_point ? kNoNode : w.node_of_vertex[v]);
  }
  // Without named ends, build() has checked the upstream vertex; with them it is not read.
  const uint32_t upstream_node =
      options.ends.empty() ? w.node_of_vertex[options.upstream_vertex] : kNoNode;
  auto distance_to = [&](const std::vector<uint32_t>& side, const glm::vec3& point) {
    double d = std::numeric_limits<double>::max();
    for (const uint32_t n : side) d = std::min(d, glm::distance(DVec3(pos[n]), DVec3(point)));
    return d;
  };
  // With the ends on the even or the odd sides: which side each mark (or the upstream vertex)
  // names, or an empty answer where one lies on no end or two share one; `far` sums how far the
  // named points lie from their ends.
  auto ends_named = [&](size_t parity, size_t* bad_mark, double* far, size_t* matched) {
    const std::vector<uint32_t> wanted =
        options.ends.empty() ? std::vector<uint32_t>{upstream_node} : mark_node;
    std::vector<size_t> side_of(wanted.size(), SIZE_MAX);
    *far = 0.0;
    *matched = 0;
    for (size_t m = 0; m < wanted.size(); ++m) {
      size_t best = SIZE_MAX;
      double best_d = std::numeric_limits<double>::max();
      for (size_t i = parity; i < side_count; i += 2) {
        const auto& side = sides.sides[i];
        const double d =
            wanted[m] == kNoNode
                ? distance_to(side, options.ends[m].point)
                : (std::find(side.begin(), side.end(), wanted[m]) != side.end() ? 0.0 : best_d);
        if (d < best_d) {
          best_d = d;
          best = i;
        }
      }
      if (best == SIZE_MAX || std::find(side_of.begin(), side_of.end(), best) != side_of.end()) {
        if (*bad_mark == SIZE_MAX) *bad_mark = m;
        continue;
      }
      side_of[m] = best;
      *far += best_d;
      ++*matched;
    }
    return *bad_mark == SIZE_MAX ? side_of : std::vector<size_t>();
  };
  auto end_length = [&](size_t parity) {
    double len = 0.0;
    for (size_t i = parity; i < side_count; i += 2) len += path_length(pos, sides.sides[i]);
    return len;
  };
  size_t bad[2] = {SIZE_MAX, SIZE_MAX}, matched[2] = {0, 0};
  double far[2] = {0.0, 0.0};
  const std::vector<size_t> named[2] = {ends_named(0, &bad[0], &far[0], &matched[0]),
                                        ends_named(1, &bad[1], &far[1], &matched[1])};
  size_t parity = 0;
  if (named[0].empty() && named[1].empty()) {
    if (options.ends.empty()) {
      return Status::error(text_format(
          "river vertex %u marks the upstream end but lies on no end of the river network (its "
          "ends run between the corners at vertices %s)",
          options.upstream_vertex, corner_names.c_str()));
    }
    const size_t m = bad[matched[1] > matched[0] ? 1 : 0];  // the way more marks agree with
    const RiverEndMark& mark = options.ends[m];
    return Status::error(text_format(
        "ends[%zu]: %s is not on an end of the river mesh, or shares its end with another "
        "(the ends run between the corners at vertices %s)",
        m,
        mark.at_point
            ? text_format("the end nearest (%g, %g, %g)", mark.point.x, mark.point.y, mark.point.z)
                  .c_str()
            : text_format("vertex %u", mark.vertex).c_str(),
        corner_names.c_str()));
  }
  // Both ways work: the one nearer the named points, else with the shorter ends (a river is
  // longer than it is wide).
  if (named[0].empty() ||
      (!named[1].empty() && (far[1] != far[0] ? far[1] < far[0] : end_length(1) < end_length(0)))) {
    parity = 1;
  }
  const std::vector<size_t>& side_of_mark = named[parity];
  sides.is_end.assign(side_count, 0);
  for (size_t i = parity; i < side_count; i += 2) sides.is_end[i] = 1;

  // --- The root end: the single inflow, or the single outflow.
  std::vector<uint8_t> side_inflow(side_count, 0);
  std::vector<uint32_t> side_mark(side_count, kNoEndMark);
  if (options.ends.empty()) {
    sides.root = side_of_mark[0];
    side_inflow[sides.root] = 1;
  } else {
    size_t inflows = 0;
    for (size_t m = 0; m < options.ends.size(); ++m) {
      side_inflow[side_of_mark[m]] = options.ends[m].inflow ? 1 : 0;
      side_mark[side_of_mark[m]] = static_cast<uint32_t>(m);
      inflows += options.ends[m].inflow ? 1 : 0;
    }
    const size_t outflows = end_count - inflows;
    if (inflows == 0 || outflows == 0 || (inflows > 1 && outflows > 1)) {
      return Status::error(text_format(
          "ends: %zu inflows and %zu outflows: a river network takes one inflow and several "
          "outflows (a fork) or several inflows and one outflow (a confluence)",
          inflows, outflows));
    }
    const bool root_inflow = inflows == 1;
    for (size_t m = 0; m < options.ends.size(); ++m) {
      if (options.ends[m].inflow == root_inflow) sides.root = side_of_mark[m];
    }
  }
  sides.root_is_inflow = side_inflow[sides.root] != 0;

  NetworkLayering net;
  SIVIFLOW_TRY(layer_network(mesh, sides, &net));

  // --- Border ids: the root end's left and right banks, the islands, the other banks.
  const size_t island_count = w.island_loops.size();
  if (island_count + net.bank_count > size_t{std::numeric_limits<BorderId>::max()}) {
    return Status::error(text_format(
        "the river network has %zu islands and %u banks, more borders than the limit of %u",
        island_count, net.bank_count, unsigned{std::numeric_limits<BorderId>::max()}));
  }
  const auto root_segment = std::find_if(net.segments.begin(), net.segments.end(),
                                         [](const ArmSegment& s) { return s.layer == 0; });
  std::vector<BorderId> border_id(net.bank_count + island_count);
  {
    BorderId next = island_border(island_count);
    for (uint32_t b = 0; b < net.bank_count; ++b) {
      border_id[b] = b == root_segment->left_border    ? kLeftBankBorder
                     : b == root_segment->right_border ? kRightBankBorder
                                                       : next++;
    }
    for (size_t i = 0; i < island_count; ++i) border_id[net.bank_count + i] = island_border(i);
  }

  RiverSurface s;
  const uint32_t max_layer = net.max_layer;
  const size_t section_count = size_t{max_layer} + 1;
  auto section_of_layer = [&](uint32_t l) { return sides.root_is_inflow ? l : max_layer - l; };
  s.node_section_.resize(node_count);
  s.node_bank_.assign(node_count, Bank::kNone);
  s.node_d_left_.assign(node_count, 0.0f);
  s.node_d_right_.assign(node_count, 0.0f);
  s.node_left_border_.assign(node_count, kLeftBankBorder);
  s.node_right_border_.assign(node_count, kLeftBankBorder);
  for (uint32_t n = 0; n < node_count; ++n) {
    s.node_section_[n] = section_of_layer(net.layer[n]);
    if (net.border[n] == kNoNode) continue;
    const BorderId b = border_id[net.border[n]];
    s.node_left_border_[n] = s.node_right_border_[n] = b;
    if (b == kLeftBankBorder) s.node_bank_[n] = Bank::kLeft;
    if (b == kRightBankBorder) s.node_bank_[n] = Bank::kRight;
  }

  DVec3 lo(std::numeric_limits<double>::max()), hi(-std::numeric_limits<double>::max());
  for (const glm::vec3& p : pos) {
    lo = glm::min(lo, DVec3(p));
    hi = glm::max(hi, DVec3(p));
  }
  const double extent = glm::length(hi - lo);

  // --- Per node, from its arm: the borders either side and the distances along the arm. A node
  // of the root end's banks on a single arm is a shore as in a strip; any other border node lies
  // on its border from both sides.
  std::vector<uint8_t> arms_at(node_count, 0);
  for (const ArmSegment& seg : net.segments) {
    for (const uint32_t n :
         {net.segment_nodes[seg.first], net.segment_nodes[seg.first + seg.count - 1]}) {
      arms_at[n] = static_cast<uint8_t>(std::min(arms_at[n] + 1, 2));
    }
  }
  std::vector<double> arm_width(net.segments.size());
  std::vector<double> arc;
  for (size_t i = 0; i < net.segments.size(); ++i) {
    const ArmSegment& seg = net.segments[i];
    const uint32_t* nodes = &net.segment_nodes[seg.first];
    arc.assign(seg.count, 0.0);
    for (size_t j = 1; j < seg.count; ++j) {
      arc[j] = arc[j - 1] + glm::distance(DVec3(pos[nodes[j - 1]]), DVec3(pos[nodes[j]]));
    }
    const double width = arm_width[i] = arc.back();
    if (!(width > kMinSectionWidthRelative * extent)) {
      return Status::error(text_format(
          "section %u of the river network has a zero-width neck (%g m of water between vertices "
          "%s and %s)",
          section_of_layer(seg.layer), width, name(nodes[0]).c_str(),
          name(nodes[seg.count - 1]).c_str()));
    }
    const BorderId left = border_id[seg.left_border], right = border_id[seg.right_border];
    for (size_t j = 0; j < seg.count; ++j) {
      const uint32_t n = nodes[j];
      const bool shore = net.border[n] != kNoNode;
      const bool bank_shore = shore && arms_at[n] == 1 && s.node_bank_[n] != Bank::kNone;
      if (shore && !bank_shore) continue;
      s.node_left_border_[n] = left;
      s.node_right_border_[n] = right;
      s.node_d_left_[n] = static_cast<float>(arc[j]);
      s.node_d_right_[n] = static_cast<float>(width - arc[j]);
    }
  }

  // --- Sections: each layer's arms, left to right within an arm; a node shared by two arms (an
  // island's tip) once; border nodes no arm reaches at the end.
  {
    std::vector<std::pair<uint64_t, uint32_t>> order;
    order.reserve(node_count);
    std::vector<uint8_t> placed(node_count, 0);
    uint64_t seq = 0;
    for (const ArmSegment& seg : net.segments) {
      for (uint32_t j = 0; j < seg.count; ++j) {
        const uint32_t n = net.segment_nodes[seg.first + j];
        if (placed[n]) continue;
        placed[n] = 1;
        order.emplace_back((uint64_t{s.node_section_[n]} << 32) | seq++, n);
      }
    }
    for (uint32_t n = 0; n < node_count; ++n) {
      if (!placed[n]) order.emplace_back((uint64_t{s.node_section_[n]} << 32) | (seq++), n);
    }
    std::sort(order.begin(), order.end());
    s.section_nodes_.reserve(node_count);
    for (const auto& [key, n] : order) s.section_nodes_.push_back(n);
  }
  s.sections_.resize(section_count);
  {
    std::vector<DVec3> mid_sum(section_count, DVec3(0.0)), flow_sum(section_count, DVec3(0.0));
    std::vector<double> width(section_count, 0.0);
    std::vector<uint32_t> arms(section_count, 0);
    for (size_t i = 0; i < net.segments.size(); ++i) {
      const ArmSegment& seg = net.segments[i];
      const uint32_t k = section_of_layer(seg.layer);
      mid_sum[k] += 0.5 * (DVec3(pos[net.segment_nodes[seg.first]]) +
                           DVec3(pos[net.segment_nodes[seg.first + seg.count - 1]]));
      flow_sum[k] += DVec3(seg.downstream);
      width[k] += arm_width[i];
      ++arms[k];
    }
    uint32_t first = 0;
    for (size_t k = 0; k < section_count; ++k) {
      RiverSection& sec = s.sections_[k];
      sec.first_node = first;
      while (first < node_count && s.node_section_[s.section_nodes_[first]] == k) ++first;
      sec.node_count = first - sec.first_node;
      if (arms[k] == 0) {
        return Status::error(text_format(
            "section %zu of the river network holds no water: its vertices (%s first) all lie "
            "on borders",
            k, name(s.section_nodes_[sec.first_node]).c_str()));
      }
      sec.width = static_cast<float>(width[k]);
      sec.midpoint = glm::vec3(mid_sum[k] / double(arms[k]));
      const double flow_len = glm::length(flow_sum[k]);
      sec.flow_direction = flow_len > 0.0 ? glm::vec3(flow_sum[k] / flow_len) : glm::vec3(1, 0, 0);
      s.widest_ = std::max(s.widest_, sec.width);
    }
    // Along the river: each section's distance from the one upstream, as the mean over its
    // nodes of the shortest edge back to it.
    std::vector<double> step_sum(section_count, 0.0);
    std::vector<uint32_t> step_count(section_count, 0);
    for (uint32_t n = 0; n < node_count; ++n) {
      const uint32_t k = s.node_section_[n];
      if (k == 0) continue;
      double nearest = std::numeric_limits<double>::max();
      for (const uint32_t m : w.adj.of(n)) {
        if (s.node_section_[m] + 1 == k)
          nearest = std::min(nearest, glm::distance(DVec3(pos[n]), DVec3(pos[m])));
      }
      if (nearest == std::numeric_limits<double>::max()) continue;
      step_sum[k] += nearest;
      ++step_count[k];
    }
    double along = 0.0;
    for (size_t k = 1; k < section_count; ++k) {
      if (step_count[k] > 0) along += step_sum[k] / step_count[k];
      s.sections_[k].along = static_cast<float>(along);
    }
  }

  // --- Ends in border order from the root, banks and islands.
  for (size_t j = 0; j < side_count; ++j) {
    const size_t i = (sides.root + j) % side_count;
    const std::vector<uint32_t>& side = sides.sides[i];
    if (!sides.is_end[i]) {
      RiverBank bank;
      bank.border = border_id[net.side_bank[i]];
      bank.first_node = static_cast<uint32_t>(s.bank_nodes_.size());
      bank.node_count = static_cast<uint32_t>(side.size());
      s.bank_nodes_.insert(s.bank_nodes_.end(), side.begin(), side.end());
      s.banks_.push_back(bank);
      continue;
    }
    const uint32_t l = net.layer[side.front()];
    const auto seg =
        std::find_if(net.segments.begin(), net.segments.end(), [&](const ArmSegment& a) {
          const uint32_t a0 = net.segment_nodes[a.first],
                         a1 = net.segment_nodes[a.first + a.count - 1];
          return a.layer == l && a.count == side.size() &&
                 ((a0 == side.front() && a1 == side.back()) ||
                  (a0 == side.back() && a1 == side.front()));
        });
    if (seg == net.segments.end()) {
      return Status::error(text_format(
          "the river network's end from vertex %s to vertex %s is not one section of water",
          name(side.front()).c_str(), name(side.back()).c_str()));
    }
    RiverEnd end;
    end.first_node = static_cast<uint32_t>(s.end_nodes_.size());
    end.node_count = seg->count;
    end.inflow = side_inflow[i] != 0;
    end.section = section_of_layer(l);
    end.left_border = border_id[seg->left_border];
    end.right_border = border_id[seg->right_border];
    end.width = static_cast<float>(arm_width[seg - net.segments.begin()]);
    end.mark = side_mark[i];
    s.end_nodes_.insert(s.end_nodes_.end(), net.segment_nodes.begin() + seg->first,
                        net.segment_nodes.begin() + seg->first + seg->count);
    s.ends_.push_back(end);
  }
  for (const std::vector<uint32_t>& island : w.island_loops) {
    s.islands_.push_back(
        {static_cast<uint32_t>(s.island_nodes_.size()), static_cast<uint32_t>(island.size())});
    s.island_nodes_.insert(s.island_nodes_.end(), island.begin(), island.end());
  }

  // --- Wind every triangle counter-clockwise seen from above (+Y).
  std::vector<uint32_t>& tris = w.tris;
  if (options.rewound != nullptr) options.rewound->assign(tris.size() / 3, false);
  for (size_t t = 0; t < tris.size() / 3; ++t) {
    uint32_t* tri = &tris[3 * t];
    const DVec3 a(pos[tri[0]]);
    if (glm::cross(DVec3(pos[tri[1]]) - a, DVec3(pos[tri[2]]) - a).y < 0.0) {
      std::swap(tri[1], tri[2]);
      if (options.rewound != nullptr) (*options.rewound)[t] = true;
    }
  }

  if (node_count != w.vertex_count) {
    s.node_of_vertex_ = std::move(w.node_of_vertex);
    s.node_vertex_ = std::move(w.node_vertex);
  }
  w.pos.shrink_to_fit();
  s.node_positions_ = std::move(w.pos);
  s.triangles_ = std::move(w.tris);
  s.node_triangles_ = std::move(w.node_tris);
  s.extent_ = static_cast<float>(extent);
  s.drop_section_list_of_runs();
  *out = std::move(s);
  return Status::success();
}

}  // namespace siviflow
