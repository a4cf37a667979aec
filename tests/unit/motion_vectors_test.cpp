// The capture's motion layer on the CPU (tools/motion_vectors.h), against motion worked out here
// from the cameras alone: a ground plane seen from cameras that move, turn, pass their points or
// stand still, and a body that moves over it.
#include "motion_vectors.h"

#include <cmath>
#include <vector>

#include <glm/gtc/matrix_transform.hpp>
#include <glm/mat4x4.hpp>
#include <glm/vec4.hpp>
#include <gtest/gtest.h>

namespace siviflow {
namespace {

constexpr uint32_t kWidth = 64;
constexpr uint32_t kHeight = 36;
constexpr VkExtent2D kExtent{kWidth, kHeight};

Camera camera_at(glm::vec3 position, glm::vec3 target) {
  Camera camera;
  camera.position = position;
  camera.target = target;
  return camera;
}

glm::dmat4 view_projection(const Camera& camera) {
  const View view = camera_view(camera, kExtent);
  return glm::dmat4(view.projection) * glm::dmat4(view.view);
}

// Where a world point (w 1) or direction (w 0) lands in a camera's image (pixels, y down), or
// false behind it.
bool pixel_of(const Camera& camera, glm::dvec3 point, glm::dvec2* pixel, double w = 1.0) {
  const glm::dvec4 clip = view_projection(camera) * glm::dvec4(point, w);
  if (clip.w <= 0.0) return false;
  *pixel = (glm::dvec2(clip) / clip.w + 1.0) * 0.5 * glm::dvec2(kWidth, kHeight);
  return true;
}

// The ground plane y = 0 as `camera` sees it: each pixel's window depth (1 where the sky is) and
// the world point it shows, or the direction it looks in at the sky.
struct Ground {
  std::vector<float> depth;
  std::vector<glm::dvec3> point;
  std::vector<glm::dvec3> direction;
  std::vector<float> water;
};

Ground ground_seen_by(const Camera& camera) {
  Ground g;
  g.depth.assign(kWidth * kHeight, 1.0f);
  g.point.assign(kWidth * kHeight, glm::dvec3(0.0));
  g.direction.assign(kWidth * kHeight, glm::dvec3(0.0));
  g.water.assign(kWidth * kHeight, 0.0f);
  const glm::dmat4 to_world = glm::inverse(view_projection(camera));
  for (uint32_t y = 0; y < kHeight; ++y) {
    for (uint32_t x = 0; x < kWidth; ++x) {
      const glm::dvec2 ndc = glm::dvec2(x + 0.5, y + 0.5) / glm::dvec2(kWidth, kHeight) * 2.0 - 1.0;
      const glm::dvec4 near = to_world * glm::dvec4(ndc, 0.0, 1.0);
      const glm::dvec4 far = to_world * glm::dvec4(ndc, 1.0, 1.0);
      const glm::dvec3 a = glm::dvec3(near) / near.w;
      const glm::dvec3 b = glm::dvec3(far) / far.w;
      const size_t i = size_t{y} * kWidth + x;
      g.direction[i] = b - a;
      if (b.y >= a.y) continue;  // the ray never comes down to the ground
      const glm::dvec3 hit = a + (b - a) * (a.y / (a.y - b.y));
      const glm::dvec4 clip = view_projection(camera) * glm::dvec4(hit, 1.0);
      g.depth[i] = static_cast<float>(clip.z / clip.w);
      g.point[i] = hit;
    }
  }
  return g;
}

std::vector<float> motion_of(const Ground& g, const Camera& previous, const Camera& current,
                             const Camera& next, std::span<const MovingBody> bodies = {}) {
  MotionFrame frame;
  frame.width = kWidth;
  frame.height = kHeight;
  frame.window_depth = g.depth.data();
  frame.water_mask = g.water.data();
  frame.previous = camera_view(previous, kExtent);
  frame.current = camera_view(current, kExtent);
  frame.next = camera_view(next, kExtent);
  frame.bodies = bodies;
  std::vector<float> xyzw;
  compute_motion(frame, &xyzw);
  return xyzw;
}

// The depth buffer holds 24 bits of window depth: the point a pixel shows is only that exact.
constexpr double kTolerancePx = 0.02;

TEST(MotionVectors, AStillCameraGivesPositiveZeroEverywhere) {
  const Camera camera = camera_at({0.0f, 3.0f, -10.0f}, {0.0f, 0.0f, 0.0f});
  const std::vector<float> xyzw = motion_of(ground_seen_by(camera), camera, camera, camera);
  ASSERT_EQ(xyzw.size(), size_t{kWidth} * kHeight * 4);
  for (size_t i = 0; i < xyzw.size(); ++i) {
    ASSERT_EQ(xyzw[i], 0.0f) << i;
    ASSERT_FALSE(std::signbit(xyzw[i])) << i;
  }
}

TEST(MotionVectors, TheGroundMovesAsTheNeighbouringCamerasProjectIt) {
  const Camera previous = camera_at({-0.4f, 3.0f, -10.2f}, {-0.4f, 0.0f, -0.2f});
  const Camera current = camera_at({0.0f, 3.0f, -10.0f}, {0.0f, 0.0f, 0.0f});
  const Camera next = camera_at({0.5f, 3.1f, -9.7f}, {0.3f, 0.0f, 0.4f});  // moves and turns
  const Ground g = ground_seen_by(current);
  const std::vector<float> xyzw = motion_of(g, previous, current, next);
  size_t ground = 0;
  for (size_t i = 0; i < g.depth.size(); ++i) {
    if (g.depth[i] >= 1.0f) continue;
    glm::dvec2 now, then, later;
    ASSERT_TRUE(pixel_of(current, g.point[i], &now));
    ASSERT_TRUE(pixel_of(previous, g.point[i], &then));
    ASSERT_TRUE(pixel_of(next, g.point[i], &later));
    // Blender's layout: X, Y previous minus now; Z, W now minus next; y up.
    EXPECT_NEAR(xyzw[i * 4 + 0], then.x - now.x, kTolerancePx) << i;
    EXPECT_NEAR(xyzw[i * 4 + 1], now.y - then.y, kTolerancePx) << i;
    EXPECT_NEAR(xyzw[i * 4 + 2], now.x - later.x, kTolerancePx) << i;
    EXPECT_NEAR(xyzw[i * 4 + 3], later.y - now.y, kTolerancePx) << i;
    for (int c = 0; c < 4; ++c) {  // in steps of 1/1024 px
      const double steps = xyzw[i * 4 + c] * 1024.0;
      ASSERT_EQ(steps, std::round(steps)) << i;
    }
    ++ground;
  }
  EXPECT_GT(ground, g.depth.size() / 3) << "the ground fills much of the view";
}

TEST(MotionVectors, TheSkyMovesWithTheCamerasTurnAlone) {
  const Camera current = camera_at({0.0f, 3.0f, -10.0f}, {0.0f, 2.0f, 0.0f});
  const Camera moved = camera_at({2.0f, 3.5f, -8.0f}, {2.0f, 2.5f, 2.0f});   // the same heading
  const Camera turned = camera_at({0.0f, 3.0f, -10.0f}, {1.0f, 2.0f, 0.0f});
  const Ground g = ground_seen_by(current);
  const std::vector<float> xyzw = motion_of(g, moved, current, turned);
  size_t sky = 0;
  for (size_t i = 0; i < g.depth.size(); ++i) {
    if (g.depth[i] < 1.0f) continue;
    ++sky;
    EXPECT_EQ(xyzw[i * 4 + 0], 0.0f) << i;  // translation does not move a direction
    EXPECT_EQ(xyzw[i * 4 + 1], 0.0f) << i;
    glm::dvec2 now, later;
    ASSERT_TRUE(pixel_of(current, g.direction[i], &now, 0.0));
    ASSERT_TRUE(pixel_of(turned, g.direction[i], &later, 0.0));
    EXPECT_NEAR(xyzw[i * 4 + 2], now.x - later.x, kTolerancePx) << i;
    EXPECT_NEAR(xyzw[i * 4 + 3], later.y - now.y, kTolerancePx) << i;
    EXPECT_GT(std::abs(xyzw[i * 4 + 2]), 1.0f) << "the turn moves the sky by pixels";
  }
  EXPECT_GT(sky, g.depth.size() / 4);
}

TEST(MotionVectors, APointBehindANeighboursCameraHasNoMotionThere) {
  const Camera current = camera_at({0.0f, 3.0f, -10.0f}, {0.0f, 0.0f, 0.0f});
  // The next camera stands far ahead, looking on: the near ground is behind it.
  const Camera next = camera_at({0.0f, 3.0f, 8.0f}, {0.0f, 0.0f, 18.0f});
  const Ground g = ground_seen_by(current);
  const std::vector<float> xyzw = motion_of(g, current, current, next);
  size_t behind = 0;
  for (size_t i = 0; i < g.depth.size(); ++i) {
    if (g.depth[i] >= 1.0f) continue;
    glm::dvec2 later;
    if (pixel_of(next, g.point[i], &later)) continue;
    ++behind;
    EXPECT_EQ(xyzw[i * 4 + 2], 0.0f) << i;
    EXPECT_EQ(xyzw[i * 4 + 3], 0.0f) << i;
  }
  EXPECT_GT(behind, 100u);
}

TEST(MotionVectors, MotionIsHeldWithinTheLargestHalf) {
  const Camera current = camera_at({0.0f, 3.0f, -10.0f}, {0.0f, 0.0f, 0.0f});
  const Ground g = ground_seen_by(current);
  // A previous camera 10 m above and a millimetre beside the ground point at the image's centre,
  // looking past it: that point lands far below its image.
  const glm::vec3 p = glm::vec3(g.point[size_t{kHeight / 2} * kWidth + kWidth / 2]);
  const Camera previous =
      camera_at(p + glm::vec3(1e-3f, 10.0f, 0.0f), p + glm::vec3(-10.0f, 10.0f, 0.0f));
  const std::vector<float> xyzw = motion_of(g, previous, current, current);
  size_t held = 0;
  for (size_t i = 0; i < g.depth.size(); ++i) {
    ASSERT_TRUE(std::isfinite(xyzw[i * 4 + 0]) && std::isfinite(xyzw[i * 4 + 1])) << i;
    glm::dvec2 now, then;
    if (g.depth[i] >= 1.0f || !pixel_of(previous, g.point[i], &then)) continue;
    ASSERT_TRUE(pixel_of(current, g.point[i], &now));
    const double dy = now.y - then.y;
    if (std::abs(dy) <= 70000.0) continue;  // clearly past 65504, whatever the depth's rounding
    EXPECT_EQ(xyzw[i * 4 + 1], dy > 0.0 ? 65504.0f : -65504.0f) << i;
    ++held;
  }
  EXPECT_GT(held, 0u) << "some point lands beyond what a half holds";
}

TEST(MotionVectors, ABodyCarriesTheGroundInItsReachButNotTheWater) {
  const Camera camera = camera_at({0.0f, 6.0f, -6.0f}, {0.0f, 0.0f, 0.0f});
  Ground g = ground_seen_by(camera);
  MovingBody body;
  body.previous_centre = {-0.5f, 0.0f, 0.0f};
  body.centre = {0.0f, 0.0f, 0.0f};
  body.next_centre = {0.5f, 0.0f, 0.0f};
  body.radii = {1.0f, 1.0f, 1.0f};
  // The water covers the body's reach where x > 0.
  for (size_t i = 0; i < g.depth.size(); ++i) g.water[i] = g.point[i].x > 0.0 ? 1.0f : 0.0f;
  const MovingBody bodies[] = {body};
  const std::vector<float> xyzw = motion_of(g, camera, camera, camera, bodies);
  size_t carried = 0;
  for (size_t i = 0; i < g.depth.size(); ++i) {
    if (g.depth[i] >= 1.0f) continue;
    const double reach = glm::length(g.point[i]);
    if (std::abs(reach - 1.15) < 0.05) continue;  // the edge of its reach, as depth rounds it
    if (reach > 1.15 || g.water[i] > 0.5f) {
      EXPECT_EQ(xyzw[i * 4 + 0], 0.0f) << i;
      EXPECT_EQ(xyzw[i * 4 + 2], 0.0f) << i;
      continue;
    }
    glm::dvec2 now, then, later;
    ASSERT_TRUE(pixel_of(camera, g.point[i], &now));
    ASSERT_TRUE(pixel_of(camera, g.point[i] + glm::dvec3(-0.5, 0.0, 0.0), &then));
    ASSERT_TRUE(pixel_of(camera, g.point[i] + glm::dvec3(0.5, 0.0, 0.0), &later));
    EXPECT_NEAR(xyzw[i * 4 + 0], then.x - now.x, kTolerancePx) << i;
    EXPECT_NEAR(xyzw[i * 4 + 2], now.x - later.x, kTolerancePx) << i;
    EXPECT_GT(std::abs(xyzw[i * 4 + 0]), 0.5f) << "half a metre is pixels here";
    ++carried;
  }
  EXPECT_GT(carried, 10u);
}

}  // namespace
}  // namespace siviflow
