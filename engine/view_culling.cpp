#include "view_culling.h"

#include <algorithm>
#include <iterator>

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

bool box_outside_view(const glm::vec3& lo, const glm::vec3& hi, const glm::mat4& view_proj,
                      const glm::vec4& clip_plane) {
  if (below(lo, hi, clip_plane)) return true;
  // Gribb and Hartmann's planes from the rows of the matrix: -w <= x, y <= w and 0 <= z <= w
  // (Vulkan's depth range in either convention; an infinite far plane is a plane of no normal
  // that keeps everything).
  const glm::mat4 m = glm::transpose(view_proj);
  const glm::vec4 planes[] = {m[3] + m[0], m[3] - m[0], m[3] + m[1], m[3] - m[1], m[2], m[3] - m[2]};
  return std::any_of(std::begin(planes), std::end(planes),
                     [&](const glm::vec4& plane) { return below(lo, hi, plane); });
}

}  // namespace siviflow
