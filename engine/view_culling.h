// Whether a box can show in a view: outside the frustum or wholly below a clip plane, it cannot;
// and where on the view it can. Shared by the water's chunks and the built-in world's pieces.
#pragma once

#include <glm/mat4x4.hpp>
#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

namespace siviflow {

// `view_proj` maps to Vulkan clip space (standard or reverse depth, a far plane at infinity
// too); kept are points with dot(clip_plane, (p, 1)) >= 0.
bool box_outside_view(const glm::vec3& lo, const glm::vec3& hi, const glm::mat4& view_proj,
                      const glm::vec4& clip_plane = glm::vec4(0.0f, 0.0f, 0.0f, 1.0f));

// The part of the view a box can cover: (x0, y0, x1, y1) in the view's texture coordinates (0 at
// the top-left pixel's corner, 1 at the bottom-right's), within [0, 1]. A box that reaches
// behind the eye is cut there first. x0 > x1 when it lies wholly behind.
glm::vec4 box_screen_bounds(const glm::vec3& lo, const glm::vec3& hi, const glm::mat4& view_proj);

// `view_proj` narrowed to the part `area` (x0, y0, x1, y1 in texture coordinates, x0 < x1 and
// y0 < y1) of its view: that part maps to the whole of clip space, so box_outside_view culls
// what lies outside it.
glm::mat4 narrowed_view(const glm::mat4& view_proj, const glm::vec4& area);

}  // namespace siviflow
