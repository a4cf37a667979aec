// Islands in the stream function, against an independent oracle: a finite-difference solution of
// Laplace's equation for psi on a fine grid over the same channel and island, the island's psi
// set by zero circulation about it (superposition of two solves). The discharge split, the
// velocity field and the flux through every arm.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <set>
#include <utility>
#include <vector>

#include "siviflow/sim/stream_function.h"
#include "unit/river_test_meshes.h"

namespace siviflow {
namespace {

using test::TestMesh;

constexpr float kWidth = 10.0f;   // x from +5 (left bank, psi = Q) to -5 (right bank, psi = 0)
constexpr float kLength = 60.0f;  // z from 0 to 60, downstream
constexpr uint32_t kSections = 61, kAcross = 21;  // quads 1 m along, 0.5 m across
constexpr double kQ = 8.0;

// The island as the mesh has it: the quads of the grid (k along, j across) it lacks.
struct QuadIsland {
  std::set<std::pair<int, int>> cut;
  bool covers(double x, double z) const {  // inside or on the border of a cut quad
    const double j = (0.5 * kWidth - x) / (kWidth / (kAcross - 1)), k = z;
    for (const int dk : {0, -1}) {
      for (const int dj : {0, -1}) {
        const int qk = int(std::floor(k + 1e-9)) + dk, qj = int(std::floor(j + 1e-9)) + dj;
        if (k - qk > 1 + 1e-9 || j - qj > 1 + 1e-9) continue;
        if (cut.count({qk, qj})) return true;
      }
    }
    return false;
  }
};

QuadIsland island_of(const TestMesh& m) {
  std::set<std::pair<int, int>> present;
  for (size_t t = 0; t < m.indices.size(); t += 3) {
    const glm::vec3 c = (m.positions[m.indices[t]] + m.positions[m.indices[t + 1]] +
                         m.positions[m.indices[t + 2]]) /
                        3.0f;
    present.insert({int(std::floor(c.z)), int(std::floor((0.5f * kWidth - c.x) / 0.5f))});
  }
  QuadIsland island;
  for (int k = 0; k + 1 < int(kSections); ++k) {
    for (int j = 0; j + 1 < int(kAcross); ++j) {
      if (!present.count({k, j})) island.cut.insert({k, j});
    }
  }
  return island;
}

// psi on a grid of spacing h: Q on the left bank, 0 on the right, uniform flow at both ends, the
// island's psi the value of zero circulation about it.
class LaplaceOracle {
 public:
  LaplaceOracle(const QuadIsland& island, double h) : h_(h) {
    nx_ = int(std::lround(kWidth / h)) + 1;
    nz_ = int(std::lround(kLength / h)) + 1;
    island_.resize(size_t(nx_) * nz_);
    for (int i = 0; i < nx_; ++i) {
      for (int k = 0; k < nz_; ++k) island_[index(i, k)] = island.covers(x_of(i), k * h_);
    }
    const std::vector<double> base = relax(kQ, 0.0), unit = relax(0.0, 1.0);
    island_psi_ = -circulation(base) / circulation(unit);
    psi_.resize(base.size());
    for (size_t n = 0; n < base.size(); ++n) psi_[n] = base[n] + island_psi_ * unit[n];
  }

  double island_psi() const { return island_psi_; }
  // Velocity grad(psi) x +Y = (-dpsi/dz, 0, dpsi/dx), bilinear between central differences.
  glm::dvec3 velocity(double x, double z) const {
    const double fi = (0.5 * kWidth - x) / h_, fk = z / h_;
    const int i = std::clamp(int(fi), 1, nx_ - 3), k = std::clamp(int(fk), 1, nz_ - 3);
    const double u = fi - i, w = fk - k;
    glm::dvec3 v(0.0);
    for (const auto& [di, dk, weight] :
         {std::tuple{0, 0, (1 - u) * (1 - w)}, std::tuple{1, 0, u * (1 - w)},
          std::tuple{0, 1, (1 - u) * w}, std::tuple{1, 1, u * w}}) {
      const int a = i + di, b = k + dk;
      // x decreases with i.
      const double dpsi_dx = -(psi_[index(a + 1, b)] - psi_[index(a - 1, b)]) / (2 * h_);
      const double dpsi_dz = (psi_[index(a, b + 1)] - psi_[index(a, b - 1)]) / (2 * h_);
      v += weight * glm::dvec3(-dpsi_dz, 0.0, dpsi_dx);
    }
    return v;
  }

