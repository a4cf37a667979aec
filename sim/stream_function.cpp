#include "siviflow/sim/stream_function.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include <glm/common.hpp>
#include <glm/geometric.hpp>

#include "end_discharges.h"
#include "island_circulation.h"
#include "siviflow/sim/world_limits.h"
#include "siviflow/text_format.h"

namespace siviflow {
namespace {

using DVec3 = glm::dvec3;

// A full solve's statistics: every node and triangle, the velocity changed everywhere.
FlowUpdateStats full_update(size_t nodes, size_t triangles) {
  return {nodes, triangles, nodes, {XzBox::everywhere()}};
}

// Squared x/z distance from p to the box [lo, hi].
double box_distance2(glm::dvec2 lo, glm::dvec2 hi, const glm::vec3& p) {
  const glm::dvec2 at(p.x, p.z);
  const glm::dvec2 d = glm::max(glm::max(lo - at, at - hi), glm::dvec2(0.0));
  return d.x * d.x + d.y * d.y;
}

// The compact-support blend of eq. 2.3 as corrected: f(0) = 0, f(1) = 1, flat at both ends.
double blend(double t) {
  t = std::clamp(t, 0.0, 1.0);
  return t * t * t * (t * (6.0 * t - 15.0) + 10.0);
}

// r^p for r in (0, 1], with the common powers spared a pow().
double ratio_pow(double r, double p) {
  if (p == 1.0) return r;
  if (p == 1.5) return r * std::sqrt(r);
  if (p == 2.0) return r * r;
  return std::pow(r, p);
}

glm::dvec2 xz(const glm::vec3& v) { return {v.x, v.z}; }

// 2 x a triangle's area, as the P1 gradient wants it, rounded to float as the velocities are.
float area2_of(const DVec3& a, const DVec3& b, const DVec3& c) {
  return static_cast<float>(glm::length(glm::cross(b - a, c - a)));
}

glm::vec3 pos_of(const RiverSurface& s, uint32_t n) { return s.node_positions()[n]; }

}  // namespace

Status StreamFunction::validate_params(const FlowParams& params) {
  if (!std::isfinite(params.discharge)) {
    return Status::error(text_format("flow discharge %g is not finite", params.discharge));
  }
  if (!std::isfinite(params.p) || !(params.p > 0.0f) || params.p > 16.0f) {
    return Status::error(text_format("flow power p = %g: it must be in (0, 16]", params.p));
  }
  if (!std::isfinite(params.search_radius) || params.search_radius < 0.0f) {
    return Status::error(text_format(
        "flow search radius %g m: it must be positive (or 0 for %g x the widest section)",
        params.search_radius, kDefaultSearchRadiusFactor));
  }
  return Status::success();
}

Status StreamFunction::create(RiverSurface surface, const FlowParams& params, StreamFunction* out) {
  SIVIFLOW_TRY(validate_params(params));
  if (surface.node_count() == 0) return Status::error("the river surface is empty");

  StreamFunction f;
  f.params_ = params;
  if (f.params_.search_radius == 0.0f) {
    f.params_.search_radius = kDefaultSearchRadiusFactor * surface.widest_section();
  }
  f.surface_ = std::move(surface);
  const RiverSurface& s = f.surface_;
  const size_t nodes = s.node_count();
  const double radius = f.params_.search_radius;

  // Eq. 2.1 is undefined with a single boundary in reach: every vertex not on a bank needs both.
  const auto d_left = s.node_d_left();
  const auto d_right = s.node_d_right();
  for (uint32_t n = 0; n < nodes; ++n) {
    if (d_left[n] > 0.0f && d_right[n] > 0.0f && (d_left[n] >= radius || d_right[n] >= radius)) {
      return Status::error(text_format(
          "river vertex %u (section %u) has only one boundary within the search radius s = %g m "
          "(%g m to the left bank, %g m to the right bank): raise the search radius above %g m",
          s.vertex_of_node(n), s.node_section()[n], radius, d_left[n], d_right[n],
          std::max(d_left[n], d_right[n])));
    }
  }

  // psi on the borders: the banks from the ends' discharges, the islands from their circulation.
  SIVIFLOW_TRY(end_discharges(s, params.discharge, params.end_discharges, &f.end_discharge_));
  SIVIFLOW_TRY(bank_stream_values(s, f.end_discharge_, &f.border_psi_));
  std::vector<double> island_psi;
  SIVIFLOW_TRY(island_stream_values(s, f.border_psi_, &island_psi));
  for (size_t i = 0; i < island_psi.size(); ++i) f.border_psi_[island_border(i)] = island_psi[i];
  // A shore's tangent from its neighbours along it; a network bank's ends (its corners) take
  // the one neighbour they have along the bank.
  auto add_tangents = [&](std::span<const uint32_t> border, bool closed) {
    const size_t size = border.size();
    for (size_t j = 0; j < size; ++j) {
      const uint32_t prev = closed ? border[(j + size - 1) % size] : border[j == 0 ? 0 : j - 1];
      const uint32_t next = closed ? border[(j + 1) % size] : border[std::min(j + 1, size - 1)];
      // In double, as bank_tangent: a float difference of far coordinates may overflow.
      const DVec3 here(pos_of(s, border[j]));
      const DVec3 d = DVec3(pos_of(s, next)) - DVec3(pos_of(s, prev));
      const double length = glm::length(d);
      // A tongue's tip, where the border turns back on itself, has no tangent: its velocity is
      // its triangles' as they are.
      const bool tip = glm::dot(here - DVec3(pos_of(s, prev)), DVec3(pos_of(s, next)) - here) < 0.0;
      f.shore_tangent_.push_back({border[j], length > 0.0 && std::isfinite(length) && !tip
                                                 ? glm::vec3(d / length)
                                                 : glm::vec3(0.0f)});
    }
  };
  for (size_t i = 0; i < s.islands().size(); ++i) add_tangents(s.island_nodes(i), true);
  for (size_t b = 0; b < s.banks().size(); ++b) add_tangents(s.bank_nodes(b), false);
  f.find_junctions();
  std::sort(f.shore_tangent_.begin(), f.shore_tangent_.end(),
            [](const auto& a, const auto& b) { return a.first < b.first; });

  f.solve_all(false);  // no obstacles yet: the field is the obstacle-free one
  *out = std::move(f);
  return Status::success();
}

double StreamFunction::evaluate(uint32_t n, bool use_obstacles, bool* wet) const {
  *wet = true;
  const double s = params_.search_radius;
  const BorderId left = surface_.node_left_border(n), right = surface_.node_right_border(n);
  const double psi_left = border_psi(left), psi_right = border_psi(right);
  double dl = surface_.node_d_left()[n];
  double dr = surface_.node_d_right()[n];

  // Pass 1: dry?, on a boundary?, and the nearest boundary distance (the weights' scale). The
  // obstacles in reach are remembered for pass 2 (recomputed past kKept of them).
  constexpr size_t kKept = 16;
  double kept_d[kKept];
  double kept_psi[kKept];
  size_t reached = 0;
  double nearest = std::numeric_limits<double>::max();
  const double* on_obstacle = nullptr;
  if (use_obstacles) {
    const glm::dvec2 p = xz(surface_.node_positions()[n]);
    for (const uint32_t j : active_) {
      const ObstacleState& st = state_[j];
      if (!influences(st, j, n)) continue;
      const double d = footprint_distance(obstacles_[j], xz(st.centre), p);
      if (d < 0.0) {
        *wet = false;
        return st.psi;
      }
      if (st.merged == Bank::kLeft) {
        if (left == kLeftBankBorder) dl = std::min(dl, d);
      } else if (st.merged == Bank::kRight) {
        if (right == kRightBankBorder) dr = std::min(dr, d);
      } else {
        if (d == 0.0 && on_obstacle == nullptr) on_obstacle = &st.psi;
        nearest = std::min(nearest, d);
        if (reached < kKept) {
          kept_d[reached] = d;
          kept_psi[reached] = st.psi;
        }
        ++reached;
      }
    }
  }
  const double nearest_obstacle = nearest;
  const double p = params_.p;
  // Pass 2, between the borders either side and the obstacles: w_i scaled by nearest^p, which is
  // the product form of algorithms.md §1.1 divided by a common factor: finite and exact on a
  // boundary, no overflow however many boundaries.
  auto interpolate = [&](double to_left, double left_psi, double to_right, double right_psi) {
    double closest = nearest_obstacle;
    if (to_left < s) closest = std::min(closest, to_left);
    if (to_right < s) closest = std::min(closest, to_right);
    if (to_left <= 0.0) return left_psi;
    if (to_right <= 0.0) return right_psi;
    if (on_obstacle != nullptr) return *on_obstacle;
    double num = 0.0, den = 0.0;
    auto add = [&](double d, double value) {
      const double w = blend(1.0 - d / s) * ratio_pow(closest / d, p);
      num += w * value;
      den += w;
    };
    if (to_left < s) add(to_left, left_psi);
    if (to_right < s) add(to_right, right_psi);
    if (reached <= kKept) {
      for (size_t i = 0; i < reached; ++i) add(kept_d[i], kept_psi[i]);
    } else {
      const glm::dvec2 pn = xz(surface_.node_positions()[n]);
      for (const uint32_t j : active_) {
        const ObstacleState& st = state_[j];
        if (st.merged != Bank::kNone || !influences(st, j, n)) continue;
        add(footprint_distance(obstacles_[j], xz(st.centre), pn), st.psi);
      }
    }
    if (den > 0.0) return num / den;
    return use_obstacles ? node_psi_free(n) : 0.0;  // every weight underflowed
  };
  const double psi = interpolate(dl, psi_left, dr, psi_right);

  // Beyond a junction the streamlines parting its arms leave from its tips: the field as if the
  // tongues went on (a divider at each tip's place across the river, at its tongue's psi),
  // giving way to the plain one with the distance from the tips (river_tuning.h).
  for (const Junction& junction : junctions_) {
    if (junction.left != left || junction.right != right) continue;
    const double x = std::abs(double{surface_.sections()[surface_.node_section()[n]].along} - junction.along);
    const double width = double{surface_.node_d_left()[n]} + surface_.node_d_right()[n];
    if (!(x < kTipReachWidths * width)) continue;  // past its reach (blend 0)
    const double g = std::exp(-kTipRelaxationRoot * std::sqrt(x / width) - kTipRelaxationLinear * x / width) *
                     blend(1.0 - x / (kTipReachWidths * width));
    if (g <= 0.0) continue;
    // The dividers (or borders) either side of the node, and how far along the section.
    const double arc = surface_.node_d_left()[n];
    double to_left = dl, left_psi = psi_left, to_right = dr, right_psi = psi_right;
    for (const auto& [fraction, tongue_psi] : junction.dividers) {
      const double at = fraction * width;
      if (at <= arc) {
        to_left = arc - at;
        left_psi = tongue_psi;
      } else {
        to_right = at - arc;
        right_psi = tongue_psi;
        break;
      }
    }
    return psi + g * (interpolate(to_left, left_psi, to_right, right_psi) - psi);
  }
  return psi;
}

double StreamFunction::node_psi_free(uint32_t n) const {
  bool wet = true;
  return evaluate(n, false, &wet);
}

bool StreamFunction::influences(const ObstacleState& st, size_t obstacle, uint32_t n) const {
  const double s = params_.search_radius;
  const float along = surface_.sections()[surface_.node_section()[n]].along;
  // Only vertices within s along the river: the next loop of a meander, close across the land,
  // must not feel an object in this one.
  if (along < st.along_lo - s || along > st.along_hi + s) return false;
  const glm::vec3& p = surface_.node_positions()[n];
  if (p.x <= st.lo.x - s || p.x >= st.hi.x + s || p.z <= st.lo.y - s || p.z >= st.hi.y + s) {
    return false;
  }
  return footprint_distance(obstacles_[obstacle], xz(st.centre), xz(p)) < s;
}

double StreamFunction::node_psi(uint32_t n) const {
  bool wet = true;
  return evaluate(n, true, &wet);
}

float StreamFunction::triangle_area2(uint32_t t) const {
  const auto tri = surface_.triangles().subspan(3 * size_t{t}, 3);
  const auto pos = surface_.node_positions();
  return area2_of(DVec3(pos[tri[0]]), DVec3(pos[tri[1]]), DVec3(pos[tri[2]]));
}

StreamFunction::TriangleFlow StreamFunction::triangle_flow(uint32_t t, double psi_a, double psi_b,
                                                           double psi_c) const {
  const auto tri = surface_.triangles().subspan(3 * size_t{t}, 3);
  const auto pos = surface_.node_positions();
  const DVec3 a(pos[tri[0]]), b(pos[tri[1]]), c(pos[tri[2]]);
  const float area2 = area2_of(a, b, c);
  // grad(psi) x n = sum_i psi_i e_i / (2 area), e_i the edge opposite vertex i, counter-clockwise
  // about n; the edges sum to zero, so psi_a drops out (and with it the rounding of large psi).
  const DVec3 g = (psi_b - psi_a) * (a - c) + (psi_c - psi_a) * (b - a);
  return {glm::vec3(g / double{area2}), area2};
}

template <class PsiOf>
StreamFunction::TriangleFlow StreamFunction::triangle_flow(uint32_t t, const PsiOf& psi_of) const {
  const auto tri = surface_.triangles().subspan(3 * size_t{t}, 3);
  return triangle_flow(t, psi_of(tri[0]), psi_of(tri[1]), psi_of(tri[2]));
}

glm::vec3 StreamFunction::triangle_velocity(uint32_t t) const {
  return triangle_flow(t, [this](uint32_t n) { return node_psi(n); }).velocity;
}

glm::vec3 StreamFunction::bank_tangent(uint32_t n) const {
  if (surface_.on_island(n) || surface_.network()) {
    const auto it = std::lower_bound(shore_tangent_.begin(), shore_tangent_.end(), n,
                                     [](const auto& entry, uint32_t node) { return entry.first < node; });
    return it != shore_tangent_.end() && it->first == n ? it->second : glm::vec3(0.0f);
  }
  const Bank bank = surface_.node_bank()[n];
  if (bank == Bank::kNone) return glm::vec3(0.0f);
  const auto sections = surface_.sections();
  const size_t k = surface_.node_section()[n];
  const size_t prev = k == 0 ? 0 : k - 1;
  const size_t next = std::min(k + 1, sections.size() - 1);
  auto shore = [&](size_t j) {
    return bank == Bank::kLeft ? surface_.section_nodes(j).front()
                               : surface_.section_nodes(j).back();
  };
  const auto pos = surface_.node_positions();
  return glm::vec3(glm::normalize(DVec3(pos[shore(next)]) - DVec3(pos[shore(prev)])));
}

template <class PsiOf>
void StreamFunction::update_node_velocity(uint32_t n, const PsiOf& psi_of) {
  if (!wet_[n]) {
    node_velocity_[n] = glm::vec3(0.0f);
    return;
  }
  DVec3 sum(0.0);
  double area = 0.0;
  for (const uint32_t t : surface_.node_triangles(n)) {
    const TriangleFlow flow = triangle_flow(t, psi_of);
    sum += double{flow.area2} * DVec3(flow.velocity);
    area += flow.area2;
  }
  glm::vec3 v(sum / area);
  const glm::vec3 tangent = bank_tangent(n);
  if (tangent != glm::vec3(0.0f)) v = glm::dot(v, tangent) * tangent;  // a bank is a streamline
  node_velocity_[n] = v;
}

size_t StreamFunction::memory_bytes() const {
  const auto bytes = [](const auto& v) { return v.capacity() * sizeof(v[0]); };
  return surface_.memory_bytes() + wet_.capacity() / 8 + bytes(node_velocity_) + bytes(junctions_) +
         bytes(border_psi_) + bytes(end_discharge_) + bytes(shore_tangent_) + bytes(obstacles_) +
         bytes(state_) + bytes(active_) + node_grid_.memory_bytes() +
         triangle_grid_.memory_bytes() + bytes(node_stamp_) + bytes(triangle_stamp_) +
         bytes(scratch_nodes_) + bytes(scratch_triangles_) + bytes(psi_values_);
}

void StreamFunction::solve_full() { solve_all(true); }

void StreamFunction::solve_all(bool use_obstacles) {
  const size_t nodes = surface_.node_count();
  std::vector<double> psi(nodes);
  wet_.resize(nodes);
  for (uint32_t n = 0; n < nodes; ++n) {
    bool wet = true;
    psi[n] = evaluate(n, use_obstacles, &wet);
    wet_[n] = wet;
  }
  node_velocity_.resize(nodes);
  const auto psi_of = [&psi](uint32_t n) { return psi[n]; };
  for (uint32_t n = 0; n < nodes; ++n) update_node_velocity(n, psi_of);
  stats_ = full_update(nodes, surface_.triangle_count());
}

void StreamFunction::build_grids() {
  if (!node_grid_.empty()) return;
  const auto pos = surface_.node_positions();
  glm::dvec2 lo(std::numeric_limits<double>::max()), hi(-std::numeric_limits<double>::max());
  for (const glm::vec3& p : pos) {
    lo = glm::min(lo, xz(p));
    hi = glm::max(hi, xz(p));
  }
  // Cells of about two triangle edges hold a few vertices each in the river, whatever its shape.
  double mean_area2 = 0.0;
  const size_t tris = surface_.triangle_count();
  for (uint32_t t = 0; t < tris; ++t) mean_area2 += triangle_area2(t);
  mean_area2 /= static_cast<double>(std::max<size_t>(tris, 1));
  const double cell = std::max(2.0 * std::sqrt(mean_area2), 1e-6 * surface_.extent());
  const size_t max_cells = static_cast<size_t>(kMaxGridCellsPerVertex * static_cast<double>(pos.size())) + 16;
  node_grid_.init(lo, hi, cell, max_cells);
  node_grid_.insert_points(pos);
  triangle_grid_.init(lo, hi, cell, max_cells);
  triangle_grid_.insert_triangles(pos, surface_.triangles());
  node_stamp_.assign(pos.size(), 0);
  triangle_stamp_.assign(surface_.triangle_count(), 0);
  stamp_ = 0;
}

StreamFunction::ObstacleState StreamFunction::place(size_t obstacle, const glm::vec3& centre) const {
  const Obstacle& o = obstacles_[obstacle];
  ObstacleState st;
  st.centre = centre;
  const glm::dvec2 c = xz(centre);
  footprint_bounds(o, c, &st.lo, &st.hi);
  const auto pos = surface_.node_positions();
  const auto tri = surface_.triangles();
  const auto node_section = surface_.node_section();
  const auto sections = surface_.sections();
  auto corners = [&](uint32_t t) {
    return std::array<glm::dvec2, 3>{xz(pos[tri[3 * t]]), xz(pos[tri[3 * t + 1]]),
                                     xz(pos[tri[3 * t + 2]])};
  };
  auto interpolate = [&](uint32_t t, const glm::dvec3& bary) {
    return bary.x * node_psi_free(tri[3 * t]) + bary.y * node_psi_free(tri[3 * t + 1]) +
           bary.z * node_psi_free(tri[3 * t + 2]);
  };

  // Wet footprint: the triangles it overlaps, and their span along the river.
  const auto node_bank = surface_.node_bank();
  bool crosses_left = false, crosses_right = false;
  float along_lo = std::numeric_limits<float>::max(), along_hi = -along_lo;
  uint32_t nearest_tri = std::numeric_limits<uint32_t>::max();
  double nearest_dist = std::numeric_limits<double>::max();
  triangle_grid_.for_each_in(st.lo, st.hi, [&](uint32_t t) {
    const auto corner = corners(t);
    if (!footprint_overlaps_triangle(o, c, corner)) return;
    st.in_water = true;
    for (int i = 0; i < 3; ++i) {
      const uint32_t a = tri[3 * t + i], b = tri[3 * t + (i + 1) % 3];
      const float along = sections[node_section[a]].along;
      along_lo = std::min(along_lo, along);
      along_hi = std::max(along_hi, along);
      // Two shore nodes of one bank in one triangle make a bank edge.
      const Bank bank = node_bank[a];
      if (bank != Bank::kNone && node_bank[b] == bank && node_section[a] != node_section[b] &&
          footprint_overlaps_segment(o, c, xz(pos[a]), xz(pos[b]))) {
        (bank == Bank::kLeft ? crosses_left : crosses_right) = true;
      }
    }
    const glm::dvec3 b = closest_barycentric(corner, c);
    const double d = glm::length(b.x * corner[0] + b.y * corner[1] + b.z * corner[2] - c);
    if (d < nearest_dist || (d == nearest_dist && t < nearest_tri)) {
      nearest_dist = d;
      nearest_tri = t;
    }
  });
  if (!st.in_water) return st;
  st.along_lo = along_lo;
  st.along_hi = along_hi;

  // psi of the obstacle: the obstacle-free field at its centre. Where the river passes over
  // itself, the triangle nearest the centre in height wins; a centre over land takes the
  // nearest wet point of the footprint.
  uint32_t best = std::numeric_limits<uint32_t>::max();
  double best_dy = std::numeric_limits<double>::max();
  glm::dvec3 best_bary(0.0);
  triangle_grid_.for_each_in(c, c, [&](uint32_t t) {
    const auto corner = corners(t);
    const glm::dvec3 b = closest_barycentric(corner, c);
    const glm::dvec2 p = b.x * corner[0] + b.y * corner[1] + b.z * corner[2];
    if (glm::length(p - c) > 1e-9 * (1.0 + glm::length(c))) return;  // not under the centre
    const double y = b.x * pos[tri[3 * t]].y + b.y * pos[tri[3 * t + 1]].y + b.z * pos[tri[3 * t + 2]].y;
    const double dy = std::abs(y - double{centre.y});
    if (dy < best_dy || (dy == best_dy && t < best)) {
      best_dy = dy;
      best = t;
      best_bary = b;
    }
  });
  if (best == std::numeric_limits<uint32_t>::max()) {
    best = nearest_tri;
    best_bary = closest_barycentric(corners(best), c);
  }
  st.psi = interpolate(best, best_bary);
  // Touching one bank, the obstacle extends it: no water passes between them. Across both it
  // dams the river; it stays a boundary of its own (the flow there is moot, but finite).
  if (crosses_left != crosses_right) {
    st.merged = crosses_left ? Bank::kLeft : Bank::kRight;
    st.psi = border_psi(crosses_left ? kLeftBankBorder : kRightBankBorder);
  }
  return st;
}

void StreamFunction::refresh_active() {
  active_.clear();
  for (uint32_t j = 0; j < state_.size(); ++j) {
    if (state_[j].in_water) active_.push_back(j);
  }
}

Status StreamFunction::set_obstacles(std::vector<Obstacle> obstacles, double time) {
  if (obstacles.size() > kMaxObstacles) {
    return Status::error(text_format("%zu obstacles, more than the limit of %zu",
                                     obstacles.size(), kMaxObstacles));
  }
  for (size_t i = 0; i < obstacles.size(); ++i) SIVIFLOW_TRY(validate_obstacle(obstacles[i], i));
  if (obstacles.empty() && obstacles_.empty()) {
    // None before (never, or all removed: the local updates end where a full solve does, bit for
    // bit) and none now: the field already is the obstacle-free one a full solve would give again
    // (a long river's whole flow), and is reported as one.
    stats_ = full_update(surface_.node_count(), surface_.triangle_count());
    return Status::success();
  }
  if (!obstacles.empty()) build_grids();
  obstacles_ = std::move(obstacles);
  state_.clear();
  for (size_t i = 0; i < obstacles_.size(); ++i) {
    state_.push_back(place(i, obstacle_centre_at(obstacles_[i], time)));
  }
  refresh_active();
  solve_full();
  return Status::success();
}

Status StreamFunction::move_obstacle(size_t index, const glm::vec3& centre) {
  if (index >= obstacles_.size()) {
    return Status::error(text_format("no obstacle %zu to move (there are %zu)", index,
                                     obstacles_.size()));
  }
  if (!within_world(centre)) {
    return Status::error(text_format("obstacle %zu: the new centre ", index) + world_limit_problem(centre));
  }
  stats_ = {};
  move_incremental(index, place(index, centre));
  return Status::success();
}

Status StreamFunction::add_obstacle(Obstacle obstacle, double time) {
  if (obstacles_.size() >= kMaxObstacles) {
    return Status::error(text_format("%zu obstacles already, the limit", obstacles_.size()));
  }
  if (!std::isfinite(time)) return Status::error(text_format("flow time %g is not finite", time));
  SIVIFLOW_TRY(validate_obstacle(obstacle, obstacles_.size()));
  build_grids();
  stats_ = {};
  const glm::vec3 centre = obstacle_centre_at(obstacle, time);
  obstacles_.push_back(std::move(obstacle));
  state_.push_back(ObstacleState{});  // not in the water yet: nothing to undo
  const size_t index = obstacles_.size() - 1;
  move_incremental(index, place(index, centre));
  return Status::success();
}

Status StreamFunction::replace_obstacle(size_t index, Obstacle obstacle, double time) {
  if (index >= obstacles_.size()) {
    return Status::error(text_format("no obstacle %zu to replace (there are %zu)", index,
                                     obstacles_.size()));
  }
  if (!std::isfinite(time)) return Status::error(text_format("flow time %g is not finite", time));
  SIVIFLOW_TRY(validate_obstacle(obstacle, index));
  stats_ = {};
  // Out of the water with the old footprint, then in with the new: each step reaches exactly the
  // vertices its own footprint influences.
  move_incremental(index, ObstacleState{});
  const glm::vec3 centre = obstacle_centre_at(obstacle, time);
  obstacles_[index] = std::move(obstacle);
  move_incremental(index, place(index, centre));
  return Status::success();
}

Status StreamFunction::remove_obstacle(size_t index) {
  if (index >= obstacles_.size()) {
    return Status::error(text_format("no obstacle %zu to remove (there are %zu)", index,
                                     obstacles_.size()));
  }
  stats_ = {};
  move_incremental(index, ObstacleState{});
  obstacles_.erase(obstacles_.begin() + static_cast<std::ptrdiff_t>(index));
  state_.erase(state_.begin() + static_cast<std::ptrdiff_t>(index));
  refresh_active();  // later indices moved down; their order, and so every sum, is unchanged
  return Status::success();
}

Status StreamFunction::set_time(double t) {
  if (!std::isfinite(t)) return Status::error(text_format("flow time %g is not finite", t));
  stats_ = {};
  for (size_t j = 0; j < obstacles_.size(); ++j) {
    if (obstacles_[j].keys.empty()) continue;
    const glm::vec3 c = obstacle_centre_at(obstacles_[j], t);
    if (c != state_[j].centre) move_incremental(j, place(j, c));
  }
  return Status::success();
}

void StreamFunction::move_incremental(size_t j, const ObstacleState& new_state) {
  const double s = params_.search_radius;
  // `count` fresh generation stamps, the first returned (where they would wrap around, the stamps
  // are cleared first).
  auto fresh_stamps = [&](size_t count) {
    if (stamp_ > std::numeric_limits<uint32_t>::max() - count) {
      std::fill(node_stamp_.begin(), node_stamp_.end(), 0u);
      std::fill(triangle_stamp_.begin(), triangle_stamp_.end(), 0u);
      stamp_ = 0;
    }
    const uint32_t first = stamp_ + 1;
    stamp_ += static_cast<uint32_t>(count);
    return first;
  };
  auto next_stamp = [&] { return fresh_stamps(1); };

  // 1. The vertices within s of the old or of the new footprint, in one sweep of the grid over
  // both boxes (a drifting object's old and new reach mostly overlap).
  uint32_t gen = next_stamp();
  scratch_nodes_.clear();
  const ObstacleState old_state = state_[j];
  const bool old_wet = old_state.in_water, new_wet = new_state.in_water;
  if (old_wet || new_wet) {
    glm::dvec2 lo(std::numeric_limits<double>::max()), hi(-std::numeric_limits<double>::max());
    for (const ObstacleState* st : {&old_state, &new_state}) {
      if (!st->in_water) continue;
      lo = glm::min(lo, st->lo - s);
      hi = glm::max(hi, st->hi + s);
    }
    node_grid_.for_each_in(lo, hi, [&](uint32_t n) {
      if (node_stamp_[n] == gen) return;
      if ((old_wet && influences(old_state, j, n)) || (new_wet && influences(new_state, j, n))) {
        node_stamp_[n] = gen;
        scratch_nodes_.push_back(n);
      }
    });
  }
  state_[j] = new_state;
  if (new_wet != old_wet) refresh_active();

  // 2. The triangles around them, 3. the nodes around those, whose velocities are re-derived.
  scratch_triangles_.clear();
  for (const uint32_t n : scratch_nodes_) {
    for (const uint32_t t : surface_.node_triangles(n)) {
      if (triangle_stamp_[t] != gen) {
        triangle_stamp_[t] = gen;
        scratch_triangles_.push_back(t);
      }
    }
  }
  const size_t resolved = scratch_nodes_.size();
  gen = next_stamp();
  scratch_nodes_.clear();
  const auto tri = surface_.triangles();
  const auto pos = surface_.node_positions();
  // One box about the old place and one about the new, so an obstacle moved far away leaves the
  // river between them alone; each node goes to the nearer footprint's.
  XzBox near_old, near_new;
  for (const uint32_t t : scratch_triangles_) {
    for (int i = 0; i < 3; ++i) {
      const uint32_t n = tri[3 * size_t{t} + i];
      if (node_stamp_[n] != gen) {
        node_stamp_[n] = gen;
        scratch_nodes_.push_back(n);
        const bool old_side =
            old_wet && (!new_wet || box_distance2(old_state.lo, old_state.hi, pos[n]) <=
                                        box_distance2(new_state.lo, new_state.hi, pos[n]));
        (old_side ? near_old : near_new).grow(pos[n]);
      }
    }
  }
  // 4. psi (and wet) at the corners of their triangles: the re-solved nodes' anew, the others' as
  // their last solve left them, since no obstacle reaching them changed. A corner's stamp is its
  // own, base + its place among the values: it marks the corner and finds its psi.
  // As many stamps as there are corners to visit, not one a node: a river's stamps are cleared
  // once the generations run out, and a move that reaches nothing uses none.
  size_t corners = 0;
  for (const uint32_t n : scratch_nodes_) corners += 3 * surface_.node_triangles(n).size();
  const uint32_t base = fresh_stamps(corners);
  psi_values_.clear();
  for (const uint32_t n : scratch_nodes_) {
    for (const uint32_t t : surface_.node_triangles(n)) {
      for (int i = 0; i < 3; ++i) {
        const uint32_t corner = tri[3 * size_t{t} + i];
        if (node_stamp_[corner] >= base) continue;
        node_stamp_[corner] = base + static_cast<uint32_t>(psi_values_.size());
        bool wet = true;
        psi_values_.push_back(evaluate(corner, true, &wet));
        wet_[corner] = wet;
      }
    }
  }
  const auto psi_of = [&](uint32_t n) { return psi_values_[node_stamp_[n] - base]; };
  for (const uint32_t n : scratch_nodes_) update_node_velocity(n, psi_of);
  for (const XzBox& box : {near_old, near_new}) {
    if (!box.empty()) stats_.velocity_changed.push_back(box);
  }
  stats_.nodes_resolved += resolved;
  stats_.triangles_updated += scratch_triangles_.size();
  stats_.nodes_velocity += scratch_nodes_.size();
}

}  // namespace siviflow
