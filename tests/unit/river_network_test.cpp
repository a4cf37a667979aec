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

using test::triangle_on_edge;
using test::YMesh;

const test::YShape kShape;  // arms 4 m wide, main 24 m, left arm 16 m, right 10 m, spread 0.25
constexpr float kDz = 0.5f;
constexpr uint32_t kAcross = 8;
constexpr double kLeftQ = 2.0, kRightQ = 1.0;

YMesh y_mesh(const test::YShape& shape = kShape) {
  return test::y_channel(float(shape.arm_width), float(shape.main_length), float(shape.left_length),
                         float(shape.right_length), float(shape.spread), kDz, kAcross);
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
    if (s.node_positions()[n].z == z) row.emplace_back(s.node_positions()[n].x, flow.node_psi(n));
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

// A network's build flags the triangles it wound otherwise, as a strip's does.
TEST(RiverNetwork, RewoundFlagsTheTrianglesGivenClockwise) {
  YMesh y = y_mesh();
  for (size_t t = 0; t < y.mesh.indices.size() / 3; t += 2) {
    std::swap(y.mesh.indices[3 * t + 1], y.mesh.indices[3 * t + 2]);
  }
  std::vector<bool> rewound(7, true);  // what a build must replace, not extend
  RiverSurfaceOptions options = confluence_ends(y);
  options.rewound = &rewound;
  const RiverSurface s = surface_of(y, options);
  ASSERT_EQ(rewound.size(), y.mesh.indices.size() / 3);
  std::vector<uint32_t> given_back(s.triangles().begin(), s.triangles().end());
  for (size_t t = 0; t < rewound.size(); ++t) {
    if (rewound[t]) std::swap(given_back[3 * t + 1], given_back[3 * t + 2]);
  }
  EXPECT_EQ(given_back, y.mesh.indices);
  EXPECT_GT(std::ranges::count(rewound, true), 0);
  EXPECT_LT(std::ranges::count(rewound, true), static_cast<long>(rewound.size()));
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
    for (const auto& [left_q, right_q] :
         {std::pair{2.0, 1.0}, std::pair{1.0, 3.0}, std::pair{1.0, 1.0}}) {
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
        EXPECT_NEAR(ours, theirs, 0.02 * width) << "spread " << shape.spread << ", inflows "
                                                << left_q << " and " << right_q << ", z = " << z;
        worst = std::max(worst, std::abs(ours - theirs));
      }
      // Far downstream, the discharges' own split: the right inflow's share of the width.
      EXPECT_NEAR(mesh_crossing(flow, 16.0f, psi_tongue),
                  -shape.arm_width + width * right_q / (left_q + right_q), 1e-3 * width);
      std::printf(
          "spread %.2f, inflows %.0f and %.0f: the parting streamline within %.3f m of the "
          "oracle's\n",
          shape.spread, left_q, right_q, worst);
    }
  }
}

// Every arm of every section carries the difference of psi between its borders: exactly by the
// triangles' velocities (P1), within 1 % by the vertex velocities away from the tip (where the
// parting streamline bends), within 3 % beside it; the outflow carries both inflows.
TEST(RiverNetwork, EveryArmOfEverySectionCarriesItsDischarge) {
  for (const float p : {1.0f, 1.5f}) {
    const StreamFunction flow = confluence_flow(p, 0.0f);
    const RiverSurface& s = flow.surface();
    const auto pos = s.node_positions();
    const auto vel = flow.node_velocity();
    size_t arms = 0;
    for (size_t k = 0; k < s.sections().size(); ++k) {
      const auto nodes = s.section_nodes(k);
      size_t first = 0;
      for (size_t i = 1; i <= nodes.size(); ++i) {
        const bool arm_ends =
            i == nodes.size() || triangle_on_edge(s, nodes[i - 1], nodes[i]) == UINT32_MAX;
        if (!arm_ends) continue;
        const double expected = flow.node_psi(nodes[first]) - flow.node_psi(nodes[i - 1]);
        double by_vertices = 0.0;
        const double by_triangles = test::triangle_flux(flow, k, first, i - 1);
        for (size_t j = first; j + 1 < i; ++j) {
          const glm::vec3 &u = pos[nodes[j]], &w = pos[nodes[j + 1]];
          const glm::dvec3 v = 0.5 * (glm::dvec3(vel[nodes[j]]) + glm::dvec3(vel[nodes[j + 1]]));
          by_vertices +=
              glm::dot(v, test::segment_normal(u, w)) * glm::distance(glm::dvec3(u), glm::dvec3(w));
        }
        const float z = pos[nodes[first]].z;
        EXPECT_GT(expected, 0.0) << "section " << k;
        EXPECT_NEAR(by_triangles, expected, 1e-6 * (kLeftQ + kRightQ)) << "section " << k;
        const bool beside_tip = z > -1.0f && z < 12.0f;
        EXPECT_NEAR(by_vertices, expected, (beside_tip ? 0.03 : 0.01) * expected)
            << "p " << p << ", section " << k << " at z = " << z;
        ++arms;
        first = i;
      }
    }
    EXPECT_GT(arms, s.sections().size());  // the tributaries' sections have two
    const RiverEnd& out = s.ends()[0];
    EXPECT_NEAR(test::vertex_flux(flow, out.section), kLeftQ + kRightQ, 0.01 * (kLeftQ + kRightQ));
  }
}

