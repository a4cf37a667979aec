// Foam from the flow (sim/foam.h) in a straight channel with a boulder: none in open water, a
// wake strongest just behind the boulder and thinning downstream, a line along the moving banks,
// and a wake that follows the boulder when it moves.
#include "sim/foam.h"

#include <cmath>
#include <algorithm>
#include <cstdio>
#include <functional>
#include <vector>

#include <gtest/gtest.h>

#include "siviflow/sim/stream_function.h"
#include "unit/foam_inputs.h"
#include "unit/river_test_meshes.h"

namespace siviflow {
namespace {

// 10 m wide, 60 m long, 0.5 m between vertices, 1 m/s; flow along +z.
constexpr float kWidth = 10.0f, kLength = 60.0f, kQ = 10.0f, kRadius = 1.0f;
constexpr uint32_t kSections = 121, kAcross = 21;

class FoamTest : public ::testing::Test {
 protected:
  void SetUp() override {
    mesh_ = test::symmetric_channel(kWidth, kLength, kSections, kAcross);
    RiverSurface surface;
    ASSERT_TRUE(RiverSurface::build(mesh_.positions, mesh_.indices, {}, &surface).ok());
    ASSERT_TRUE(StreamFunction::create(std::move(surface), {kQ, 1.5f, 0.0f}, &flow_).ok());
    ASSERT_TRUE(TriangleBvh::build(mesh_.positions, mesh_.indices, &bvh_).ok());
    test::FoamInputs in = test::foam_inputs(flow_.surface(), mesh_.positions.size());
    bank_ = std::move(in.bank);
    section_ = std::move(in.section);
    ASSERT_TRUE(FoamField::create(mesh_.positions, mesh_.indices, section_, &bvh_, FoamParams{},
                                  &field_).ok());
  }

  // Foam per vertex for the flow as it is now.
  std::vector<float> foam() {
    std::vector<glm::vec3> velocity(mesh_.positions.size());
    for (size_t v = 0; v < velocity.size(); ++v) velocity[v] = flow_.velocity(v);
    std::vector<float> out(velocity.size());
    field_.compute(velocity, bank_, out);
    return out;
  }

  // The vertex at (x, z) (the channel's grid).
  size_t at(float x, float z) const {
    const auto j = static_cast<size_t>(std::lround((0.5f * kWidth - x) / kWidth * (kAcross - 1)));
    const auto k = static_cast<size_t>(std::lround(z / kLength * (kSections - 1)));
    return k * kAcross + j;
  }

  static Obstacle boulder(float z) {
    Obstacle o;
    o.centre = {0.0f, 0.0f, z};
    o.radius = kRadius;
    return o;
  }

