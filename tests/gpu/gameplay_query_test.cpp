// Renderer::query_water and drift_bodies through the public API: the default river as a host
// sees it, placed in a Z-up world, with the river's own boulders and the host's runtime
// obstacles named by their ids, and bad points refused by name.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <vector>

#include <glm/geometric.hpp>
#include <glm/gtc/matrix_transform.hpp>
#include <gtest/gtest.h>

#include "gpu_test.h"
#include "siviflow/drift.h"

namespace siviflow {
namespace {

class GameplayQueryTest : public testing::GpuTest {
 protected:
  std::unique_ptr<Renderer> make(const glm::mat4& world_from_river = glm::mat4(1.0f)) {
    CreateInfo info = context_->renderer_create_info({160, 90}, VK_FORMAT_R16G16B16A16_SFLOAT);
    info.depth_format = VK_FORMAT_D32_SFLOAT;
    info.world_from_river = world_from_river;
    std::unique_ptr<Renderer> renderer;
    const Status created = Renderer::create(info, &renderer);
    EXPECT_TRUE(created.ok()) << created.message();
    return renderer;
  }

  // Every point of a 0.5 m grid over the default river's box, at height `y`.
  static std::vector<glm::vec3> grid(float y) {
    std::vector<glm::vec3> points;
    for (float z = -122.0f; z <= 123.0f; z += 0.5f) {
      for (float x = -20.5f; x <= 19.0f; x += 0.5f) points.push_back({x, y, z});
    }
    return points;
  }

