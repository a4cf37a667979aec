#include "sim/water_query.h"

#include <cstdint>

#include <glm/geometric.hpp>

#include "siviflow/sim/obstacle.h"

namespace siviflow {

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
  const uint32_t t = bvh_ == nullptr ? UINT32_MAX : bvh_->locate_xz(point.x, point.z, &w);
  if (t == UINT32_MAX) return s;
  const uint32_t i0 = bvh_->triangle_vertex(t, 0), i1 = bvh_->triangle_vertex(t, 1);
  const uint32_t i2 = bvh_->triangle_vertex(t, 2);
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

}  // namespace siviflow
