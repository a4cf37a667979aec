#include "sim/water_heights.h"

#include <cmath>
#include <vector>

#include <gtest/gtest.h>

namespace siviflow {
namespace {

// A sloping strip of water along z: x in [0, 4], z in [0, 20], height -0.05 z, vertices 1 m apart.
std::vector<glm::vec3> sloping_strip() {
  std::vector<glm::vec3> points;
  for (int z = 0; z <= 20; ++z) {
    for (int x = 0; x <= 4; ++x) points.push_back({float(x), -0.05f * float(z), float(z)});
  }
  return points;
}

TEST(WaterHeights, CoversTheSurfaceAndItsMargin) {
  const WaterHeights grid = water_heights(sloping_strip(), 0.5f, 3.0f, 2048);
  EXPECT_FLOAT_EQ(grid.origin.x, -3.0f);
  EXPECT_FLOAT_EQ(grid.origin.y, -3.0f);
  EXPECT_FLOAT_EQ(grid.spacing, 0.5f);
  EXPECT_EQ(grid.columns, 21u);  // 10 m / 0.5 + 1
  EXPECT_EQ(grid.rows, 53u);     // 26 m / 0.5 + 1
  ASSERT_EQ(grid.heights.size(), size_t{grid.columns} * grid.rows);
  ASSERT_EQ(grid.steps.size(), grid.heights.size());
}

TEST(WaterHeights, SamplesOnTheWaterTakeItsHeight) {
  const WaterHeights grid = water_heights(sloping_strip(), 0.5f, 3.0f, 2048);
  for (uint32_t row = 0; row < grid.rows; ++row) {
    for (uint32_t column = 0; column < grid.columns; ++column) {
      const float x = grid.origin.x + grid.spacing * float(column);
      const float z = grid.origin.y + grid.spacing * float(row);
      if (x < 0.0f || x > 4.0f || z < 0.0f || z > 20.0f) continue;
      // The nearest vertex is at most half a metre away along z: 0.025 m of height.
      EXPECT_NEAR(grid.at(column, row), -0.05f * z, 0.025f + 1e-6f) << x << ", " << z;
      // Vertices sit on every other sample: the one between four of them is two steps away.
      EXPECT_LE(grid.steps[size_t{row} * grid.columns + column], 2u);
    }
  }
}

TEST(WaterHeights, SamplesBeyondTheBanksTakeTheNearestWaterAndSayHowFar) {
  const WaterHeights grid = water_heights(sloping_strip(), 0.5f, 3.0f, 2048);
  // Straight beside the strip at z = 10: the water's height there, 3 m (6 samples) out.
  const uint32_t row = 26;  // z = -3 + 13 = 10
  EXPECT_FLOAT_EQ(grid.at(0, row), -0.5f);
  EXPECT_EQ(grid.steps[size_t{row} * grid.columns + 0], 6u);
  EXPECT_FLOAT_EQ(grid.at(grid.columns - 1, row), -0.5f);
  // Beyond the upstream end, where the water is highest; the corner is 6 + 6 steps away.
  EXPECT_FLOAT_EQ(grid.at(10, 0), 0.0f);
  EXPECT_EQ(grid.steps[0], 12u);
  // Beyond the downstream end.
  EXPECT_FLOAT_EQ(grid.at(10, grid.rows - 1), -1.0f);
}

TEST(WaterHeights, WideSurfacesWidenTheSpacingToStayWithinTheCap) {
  const WaterHeights grid = water_heights(sloping_strip(), 0.1f, 0.0f, 11);
  EXPECT_FLOAT_EQ(grid.spacing, 2.0f);  // 20 m over 10 intervals
  EXPECT_EQ(grid.rows, 11u);
  EXPECT_LE(grid.columns, 11u);
}

TEST(WaterHeights, IsDeterministic) {
  const WaterHeights a = water_heights(sloping_strip(), 0.5f, 3.0f, 2048);
  const WaterHeights b = water_heights(sloping_strip(), 0.5f, 3.0f, 2048);
  EXPECT_EQ(a.heights, b.heights);
  EXPECT_EQ(a.steps, b.steps);
}

}  // namespace
}  // namespace siviflow