  static WaterQueryFunction asker(const Renderer& renderer) {
    return [&renderer](std::span<const glm::vec3> p, std::span<WaterSample> s) {
      return renderer.query_water(p, s);
    };
  }
};

TEST_F(GameplayQueryTest, DefaultRiverFlowsDownstreamAroundItsBoulders) {
  const std::unique_ptr<Renderer> water = make();
  ASSERT_NE(water, nullptr);
  const std::vector<glm::vec3> points = grid(5.0f);
  std::vector<WaterSample> samples(points.size());
  ASSERT_TRUE(water->query_water(points, samples).ok());
  size_t wet = 0, in_boulder = 0, downstream = 0;
  for (size_t i = 0; i < points.size(); ++i) {
    const WaterSample& s = samples[i];
    if (s.on_surface) {
      EXPECT_NEAR(s.surface.y, 0.0f, 1e-4f);  // level at y = 0, found below the point
      EXPECT_NEAR(s.normal.y, 1.0f, 1e-5f);
      EXPECT_GT(s.depth, 0.0f);
      EXPECT_GE(s.foam, 0.0f);
      EXPECT_LE(s.foam, 1.0f);
    }
    if (s.wet) {
      ++wet;
      downstream += s.velocity.z > 0.0f ? 1 : 0;
    } else if (s.on_surface) {
      // Dry on the river: inside one of the default river's two boulders.
      EXPECT_GE(s.obstacle, WaterSample::kRiverObstacle);
      EXPECT_LE(s.obstacle, WaterSample::kRiverObstacle + 1);
      EXPECT_EQ(s.velocity, glm::vec3(0.0f));
      ++in_boulder;
    } else {
      EXPECT_EQ(s.obstacle == WaterSample::kNoObstacle || s.obstacle >= WaterSample::kRiverObstacle, true);
    }
  }
  std::printf("%zu wet samples (%zu flowing downstream), %zu in the river's boulders\n", wet,
              downstream, in_boulder);
  EXPECT_GT(wet, 5000u);
  EXPECT_GT(in_boulder, 5u);
  EXPECT_GT(downstream, wet * 95 / 100);  // the river flows to +z; eddies behind boulders aside
}

TEST_F(GameplayQueryTest, RuntimeObstaclesAreNamedByTheirIds) {
  const std::unique_ptr<Renderer> water = make();
  ASSERT_NE(water, nullptr);
  const glm::vec3 point(0.0f, 0.0f, -60.0f);
  WaterSample s;
  // The default river's centre there: find a wet point across it.
  glm::vec3 on_water = point;
  for (float x = -15.0f; x <= 15.0f; x += 0.5f) {
    const glm::vec3 p(x, 0.0f, point.z);
    ASSERT_TRUE(water->query_water({&p, 1}, {&s, 1}).ok());
    if (s.wet) {
      on_water = p;
      break;
    }
  }
  ASSERT_TRUE(s.wet);
  WaterObstacle rock;
  rock.centre = on_water + glm::vec3(1.0f, 0.0f, 0.0f);
  rock.radius = 1.5f;
  uint32_t id = 0;
  ASSERT_TRUE(water->add_obstacle(rock, &id).ok());
  ASSERT_TRUE(water->query_water({&on_water, 1}, {&s, 1}).ok());
  EXPECT_FALSE(s.wet);
  EXPECT_TRUE(s.on_surface);
  EXPECT_EQ(s.obstacle, id);
  ASSERT_TRUE(water->move_obstacle(id, on_water + glm::vec3(0.0f, 0.0f, 20.0f)).ok());
  ASSERT_TRUE(water->query_water({&on_water, 1}, {&s, 1}).ok());
  EXPECT_TRUE(s.wet);
  ASSERT_TRUE(water->remove_obstacle(id).ok());
}

TEST_F(GameplayQueryTest, PlacedRiverAnswersInTheHostsWorld) {
  // A Z-up engine: river +Y is world +Z, and the river sits 100 m east, 7 m up.
  const glm::mat4 placement = glm::translate(glm::mat4(1.0f), glm::vec3(100.0f, 0.0f, 7.0f)) *
                              glm::rotate(glm::mat4(1.0f), glm::radians(90.0f), glm::vec3(1, 0, 0));
  const std::unique_ptr<Renderer> plain = make();
  const std::unique_ptr<Renderer> placed = make(placement);
  ASSERT_NE(plain, nullptr);
  ASSERT_NE(placed, nullptr);
  const std::vector<glm::vec3> points = grid(2.0f);
  std::vector<glm::vec3> in_world;
  for (const glm::vec3& p : points) in_world.push_back(glm::vec3(placement * glm::vec4(p, 1.0f)));
  std::vector<WaterSample> a(points.size()), b(points.size());
  ASSERT_TRUE(plain->query_water(points, a).ok());
  ASSERT_TRUE(placed->query_water(in_world, b).ok());
  const glm::mat3 rotate(placement);
  for (size_t i = 0; i < points.size(); ++i) {
    ASSERT_EQ(a[i].wet, b[i].wet) << i;
    ASSERT_EQ(a[i].obstacle, b[i].obstacle) << i;
    if (!a[i].on_surface) continue;
    const glm::vec3 surface(placement * glm::vec4(a[i].surface, 1.0f));
    EXPECT_LT(glm::distance(b[i].surface, surface), 1e-3f);
    EXPECT_LT(glm::distance(b[i].normal, glm::vec3(0.0f, 0.0f, 1.0f)), 1e-5f);
    EXPECT_LT(glm::distance(b[i].velocity, rotate * a[i].velocity), 1e-4f);
  }
}

TEST_F(GameplayQueryTest, MovedObstacleDeflectsAFloatReleasedAfterTheMove) {
  const std::unique_ptr<Renderer> water = make();
  ASSERT_NE(water, nullptr);
  // A float's path down the river, 10 s from a release point.
  const auto drift_path = [&](glm::vec3 release) {
    std::vector<FloatingBody> body(1);
    body[0].position = release;
    body[0].radius = 0.2f;
    body[0].drag = 8.0f;
    std::vector<glm::vec3> path;
    for (int frame = 0; frame < 300; ++frame) {
      const Status s = drift_bodies(body, 1.0f / 30.0f, asker(*water));
      EXPECT_TRUE(s.ok()) << s.message();
      path.push_back(body[0].position);
    }
    return path;
  };
  // Release mid-river at z = -80: halfway across the wet span there.
  float first_wet = 1e9f, last_wet = -1e9f;
  for (float x = -20.0f; x <= 19.0f; x += 0.25f) {
    WaterSample s;
    const glm::vec3 p(x, 0.0f, -80.0f);
    ASSERT_TRUE(water->query_water({&p, 1}, {&s, 1}).ok());
    if (s.wet) {
      first_wet = std::min(first_wet, x);
      last_wet = std::max(last_wet, x);
    }
  }
  ASSERT_LT(first_wet, last_wet);
  const glm::vec3 release(0.5f * (first_wet + last_wet), 0.0f, -80.0f);
  const std::vector<glm::vec3> free_path = drift_path(release);
  ASSERT_GT(free_path.back().z, release.z + 3.0f) << "the float did not travel";
  // An obstacle placed elsewhere, then moved across the float's path 2 m downstream.
  WaterObstacle rock;
  rock.centre = release + glm::vec3(0.0f, 0.0f, -40.0f);
  rock.radius = 1.2f;
  uint32_t id = 0;
  ASSERT_TRUE(water->add_obstacle(rock, &id).ok());
  // Its edge a third of a metre beside the float's path, where the float's centre would pass: it
  // is pushed around (straight ahead, the flow's slow water in front of a boulder holds a float).
  const glm::vec3 in_path = free_path[free_path.size() / 3] + glm::vec3(1.5f, 0.0f, 0.0f);
  ASSERT_TRUE(water->move_obstacle(id, in_path).ok());
  const std::vector<glm::vec3> deflected = drift_path(release);
  float closest = 1e9f, apart = 0.0f;
  for (size_t i = 0; i < deflected.size(); ++i) {
    closest = std::min(closest, glm::length(glm::vec2(deflected[i].x - in_path.x, deflected[i].z - in_path.z)));
    apart = std::max(apart, glm::distance(deflected[i], free_path[i]));
  }
  std::printf("float released at (%.2f, %.2f): %.1f m travelled; with the moved obstacle at most "
              "%.2f m from the free path, never nearer its centre than %.2f m\n",
              double(release.x), double(release.z), double(free_path.back().z - release.z),
              double(apart), double(closest));
  EXPECT_GE(closest, rock.radius) << "the float entered the moved obstacle";
  EXPECT_GT(apart, 0.3f) << "the moved obstacle did not deflect the float";
  EXPECT_GT(deflected.back().z, in_path.z + rock.radius) << "the float did not get past it";
}

// docs/embedding.md quotes the three statements in the middle.
TEST_F(GameplayQueryTest, TheGuidesDriftExampleRuns) {
  const std::unique_ptr<Renderer> water = make();
  ASSERT_NE(water, nullptr);
  const float frame_seconds = 1.0f / 60.0f;
  std::vector<siviflow::FloatingBody> crates = {{{2.0f, 0.0f, -60.0f}}, {{-1.0f, 0.0f, -64.0f}}};
  auto ask = [&](std::span<const glm::vec3> p, std::span<siviflow::WaterSample> s) {
    return water->query_water(p, s);
  };
  siviflow::Status moved = siviflow::drift_bodies(crates, frame_seconds, ask);
  EXPECT_TRUE(moved.ok()) << moved.message();
}

TEST_F(GameplayQueryTest, BadPointsAreRefusedByNameAndNothingIsWritten) {
  const std::unique_ptr<Renderer> water = make();
  ASSERT_NE(water, nullptr);
  const std::vector<glm::vec3> points = {{0, 0, 0}, {1.0f, NAN, 2.0f}};
  std::vector<WaterSample> out(2);
  out[0].depth = -7.0f;  // a sentinel: nothing may be written
  EXPECT_EQ(water->query_water(points, out).message(),
            "siviflow::Renderer: query_water: points[1] (1, nan, 2) is not finite");
  EXPECT_EQ(out[0].depth, -7.0f);
  EXPECT_EQ(water->query_water(points, std::span<WaterSample>(out.data(), 1)).message(),
            "siviflow::Renderer: query_water: out holds 1 samples for 2 points");
  EXPECT_TRUE(water->query_water({}, {}).ok());
}

}  // namespace
}  // namespace siviflow
