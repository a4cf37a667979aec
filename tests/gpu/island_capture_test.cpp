// End to end against an independent answer: the flow a capture records (its flow AOV) about an
// island in a straight river, against the finite-difference Laplace oracle of the same channel
// and island (laplace_oracle.h), and pointing downstream.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <glm/geometric.hpp>
#include <string>
#include <vector>

#include "captured_flow.h"
#include "laplace_oracle.h"
#include "siviflow/sim/procedural_river.h"

namespace siviflow::testing {
namespace {

// A straight river 20 m wide and 120 m long, 1 m quads, an island 5 m wide and 40 m long 3 m
// towards the left bank. p = 1 with a search radius far beyond the width: plug flow between the
// borders, as potential flow has it.
constexpr const char* kScene = R"({"version":1,
  "river":{"procedural":{"length":120.0,"width":20.0,"width_variation":0.0,"meander_amplitude":0.0,
    "vertices_across":21,"section_spacing":1.0,
    "islands":[{"center_z":0.0,"offset":3.0,"length":40.0,"width":5.0}]}},
  "flow":{"discharge":20.0,"p":1.0,"search_radius":1000.0},
  "camera":{"fov_y_deg":50.0,"keys":[{"t":0.0,"position":[0.0,90.0,0.01],"target":[0.0,0.0,0.0]}]}})";

TEST(IslandCapture, TheCapturedFlowIsTheOraclesAboutTheIsland) {
  CapturedFlow captured;
  ASSERT_TRUE(capture_flow("island_capture", kScene, "320x180", &captured));
  const std::vector<float>* water = captured.water;
  const std::vector<float>* fx = captured.x;
  const std::vector<float>* fz = captured.z;

  // The oracle, on the very mesh the capture drew.
  ProceduralRiverParams params;
  params.length = 120.0f;
  params.width = 20.0f;
  params.width_variation = 0.0f;
  params.meander_amplitude = 0.0f;
  params.vertices_across = 21;
  params.islands = {{0.0f, 3.0f, 40.0f, 5.0f}};
  RiverMesh mesh;
  ASSERT_TRUE(ProceduralRiver(params).generate_mesh(&mesh).ok());
  const test::Channel channel{20.0, -60.0, 120.0, 1.0, 1.0};
  const test::QuadIsland island = test::island_of(channel, mesh.positions, mesh.indices);
  ASSERT_GT(island.cut.size(), 100u);
  const test::LaplaceOracle oracle(island, 20.0, 0.25);

  // Seen from 90 m: screen right is +X, down is +Z, 2.14 px a metre.
  const double px_per_m = 90.0 / (90.0 * std::tan(25.0 * M_PI / 180.0));
  std::vector<double> errors;
  size_t downstream = 0, sampled = 0;
  for (double z = -35.0; z <= 35.0; z += 1.0) {
    for (double x = -9.0; x <= 9.0; x += 0.5) {
      if (island.covers(x, z) || island.covers(x + 1.5, z) || island.covers(x - 1.5, z)) continue;
      const int u = int(std::lround(160.0 + x * px_per_m)),
                v = int(std::lround(90.0 + z * px_per_m));
      const size_t p = size_t(v) * 320u + size_t(u);
      if ((*water)[p] < 0.5f) continue;
      const glm::dvec3 expected = oracle.velocity(x, z);
      const glm::dvec3 got((*fx)[p], 0.0, (*fz)[p]);
      errors.push_back(glm::length(got - expected) / glm::length(expected));
      downstream += got.z > 0.0 ? 1 : 0;
      ++sampled;
    }
  }
  ASSERT_GT(sampled, 1000u);
  EXPECT_EQ(downstream, sampled) << "the flow points downstream everywhere";
  std::sort(errors.begin(), errors.end());
  const double median = errors[errors.size() / 2], p90 = errors[errors.size() * 9 / 10];
  RecordProperty("error",
                 "median " + std::to_string(median) + ", 90th percentile " + std::to_string(p90));
  EXPECT_LT(median, 0.05);
  EXPECT_LT(p90, 0.15);
}

}  // namespace
}  // namespace siviflow::testing
