// End to end against an independent answer: the flow a capture records (its flow AOV) where two
// tributaries of given discharges join, against the finite-difference Laplace oracle of the
// same Y (y_laplace_oracle.h), and pointing downstream; the scene names its ends by points.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <glm/geometric.hpp>
#include <string>
#include <vector>

#include "captured_flow.h"
#include "y_laplace_oracle.h"

namespace siviflow::testing {
namespace {

// A straight river 20 m wide and 120 m long, 1 m quads; two tributaries 10 m wide, 30 degrees
// apart, join at z = -20, the left (+X) bringing 12 m^2/s and the right 8. p = 1 with a search
// radius far beyond the width: plug flow between the borders, as potential flow has it.
constexpr const char* kScene = R"({"version":1,
  "river":{"procedural":{"length":120.0,"width":20.0,"width_variation":0.0,"meander_amplitude":0.0,
    "vertices_across":21,"section_spacing":1.0,
    "confluence":{"tip_z":-20.0,"offset":0.0,"angle_deg":30.0}},
    "ends":[{"near":[16.0,0.0,-60.0],"inflow":12.0},{"near":[-16.0,0.0,-60.0],"inflow":8.0},
            {"near":[0.0,0.0,60.0],"outflow":20.0}]},
  "flow":{"p":1.0,"search_radius":1000.0},
  "camera":{"fov_y_deg":50.0,"keys":[{"t":0.0,"position":[0.0,100.0,-14.99],"target":[0.0,0.0,-15.0]}]}})";

TEST(ConfluenceCapture, TheCapturedFlowIsTheOraclesWhereTheArmsJoin) {
  CapturedFlow captured;
  ASSERT_TRUE(capture_flow("confluence_capture", kScene, "640x360", &captured));
  const std::vector<float>* water = captured.water;
  const std::vector<float>* fx = captured.x;
  const std::vector<float>* fz = captured.z;

  // The oracle's Y has its tip at z = 0.
  test::YShape shape;
  shape.arm_width = 10.0;
  shape.main_length = 80.0;
  shape.left_length = 40.0;
  shape.right_length = 40.0;
  shape.spread = std::tan(15.0 * M_PI / 180.0);
  const test::YLaplaceOracle oracle(shape, 20.0, 8.0, 0.2);

  // Seen from 100 m above z = -15: screen right is +X, down is +Z.
  const double px_per_m = 180.0 / (100.0 * std::tan(25.0 * M_PI / 180.0));
  std::vector<double> errors, near_tip;
  size_t downstream = 0, sampled = 0;
  for (double z = -58.0; z <= 28.0; z += 1.0) {
    for (double x = -24.0; x <= 24.0; x += 0.5) {
      if (!oracle.inside(x, z + 20.0, 1.5)) continue;
      const int u = int(std::lround(320.0 + x * px_per_m)),
                v = int(std::lround(180.0 + (z + 15.0) * px_per_m));
      if (u < 0 || u >= 640 || v < 0 || v >= 360) continue;
      const size_t p = size_t(v) * 640u + size_t(u);
      if ((*water)[p] < 0.5f) continue;
      const glm::dvec3 expected = oracle.velocity(x, z + 20.0);
      const glm::dvec3 got((*fx)[p], 0.0, (*fz)[p]);
      const double error = glm::length(got - expected) / glm::length(expected);
      errors.push_back(error);
      if (std::abs(z + 20.0) < 5.0) near_tip.push_back(error);
      downstream += got.z > 0.0 ? 1 : 0;
      ++sampled;
    }
  }
  ASSERT_GT(sampled, 1500u);
  EXPECT_EQ(downstream, sampled) << "the flow points downstream everywhere";
  std::sort(errors.begin(), errors.end());
  std::sort(near_tip.begin(), near_tip.end());
  const double median = errors[errors.size() / 2], p90 = errors[errors.size() * 9 / 10];
  const double tip_median = near_tip[near_tip.size() / 2];
  RecordProperty("error", "median " + std::to_string(median) + ", 90th percentile " +
                              std::to_string(p90) + ", within 5 m of the tip " +
                              std::to_string(tip_median));
  std::printf("%zu samples: median %.4f, p90 %.4f, within 5 m of the tip (%zu) median %.4f\n",
              sampled, median, p90, near_tip.size(), tip_median);
  EXPECT_LT(median, 0.05);
  EXPECT_LT(p90, 0.15);
  EXPECT_LT(tip_median, 0.15);  // beside the tip the field bends most
}

}  // namespace
}  // namespace siviflow::testing
