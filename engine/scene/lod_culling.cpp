#include "scene/lod_culling.h"

#include <cmath>

#include <glm/common.hpp>
#include <glm/geometric.hpp>

#include "view_culling.h"

namespace siviflow {

uint32_t choose_level(const LodPiece& piece, const CullView& view) {
  if (piece.levels.empty() ||
      box_outside_view(piece.lo, piece.hi, view.view_proj, view.clip_plane)) {
    return kCulled;
  }
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