  test::TestMesh mesh_;
  StreamFunction flow_;
  TriangleBvh bvh_;
  FoamField field_;
  MarginDistances bank_;
  std::vector<uint32_t> section_;
};

TEST_F(FoamTest, OpenWaterHasFoamOnlyAlongTheBanks) {
  const std::vector<float> f = foam();
  for (float z : {10.0f, 30.0f, 50.0f}) {
    for (float x : {-2.0f, -1.0f, 0.0f, 1.0f, 2.0f}) {
      EXPECT_LT(f[at(x, z)], 0.05f) << "open water at x " << x << " z " << z;
    }
    // The shear of the flow's profile near the banks starts the bank line a little early.
    EXPECT_LT(f[at(-3.0f, z)], 0.15f);
    EXPECT_LT(f[at(3.0f, z)], 0.15f);
    EXPECT_GT(f[at(-5.0f, z)], 0.4f) << "right bank at z " << z;
    EXPECT_GT(f[at(5.0f, z)], 0.4f) << "left bank at z " << z;
    EXPECT_LT(f[at(-4.0f, z)], f[at(-5.0f, z)]) << "the bank line thins away from the bank";
  }
}

TEST_F(FoamTest, ABoulderLeavesAWakeThatThinsDownstream) {
  ASSERT_TRUE(flow_.set_obstacles({boulder(20.0f)}).ok());
  const std::vector<float> f = foam();
  EXPECT_LT(f[at(0.0f, 12.0f)], 0.05f) << "upstream of the boulder";
  EXPECT_LT(f[at(2.5f, 28.0f)] + f[at(-2.5f, 28.0f)], 0.6f) << "beside the wake";
  const float behind = f[at(0.0f, 21.5f)];
  EXPECT_GT(behind, 0.6f);
  EXPECT_LT(f[at(0.0f, 18.5f)], 0.5f * behind) << "the water slowing in front foams less";
  float last = behind;
  std::printf("wake on the centreline:");
  for (float z : {24.0f, 28.0f, 32.0f, 36.0f}) {
    const float here = f[at(0.0f, z)];
    std::printf(" z %.0f: %.3f", double(z), double(here));
    EXPECT_LT(here, last + 1e-4f) << "thinning at z " << z;
    last = here;
  }
  std::printf("\n");
  EXPECT_GT(f[at(0.0f, 28.0f)], 0.2f) << "still foamy a few metres on";
  EXPECT_LT(f[at(0.0f, 36.0f)], 0.6f * behind) << "thinner far behind";
}

TEST_F(FoamTest, TheWakeFollowsAMovedBoulder) {
  ASSERT_TRUE(flow_.set_obstacles({boulder(20.0f)}).ok());
  const std::vector<float> before = foam();
  ASSERT_TRUE(flow_.move_obstacle(0, {0.0f, 0.0f, 40.0f}).ok());
  const std::vector<float> after = foam();
  EXPECT_GT(before[at(0.0f, 23.0f)], 0.4f);
  EXPECT_LT(after[at(0.0f, 23.0f)], 0.05f) << "the old wake is gone";
  EXPECT_GT(after[at(0.0f, 43.0f)], 0.4f) << "behind the boulder's new place";
}

// The river surface's triangles around its nodes (what a long river shares instead of building
// its own) give the same foam, bit for bit, as the field's own adjacency; a mismatched one is
// refused.
TEST_F(FoamTest, SharedAdjacencyGivesTheSameFoam) {
  ASSERT_TRUE(flow_.set_obstacles({boulder(20.0f)}).ok());
  const std::vector<float> own = foam();
  const RiverSurface& surface = flow_.surface();
  ASSERT_FALSE(surface.welded());
  ASSERT_TRUE(FoamField::create(mesh_.positions, mesh_.indices, section_, &bvh_, FoamParams{},
                                &field_, &surface.triangles_around())
                  .ok());
  EXPECT_EQ(foam(), own);
  FoamField field;
  // One vertex more than the mesh has.
  const TrianglesAround too_many =
      TrianglesAround::of_mesh(mesh_.positions.size() + 1, mesh_.indices);
  const Status status = FoamField::create(mesh_.positions, mesh_.indices, section_, &bvh_,
                                          FoamParams{}, &field, &too_many);
  EXPECT_FALSE(status.ok());
  EXPECT_NE(status.message().find("around"), std::string::npos) << status.message();
}

// A vertex that no triangle uses is refused: update() finds vertices through the triangles.
TEST_F(FoamTest, AVertexOfNoTriangleIsRefused) {
  std::vector<glm::vec3> positions = mesh_.positions;
  positions.push_back({0.0f, 0.0f, 30.0f});
  std::vector<uint32_t> section = section_;
  section.push_back(section_[at(0.0f, 30.0f)]);
  FoamField field;
  const Status status =
      FoamField::create(positions, mesh_.indices, section, &bvh_, FoamParams{}, &field);
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.message().find("vertex " + std::to_string(positions.size() - 1)),
            std::string::npos)
      << status.message();
}

// A long channel (2 km; 10 m wide, 1 m between vertices): an obstacle added, moved and removed
// re-derives the foam only around where the flow changed, and the foam equals a full compute
// bit for bit after each step.
TEST(FoamUpdateTest, OnlyWhereTheFlowChangedAndEqualToAFullCompute) {
  const test::TestMesh mesh = test::symmetric_channel(10.0f, 2000.0f, 2001, 11);
  RiverSurface surface;
  ASSERT_TRUE(RiverSurface::build(mesh.positions, mesh.indices, {}, &surface).ok());
  StreamFunction flow;
  ASSERT_TRUE(StreamFunction::create(std::move(surface), {10.0f, 1.5f, 0.0f}, &flow).ok());
  TriangleBvh bvh;
  ASSERT_TRUE(TriangleBvh::build(mesh.positions, mesh.indices, &bvh).ok());
  const size_t count = mesh.positions.size();
  const auto [bank, section] = test::foam_inputs(flow.surface(), count);
  FoamField field, reference;
  ASSERT_TRUE(FoamField::create(mesh.positions, mesh.indices, section, &bvh, {}, &field).ok());
  ASSERT_TRUE(FoamField::create(mesh.positions, mesh.indices, section, &bvh, {}, &reference).ok());
  std::vector<glm::vec3> velocity(count);
  const auto read_velocity = [&] {
    for (size_t v = 0; v < count; ++v) velocity[v] = flow.velocity(v);
  };
  std::vector<float> foam(count, -1.0f), expected(count);
  read_velocity();
  const FlowUpdateStats& last = flow.last_update();
  field.update(velocity, bank, last.velocity_changed, foam);
  EXPECT_EQ(field.last_rederived(), count) << "the first update computes everything";

  Obstacle rock;
  rock.centre = {1.0f, 0.0f, 300.0f};
  rock.radius = 1.5f;
  struct Step {
    const char* what;
    std::function<Status()> apply;
  };
  const std::vector<Step> steps = {
      {"added", [&] { return flow.add_obstacle(rock); }},
      {"moved a little", [&] { return flow.move_obstacle(0, {-1.0f, 0.0f, 302.0f}); }},
      {"moved far", [&] { return flow.move_obstacle(0, {2.0f, 0.0f, 1500.0f}); }},
      {"removed", [&] { return flow.remove_obstacle(0); }},
  };
  for (const Step& step : steps) {
    ASSERT_TRUE(step.apply().ok()) << step.what;
    read_velocity();
    ASSERT_FALSE(last.velocity_changed.empty()) << step.what;
    field.update(velocity, bank, last.velocity_changed, foam);
    reference.compute(velocity, bank, expected);
    EXPECT_EQ(foam, expected) << "bit for bit after the obstacle was " << step.what;
    EXPECT_GT(field.last_rederived(), 0u) << step.what;
    // Moved far, both the old and the new place are re-derived: a window at each end.
    EXPECT_LT(field.last_rederived(), count / 2) << step.what;
    std::printf("%s: %zu of %zu vertices re-derived\n", step.what, field.last_rederived(), count);
  }
  EXPECT_GT(*std::max_element(expected.begin(), expected.end()), 0.5f) << "foam to compare";

  field.update(velocity, bank, {}, foam);  // nothing changed
  EXPECT_EQ(field.last_rederived(), 0u);
  EXPECT_EQ(foam, expected);
}

TEST(FoamParamsTest, BadParametersAreRefused) {
  FoamParams lifeless, no_lee, too_much_front;
  lifeless.lifetime_s = 0.0f;
  no_lee.lee_acceleration = 0.0f;
  too_much_front.front_share = 1.5f;
  for (const FoamParams& params : {lifeless, no_lee, too_much_front}) {
    FoamField field;
    TriangleBvh bvh;
    const Status status = FoamField::create({}, {}, {}, &bvh, params, &field);
    EXPECT_FALSE(status.ok());
    EXPECT_NE(status.message().find("FoamParams"), std::string::npos) << status.message();
  }
}

}  // namespace
}  // namespace siviflow
