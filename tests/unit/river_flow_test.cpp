// RiverFlow (engine/river_simulation.h): the foam it keeps after obstacles move at runtime or by
// their keys, re-derived only where the flow changed, equals that of a river created with the
// obstacles where they now stand, bit for bit.
#include <gtest/gtest.h>

#include <algorithm>
#include <limits>
#include <span>
#include <tuple>
#include <vector>

#include "default_river.h"
#include "sim/half_float.h"
#include "siviflow/sim/procedural_river.h"
#include "unit/river_flow_fixture.h"

namespace siviflow {
namespace {

Obstacle rock(glm::vec3 centre) {
  Obstacle o;
  o.centre = centre;
  o.radius = 1.5f;
  return o;
}

// The obstacles as a river created now would take them: each at its centre at `time`, unkeyed.
std::vector<Obstacle> standing_at(const std::vector<Obstacle>& obstacles, double time) {
  std::vector<Obstacle> out;
  for (const Obstacle& o : obstacles) {
    Obstacle still = o;
    still.centre = obstacle_centre_at(o, time);
    still.keys.clear();
    out.push_back(still);
  }
  return out;
}

void expect_same_foam(const RiverFlow& moved, const RiverFlow& fresh, const char* when) {
  const std::span<const float> a = moved.field().foam, b = fresh.field().foam;
  ASSERT_EQ(a.size(), b.size());
  EXPECT_EQ(std::vector<float>(a.begin(), a.end()), std::vector<float>(b.begin(), b.end())) << when;
  float most = 0.0f;
  for (const float f : a) most = std::max(most, f);
  EXPECT_GT(most, 0.5f) << when << ": a wake to compare";
}

// The channel's triangles each with corners of their own (no indices): a mesh the surface welds,
// whose flow RiverFlow copies per vertex.
test::TestMesh unwelded(const test::TestMesh& mesh) {
  test::TestMesh out;
  for (const uint32_t i : mesh.indices) out.positions.push_back(mesh.positions[i]);
  return out;
}

void expect_same_velocity(const RiverFlow& moved, const RiverFlow& fresh, const char* when) {
  const std::span<const glm::vec3> a = moved.field().flow, b = fresh.field().flow;
  EXPECT_TRUE(std::equal(a.begin(), a.end(), b.begin(), b.end())) << when;
}

// A 2 km channel, indexed and welded: two boats keyed at its two ends (far apart, so each move
// is re-derived about its own place), then a rock added and moved at runtime.
class RiverFlowMoves : public ::testing::TestWithParam<bool> {};

TEST_P(RiverFlowMoves, FoamAndVelocityEqualAFreshRiversWithTheObstaclesThere) {
  const test::TestMesh channel = test::symmetric_channel(10.0f, 2000.0f, 2001, 11);
  const test::TestMesh mesh = GetParam() ? unwelded(channel) : channel;
  const FlowParams params{10.0f, 1.5f, 0.0f};
  std::vector<Obstacle> boats = {rock({1.0f, 0.0f, 300.0f}), rock({-1.0f, 0.0f, 1700.0f})};
  boats[0].keys = {{0.0, {1.0f, 0.0f, 300.0f}}, {10.0, {1.0f, 0.0f, 340.0f}}};
  boats[1].keys = {{0.0, {-1.0f, 0.0f, 1700.0f}}, {10.0, {2.0f, 0.0f, 1690.0f}}};
  auto flow = test::river_flow(mesh, params, boats);
  for (const double t : {0.5, 4.0, 9.5}) {
    ASSERT_TRUE(flow->set_time(t).ok());
    auto fresh = test::river_flow(mesh, params, standing_at(boats, t));
    expect_same_foam(*flow, *fresh, "keyed boats");
    expect_same_velocity(*flow, *fresh, "keyed boats");
  }
  std::vector<Obstacle> all = standing_at(boats, 9.5);
  all.push_back(rock({0.0f, 0.0f, 1000.0f}));
  ASSERT_TRUE(flow->add_obstacle(all.back()).ok());
  auto fresh = test::river_flow(mesh, params, all);
  expect_same_foam(*flow, *fresh, "a rock added");
  ASSERT_TRUE(flow->move_obstacle(2, {0.5f, 0.0f, 1003.0f}).ok());
  all.back().centre = {0.5f, 0.0f, 1003.0f};
  fresh = test::river_flow(mesh, params, all);
  expect_same_foam(*flow, *fresh, "the rock moved");
  expect_same_velocity(*flow, *fresh, "the rock moved");
}

INSTANTIATE_TEST_SUITE_P(IndexedAndWelded, RiverFlowMoves, ::testing::Bool());

// A keyed obstacle added at runtime to a river with no keyed one starts where its keys put it
// at the river's time, and moves as the time goes on (Renderer::add_obstacle's contract).
TEST(RiverFlowTest, AKeyedObstacleAddedAtRuntimeMovesWithTheTime) {
  const test::TestMesh mesh = test::symmetric_channel(10.0f, 400.0f, 401, 11);
  const FlowParams params{10.0f, 1.5f, 0.0f};
  auto flow = test::river_flow(mesh, params);
  ASSERT_TRUE(flow->set_time(5.0).ok());
  Obstacle boat = rock({0.0f, 0.0f, 100.0f});
  boat.keys = {{0.0, {0.0f, 0.0f, 100.0f}}, {10.0, {0.0f, 0.0f, 200.0f}}};
  ASSERT_TRUE(flow->add_obstacle(boat).ok());
  EXPECT_EQ(flow->obstacle_centre(0), glm::vec3(0.0f, 0.0f, 150.0f));
  ASSERT_TRUE(flow->set_time(8.0).ok());
  EXPECT_EQ(flow->obstacle_centre(0), glm::vec3(0.0f, 0.0f, 180.0f));
  auto fresh = test::river_flow(mesh, params, standing_at({boat}, 8.0));
  expect_same_foam(*flow, *fresh, "the added boat at t 8");
}

// What a host's river keeps of the host's arrays once river_input_from calls back (the host
// frees them there): none of its mesh where the surface's nodes and triangles are the mesh, the
// indices as the host wound them where the surface wound them otherwise (the foam and the
// queries add a triangle's corners in that order), the whole mesh where vertices were welded;
// the host's arrays are not read after the callback.
TEST(RiverFlowTest, AHostsRiverKeepsACopyOfItsMeshOnlyWhereTheSurfaceDiffers) {
  const test::TestMesh wound = test::straight_channel(6.0f, 40.0f, 21, 5);
  test::TestMesh rewound = wound;
  for (size_t t = 0; t < rewound.indices.size(); t += 6) {
    std::swap(rewound.indices[t + 1], rewound.indices[t + 2]);
  }
  test::TestMesh soup;
  for (const uint32_t i : wound.indices) soup.positions.push_back(wound.positions[i]);
  using Case = std::tuple<const test::TestMesh*, bool, bool>;  // keeps positions, indices
  for (const auto& [mesh, keeps_positions, keeps_indices] :
       {Case{&wound, false, false}, Case{&rewound, true, true}, Case{&soup, true, false}}) {
    const std::vector<float> depth(mesh->positions.size(), 1.0f),
        slope(mesh->positions.size(), 0.0f);
    test::TestMesh host = *mesh;  // spoiled where the host would free it
    WaterRiver river;
    river.positions = host.positions;
    river.indices = host.indices;
    river.depth = depth;
    river.slope = slope;
    int calls = 0;
    RiverInput input;
    const auto spoil = [&] {
      ++calls;
      std::ranges::fill(host.positions, glm::vec3(std::numeric_limits<float>::quiet_NaN()));
      std::ranges::fill(host.indices, 0xffffffffu);
    };
    ASSERT_TRUE(river_input_from(river, spoil, &input).ok());
    EXPECT_EQ(calls, 1);
    EXPECT_EQ(input.mesh.positions.empty(), !keeps_positions);
    if (keeps_positions) {
      EXPECT_TRUE(std::ranges::equal(input.mesh.positions, mesh->positions));
    }
    EXPECT_EQ(input.mesh.indices.empty(), !keeps_indices);
    if (keeps_indices) {
      EXPECT_TRUE(std::ranges::equal(input.mesh.indices, mesh->indices));
    }
  }
}

// A host's depth and slope are kept to 11 significant bits (binary16) and read back as such
// (by the particles and the queries); values a half cannot hold are refused, naming the vertex.
TEST(RiverFlowTest, AHostsDepthAndSlopeAreKeptAsHalvesAndRefusedBeyondThem) {
  const test::TestMesh mesh = test::straight_channel(6.0f, 40.0f, 21, 5);
  std::vector<float> depth(mesh.positions.size()), slope(mesh.positions.size());
  for (size_t v = 0; v < depth.size(); ++v) {
    depth[v] = 0.1f + 0.37f * float(v);
    slope[v] = 0.0013f * float(v % 7);
  }
  depth[1] = kLargestHalf;
  WaterRiver river;
  river.positions = mesh.positions;
  river.indices = mesh.indices;
  river.depth = depth;
  river.slope = slope;
  RiverInput input;
  ASSERT_TRUE(river_input_from(river, {}, &input).ok());
  ASSERT_EQ(input.depth.size(), depth.size());
  ASSERT_EQ(input.slope.size(), slope.size());
  EXPECT_TRUE(input.mesh.depth.empty());
  for (size_t v = 0; v < depth.size(); ++v) {
    EXPECT_EQ(input.depth[v], to_half(depth[v])) << "vertex " << v;
    EXPECT_EQ(input.slope[v], to_half(slope[v])) << "vertex " << v;
    EXPECT_NEAR(from_half(input.depth[v]), depth[v], depth[v] / 2048.0f) << "vertex " << v;
  }

  const auto refused = [&](const std::vector<float>& d, const std::vector<float>& s,
                           const char* part) {
    WaterRiver bad = river;
    bad.depth = d;
    bad.slope = s;
    RiverInput out;
    const Status status = river_input_from(bad, {}, &out);
    ASSERT_FALSE(status.ok()) << part;
    EXPECT_NE(status.message().find(part), std::string::npos) << status.message();
  };
  std::vector<float> deep = depth;
  deep[4] = 70000.0f;
  refused(deep, slope, "CreateInfo::river->depth[4] 70000 is not a depth from 0 to 65504 m");
  std::vector<float> cliff = slope;
  cliff[9] = std::numeric_limits<float>::infinity();
  refused(depth, cliff, "CreateInfo::river->slope[9] inf is not a slope from 0 to 65504");
  std::vector<float> unknown = depth;
  unknown[2] = std::numeric_limits<float>::quiet_NaN();
  refused(unknown, slope, "CreateInfo::river->depth[2] nan is not a depth from 0 to 65504 m");

  // The procedural river's too, and its mesh's floats freed.
  const ProceduralRiver procedural(default_river_params());
  RiverMesh generated;
  ASSERT_TRUE(procedural.generate_mesh(&generated).ok());
  RiverInput made;
  ASSERT_TRUE(procedural_river_input(procedural, &made).ok());
  EXPECT_TRUE(made.mesh.depth.empty() && made.mesh.slope.empty());
  ASSERT_EQ(made.depth.size(), generated.depth.size());
  ASSERT_EQ(made.slope.size(), generated.slope.size());
  for (size_t v = 0; v < made.depth.size(); ++v) {
    ASSERT_EQ(made.depth[v], to_half(generated.depth[v])) << "vertex " << v;
    ASSERT_EQ(made.slope[v], to_half(generated.slope[v])) << "vertex " << v;
  }
}

// RiverFlow::create takes the depth and slope as halves, one a vertex or none.
TEST(RiverFlowTest, CreateRefusesDepthsThatAreNotOneHalfAVertex) {
  const test::TestMesh mesh = test::straight_channel(6.0f, 40.0f, 21, 5);
  for (const int wrong : {0, 1}) {
    RiverInput input;
    if (wrong == 0) input.mesh.depth.assign(mesh.positions.size(), 1.0f);
    if (wrong == 1) input.depth.assign(mesh.positions.size() - 1, to_half(1.0f));
    ASSERT_TRUE(RiverSurface::build(mesh.positions, mesh.indices, {}, &input.surface).ok());
    RiverFlow flow;
    const Status status = flow.create(std::move(input), FlowParams{}, {});
    ASSERT_FALSE(status.ok()) << wrong;
    EXPECT_NE(status.message().find("RiverFlow::create: "), std::string::npos) << status.message();
  }
}

}  // namespace
}  // namespace siviflow
