// Islands in the stream function, against an independent oracle (laplace_oracle.h: Laplace's
// equation for psi on a fine grid over the same channel and island, zero circulation about it):
// the discharge split, the velocity field and the flux through every arm.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <set>
#include <utility>
#include <vector>

#include "siviflow/sim/stream_function.h"
#include "laplace_oracle.h"
#include "unit/river_test_meshes.h"

namespace siviflow {
namespace {

using test::TestMesh;

constexpr float kWidth = 10.0f;   // x from +5 (left bank, psi = Q) to -5 (right bank, psi = 0)
constexpr float kLength = 60.0f;  // z from 0 to 60, downstream
constexpr uint32_t kSections = 61, kAcross = 21;  // quads 1 m along, 0.5 m across
constexpr double kQ = 8.0;

const test::Channel kChannel{kWidth, 0.0, kLength, kWidth / (kAcross - 1), 1.0};

test::QuadIsland island_of(const TestMesh& m) { return test::island_of(kChannel, m.positions, m.indices); }

StreamFunction flow_around(const TestMesh& m, float p, float search_radius = 0.0f) {
  RiverSurface surface;
  const Status built = RiverSurface::build(m.positions, m.indices, {}, &surface);
  EXPECT_TRUE(built.ok()) << built.message();
  StreamFunction flow;
  FlowParams params;
  params.discharge = float(kQ);
  params.p = p;
  params.search_radius = search_radius;
  const Status created = StreamFunction::create(std::move(surface), params, &flow);
  EXPECT_TRUE(created.ok()) << created.message();
  return flow;
}

TEST(IslandFlow, ASymmetricIslandSplitsTheDischargeInHalves) {
  const TestMesh m =
      test::channel_with_island(kWidth, kLength, kSections, kAcross, 0.0f, 30.0f, 2.0f, 10.0f);
  const StreamFunction flow = flow_around(m, 1.0f);
  ASSERT_EQ(flow.surface().islands().size(), 1u);
  EXPECT_NEAR(flow.island_psi(0) / kQ, 0.5, 0.01 * 0.5);
  const test::LaplaceOracle oracle(island_of(m), kQ, 0.125);
  EXPECT_NEAR(oracle.island_psi() / kQ, 0.5, 0.01 * 0.5);  // the oracle's own symmetry
}

TEST(IslandFlow, AnOffCentreIslandSplitsTheDischargeAsLaplaceDoes) {
  for (const auto& [x, rx, rz] : {std::tuple{1.5f, 1.5f, 12.0f}, std::tuple{-2.0f, 1.0f, 6.0f}}) {
    const TestMesh m =
        test::channel_with_island(kWidth, kLength, kSections, kAcross, x, 30.0f, rx, rz);
    const StreamFunction flow = flow_around(m, 1.0f);
    const test::LaplaceOracle oracle(island_of(m), kQ, 0.125);
    // The right arm carries psi_island - 0, the left Q - psi_island: the smaller within 3 %.
    const double right = flow.island_psi(0), right_oracle = oracle.island_psi();
    const double smaller = std::min(right_oracle, kQ - right_oracle);
    EXPECT_NEAR(right, right_oracle, 0.03 * smaller) << "island at x = " << x;
    RecordProperty("split_" + std::to_string(int(x * 10)),
                   std::to_string(right / kQ) + " vs " + std::to_string(right_oracle / kQ));
  }
}

TEST(IslandFlow, VelocitiesAgreeWithLaplaceAwayFromTheEnds) {
  const TestMesh m =
      test::channel_with_island(kWidth, kLength, kSections, kAcross, 1.5f, 30.0f, 1.5f, 12.0f);
  // p = 1 with a search radius far beyond the width: psi linear across each arm, plug flow, which
  // is what potential flow gives in a straight arm (the default p = 1.5 slows the water at the
  // shores on purpose, and potential flow does not).
  const StreamFunction flow = flow_around(m, 1.0f, 1000.0f);
  const test::LaplaceOracle oracle(island_of(m), kQ, 0.125);
  std::vector<double> errors;
  const RiverSurface& s = flow.surface();
  for (uint32_t n = 0; n < s.node_count(); ++n) {
    const glm::vec3 p = s.node_positions()[n];
    // Not on the island's shore: the oracle's central differences there reach into the island.
    if (p.z < 10.0f || p.z > 50.0f || s.on_island(n)) continue;
    const glm::dvec3 expected = oracle.velocity(p.x, p.z);
    errors.push_back(glm::length(glm::dvec3(flow.node_velocity()[n]) - expected) /
                     glm::length(expected));
  }
  std::nth_element(errors.begin(), errors.begin() + long(errors.size() / 2), errors.end());
  EXPECT_LT(errors[errors.size() / 2], 0.05);
}

// The discharge through each arm of a section, from the vertex velocities (the trapezoid rule)
// or, exactly, from the triangles' (whose flux through an edge is the psi difference along it).
struct ArmFlux {
  size_t section;
  double width;
  double from_vertices;
  double from_triangles;
  double expected;  // psi at the arm's left border minus psi at its right
};

std::vector<ArmFlux> arm_fluxes(const StreamFunction& flow) {
  const RiverSurface& s = flow.surface();
  std::vector<ArmFlux> arms;
  for (size_t k = 1; k + 1 < s.sections().size(); ++k) {
    const auto nodes = s.section_nodes(k);
    ArmFlux arm{k, 0.0, 0.0, 0.0, 0.0};
    double start_psi = flow.border_psi(kLeftBankBorder);
    for (size_t i = 1; i < nodes.size(); ++i) {
      const uint32_t a = nodes[i - 1], b = nodes[i];
      if (s.on_island(a) && s.on_island(b)) {  // along a shore, or across the island
        start_psi = flow.border_psi(s.node(b).left_border);
        continue;
      }
      const glm::vec3 pa = s.node_positions()[a], pb = s.node_positions()[b];
      const double dx = std::abs(pa.x - pb.x);
      arm.width += dx;
      arm.from_vertices += 0.5 * double(flow.node_velocity()[a].z + flow.node_velocity()[b].z) * dx;
      arm.from_triangles += std::abs(flow.node_psi(a) - flow.node_psi(b));
      const bool last = i + 1 == nodes.size();
      if (!s.on_island(b) && !last) continue;
      const double end_psi = flow.border_psi(last ? kRightBankBorder : s.node(b).left_border);
      arm.expected = start_psi - end_psi;
      arms.push_back(arm);
      arm = ArmFlux{k, 0.0, 0.0, 0.0, 0.0};
      start_psi = end_psi;
    }
  }
  return arms;
}

TEST(IslandFlow, EveryArmOfEverySectionCarriesItsDischarge) {
  const TestMesh m =
      test::channel_with_island(kWidth, kLength, kSections, kAcross, 1.5f, 30.0f, 1.5f, 12.0f);
  for (const float p : {1.0f, 1.5f}) {
    const StreamFunction flow = flow_around(m, p);
    const std::vector<ArmFlux> arms = arm_fluxes(flow);
    EXPECT_GT(arms.size(), flow.surface().sections().size());  // those beside the island have two
    size_t smooth = 0;
    for (size_t i = 0; i < arms.size(); ++i) {
      const ArmFlux& arm = arms[i];
      EXPECT_NEAR(arm.from_triangles, arm.expected, 1e-9 * kQ) << "section " << arm.section;
      // Where the island's shore steps (the quads cut from the grid), an arm is half a metre
      // wider than the one before it and the vertex velocities average the two: within 8 %.
      EXPECT_NEAR(arm.from_vertices, arm.expected, 0.08 * arm.expected)
          << "section " << arm.section;
      // The arms as wide as in the sections on both sides: within 1 %.
      const auto same = [&](size_t j) {
        return j < arms.size() && arms[j].section != arm.section &&
               std::abs(arms[j].width - arm.width) < 1e-4 && arms[j].expected == arm.expected;
      };
      const bool before = (i >= 1 && same(i - 1)) || (i >= 2 && same(i - 2));
      const bool after = same(i + 1) || same(i + 2);
      if (!before || !after) continue;
      EXPECT_NEAR(arm.from_vertices, arm.expected, 0.01 * arm.expected)
          << "section " << arm.section;
      ++smooth;
    }
    EXPECT_GT(smooth, arms.size() / 2);
  }
}

// A rock moved about an island's arm re-solves only near it, and the field is then the one a
// fresh river with the rock where it now is gives, bit for bit; the island's shore keeps its psi.
TEST(IslandFlow, ARockMovedInAnArmEqualsAFreshSolve) {
  const TestMesh m =
      test::channel_with_island(kWidth, kLength, kSections, kAcross, 1.5f, 30.0f, 1.5f, 12.0f);
  StreamFunction moved = flow_around(m, 1.5f, 12.0f);
  Obstacle rock;
  rock.radius = 0.6f;
  rock.centre = {-2.0f, 0.0f, 10.0f};
  ASSERT_TRUE(moved.set_obstacles({rock}).ok());
  for (const glm::vec3 centre : {glm::vec3(-2.0f, 0.0f, 28.0f), glm::vec3(4.2f, 0.0f, 33.0f),
                                 glm::vec3(1.5f, 0.0f, 44.0f)}) {
    ASSERT_TRUE(moved.move_obstacle(0, centre).ok());
    EXPECT_LT(moved.last_update().nodes_resolved, moved.surface().node_count());  // not a full solve
    StreamFunction fresh = flow_around(m, 1.5f, 12.0f);
    rock.centre = centre;
    ASSERT_TRUE(fresh.set_obstacles({rock}).ok());
    EXPECT_EQ(test::nodes_that_differ(moved, fresh), 0u) << "rock at z = " << centre.z;
    for (const uint32_t n : moved.surface().island_nodes(0)) {
      EXPECT_EQ(moved.node_psi(n), moved.island_psi(0)) << "shore vertex " << n;
    }
  }
}

}  // namespace
}  // namespace siviflow
