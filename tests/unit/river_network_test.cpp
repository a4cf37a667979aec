// River networks: a Y of two arms into one channel (a confluence, or read downstream-up a fork):
// its ends, arms and borders; the discharge each end brings; the streamline parting the arms
// against a fine-grid Laplace oracle; mass conservation in every arm; bad ends refused.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>

#include "river_network_meshes.h"
#include "siviflow/sim/river_surface.h"
#include "siviflow/sim/stream_function.h"
#include "y_laplace_oracle.h"

namespace siviflow {
namespace {

using test::YMesh;

const test::YShape kShape;  // arms 4 m wide, main 24 m, left arm 16 m, right 10 m, spread 0.25
constexpr float kDz = 0.5f;
constexpr uint32_t kAcross = 8;
constexpr double kLeftQ = 2.0, kRightQ = 1.0;

YMesh y_mesh(const test::YShape& shape = kShape) {
  return test::y_channel(float(shape.arm_width), float(shape.main_length),
                         float(shape.left_length), float(shape.right_length), float(shape.spread),
                         kDz, kAcross);
}

RiverSurfaceOptions confluence_ends(const YMesh& y) {
  RiverSurfaceOptions options;
  options.ends = {{y.left_end, true}, {y.right_end, true}, {y.main_end, false}};
  return options;
}

RiverSurface surface_of(const YMesh& y, const RiverSurfaceOptions& options) {
  RiverSurface s;
  const Status built = RiverSurface::build(y.mesh.positions, y.mesh.indices, options, &s);
  EXPECT_TRUE(built.ok()) << built.message();
  return s;
}

// The discharges in RiverSurface::ends() order, from the ends' marks.
std::vector<float> by_end(const RiverSurface& s, const std::vector<float>& per_mark) {
  std::vector<float> q;
  for (const RiverEnd& end : s.ends()) q.push_back(per_mark[end.mark]);
  return q;
}

StreamFunction confluence_flow(float p, float search_radius, double left_q = kLeftQ,
                               double right_q = kRightQ, const test::YShape& shape = kShape) {
  const YMesh y = y_mesh(shape);
  RiverSurface s = surface_of(y, confluence_ends(y));
  FlowParams params;
  params.discharge = float(left_q + right_q);
  params.p = p;
  params.search_radius = search_radius;
  params.end_discharges = by_end(s, {float(left_q), float(right_q), float(left_q + right_q)});
  StreamFunction flow;
  const Status created = StreamFunction::create(std::move(s), params, &flow);
  EXPECT_TRUE(created.ok()) << created.message();
  return flow;
}

// The x where psi crosses `value` along the mesh row at z, from +X towards -X.
double mesh_crossing(const StreamFunction& flow, float z, double value) {
  const RiverSurface& s = flow.surface();
  std::vector<std::pair<float, double>> row;
  for (uint32_t n = 0; n < s.node_count(); ++n) {
    if (s.node_positions()[n].z == z) row.emplace_back(s.node_positions()[n].x, flow.node_psi()[n]);
  }
  std::sort(row.begin(), row.end(), [](const auto& a, const auto& b) { return a.first > b.first; });
  for (size_t i = 0; i + 1 < row.size(); ++i) {
    const double a = row[i].second, b = row[i + 1].second;
    if ((a - value) * (b - value) <= 0.0 && a != b) {
      return row[i].first + (row[i + 1].first - row[i].first) * (a - value) / (a - b);
    }
  }
  return NAN;
}

TEST(RiverNetwork, AConfluenceHasThreeEndsTwoArmsAndATongue) {
  const YMesh y = y_mesh();
  const RiverSurface s = surface_of(y, confluence_ends(y));
  ASSERT_TRUE(s.network());
  ASSERT_EQ(s.ends().size(), 3u);
  EXPECT_FALSE(s.ends()[0].inflow);  // the root: the single outflow
  EXPECT_EQ(s.ends()[0].mark, 2u);
  EXPECT_EQ(s.border_count(), 3u);
  EXPECT_EQ(s.banks().size(), 3u);
  const BorderId tongue = island_border(0);
  for (uint32_t n = 0; n < s.node_count(); ++n) {
    const glm::vec3 p = s.node_positions()[n];
    const RiverVertex v = s.node(n);
    if (p.z > 0.0f) {  // the main channel: between the outer banks
      EXPECT_EQ(v.left_border, kLeftBankBorder) << n;
      EXPECT_EQ(v.right_border, kRightBankBorder) << n;
      EXPECT_NEAR(v.d_left + v.d_right, 2 * kShape.arm_width, 1e-4) << n;
      EXPECT_NEAR(v.d_left, kShape.arm_width - p.x, 1e-4) << n;
    } else if (p.z < 0.0f && s.on_tongue(n)) {
      EXPECT_EQ(v.left_border, tongue);
    } else if (p.z < 0.0f && v.bank == Bank::kNone) {
      // Each arm between its outer bank and the tongue.
      EXPECT_EQ(v.left_border, p.x > 0.0f ? kLeftBankBorder : tongue) << n;
      EXPECT_EQ(v.right_border, p.x > 0.0f ? tongue : kRightBankBorder) << n;
      EXPECT_NEAR(v.d_left + v.d_right, kShape.arm_width, 1e-4) << n;
    }
  }
  // Sections run upstream to downstream: the main channel's end is the last.
  EXPECT_EQ(s.ends()[0].section, s.sections().size() - 1);
  EXPECT_NEAR(s.sections().back().along - s.sections().front().along,
              kShape.main_length + kShape.left_length, 0.05 * kShape.main_length);
}

// The streamline parting the two inflows (psi = the tongue's) against the oracle's, row by row
// from half a metre past the tip to 16 m on: within 3 % of the 8 m channel everywhere, so it leaves
// from the tip and bends to where the discharges put it as potential flow does. With p = 1 and
// a wide search radius the straight reaches carry plug flow, which is potential flow there.
TEST(RiverNetwork, TheStreamlineBetweenTheArmsLeavesTheTipAsLaplaceSays) {
  test::YShape wide = kShape;  // a blunter tongue, the arms 53 degrees apart
  wide.spread = 0.5;
  wide.left_length = 8.0;
  for (const test::YShape& shape : {kShape, wide}) {
    for (const auto& [left_q, right_q] : {std::pair{2.0, 1.0}, std::pair{1.0, 3.0}, std::pair{1.0, 1.0}}) {
      const StreamFunction flow = confluence_flow(1.0f, 1000.0f, left_q, right_q, shape);
      const double psi_tongue = flow.border_psi(island_border(0));
      EXPECT_NEAR(psi_tongue, right_q, 1e-9);
      EXPECT_NEAR(flow.border_psi(kLeftBankBorder), left_q + right_q, 1e-9);
      const test::YLaplaceOracle oracle(shape, left_q + right_q, right_q, 0.05);
      const double width = 2 * shape.arm_width;
      double worst = 0.0;
      for (const float z : {0.5f, 1.0f, 1.5f, 2.0f, 3.0f, 4.0f, 6.0f, 8.0f, 12.0f, 16.0f}) {
        const double ours = mesh_crossing(flow, z, psi_tongue);
        const double theirs = oracle.crossing(z, psi_tongue);
        EXPECT_NEAR(ours, theirs, 0.02 * width)
            << "spread " << shape.spread << ", inflows " << left_q << " and " << right_q << ", z = " << z;
        worst = std::max(worst, std::abs(ours - theirs));
      }
      // Far downstream, the discharges' own split: the right inflow's share of the width.
      EXPECT_NEAR(mesh_crossing(flow, 16.0f, psi_tongue),
                  -shape.arm_width + width * right_q / (left_q + right_q), 1e-3 * width);
      std::printf("spread %.2f, inflows %.0f and %.0f: the parting streamline within %.3f m of the "
                  "oracle's\n", shape.spread, left_q, right_q, worst);
    }
  }
}

}  // namespace
}  // namespace siviflow
