// The maths of a host's view: depth convention and distances along a pixel's ray derived from
// the projection, whatever its form; matrices that are not a finite perspective are refused.
#include <cmath>

#include <glm/gtc/matrix_transform.hpp>
#include <glm/geometric.hpp>
#include <gtest/gtest.h>

#include "view_math.h"

namespace siviflow {
namespace {

const glm::mat4 kView = glm::lookAtRH(glm::vec3(1.0f, 5.0f, -20.0f), glm::vec3(0.0f),
                                      glm::vec3(0.0f, 1.0f, 0.0f));

glm::mat4 standard(float near_plane, float far_plane) {
  glm::mat4 p = glm::perspectiveRH_ZO(glm::radians(50.0f), 16.0f / 9.0f, near_plane, far_plane);
  p[1][1] *= -1.0f;
  return p;
}

glm::mat4 reverse_infinite(float near_plane) {
  glm::mat4 p(0.0f);
  p[0][0] = 1.2f;
  p[1][1] = -2.1f;
  p[2][3] = -1.0f;
  p[3][2] = near_plane;
  return p;
}

// Window depth of a point `distance` in front of the eye along the view axis.
float depth_of(const glm::mat4& projection, float distance) {
  const glm::vec4 clip = projection * glm::vec4(0.0f, 0.0f, -distance, 1.0f);
  return clip.z / clip.w;
}

// The ratio of the distances of two depths of one pixel, as the flow material computes it.
float distance_ratio(const ViewMath& math, float far_depth_value, float near_depth_value) {
  const float k = math.depth_ratio_constant;
  return (near_depth_value - k) / (far_depth_value - k);
}

TEST(ViewMath, StandardProjectionIsNotReverseAndRecoversDistances) {
  ViewMath math;
  ASSERT_TRUE(derive_view_math(kView, standard(0.1f, 1000.0f), &math).ok());
  EXPECT_FALSE(math.reverse_z);
  const glm::mat4 p = standard(0.1f, 1000.0f);
  EXPECT_NEAR(distance_ratio(math, depth_of(p, 30.0f), depth_of(p, 10.0f)), 3.0f, 1e-3f);
  EXPECT_NEAR(glm::distance(math.camera_position, glm::vec3(1.0f, 5.0f, -20.0f)), 0.0f, 1e-4f);
  const glm::vec3 towards_target = glm::normalize(-glm::vec3(1.0f, 5.0f, -20.0f));
  EXPECT_NEAR(glm::distance(math.forward, towards_target), 0.0f, 1e-5f);
}

TEST(ViewMath, ReverseInfiniteProjectionIsReverseAndRecoversDistances) {
  ViewMath math;
  const glm::mat4 p = reverse_infinite(0.1f);
  ASSERT_TRUE(derive_view_math(kView, p, &math).ok());
  EXPECT_TRUE(math.reverse_z);
  EXPECT_FLOAT_EQ(far_depth(true), 0.0f);
  EXPECT_NEAR(distance_ratio(math, depth_of(p, 30.0f), depth_of(p, 10.0f)), 3.0f, 1e-4f);
}

TEST(ViewMath, JitteredAndOffCentreProjectionsKeepTheirConvention) {
  glm::mat4 p = standard(0.5f, 200.0f);
  p[2][0] += 0.003f;  // jitter
  p[2][1] -= 0.2f;    // off-centre
  ViewMath math;
  ASSERT_TRUE(derive_view_math(kView, p, &math).ok());
  EXPECT_FALSE(math.reverse_z);
  EXPECT_NEAR(distance_ratio(math, depth_of(p, 40.0f), depth_of(p, 8.0f)), 5.0f, 1e-3f);
}

TEST(ViewMath, PixelShiftMovesAPointByThosePixelsAndBack) {
  const glm::mat4 p = glm::perspectiveRH_ZO(glm::radians(60.0f), 16.0f / 9.0f, 0.1f, 100.0f);
  const glm::vec2 size(640.0f, 360.0f);
  const glm::vec2 jitter(0.3f, -0.45f);
  const glm::mat4 shifted = shifted_by_pixels(p, jitter, size);
  const glm::vec4 point(1.5f, -0.7f, -12.0f, 1.0f);
  const auto pixel = [&](const glm::mat4& m) {
    const glm::vec4 clip = m * point;
    return (0.5f * glm::vec2(clip) / clip.w + 0.5f) * size;
  };
  const glm::vec2 moved = pixel(shifted) - pixel(p);
  EXPECT_NEAR(moved.x, jitter.x, 1e-3f);
  EXPECT_NEAR(moved.y, jitter.y, 1e-3f);
  const glm::mat4 back = shifted_by_pixels(shifted, -jitter, size);
  for (int c = 0; c < 4; ++c) {
    for (int r = 0; r < 4; ++r) EXPECT_NEAR(back[c][r], p[c][r], 1e-6f);
  }
}

TEST(ViewMath, MirrorReflectsAboutTheWaterPlane) {
  const glm::vec3 mirrored = mirrored_point(glm::vec3(1.0f, 5.0f, 2.0f), 1.5f);
  EXPECT_EQ(mirrored, glm::vec3(1.0f, -2.0f, 2.0f));
  const glm::mat4 vp = standard(0.1f, 100.0f) * kView;
  const glm::vec4 above(3.0f, 4.0f, 0.0f, 1.0f);
  const glm::vec4 below(3.0f, 2.0f * 1.5f - 4.0f, 0.0f, 1.0f);
  const glm::vec4 a = mirrored_view_proj(vp, 1.5f) * above;
  const glm::vec4 b = vp * below;
  for (int i = 0; i < 4; ++i) EXPECT_NEAR(a[i], b[i], 1e-4f);
}

// Vulkan's signed area of a triangle in framebuffer coordinates (x right, y down; the spec's
// a = -1/2 sum(x_i y_i+1 - x_i+1 y_i)): positive is counter-clockwise. In doubles, so a view a
// thousand kilometres out is measured exactly enough.
double framebuffer_area(const glm::dmat4& view_proj, const glm::dvec3 (&corners)[3]) {
  glm::dvec2 ndc[3];
  for (int i = 0; i < 3; ++i) {
    const glm::dvec4 clip = view_proj * glm::dvec4(corners[i], 1.0);
    ndc[i] = glm::dvec2(clip) / clip.w;
  }
  double sum = 0.0;
  for (int i = 0; i < 3; ++i) {
    const glm::dvec2 a = ndc[i], b = ndc[(i + 1) % 3];
    sum += a.x * b.y - b.x * a.y;
  }
  return -0.5 * sum;
}

TEST(ViewMath, OutsideFacesLandAsTheRasterizerSeesThem) {
  glm::mat4 unflipped = standard(0.001f, 1000.0f);
  unflipped[1][1] *= -1.0f;  // +Y up on screen: the image upside down, the winding reversed
  glm::mat4 off_centre = reverse_infinite(0.001f);
  off_centre[2][0] = 0.3f;  // an asymmetric frustum, or a TAA jitter
  off_centre[2][1] = -0.2f;
  const glm::mat4 projections[] = {standard(0.1f, 1000.0f), reverse_infinite(0.1f), unflipped,
                                   off_centre};
  glm::mat4 mirror(1.0f);  // about the water plane y = 2, as the reflection's view
  mirror[1][1] = -1.0f;
  mirror[3][1] = 4.0f;
  int checked = 0;
  for (const glm::vec3 eye : {glm::vec3(1.0f, 5.0f, -20.0f), glm::vec3(9.0e5f, 12.0f, -9.0e5f)}) {
    const glm::mat4 looking =
        glm::lookAtRH(eye, eye + glm::vec3(3.0f, -1.0f, 4.0f), glm::vec3(0.0f, 1.0f, 0.0f));
    for (const glm::mat4& view : {looking, looking * mirror}) {
      const glm::dmat4 inverse_view = glm::inverse(glm::dmat4(view));
      const glm::dvec3 camera(inverse_view[3]);
      for (const glm::mat4& projection : projections) {
        const bool clockwise = outside_lands_clockwise(view, projection);
        // Triangles ten metres in front of the eye, both windings: one is seen from outside.
        for (const double turn : {1.0, -1.0}) {
          const glm::dvec3 corners[3] = {
              glm::dvec3(inverse_view * glm::dvec4(0.0, 0.0, -10.0, 1.0)),
              glm::dvec3(inverse_view * glm::dvec4(1.0, 0.0, -10.0, 1.0)),
              glm::dvec3(inverse_view * glm::dvec4(0.0, turn, -10.0, 1.0))};
          const glm::dvec3 normal = glm::cross(corners[1] - corners[0], corners[2] - corners[0]);
          const bool outside = glm::dot(normal, camera - corners[0]) > 0.0;
          const double area = framebuffer_area(glm::dmat4(projection) * glm::dmat4(view), corners);
          EXPECT_EQ(area < 0.0, outside == clockwise) << "eye " << eye.x << " turn " << turn;
          ++checked;
        }
      }
    }
  }
  EXPECT_EQ(checked, 2 * 2 * 4 * 2);
  // The main view and its mirror land the other way round; the depth convention changes nothing.
  EXPECT_NE(outside_lands_clockwise(kView, standard(0.1f, 1000.0f)),
            outside_lands_clockwise(kView * mirror, standard(0.1f, 1000.0f)));
  EXPECT_EQ(outside_lands_clockwise(kView, standard(0.1f, 1000.0f)),
            outside_lands_clockwise(kView, reverse_infinite(0.1f)));
}

TEST(ViewMath, RefusesWhatIsNotAFinitePerspective) {
  ViewMath math;
  Status status = derive_view_math(kView, glm::orthoRH_ZO(-1.0f, 1.0f, -1.0f, 1.0f, 0.1f, 10.0f), &math);
  EXPECT_NE(status.message().find("View::projection is not a perspective"), std::string::npos) << status.message();
  glm::mat4 nan_view = kView;
  nan_view[3][0] = std::nanf("");
  status = derive_view_math(nan_view, standard(0.1f, 10.0f), &math);
  EXPECT_NE(status.message().find("View::view has a non-finite"), std::string::npos) << status.message();
  status = derive_view_math(glm::mat4(0.0f), standard(0.1f, 10.0f), &math);
  EXPECT_NE(status.message().find("View::view is singular"), std::string::npos) << status.message();
  glm::mat4 flat = standard(0.1f, 10.0f);
  flat[0][0] = 0.0f;
  status = derive_view_math(kView, flat, &math);
  EXPECT_NE(status.message().find("View::projection is singular"), std::string::npos) << status.message();
}

}  // namespace
}  // namespace siviflow
