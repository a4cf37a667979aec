#include "motion_vectors.h"

#include <algorithm>
#include <cmath>
#include <cstdint>

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
// noise of the low mantissa bits gone deflate packs the layer several times smaller (5x when it
// was FLOAT). It is held within the half's range, which the layer is written in; no motion is +0.
constexpr double kSteps = 1024.0;
constexpr double kLargestHalf = 65504.0;
float rounded(double pixels) {
  if (std::isnan(pixels)) return 0.0f;  // two infinite positions: no motion to tell
  const double steps = std::clamp(pixels, -kLargestHalf, kLargestHalf) * kSteps;
  // Half away from zero as std::round, inline: its library call took a fifth of a pixel's time.
  // The fraction left after truncating is exact, so ties round as std::round rounds them.
  const int64_t whole = static_cast<int64_t>(steps);
  const double fraction = steps - static_cast<double>(whole);
  const int64_t nearest = whole + (fraction >= 0.5) - (fraction <= -0.5);
  return static_cast<float>(static_cast<double>(nearest) * (1.0 / kSteps));  // exact: 2^-10
}

// Pixel position (x right, y down, pixel centres at +0.5) of a point in clip space, or false where
// it lies behind the camera.
bool to_pixel(const glm::dvec4& clip, glm::dvec2 size, glm::dvec2* pixel) {
  if (clip.w <= 0.0) return false;
  *pixel = (glm::dvec2(clip.x, clip.y) * (1.0 / clip.w) + 1.0) * 0.5 * size;
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
  // From a pixel's window point (ndc, depth, 1) straight to each camera's clip space, for the
  // points that do not move: the unprojection's w is positive in front of the camera, so the
  // product keeps the sign of w that tells a point behind a neighbour's camera.
  const glm::dmat4 now_from_window = current * unproject;
  const glm::dmat4 previous_from_window = previous * unproject;
  const glm::dmat4 next_from_window = next * unproject;
  xyzw->assign(size_t{frame.width} * frame.height * 4, 0.0f);
  // M * (ndc.x, ndc.y, depth, 1) as a row's part, M[1] * ndc.y + M[3], plus the pixel's.
  const auto row_part = [](const glm::dmat4& m, double ndc_y) { return m[1] * ndc_y + m[3]; };
  // Products by reciprocals rather than divisions: a division costs a pixel more than the rest.
  const glm::dvec2 ndc_per_pixel = 2.0 / size;
  for (uint32_t y = 0; y < frame.height; ++y) {
    const double ndc_y = (y + 0.5) * ndc_per_pixel.y - 1.0;
    const glm::dvec4 unproject_row = row_part(unproject, ndc_y);
    const glm::dvec4 now_row = row_part(now_from_window, ndc_y);
    const glm::dvec4 previous_row = row_part(previous_from_window, ndc_y);
    const glm::dvec4 next_row = row_part(next_from_window, ndc_y);
    for (uint32_t x = 0; x < frame.width; ++x) {
      const size_t pixel = size_t{y} * frame.width + x;
      const double ndc_x = (x + 0.5) * ndc_per_pixel.x - 1.0;
      const double depth = frame.window_depth[pixel];
      glm::dvec4 clip_now;
      glm::dvec4 clip_previous;
      glm::dvec4 clip_next;
      if (depth >= 1.0) {  // sky: a direction, which translation does not move
        const glm::dvec4 near_point = unproject_row + unproject[0] * ndc_x;
        const glm::dvec4 far_point = near_point + unproject[2];
        const glm::dvec4 direction(glm::dvec3(far_point) * (1.0 / far_point.w) -
                                       glm::dvec3(near_point) * (1.0 / near_point.w),
                                   0.0);
        clip_now = current * direction;
        clip_previous = previous * direction;
        clip_next = next * direction;
      } else if (frame.bodies.empty() || frame.water_mask[pixel] > 0.5f) {
        clip_now = now_row + now_from_window[0] * ndc_x + now_from_window[2] * depth;
        clip_previous =
            previous_row + previous_from_window[0] * ndc_x + previous_from_window[2] * depth;
        clip_next = next_row + next_from_window[0] * ndc_x + next_from_window[2] * depth;
      } else {
        const glm::dvec4 h = unproject_row + unproject[0] * ndc_x + unproject[2] * depth;
        const glm::dvec3 point = glm::dvec3(h) / h.w;
        glm::dvec3 to_previous;
        glm::dvec3 to_next;
        displacement(frame.bodies, point, &to_previous, &to_next);
        clip_now = current * glm::dvec4(point, 1.0);
        clip_previous = previous * glm::dvec4(point + to_previous, 1.0);
        clip_next = next * glm::dvec4(point + to_next, 1.0);
      }
      // Reprojected rather than the pixel's centre, so that a still camera gives exactly 0.
      glm::dvec2 now;
      glm::dvec2 then;
      glm::dvec2 later;
      if (!to_pixel(clip_now, size, &now)) continue;
      float* out = xyzw->data() + pixel * 4;
      // Pixel rows run down; Blender's vectors run up.
      if (to_pixel(clip_previous, size, &then)) {
        out[0] = rounded(then.x - now.x);
        out[1] = rounded(now.y - then.y);
      }
      if (to_pixel(clip_next, size, &later)) {
        out[2] = rounded(now.x - later.x);
        out[3] = rounded(later.y - now.y);
      }
    }
  }
}

}  // namespace siviflow
