// Point queries of the water (sim/water_query.h through RiverFlow::query) against the analytic
// flows of the flow tests, and floating bodies (siviflow/drift.h) against independent
// integrations of the flow's streamlines and of potential flow around a cylinder.
#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

#include <glm/geometric.hpp>
#include <glm/vec2.hpp>
#include <gtest/gtest.h>

#include "siviflow/drift.h"
#include "unit/river_flow_fixture.h"

namespace siviflow {
namespace {

using test::query;
using test::river_flow;

TEST(WaterQuery, StraightChannelIsUniformEverywhereOnIt) {
  const float width = 10.0f, q = 20.0f;
  const auto flow = river_flow(test::straight_channel(width, 40.0f, 41, 11), {q, 1.0f, 100.0f * width});
  std::mt19937 random(7);
  std::uniform_real_distribution<float> across(-0.499f * width, 0.499f * width), along(0.01f, 39.99f);
  for (int i = 0; i < 2000; ++i) {
    const glm::vec3 p(across(random), 3.0f, along(random));  // above the water: found below
    const WaterSample s = query(*flow, p);
    ASSERT_TRUE(s.on_surface && s.wet) << p.x << ", " << p.z;
    EXPECT_NEAR(s.velocity.z, q / width, 0.01f * q / width);
    EXPECT_NEAR(s.velocity.x, 0.0f, 0.01f * q / width);
    EXPECT_EQ(s.surface, glm::vec3(p.x, 0.0f, p.z));
    EXPECT_NEAR(s.normal.y, 1.0f, 1e-6f);
    EXPECT_FLOAT_EQ(s.depth, 1.0f);
    EXPECT_EQ(s.obstacle, 0u);
  }
  // Beyond the banks and the ends: not on the river.
  for (const glm::vec3 p : {glm::vec3(5.2f, 0, 20), glm::vec3(-5.2f, 0, 20), glm::vec3(0, 0, -0.2f),
                            glm::vec3(0, 0, 40.2f), glm::vec3(300, 0, 3e6f)}) {
    const WaterSample s = query(*flow, p);
    EXPECT_FALSE(s.on_surface) << p.x << ", " << p.z;
    EXPECT_FALSE(s.wet);
    EXPECT_EQ(s.velocity, glm::vec3(0.0f));
  }
}

TEST(WaterQuery, BendFlowsAlongItsArcs) {
  const float r1 = 20.0f, r2 = 30.0f, q = 5.0f;
  const auto flow = river_flow(test::bend(r1, r2, 1.5707963f, 91, 11), {q, 1.0f, 1e4f});
  const float speed = q / (r2 - r1);
  std::mt19937 random(3);
  std::uniform_real_distribution<float> radius(r1 + 0.05f, r2 - 0.05f), angle(0.01f, 1.56f);
  for (int i = 0; i < 2000; ++i) {
    const float r = radius(random), a = angle(random);
    const glm::vec3 p(r * std::cos(a), 0.0f, r * std::sin(a));
    const WaterSample s = query(*flow, p);
    ASSERT_TRUE(s.wet) << r << ", " << a;
    EXPECT_NEAR(glm::length(s.velocity), speed, 0.01f * speed);
    // Along the arc: no part towards or away from the bend's centre.
    EXPECT_NEAR(glm::dot(s.velocity, glm::normalize(p)), 0.0f, 0.01f * speed);
  }
}

TEST(WaterQuery, SurfaceHeightAndNormalFollowASlopedRiver) {
  test::TestMesh m = test::straight_channel(10.0f, 40.0f, 41, 11);
  const float drop = 0.02f;  // metres per metre downstream
  for (glm::vec3& p : m.positions) p.y = -drop * p.z;
  const auto flow = river_flow(m, {20.0f, 1.0f, 1000.0f});
  for (float z = 0.5f; z < 40.0f; z += 3.7f) {
    const WaterSample s = query(*flow, {1.3f, 10.0f, z});
    ASSERT_TRUE(s.wet);
    EXPECT_NEAR(s.surface.y, -drop * z, 1e-5f);
    EXPECT_NEAR(s.normal.z, drop / std::sqrt(1.0f + drop * drop), 1e-5f);  // leaning downstream
    EXPECT_GT(s.velocity.z, 0.0f);
    EXPECT_LT(s.velocity.y, 0.0f);  // the flow follows the surface down
  }
}

TEST(WaterQuery, FootprintsAreDryAndNamed) {
  Obstacle rock;
  rock.centre = {0.0f, 0.0f, 20.0f};
  rock.radius = 1.5f;
  Obstacle slab;
  slab.centre = {3.0f, 0.0f, 8.0f};
  slab.polygon = {{-0.5f, -1.0f}, {0.5f, -1.0f}, {0.5f, 1.0f}, {-0.5f, 1.0f}};
  const auto flow = river_flow(test::straight_channel(10.0f, 40.0f, 41, 11), {20.0f, 1.5f, 0.0f},
                               {rock, slab});
  const WaterSample in_rock = query(*flow, {0.7f, 0.0f, 20.6f});
  EXPECT_TRUE(in_rock.on_surface);
  EXPECT_FALSE(in_rock.wet);
  EXPECT_EQ(in_rock.obstacle, 1u);
  EXPECT_EQ(in_rock.velocity, glm::vec3(0.0f));
  const WaterSample in_slab = query(*flow, {3.2f, 0.0f, 8.9f});
  EXPECT_FALSE(in_slab.wet);
  EXPECT_EQ(in_slab.obstacle, 2u);
  const WaterSample beside = query(*flow, {0.0f, 0.0f, 20.0f + 1.6f});
  EXPECT_TRUE(beside.wet);
  EXPECT_EQ(beside.obstacle, 0u);
  // A moved obstacle counts from the call that moved it.
  ASSERT_TRUE(flow->move_obstacle(0, {-2.0f, 0.0f, 30.0f}).ok());
  EXPECT_TRUE(query(*flow, {0.7f, 0.0f, 20.6f}).wet);
  EXPECT_EQ(query(*flow, {-2.0f, 0.0f, 30.5f}).obstacle, 1u);
}

TEST(WaterQuery, FarFromTheOriginKeepsCentimetres) {
  test::TestMesh m = test::straight_channel(10.0f, 40.0f, 41, 11);
  for (glm::vec3& p : m.positions) p += glm::vec3(1.0e5f, 0.0f, 2.0e5f);
  const auto flow = river_flow(m, {20.0f, 1.0f, 1000.0f});
  EXPECT_TRUE(query(*flow, {1.0e5f + 4.98f, 0.0f, 2.0e5f + 10.0f}).wet);
  EXPECT_FALSE(query(*flow, {1.0e5f + 5.03f, 0.0f, 2.0e5f + 10.0f}).on_surface);
}

TEST(WaterQuery, SameQuerySameAnswer) {
  const auto flow = river_flow(test::symmetric_channel(10.0f, 40.0f, 41, 21), {20.0f, 1.5f, 0.0f});
  // Points on vertices and edges, where two triangles meet: always the same triangle's answer.
  std::vector<glm::vec3> points;
  for (float z = 0.0f; z <= 40.0f; z += 0.5f) {
    for (float x = -5.0f; x <= 5.0f; x += 0.25f) points.push_back({x, 0.0f, z});
  }
  std::vector<WaterSample> a(points.size()), b(points.size());
  flow->query(points, a);
  flow->query(points, b);
  for (size_t i = 0; i < points.size(); ++i) {
    ASSERT_TRUE(a[i].on_surface) << points[i].x << ", " << points[i].z;
    EXPECT_EQ(a[i].velocity, b[i].velocity);
    EXPECT_EQ(a[i].normal, b[i].normal);
  }
}

// --- Floating bodies ----------------------------------------------------------------------------

// Potential flow of speed `u` along +z past a cylinder of radius `a` at `c` (unbounded):
// w(zeta) = u (zeta + a^2 / zeta), zeta = (z - c.z) + i (x - c.x), dw/dzeta = v_z - i v_x.
glm::vec3 cylinder_flow(glm::vec3 p, glm::vec3 c, float a, float u) {
  const double zr = p.z - c.z, zi = p.x - c.x;
  const double r2 = zr * zr + zi * zi;
  // a^2 / zeta^2 = a^2 conj(zeta)^2 / |zeta|^4
  const double cr = zr * zr - zi * zi, ci = -2.0 * zr * zi;
  const double k = double(a) * a / (r2 * r2);
  const double vz = u * (1.0 - k * cr), vx = u * (k * ci);
  return glm::vec3(float(vx), 0.0f, float(vz));
}

// A streamline from `start` to z = `end_z`: RK4 in steps of `h` metres along the direction of
// `velocity` (a field of the point).
template <typename Field>
std::vector<glm::vec3> streamline(glm::vec3 start, float end_z, float h, Field velocity) {
  std::vector<glm::vec3> line{start};
  glm::vec3 p = start;
  const auto dir = [&](glm::vec3 x) { return glm::normalize(velocity(x)); };
  while (p.z < end_z && line.size() < 1000000) {
    const glm::vec3 k1 = dir(p), k2 = dir(p + 0.5f * h * k1), k3 = dir(p + 0.5f * h * k2);
    const glm::vec3 k4 = dir(p + h * k3);
    p += h / 6.0f * (k1 + 2.0f * k2 + 2.0f * k3 + k4);
    line.push_back(p);
  }
  return line;
}

// The largest distance of a point of `path` from the polyline `line`'s points.
float farthest_from(const std::vector<glm::vec3>& path, const std::vector<glm::vec3>& line) {
  float farthest = 0.0f;
  for (const glm::vec3& x : path) {
    float nearest = 1e9f;
    for (const glm::vec3& o : line) nearest = std::min(nearest, glm::distance(x, o));
    farthest = std::max(farthest, nearest);
  }
  return farthest;
}

TEST(Drift, AroundACylinderFollowsTheFlowsStreamline) {
  // A wide channel (walls 8 radii away either side), plug flow, a float released upstream of the
  // cylinder a little off its axis.
  const float width = 24.0f, length = 60.0f, q = 24.0f, a = 1.5f, end_z = 42.0f;
  const glm::vec3 centre(0.0f, 0.0f, 30.0f);
  Obstacle cylinder;
  cylinder.centre = centre;
  cylinder.radius = a;
  const auto flow = river_flow(test::straight_channel(width, length, 241, 97), {q, 1.0f, 100.0f * width},
                               {cylinder});
  const WaterQueryFunction ask = [&](std::span<const glm::vec3> p, std::span<WaterSample> s) {
    flow->query(p, s);
    return Status::success();
  };
  const glm::vec3 release(0.6f, 0.0f, 18.0f);
  std::vector<FloatingBody> body(1);
  body[0].position = release;
  body[0].radius = 0.1f;
  body[0].drag = 40.0f;  // follows the water closely
  body[0].velocity = {0.0f, 0.0f, q / width};
  std::vector<glm::vec3> path{release};
  float length_of_path = 0.0f;
  while (body[0].position.z < end_z && path.size() < 5000) {
    ASSERT_TRUE(drift_bodies(body, 1.0f / 30.0f, ask).ok());
    ASSERT_FALSE(body[0].stranded);
    length_of_path += glm::distance(path.back(), body[0].position);
    path.push_back(body[0].position);
    const float off_centre = glm::length(glm::vec2(body[0].position.x - centre.x, body[0].position.z - centre.z));
    ASSERT_GE(off_centre, a) << "the float entered the footprint at z " << body[0].position.z;
  }
  ASSERT_GE(body[0].position.z, end_z) << "the float stopped at z " << body[0].position.z;
  // Against the streamline of the same flow, integrated independently (RK4, 1 cm steps).
  const std::vector<glm::vec3> own = streamline(release, end_z, 0.01f, [&](glm::vec3 x) {
    return query(*flow, x).velocity;
  });
  const float from_own = farthest_from(path, own);
  // Against potential flow around a cylinder in an unbounded uniform stream: the stream-function
  // flow (Shepard interpolation between the banks and the obstacle, paper eq. 2.1) is not
  // potential flow; its obstacle reaches further across, so its streamlines swing wider.
  const std::vector<glm::vec3> potential = streamline(release, end_z, 0.01f, [&](glm::vec3 x) {
    return cylinder_flow(x, centre, a, q / width);
  });
  const float from_potential = farthest_from(path, potential);
  std::printf("float path %.2f m: farthest %.3f m (%.2f %%) from the flow's own streamline, "
              "%.3f m (%.2f %%) from potential flow's\n",
              double(length_of_path), double(from_own), double(100.0f * from_own / length_of_path),
              double(from_potential), double(100.0f * from_potential / length_of_path));
  EXPECT_LT(from_own, 0.02f * length_of_path);
  EXPECT_LT(from_potential, 0.05f * length_of_path);  // 3.6 % measured: the flow model's own gap
  // Both pass the cylinder on the side of the release.
  for (const glm::vec3& x : path) {
    if (std::abs(x.z - centre.z) < 0.5f) {
      EXPECT_GT(x.x, a);
    }
  }
}

TEST(Drift, SlidesAlongABankAndSettlesOnTheSurface) {
  test::TestMesh m = test::straight_channel(10.0f, 40.0f, 41, 11);
  for (glm::vec3& p : m.positions) p.y = -0.02f * p.z;
  const auto flow = river_flow(m, {20.0f, 1.0f, 1000.0f});
  const WaterQueryFunction ask = [&](std::span<const glm::vec3> p, std::span<WaterSample> s) {
    flow->query(p, s);
    return Status::success();
  };
  // Thrown towards the left bank (+x) while the water carries it downstream.
  std::vector<FloatingBody> body(1);
  body[0].position = {4.0f, 0.5f, 2.0f};
  body[0].velocity = {6.0f, 0.0f, 0.0f};
  body[0].drag = 0.5f;
  for (int frame = 0; frame < 30; ++frame) {
    ASSERT_TRUE(drift_bodies(body, 1.0f / 30.0f, ask).ok());
    ASSERT_LE(body[0].position.x, 5.0f);
    EXPECT_NEAR(body[0].position.y, -0.02f * body[0].position.z, 1e-4f);
  }
  EXPECT_GT(body[0].position.z, 2.3f);  // slid downstream along the bank, drag slowly taking it
  EXPECT_NEAR(body[0].velocity.x, 0.0f, 1e-3f);  // what pointed into the bank is gone
}

TEST(Drift, ABodyDriftsTheSameAloneOrBesideOthers) {
  const auto flow = river_flow(test::straight_channel(10.0f, 40.0f, 41, 11), {20.0f, 1.0f, 1000.0f});
  const WaterQueryFunction ask = [&](std::span<const glm::vec3> p, std::span<WaterSample> s) {
    flow->query(p, s);
    return Status::success();
  };
  std::vector<FloatingBody> alone(1);
  alone[0].position = {-1.0f, 0.0f, 5.0f};
  alone[0].drag = 1.5f;
  std::vector<FloatingBody> together = alone;
  together.push_back(alone[0]);
  together[1].position = {2.0f, 0.0f, 6.0f};
  together[1].radius = 0.05f;  // a leaf: far more sub-steps than the log
  together[1].drag = 8.0f;
  for (int frame = 0; frame < 30; ++frame) {
    ASSERT_TRUE(drift_bodies(alone, 1.0f / 30.0f, ask).ok());
    ASSERT_TRUE(drift_bodies(together, 1.0f / 30.0f, ask).ok());
    ASSERT_EQ(alone[0].position, together[0].position) << "frame " << frame;
    ASSERT_EQ(alone[0].velocity, together[0].velocity) << "frame " << frame;
  }
}

TEST(Drift, BadBodiesAreNamedAndNothingMoves) {
  const auto flow = river_flow(test::straight_channel(10.0f, 40.0f, 41, 11), {20.0f, 1.0f, 1000.0f});
  const WaterQueryFunction ask = [&](std::span<const glm::vec3> p, std::span<WaterSample> s) {
    flow->query(p, s);
    return Status::success();
  };
  std::vector<FloatingBody> bodies(3);
  for (size_t i = 0; i < bodies.size(); ++i) bodies[i].position = {0.0f, 0.0f, 5.0f + float(i)};
  const std::vector<FloatingBody> before = bodies;
  bodies[1].radius = -1.0f;
  Status s = drift_bodies(bodies, 0.1f, ask);
  EXPECT_EQ(s.message(), "drift_bodies: bodies[1].radius -1 must be positive and finite");
  EXPECT_EQ(bodies[0].position, before[0].position);
  bodies[1].radius = 0.5f;
  bodies[2].position.x = NAN;
  s = drift_bodies(bodies, 0.1f, ask);
  EXPECT_NE(s.message().find("bodies[2].position"), std::string::npos) << s.message();
  bodies[2].position.x = 0.0f;
  bodies[2].drag = INFINITY;
  EXPECT_NE(drift_bodies(bodies, 0.1f, ask).message().find("bodies[2].drag"), std::string::npos);
  bodies[2].drag = 1.0f;
  EXPECT_FALSE(drift_bodies(bodies, 0.0f, ask).ok());
  // Off the river: stranded, not moved.
  bodies[0].position = {20.0f, 0.0f, 5.0f};
  ASSERT_TRUE(drift_bodies(bodies, 0.1f, ask).ok());
  EXPECT_TRUE(bodies[0].stranded);
  EXPECT_EQ(bodies[0].position, glm::vec3(20.0f, 0.0f, 5.0f));
  EXPECT_FALSE(bodies[1].stranded);
  EXPECT_GT(bodies[1].position.z, 6.0f);
}

}  // namespace
}  // namespace siviflow
