// Whether a box can show in a view: outside the frustum or wholly below a clip plane, it cannot.
// Shared by the water's chunks and the built-in world's pieces.
#pragma once

#include <glm/mat4x4.hpp>
#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

namespace siviflow {

// `view_proj` maps to Vulkan clip space (standard or reverse depth, a far plane at infinity
// too); kept are points with dot(clip_plane, (p, 1)) >= 0.
bool box_outside_view(const glm::vec3& lo, const glm::vec3& hi, const glm::mat4& view_proj,
                      const glm::vec4& clip_plane = glm::vec4(0.0f, 0.0f, 0.0f, 1.0f));

}  // namespace siviflow
