// The scene file's floats replayed through the water (siviflow/scene_floats.h): released at
// their time and place, drifted as drift_bodies would drift them, the same way every time, and
// refused by name where they would start off the water.
#include <vector>

#include <glm/gtc/constants.hpp>

#include <gtest/gtest.h>

#include "siviflow/scene_floats.h"
#include "unit/river_flow_fixture.h"

namespace siviflow {
namespace {

constexpr float kWidth = 10.0f;
constexpr float kDischarge = 20.0f;  // 2 m/s across the 10 m channel
constexpr double kFrame = 1.0 / 30.0;

class SceneFloatsTest : public ::testing::Test {
 protected:
  void SetUp() override {
    Obstacle boulder;
    boulder.centre = {0.0f, 0.0f, 30.0f};
    boulder.radius = 1.5f;
    flow_ = test::river_flow(test::straight_channel(kWidth, 60.0f, 61, 21),
                             {kDischarge, 1.0f, 100.0f * kWidth}, {boulder});
    scene_.path = "floats.json";
    scene_.obstacles = {boulder};  // the scene the flow was made from
  }
  std::vector<WaterQueryFunction> queries() const {
    // Obstacles named as Renderer::query_water names the river's own.
    return {[this](std::span<const glm::vec3> p, std::span<WaterSample> s) {
      flow_->query(p, s);
      for (WaterSample& sample : s) {
        if (sample.obstacle != 0) sample.obstacle = WaterSample::kRiverObstacle + sample.obstacle - 1;
      }
      return Status::success();
    }};
  }
  SceneFloat log_at(float x, float z, double release_time = 0.0) const {
    SceneFloat f = scene_float_defaults(FloatMesh::kLog);
    f.release_point = {x, z};
    f.release_time = release_time;
    return f;
  }
  std::unique_ptr<RiverFlow> flow_;
  SceneFile scene_;
};

TEST_F(SceneFloatsTest, ReleasedAtTheirTimeAndDriftedAsTheDriftWould) {
  scene_.floats = {log_at(-2.0f, 5.0f), log_at(2.0f, 5.0f, 0.02)};
  SceneFloats floats;
  ASSERT_TRUE(SceneFloats::create(scene_, queries(), &floats).ok());
  ASSERT_EQ(floats.poses().size(), 2u);
  EXPECT_TRUE(floats.poses()[0].shown);
  EXPECT_FALSE(floats.poses()[1].shown) << "released at 0.02 s";
  EXPECT_EQ(floats.poses()[0].centre, glm::vec3(-2.0f, 0.0f, 5.0f)) << "at rest on the surface";
  EXPECT_NEAR(floats.poses()[0].heading, glm::half_pi<float>(), 0.01f) << "along the flow (+z)";
  // The first drifts the whole frame; the second, released within it, the part after 0.02 s.
  ASSERT_TRUE(floats.advance(kFrame).ok());
  ASSERT_TRUE(floats.poses()[1].shown);
  std::vector<FloatingBody> expected(2);
  for (size_t i = 0; i < 2; ++i) {
    expected[i].position = {scene_.floats[i].release_point.x, 0.0f, scene_.floats[i].release_point.y};
    expected[i].radius = scene_.floats[i].radius;
    expected[i].drag = scene_.floats[i].drag;
  }
  ASSERT_TRUE(drift_bodies(std::span(&expected[0], 1), float(kFrame), queries()[0]).ok());
  ASSERT_TRUE(drift_bodies(std::span(&expected[1], 1), float(kFrame - 0.02), queries()[0]).ok());
  for (size_t i = 0; i < 2; ++i) {
    EXPECT_EQ(floats.poses()[i].centre, expected[i].position) << i;
    EXPECT_EQ(floats.poses()[i].velocity, expected[i].velocity) << i;
  }
  for (int frame = 2; frame <= 60; ++frame) ASSERT_TRUE(floats.advance(frame * kFrame).ok());
  for (const FloatPose& pose : floats.poses()) {
    EXPECT_TRUE(pose.shown);
    EXPECT_GT(pose.centre.z, 6.0f) << "carried downstream";
    EXPECT_GT(pose.velocity.z, 1.0f);
    EXPECT_NEAR(pose.heading, glm::half_pi<float>(), 0.1f) << "turned along the flow";
  }
  EXPECT_FALSE(floats.advance(kFrame).ok()) << "time does not go back";
}

TEST_F(SceneFloatsTest, SameSceneSamePoses) {
  scene_.floats = {log_at(-1.0f, 20.0f), log_at(0.5f, 22.0f, 0.3), log_at(3.0f, 10.0f, 1.0)};
  scene_.floats[1].mesh = FloatMesh::kLeaf;
  std::vector<FloatPose> runs[2];
  for (std::vector<FloatPose>& run : runs) {
    SceneFloats floats;
    ASSERT_TRUE(SceneFloats::create(scene_, queries(), &floats).ok());
    for (int frame = 1; frame <= 90; ++frame) ASSERT_TRUE(floats.advance(frame * kFrame).ok());
    run.assign(floats.poses().begin(), floats.poses().end());
  }
  for (size_t i = 0; i < runs[0].size(); ++i) {
    EXPECT_EQ(runs[0][i].centre, runs[1][i].centre) << i;
    EXPECT_EQ(runs[0][i].heading, runs[1][i].heading) << i;
    // The boulder at z 30 stays dry: none is inside its footprint.
    const glm::vec2 off(runs[0][i].centre.x, runs[0][i].centre.z - 30.0f);
    EXPECT_GE(glm::length(off), 1.5f) << i;
  }
}

TEST_F(SceneFloatsTest, ReleasePointsOffTheWaterAreNamedAndNothingIsMade) {
  scene_.floats = {log_at(0.0f, 5.0f), log_at(40.0f, 5.0f)};
  SceneFloats floats;
  Status s = SceneFloats::create(scene_, queries(), &floats);
  EXPECT_EQ(s.message(), "floats.json: floats[1].release_point: (40, 5) is not on any river");
  EXPECT_TRUE(floats.poses().empty());
  scene_.floats = {log_at(0.5f, 30.0f)};
  s = SceneFloats::create(scene_, queries(), &floats);
  EXPECT_EQ(s.message(), "floats.json: floats[0].release_point: (0.5, 30) is inside "
                         "obstacles[0]'s footprint, not on the water");
  // A footprint of an object marked obstacle is named as the scene names it.
  scene_.objects.resize(3);
  scene_.objects[2].obstacle = true;  // its footprint is the flow's second obstacle
  scene_.floats = {log_at(0.5f, 30.0f)};
  const auto named_as_object = [this](std::span<const glm::vec3> p, std::span<WaterSample> out) {
    SIVIFLOW_TRY(queries()[0](p, out));
    for (WaterSample& sample : out) {
      if (sample.obstacle != 0) ++sample.obstacle;  // as if obstacles[0] were elsewhere
    }
    return Status::success();
  };
  s = SceneFloats::create(scene_, {named_as_object}, &floats);
  EXPECT_EQ(s.message(), "floats.json: floats[0].release_point: (0.5, 30) is inside "
                         "objects[2]'s footprint, not on the water");
  scene_.objects.clear();
  // A float's own numbers are checked before its place.
  scene_.floats = {log_at(0.0f, 5.0f), log_at(0.0f, 6.0f)};
  scene_.floats[1].radius = 0.0f;
  s = SceneFloats::create(scene_, queries(), &floats);
  EXPECT_EQ(s.message(), "floats.json: floats[1]: radius 0 must be in (0, 50] metres");
  // A host's drop: refused off the water, nothing added; taken on it, at the current time.
  scene_.floats.clear();
  ASSERT_TRUE(SceneFloats::create(scene_, queries(), &floats).ok());
  ASSERT_TRUE(floats.advance(1.0).ok());
  EXPECT_FALSE(floats.drop(log_at(-9.0f, 5.0f)).ok());
  SceneFloat bad = log_at(0.0f, 5.0f);
  bad.radius = -1.0f;
  EXPECT_FALSE(floats.drop(bad).ok());
  EXPECT_TRUE(floats.poses().empty());
  ASSERT_TRUE(floats.drop(log_at(0.0f, 5.0f)).ok());
  ASSERT_EQ(floats.poses().size(), 1u);
  EXPECT_TRUE(floats.poses()[0].shown);
}

}  // namespace
}  // namespace siviflow