// Without named ends the end holding the upstream vertex is the only inflow: the Y read from its
// wide end is a fork, its outflows sharing the discharge by width (here equal).
TEST(RiverNetwork, AForkSharesTheDischargeByTheWidthOfItsOutflows) {
  const YMesh y = y_mesh();
  RiverSurfaceOptions options;
  options.upstream_vertex = y.main_end;
  RiverSurface s = surface_of(y, options);
  ASSERT_EQ(s.ends().size(), 3u);
  EXPECT_TRUE(s.ends()[0].inflow);
  EXPECT_FALSE(s.ends()[1].inflow);
  EXPECT_FALSE(s.ends()[2].inflow);
  EXPECT_EQ(s.ends()[0].section, 0u);
  FlowParams params;
  params.discharge = 6.0f;
  StreamFunction flow;
  ASSERT_TRUE(StreamFunction::create(std::move(s), params, &flow).ok());
  EXPECT_NEAR(flow.end_discharge(1), 3.0, 1e-6);
  EXPECT_NEAR(flow.end_discharge(2), 3.0, 1e-6);
  EXPECT_NEAR(flow.border_psi(island_border(0)), 3.0, 1e-6);
  // The water flows away from the wide end: down the main channel towards -Z.
  for (uint32_t n = 0; n < flow.surface().node_count(); ++n) {
    if (flow.surface().node_positions()[n].z > 1.0f) {
      EXPECT_LT(flow.node_velocity()[n].z, 0.0f) << n;
    }
  }
}

// A rock moved about the junction re-solves only near it, and the field then equals a fresh
// river's with the rock where it now is, bit for bit.
TEST(RiverNetwork, ARockMovedAboutTheJunctionEqualsAFreshSolve) {
  StreamFunction moved = confluence_flow(1.5f, 9.0f);
  Obstacle rock;
  rock.radius = 0.5f;
  rock.centre = {2.0f, 0.0f, -6.0f};
  ASSERT_TRUE(moved.set_obstacles({rock}).ok());
  for (const glm::vec3 centre :
       {glm::vec3(-2.0f, 0.0f, -3.0f), glm::vec3(0.5f, 0.0f, 1.5f), glm::vec3(-1.0f, 0.0f, 9.0f)}) {
    ASSERT_TRUE(moved.move_obstacle(0, centre).ok());
    EXPECT_LT(moved.last_update().nodes_resolved, moved.surface().node_count());
    StreamFunction fresh = confluence_flow(1.5f, 9.0f);
    rock.centre = centre;
    ASSERT_TRUE(fresh.set_obstacles({rock}).ok());
    EXPECT_EQ(test::nodes_that_differ(moved, fresh), 0u) << "rock at z = " << centre.z;
  }
}