 private:
  size_t index(int i, int k) const { return size_t(k) * nx_ + size_t(i); }
  double x_of(int i) const { return 0.5 * kWidth - i * h_; }

  // Successive over-relaxation to a fixed point.
  std::vector<double> relax(double q, double island_value) const {
    std::vector<double> psi(size_t(nx_) * nz_);
    for (int k = 0; k < nz_; ++k) {
      for (int i = 0; i < nx_; ++i) {
        const double uniform = q * double(nx_ - 1 - i) / double(nx_ - 1);
        psi[index(i, k)] = island_[index(i, k)] ? island_value : uniform;
      }
    }
    const double omega = 2.0 / (1.0 + std::sin(M_PI * h_ / kWidth)) * 0.98;
    for (int sweep = 0; sweep < 100000; ++sweep) {
      double change = 0.0;
      for (int k = 1; k + 1 < nz_; ++k) {
        for (int i = 1; i + 1 < nx_; ++i) {
          const size_t n = index(i, k);
          if (island_[n]) continue;
          const double target = 0.25 * (psi[n - 1] + psi[n + 1] + psi[n - nx_] + psi[n + nx_]);
          change = std::max(change, std::abs(target - psi[n]));
          psi[n] += omega * (target - psi[n]);
        }
      }
      if (change < 1e-12 * std::max(1.0, q)) break;
    }
    return psi;
  }

  // Flux of grad(psi) out of a box of grid lines two steps outside the island.
  double circulation(const std::vector<double>& psi) const {
    int i0 = nx_, i1 = 0, k0 = nz_, k1 = 0;
    for (int k = 0; k < nz_; ++k) {
      for (int i = 0; i < nx_; ++i) {
        if (!island_[index(i, k)]) continue;
        i0 = std::min(i0, i - 2), i1 = std::max(i1, i + 2), k0 = std::min(k0, k - 2),
        k1 = std::max(k1, k + 2);
      }
    }
    const auto p = [&](int i, int k) { return psi[index(i, k)]; };
    double flux = 0.0;
    for (int i = i0; i < i1; ++i) {  // the upstream and downstream sides
      flux += 0.5 * (p(i, k0 - 1) - p(i, k0) + p(i + 1, k0 - 1) - p(i + 1, k0));
      flux += 0.5 * (p(i, k1 + 1) - p(i, k1) + p(i + 1, k1 + 1) - p(i + 1, k1));
    }
    for (int k = k0; k < k1; ++k) {  // the two sides
      flux += 0.5 * (p(i0 - 1, k) - p(i0, k) + p(i0 - 1, k + 1) - p(i0, k + 1));
      flux += 0.5 * (p(i1 + 1, k) - p(i1, k) + p(i1 + 1, k + 1) - p(i1, k + 1));
    }
    return flux;
  }

  double h_;
  int nx_ = 0, nz_ = 0;
  std::vector<uint8_t> island_;
  std::vector<double> psi_;
  double island_psi_ = 0.0;
};

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
  const LaplaceOracle oracle(island_of(m), 0.125);
  EXPECT_NEAR(oracle.island_psi() / kQ, 0.5, 0.01 * 0.5);  // the oracle's own symmetry
}

TEST(IslandFlow, AnOffCentreIslandSplitsTheDischargeAsLaplaceDoes) {
  for (const auto& [x, rx, rz] : {std::tuple{1.5f, 1.5f, 12.0f}, std::tuple{-2.0f, 1.0f, 6.0f}}) {
    const TestMesh m =
        test::channel_with_island(kWidth, kLength, kSections, kAcross, x, 30.0f, rx, rz);
    const StreamFunction flow = flow_around(m, 1.0f);
    const LaplaceOracle oracle(island_of(m), 0.125);
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
  const LaplaceOracle oracle(island_of(m), 0.125);
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
      arm.from_triangles += std::abs(flow.node_psi()[a] - flow.node_psi()[b]);
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
    size_t differ = 0;
    for (size_t n = 0; n < moved.node_psi().size(); ++n) {
      differ += moved.node_psi()[n] != fresh.node_psi()[n] ||
                moved.node_velocity()[n] != fresh.node_velocity()[n];
    }
    EXPECT_EQ(differ, 0u) << "rock at z = " << centre.z;
    for (const uint32_t n : moved.surface().island_nodes(0)) {
      EXPECT_EQ(moved.node_psi()[n], moved.island_psi(0)) << "shore vertex " << n;
    }
  }
}

}  // namespace
}  // namespace siviflow
