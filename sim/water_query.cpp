#include "sim/water_query.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

#include <glm/geometric.hpp>

#include "siviflow/sim/obstacle.h"

namespace siviflow {
namespace {

// A point this close outside a triangle (in barycentric weight) still lies on it: the shared edge
// of two triangles must belong to one of them whatever the rounding.
constexpr double kEdgeTolerance = 1e-9;
// Cells are this many times the median triangle's XZ extent: one or two cells a triangle, a
// handful of triangles a cell.
constexpr double kCellsPerTriangle = 2.0;

}  // namespace

uint32_t WaterQuery::vertex(uint32_t triangle, int corner) const {
  const size_t i = size_t{triangle} * 3 + static_cast<size_t>(corner);
  return field_.indices.empty() ? static_cast<uint32_t>(i) : field_.indices[i];
}

int64_t WaterQuery::cell_key(double x, double z) const {
  // Cells far beyond any river's reach are clamped: 2^31 cells either way.
  const auto cell = [&](double v) {
    const double c = std::floor(v / cell_size_);
    return static_cast<int64_t>(std::clamp(c, -2147483648.0, 2147483647.0));
  };
  return cell(x) * (int64_t{1} << 32) + cell(z);
}

Status WaterQuery::build(const RiverFlowField& field, WaterQuery* out) {
  const size_t corners = field.indices.empty() ? field.positions.size() : field.indices.size();
  if (corners == 0 || corners % 3 != 0) {
    return Status::error("WaterQuery: the river has no whole triangles");
  }
  WaterQuery q;
  q.field_ = field;
  const auto triangle_count = static_cast<uint32_t>(corners / 3);
  std::vector<double> extents(triangle_count);
  for (uint32_t t = 0; t < triangle_count; ++t) {
    const glm::vec3 a = field.positions[q.vertex(t, 0)], b = field.positions[q.vertex(t, 1)];
    const glm::vec3 c = field.positions[q.vertex(t, 2)];
    extents[t] = std::max(std::max({a.x, b.x, c.x}) - std::min({a.x, b.x, c.x}),
                          std::max({a.z, b.z, c.z}) - std::min({a.z, b.z, c.z}));
  }
  std::nth_element(extents.begin(), extents.begin() + triangle_count / 2, extents.end());
  q.cell_size_ = std::max(kCellsPerTriangle * extents[triangle_count / 2], 1e-3);

  // (cell, triangle) for every cell a triangle's XZ bounds overlap, sorted: cells in key order,
  // each one's triangles ascending.
  std::vector<std::pair<int64_t, uint32_t>> entries;
  entries.reserve(size_t{triangle_count} * 2);
  for (uint32_t t = 0; t < triangle_count; ++t) {
    glm::dvec2 lo(std::numeric_limits<double>::max()), hi(std::numeric_limits<double>::lowest());
    for (int k = 0; k < 3; ++k) {
      const glm::vec3 p = field.positions[q.vertex(t, k)];
      lo = glm::min(lo, glm::dvec2(p.x, p.z));
      hi = glm::max(hi, glm::dvec2(p.x, p.z));
    }
    const auto x0 = static_cast<int64_t>(std::floor(lo.x / q.cell_size_));
    const auto x1 = static_cast<int64_t>(std::floor(hi.x / q.cell_size_));
    const auto z0 = static_cast<int64_t>(std::floor(lo.y / q.cell_size_));
    const auto z1 = static_cast<int64_t>(std::floor(hi.y / q.cell_size_));
    for (int64_t x = x0; x <= x1; ++x) {
      for (int64_t z = z0; z <= z1; ++z) {
        entries.emplace_back(q.cell_key((double(x) + 0.5) * q.cell_size_, (double(z) + 0.5) * q.cell_size_), t);
      }
    }
  }
  std::sort(entries.begin(), entries.end());
  q.triangles_.reserve(entries.size());
  for (const auto& [key, triangle] : entries) {
    if (q.keys_.empty() || q.keys_.back() != key) {
      q.keys_.push_back(key);
      q.starts_.push_back(static_cast<uint32_t>(q.triangles_.size()));
    }
    q.triangles_.push_back(triangle);
  }
  q.starts_.push_back(static_cast<uint32_t>(q.triangles_.size()));
  *out = std::move(q);
  return Status::success();
}

uint32_t WaterQuery::locate(double x, double z, glm::dvec3* weights) const {
  const int64_t key = cell_key(x, z);
  const auto it = std::lower_bound(keys_.begin(), keys_.end(), key);
  if (it == keys_.end() || *it != key) return UINT32_MAX;
  const size_t cell = static_cast<size_t>(it - keys_.begin());
  for (uint32_t i = starts_[cell]; i < starts_[cell + 1]; ++i) {
    const uint32_t t = triangles_[i];
    // Barycentric weights in the XZ plane, relative to the first corner (doubles: far from the
    // origin a float difference would lose the centimetres).
    const glm::vec3 a = field_.positions[vertex(t, 0)], b = field_.positions[vertex(t, 1)];
    const glm::vec3 c = field_.positions[vertex(t, 2)];
    const double e0x = double(b.x) - a.x, e0z = double(b.z) - a.z;
    const double e1x = double(c.x) - a.x, e1z = double(c.z) - a.z;
    const double px = x - a.x, pz = z - a.z;
    const double det = e0x * e1z - e1x * e0z;
    if (det == 0.0) continue;
    const double v = (px * e1z - e1x * pz) / det;
    const double w = (e0x * pz - px * e0z) / det;
    const double u = 1.0 - v - w;
    if (u >= -kEdgeTolerance && v >= -kEdgeTolerance && w >= -kEdgeTolerance) {
      *weights = glm::clamp(glm::dvec3(u, v, w), 0.0, 1.0);
      return t;
    }
  }
  return UINT32_MAX;
}

WaterSample WaterQuery::sample(const glm::vec3& point,
                               std::span<const DryFootprint> footprints) const {
  WaterSample s;
  const glm::dvec2 xz(point.x, point.z);
  for (size_t i = 0; i < footprints.size(); ++i) {
    if (footprint_distance(*footprints[i].obstacle, footprints[i].centre_xz, xz) < 0.0) {
      s.obstacle = static_cast<uint32_t>(i + 1);
      break;
    }
  }
  glm::dvec3 w;
  const uint32_t t = locate(point.x, point.z, &w);
  if (t == UINT32_MAX) return s;
  const uint32_t i0 = vertex(t, 0), i1 = vertex(t, 1), i2 = vertex(t, 2);
  const glm::vec3 weights(w);
  const auto blend = [&](auto values) {
    return values[i0] * weights.x + values[i1] * weights.y + values[i2] * weights.z;
  };
  const glm::vec3 a = field_.positions[i0], b = field_.positions[i1], c = field_.positions[i2];
  s.on_surface = true;
  s.wet = s.obstacle == 0;
  s.surface = glm::vec3(point.x, float(double(a.y) * w.x + double(b.y) * w.y + double(c.y) * w.z),
                        point.z);
  glm::vec3 n = glm::normalize(glm::cross(b - a, c - a));
  s.normal = n.y < 0.0f ? -n : n;
  if (s.wet) s.velocity = blend(field_.flow);
  if (!field_.depth.empty()) s.depth = blend(field_.depth);
  if (!field_.foam.empty()) s.foam = blend(field_.foam);
  return s;
}

size_t WaterQuery::memory_bytes() const {
  return keys_.capacity() * sizeof(int64_t) + starts_.capacity() * sizeof(uint32_t) +
         triangles_.capacity() * sizeof(uint32_t);
}

}  // namespace siviflow
