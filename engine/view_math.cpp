#include "view_math.h"

#include <cmath>

#include <glm/matrix.hpp>

namespace siviflow {
namespace {

bool finite(const glm::mat4& m) {
  for (int c = 0; c < 4; ++c) {
    for (int r = 0; r < 4; ++r) {
      if (!std::isfinite(m[c][r])) return false;
    }
  }
  return true;
}

Status view_error(const std::string& message) {
  return Status::error("siviflow::Renderer: " + message);
}

// Window depth of the view-space point at z (clip z / clip w; P[col][row]).
float depth_at(const glm::mat4& p, float z) {
  return (p[2][2] * z + p[3][2]) / (p[2][3] * z + p[3][3]);
}

}  // namespace

Status derive_view_math(const glm::mat4& view, const glm::mat4& projection, ViewMath* out) {
  if (!finite(view)) return view_error("View::view has a non-finite element");
  if (!finite(projection)) return view_error("View::projection has a non-finite element");
  const float view_det = glm::determinant(view);
  if (!std::isfinite(view_det) || std::abs(view_det) < 1e-12f) {
    return view_error("View::view is singular (determinant " + std::to_string(view_det) + ")");
  }
  const glm::mat4& p = projection;
  // Clip w must be +-z and clip z depend on z (and w) alone: then every pixel's depths lie on
  // one curve of z, which the water's distance behind the surface relies on.
  if (p[0][3] != 0.0f || p[1][3] != 0.0f || p[3][3] != 0.0f || p[2][3] == 0.0f ||
      p[0][2] != 0.0f || p[1][2] != 0.0f) {
    return view_error(
        "View::projection is not a perspective projection (its last row must be (0, 0, +-1, 0) "
        "and its depth row (0, 0, a, b))");
  }
  if (p[0][0] == 0.0f || p[1][1] == 0.0f || p[3][2] == 0.0f) {
    return view_error("View::projection is singular");
  }
  // Two points in front of the camera (clip w > 0): depth falling with distance is reverse-Z.
  const float forward = p[2][3] < 0.0f ? -1.0f : 1.0f;
  out->reverse_z = depth_at(p, 2.0f * forward) < depth_at(p, forward);
  out->depth_ratio_constant = p[2][2] / p[2][3];
  out->view_proj = projection * view;
  const glm::mat4 to_world = glm::inverse(view);
  out->camera_position = glm::vec3(to_world[3]);
  out->forward = -glm::vec3(to_world[2]);
  return Status::success();
}

glm::mat4 shifted_by_pixels(const glm::mat4& m, glm::vec2 pixels, glm::vec2 size) {
  const glm::vec2 shift = 2.0f * pixels / size;
  glm::mat4 out = m;
  for (int c = 0; c < 4; ++c) {
    out[c][0] += shift.x * m[c][3];
    out[c][1] += shift.y * m[c][3];
  }
  return out;
}

bool outside_lands_clockwise(const glm::mat4& view, const glm::mat4& projection) {
  // Facing the camera, such a triangle is counter-clockwise in the view's x-y (y up) when the
  // camera looks down its -z (clip w = -z); the projection's x-y part, a looking direction of +z
  // and a mirrored view each turn it over. Clockwise is Vulkan's negative area.
  const double screen = double(projection[0][0]) * projection[1][1] -
                        double(projection[1][0]) * projection[0][1];
  const double turns = screen * -double(projection[2][3]) * glm::determinant(glm::dmat3(view));
  return turns > 0.0;
}

glm::mat4 mirrored_view_proj(const glm::mat4& view_proj, float height) {
  glm::mat4 mirror(1.0f);
  mirror[1][1] = -1.0f;
  mirror[3][1] = 2.0f * height;
  return view_proj * mirror;
}

glm::vec3 mirrored_point(const glm::vec3& point, float height) {
  return {point.x, 2.0f * height - point.y, point.z};
}

}  // namespace siviflow
