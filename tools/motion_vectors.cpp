#include "motion_vectors.h"

#include <cmath>

#include <glm/geometric.hpp>
#include <glm/mat4x4.hpp>
#include <glm/matrix.hpp>
#include <glm/vec2.hpp>
#include <glm/vec4.hpp>

namespace siviflow {
namespace {

// Bumps stand out of a boulder's ellipsoid (a log's bark out of its cylinder) by less than this
// share of its radii.
constexpr double kBodyReach = 1.15;

// Motion is rounded to 1/1024 px: finer than depth resolves it beyond a few metres, and with the
// noise of the low mantissa bits gone deflate packs the layer 5x at a third of the time.
constexpr double kSteps = 1024.0;
float rounded(double pixels) { return static_cast<float>(std::round(pixels * kSteps) / kSteps); }

// Pixel position (x right, y down, pixel centres at +0.5) of a homogeneous world point, or false
// where it lies behind the camera.
bool to_pixel(const glm::dmat4& view_proj, const glm::dvec4& point, glm::dvec2 size,
              glm::dvec2* pixel) {
  const glm::dvec4 clip = view_proj * point;
  if (clip.w <= 0.0) return false;
  *pixel = (glm::dvec2(clip.x, clip.y) / clip.w + 1.0) * 0.5 * size;
  return true;
}

bool within_reach(const MovingBody& body, const glm::dvec3& point) {
  const glm::dvec3 local = (point - glm::dvec3(body.centre)) / glm::dvec3(body.radii);
  if (!body.upright_cylinder) return glm::dot(local, local) <= kBodyReach * kBodyReach;
  return local.x * local.x + local.z * local.z <= kBodyReach * kBodyReach &&
         std::abs(local.y) <= kBodyReach;
}

// The body (if any) whose surface the world point lies on: its displacement to the previous and
// next frames, zero for the static world.
void displacement(std::span<const MovingBody> bodies, const glm::dvec3& point,
                  glm::dvec3* to_previous, glm::dvec3* to_next) {
  *to_previous = glm::dvec3(0.0);
  *to_next = glm::dvec3(0.0);
  for (const MovingBody& body : bodies) {
    if (!within_reach(body, point)) continue;
    *to_previous = glm::dvec3(body.previous_centre - body.centre);
    *to_next = glm::dvec3(body.next_centre - body.centre);
    return;
  }
}

glm::dmat4 view_projection(const View& view) {
  return glm::dmat4(view.projection) * glm::dmat4(view.view);
}

}  // namespace

void compute_motion(const MotionFrame& frame, std::vector<float>* xyzw) {
  const glm::dvec2 size(frame.width, frame.height);
  const glm::dmat4 previous = view_projection(frame.previous);
  const glm::dmat4 current = view_projection(frame.current);
  const glm::dmat4 next = view_projection(frame.next);
  const glm::dmat4 unproject = glm::inverse(current);
  xyzw->assign(size_t{frame.width} * frame.height * 4, 0.0f);
  for (uint32_t y = 0; y < frame.height; ++y) {
    for (uint32_t x = 0; x < frame.width; ++x) {
      const size_t pixel = size_t{y} * frame.width + x;
      const glm::dvec2 ndc = glm::dvec2(x + 0.5, y + 0.5) / size * 2.0 - 1.0;
      const double depth = frame.window_depth[pixel];
      glm::dvec4 point_now;
      glm::dvec4 point_previous;
      glm::dvec4 point_next;
      if (depth >= 1.0) {  // sky: a direction, which translation does not move
        const glm::dvec4 far_point = unproject * glm::dvec4(ndc, 1.0, 1.0);
        const glm::dvec4 near_point = unproject * glm::dvec4(ndc, 0.0, 1.0);
        const glm::dvec3 direction =
            glm::dvec3(far_point) / far_point.w - glm::dvec3(near_point) / near_point.w;
        point_now = point_previous = point_next = glm::dvec4(direction, 0.0);
      } else {
        const glm::dvec4 h = unproject * glm::dvec4(ndc, depth, 1.0);
        const glm::dvec3 point = glm::dvec3(h) / h.w;
        glm::dvec3 to_previous;
        glm::dvec3 to_next;
        if (frame.water_mask[pixel] > 0.5f) {
          to_previous = to_next = glm::dvec3(0.0);
        } else {
          displacement(frame.bodies, point, &to_previous, &to_next);
        }
        point_now = glm::dvec4(point, 1.0);
        point_previous = glm::dvec4(point + to_previous, 1.0);
        point_next = glm::dvec4(point + to_next, 1.0);
      }
      // Reprojected rather than the pixel's centre, so that a still camera gives exactly 0.
      glm::dvec2 now;
      glm::dvec2 then;
      glm::dvec2 later;
      if (!to_pixel(current, point_now, size, &now)) continue;
      float* out = xyzw->data() + pixel * 4;
      // Pixel rows run down; Blender's vectors run up.
      if (to_pixel(previous, point_previous, size, &then)) {
        out[0] = rounded(then.x - now.x);
        out[1] = rounded(now.y - then.y);
      }
      if (to_pixel(next, point_next, size, &later)) {
        out[2] = rounded(now.x - later.x);
        out[3] = rounded(later.y - now.y);
      }
    }
  }
}

}  // namespace siviflow
