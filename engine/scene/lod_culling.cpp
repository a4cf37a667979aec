#include "scene/lod_culling.h"

#include <algorithm>
#include <cmath>

#include <glm/common.hpp>
#include <glm/geometric.hpp>
#include <glm/matrix.hpp>

namespace siviflow {
namespace {

// Whether the box lies wholly on the negative side of the plane (a, b, c, d).
bool below(const glm::vec3& lo, const glm::vec3& hi, const glm::vec4& plane) {
  // The corner furthest along the plane's normal.
  const glm::vec3 far(plane.x >= 0.0f ? hi.x : lo.x, plane.y >= 0.0f ? hi.y : lo.y,
                      plane.z >= 0.0f ? hi.z : lo.z);
  return glm::dot(glm::vec3(plane), far) + plane.w < 0.0f;
}

}  // namespace

bool culled(const glm::vec3& lo, const glm::vec3& hi, const CullView& view) {
  if (below(lo, hi, view.clip_plane)) return true;
  // Gribb and Hartmann's planes from the rows of the matrix: -w <= x, y <= w and w > 0 (in front
  // of the camera). Depth's planes are left out: they differ between conventions and the far
  // plane may be at infinity.
  const glm::mat4 m = glm::transpose(view.view_proj);
  const glm::vec4 planes[] = {m[3] + m[0], m[3] - m[0], m[3] + m[1], m[3] - m[1], m[3]};
  return std::any_of(std::begin(planes), std::end(planes),
                     [&](const glm::vec4& plane) { return below(lo, hi, plane); });
}

uint32_t choose_level(const LodPiece& piece, const CullView& view) {
  if (piece.levels.empty() || culled(piece.lo, piece.hi, view)) return kCulled;
  // The nearest point of the box sets the smallest error the chunk needs.
  const glm::vec3 nearest = glm::clamp(view.camera, piece.lo, piece.hi);
  const float distance = glm::length(nearest - view.camera);
  uint32_t level = 0;
  while (level + 1 < piece.level_error.size() &&
         piece.level_error[level + 1] * view.focal_pixels <= view.max_error_pixels * distance) {
    ++level;
  }
  return level;
}

float focal_pixels(const glm::mat4& projection, float viewport_height) {
  return std::abs(projection[1][1]) * 0.5f * viewport_height;
}

}  // namespace siviflow