// Three arms meeting on one row (two tips side by side), and two meeting about a blunt tongue
// (its end square, 2 cells wide): the field beyond the tips bends from them, with no jump across
// the river at the tips' row. p = 1 and a wide radius: plug flow, Q / W, away from the tips.
TEST(RiverNetwork, ArmsMeetingSideBySideOrAboutABluntTongueJumpNowhere) {
  for (const auto& [arms, blunt] : {std::pair{3u, 0u}, std::pair{2u, 2u}}) {
    const std::vector<float> lengths(arms, 10.0f);
    const test::FanMesh fan =
        test::fan_channel(4.0f, 24.0f, lengths, 0.25f, 0.5f, 8, nullptr, blunt);
    RiverSurfaceOptions options;
    options.ends.push_back({fan.main_end, false});
    std::vector<float> per_mark{5.0f};
    for (uint32_t i = 0; i < arms; ++i) {
      options.ends.push_back({fan.arm_ends[i], true});
      per_mark.push_back(i == 0 ? 3.0f : 2.0f / float(arms - 1));
    }
    RiverSurface s;
    const Status built = RiverSurface::build(fan.mesh.positions, fan.mesh.indices, options, &s);
    ASSERT_TRUE(built.ok()) << built.message();
    FlowParams params;
    params.discharge = 5.0f;
    params.p = 1.0f;
    params.search_radius = 1000.0f;
    params.end_discharges = by_end(s, per_mark);
    StreamFunction flow;
    ASSERT_TRUE(StreamFunction::create(std::move(s), params, &flow).ok());
    const float width = float(arms) * 4.0f + float(arms - 1) * 0.5f * float(blunt);
    const double plug = 5.0 / width;
    double fastest = 0.0;
    for (uint32_t n = 0; n < flow.surface().node_count(); ++n) {
      const glm::vec3 p = flow.surface().node_positions()[n];
      if (p.z < -1.0f || p.z > 3.0f) continue;
      fastest = std::max(fastest, double(glm::length(flow.node_velocity()[n])));
    }
    // The left arm brings 3 of 5 m^2/s in 4 m: 0.75 m/s against the plug flow's 5 / 12.
    EXPECT_LT(fastest, 2.5 * plug) << arms << " arms, blunt " << blunt << ": plug flow " << plug;
    EXPECT_EQ(flow.surface().ends().size(), arms + 1);
  }
}

void expect_flow_error(const std::vector<float>& discharges, float total,
                       std::initializer_list<const char*> parts) {
  const YMesh y = y_mesh();
  RiverSurface s = surface_of(y, confluence_ends(y));
  FlowParams params;
  params.discharge = total;
  params.end_discharges = by_end(s, discharges);
  StreamFunction flow;
  const Status status = StreamFunction::create(std::move(s), params, &flow);
  ASSERT_FALSE(status.ok());
  for (const char* part : parts) {
    EXPECT_NE(status.message().find(part), std::string::npos)
        << status.message() << " lacks " << part;
  }
}

TEST(RiverNetwork, DischargesThatDoNotBalanceAreRefused) {
  expect_flow_error({2.0f, 1.0f, 2.5f}, 3.0f,
                    {"do not balance", "3 m^2/s flows in", "2.5 m^2/s out"});
  expect_flow_error({2.0f, -1.0f, 1.0f}, 1.0f, {"-1", "inflow", "0 or more"});
  expect_flow_error({2.0f, 1.0f, 3.0f}, 4.0f, {"bring in 3", "discharge is 4"});
}

void expect_surface_error(const RiverSurfaceOptions& options,
                          std::initializer_list<const char*> parts) {
  const YMesh y = y_mesh();
  RiverSurface s;
  const Status status = RiverSurface::build(y.mesh.positions, y.mesh.indices, options, &s);
  ASSERT_FALSE(status.ok());
  for (const char* part : parts) {
    EXPECT_NE(status.message().find(part), std::string::npos)
        << status.message() << " lacks " << part;
  }
}

TEST(RiverNetwork, EndsNamedWronglyAreRefused) {
  const YMesh y = y_mesh();
  RiverSurfaceOptions options = confluence_ends(y);
  options.ends[1].vertex = 5;  // on the tip's row, in mid-river
  expect_surface_error(options, {"ends[1]", "vertex 5", "not on an end"});
  options = confluence_ends(y);
  options.ends.pop_back();
  options.ends[1].inflow = false;  // two ends named of three
  expect_surface_error(options, {"not a strip", "6 corners", "name every end"});
  options.ends[1].inflow = true;
  expect_surface_error(options, {"both named ends are inflows"});
  options = confluence_ends(y);
  options.ends.push_back({y.main_end, false});
  expect_surface_error(options, {"4 ends are named", "has 3"});
  options = confluence_ends(y);
  options.ends[2].inflow = true;
  expect_surface_error(options, {"3 inflows and 0 outflows"});
  options = confluence_ends(y);
  options.ends[2].vertex = 100000;
  expect_surface_error(options, {"ends[2]", "vertex 100000", "not in the river mesh"});
}

}  // namespace
}  // namespace siviflow
