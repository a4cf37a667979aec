// The ray-cast hierarchy's oracle: its own triangle test, the same float operations in the same
// order, over every triangle of a mesh.
#pragma once

#include <cmath>
#include <cstdint>
#include <glm/geometric.hpp>
#include <glm/vec3.hpp>
#include <span>

#include "sim/triangle_bvh.h"

namespace siviflow::test {

// The nearest hit in [0, t_max], ties to the lower triangle (the first found).
inline bool brute_force_hit(std::span<const glm::vec3> positions, std::span<const uint32_t> indices,
                            const glm::vec3& origin, const glm::vec3& direction, float t_max,
                            RayHit* hit) {
  bool found = false;
  for (uint32_t tri = 0; tri < indices.size() / 3; ++tri) {
    const glm::vec3& v0 = positions[indices[3 * tri]];
    const glm::vec3 e1 = positions[indices[3 * tri + 1]] - v0;
    const glm::vec3 e2 = positions[indices[3 * tri + 2]] - v0;
    const glm::vec3 p = glm::cross(direction, e2);
    const float det = glm::dot(e1, p);
    if (det == 0.0f || !std::isfinite(det) || !std::isfinite(1.0f / det)) continue;
    const float inv_det = 1.0f / det;
    const glm::vec3 s = origin - v0;
    const float u = glm::dot(s, p) * inv_det;
    if (u < 0.0f || u > 1.0f) continue;
    const glm::vec3 q = glm::cross(s, e1);
    const float v = glm::dot(direction, q) * inv_det;
    if (v < 0.0f || u + v > 1.0f) continue;
    const float t = glm::dot(e2, q) * inv_det;
    if (t < 0.0f || t > t_max || (found && t >= hit->t)) continue;
    found = true;
    hit->t = t;
    hit->triangle = tri;
  }
  return found;
}

}  // namespace siviflow::test
