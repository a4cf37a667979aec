// The renderer's world -> clip transform of a camera, for tests that place world points on screen.
#pragma once

#include <cstdint>

#include <glm/gtc/matrix_transform.hpp>
#include <glm/mat4x4.hpp>

#include "siviflow/renderer.h"

namespace siviflow::testing {

// World -> Vulkan clip space of `camera` on a width x height output, as the renderer makes it.
inline glm::mat4 view_proj_of(const Camera& camera, uint32_t width, uint32_t height) {
  glm::mat4 projection =
      glm::perspectiveRH_ZO(glm::radians(camera.fov_y_deg), float(width) / float(height),
                            camera.near_plane, camera.far_plane);
  projection[1][1] *= -1.0f;  // +Y down
  return projection * glm::lookAtRH(camera.position, camera.target, glm::vec3(0.0f, 1.0f, 0.0f));
}

}  // namespace siviflow::testing
