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

glm::vec4 box_screen_bounds(const glm::vec3& lo, const glm::vec3& hi, const glm::mat4& view_proj) {
  // The part of the box in front of the eye: its corners there, and where its edges cross a plane
  // a millimetre before the eye (clip coordinates are linear along an edge). Near the eye they
  // land far off screen, on the side they are seen: clamped, the bounds stay whole.
  constexpr float kNear = 1e-3f;
  glm::vec4 clip[8];
  for (int corner = 0; corner < 8; ++corner) {
    const glm::vec3 p((corner & 1) != 0 ? hi.x : lo.x, (corner & 2) != 0 ? hi.y : lo.y,
                      (corner & 4) != 0 ? hi.z : lo.z);
    clip[corner] = view_proj * glm::vec4(p, 1.0f);
  }
  glm::vec2 low(1.0f), high(0.0f);
  const auto add = [&](const glm::vec4& c) {
    const glm::vec2 uv = 0.5f * glm::vec2(c) / c.w + 0.5f;
    low = glm::min(low, uv);
    high = glm::max(high, uv);
  };
  for (int a = 0; a < 8; ++a) {
    if (clip[a].w >= kNear) add(clip[a]);
    for (const int axis : {1, 2, 4}) {
      const int b = a | axis;
      if (b == a) continue;  // each edge once, from its lower corner
      const float wa = clip[a].w - kNear, wb = clip[b].w - kNear;
      if ((wa < 0.0f) != (wb < 0.0f)) add(clip[a] + (wa / (wa - wb)) * (clip[b] - clip[a]));
    }
  }
  return {glm::clamp(low, 0.0f, 1.0f), glm::clamp(high, 0.0f, 1.0f)};
}

glm::mat4 narrowed_view(const glm::mat4& view_proj, const glm::vec4& area) {
  // In clip space the part spans x from (2 x0 - 1) w to (2 x1 - 1) w: recentred and rescaled.
  const glm::vec2 centre = glm::vec2(area.x + area.z, area.y + area.w) - 1.0f;
  const glm::vec2 half(area.z - area.x, area.w - area.y);
  glm::mat4 narrow(1.0f);
  narrow[0][0] = 1.0f / half.x;
  narrow[1][1] = 1.0f / half.y;
  narrow[3][0] = -centre.x / half.x;
  narrow[3][1] = -centre.y / half.y;
  return narrow * view_proj;
}

}  // namespace siviflow
