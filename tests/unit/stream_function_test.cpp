// Stream-function flow against the analytic oracles of algorithms.md §6, flux conservation,
// obstacles, incremental re-solves and determinism.
#include "siviflow/sim/stream_function.h"

#include <cmath>
#include <string>

#include <gtest/gtest.h>

#include "siviflow/sim/procedural_river.h"
#include "unit/river_test_meshes.h"

namespace siviflow {
namespace {

using test::TestMesh;

StreamFunction make_flow(const TestMesh& m, const FlowParams& params) {
  RiverSurface surface;
  const Status built = RiverSurface::build(m.positions, m.indices, {}, &surface);
  EXPECT_TRUE(built.ok()) << built.message();
  StreamFunction flow;
  const Status created = StreamFunction::create(std::move(surface), params, &flow);
  EXPECT_TRUE(created.ok()) << created.message();
  return flow;
}

double blend(double t) { return t * t * t * (t * (6 * t - 15) + 10); }

// algorithms.md §6.2: psi across a straight channel of width W, d_r from the right bank.
double closed_form_psi(double d_r, double width, double q, double p, double s) {
  auto w = [&](double d) { return d >= s ? 0.0 : std::pow(d, -p) * blend(1.0 - d / s); };
  const double d_l = width - d_r;
  if (d_r <= 0) return 0.0;
  if (d_l <= 0) return q;
  return q * w(d_l) / (w(d_l) + w(d_r));
}

// Every section carries Q: exactly with the triangle velocities (the discrete identity), within
// 1 % with the vertex velocities; and no flow through the banks.
void expect_conserves_discharge(const StreamFunction& flow, double vertex_tolerance = 0.01) {
  const double q = flow.params().discharge;
  const RiverSurface& s = flow.surface();
  for (size_t k = 0; k < s.sections().size(); ++k) {
    const size_t n = s.section_nodes(k).size();
    EXPECT_NEAR(test::triangle_flux(flow, k, 0, n - 1), q, 1e-5 * q) << "section " << k;
    EXPECT_NEAR(test::vertex_flux(flow, k), q, vertex_tolerance * q) << "section " << k;
  }
  const auto pos = s.node_positions();
  const auto vel = flow.node_velocity();
  const size_t last = s.sections().size() - 1;
  for (size_t k = 0; k <= last; ++k) {
    for (const bool left : {true, false}) {
      auto shore = [&](size_t j) { return left ? s.section_nodes(j).front() : s.section_nodes(j).back(); };
      const uint32_t a = shore(k);
      if (k < last) {
        // The triangle on a bank edge: psi is constant along it, so v is parallel to it.
        const uint32_t b = shore(k + 1);
        const glm::dvec3 along = glm::normalize(glm::dvec3(pos[b] - pos[a]));
        const glm::dvec3 normal = glm::cross(glm::dvec3(0, 1, 0), along);
        const glm::dvec3 vt(flow.triangle_velocity(test::triangle_on_edge(s, a, b)));
        EXPECT_NEAR(glm::dot(vt, normal), 0.0, 1e-5 * (glm::length(vt) + 1e-3)) << "section " << k;
      }
      // The vertex velocity on a bank slides along the bank (its local tangent).
      const glm::dvec3 along =
          glm::normalize(glm::dvec3(pos[shore(std::min(k + 1, last))] - pos[shore(k == 0 ? 0 : k - 1)]));
      const glm::dvec3 normal = glm::cross(glm::dvec3(0, 1, 0), along);
      const glm::dvec3 va(vel[a]);
      EXPECT_NEAR(glm::dot(va, normal), 0.0, 1e-5 * (glm::length(va) + 1e-3)) << "section " << k;
    }
  }
}

TEST(StreamFunction, StraightChannelP1IsUniform) {
  const float width = 10.0f, q = 20.0f;
  StreamFunction flow = make_flow(test::straight_channel(width, 40.0f, 41, 11),
                                  {q, 1.0f, 100.0f * width});
  for (size_t v = 0; v < flow.surface().vertex_count(); ++v) {
    const glm::vec3 vel = flow.velocity(v);
    EXPECT_NEAR(vel.z, q / width, 0.01 * q / width) << "vertex " << v;
    EXPECT_NEAR(vel.x, 0.0f, 0.01 * q / width) << "vertex " << v;
    EXPECT_EQ(vel.y, 0.0f);
  }
  expect_conserves_discharge(flow);
}

TEST(StreamFunction, StraightChannelMatchesClosedForm) {
  const double width = 10.0, q = 20.0, p = 1.5, s = 3.0 * width;
  StreamFunction flow = make_flow(test::straight_channel(float(width), 40.0f, 41, 21),
                                  {float(q), float(p), 0.0f});
  EXPECT_FLOAT_EQ(flow.search_radius(), float(s));  // default: 3 x the widest section
  for (size_t v = 0; v < flow.surface().vertex_count(); ++v) {
    const double d_r = flow.surface().vertex(v).d_right;
    EXPECT_NEAR(flow.psi(v), closed_form_psi(d_r, width, q, p, s), 1e-4 * q) << "vertex " << v;
  }
  // Centreline speed with the compact support: Q (p/W + f'(t_c) / (2 s f(t_c))), t_c = 1 - W/2s.
  const double tc = 1.0 - width / (2.0 * s);
  const double f = blend(tc), df = 30.0 * tc * tc * (tc - 1.0) * (tc - 1.0);
  const double centre_speed = q * (p / width + df / (2.0 * s * f));
  const uint32_t centre_vertex = 20 * 21 + 10;
  EXPECT_NEAR(flow.velocity(centre_vertex).z, centre_speed, 0.01 * centre_speed);
  expect_conserves_discharge(flow);
}

TEST(StreamFunction, BendWithRadialSectionsP1IsUniform) {
  const float r1 = 20.0f, r2 = 30.0f, q = 5.0f;
  StreamFunction flow = make_flow(test::bend(r1, r2, 1.5707963f, 91, 11), {q, 1.0f, 1e4f});
  const double speed = q / (r2 - r1);
  for (size_t v = 0; v < flow.surface().vertex_count(); ++v) {
    EXPECT_NEAR(glm::length(flow.velocity(v)), speed, 0.01 * speed) << "vertex " << v;
    EXPECT_NEAR(glm::dot(flow.velocity(v), flow.surface().vertex(v).flow_direction), speed,
                0.01 * speed);
  }
  expect_conserves_discharge(flow);
}

TEST(StreamFunction, VaryingWidthChannelCarriesQEverywhere) {
  std::vector<std::vector<glm::vec3>> sections;
  for (uint32_t k = 0; k < 121; ++k) {
    const float z = 0.25f * float(k);
    const float half = 4.0f * (1.0f + 0.3f * std::sin(0.1f * z));
    const float shift = 2.0f * std::sin(0.1f * z);
    sections.push_back(test::section_line({shift + half, 0, z}, {shift - half, 0, z}, 15));
  }
  const StreamFunction flow = make_flow(test::mesh_from_sections(sections), {3.0f, 1.5f, 0.0f});
  expect_conserves_discharge(flow);
}

TEST(StreamFunction, SectionsOfDifferentVertexCountsCarryQ) {
  std::vector<std::vector<glm::vec3>> sections;
  for (uint32_t k = 0; k < 41; ++k) {
    const float z = 0.5f * float(k);
    sections.push_back(test::section_line({4, 0, z}, {-4, 0, z}, 13 + (k % 3) * 4));
  }
  const StreamFunction flow = make_flow(test::mesh_from_sections(sections), {3.0f, 1.0f, 800.0f});
  // Vertex averaging across bands of different resolutions costs a little accuracy.
  expect_conserves_discharge(flow, 0.02);
}

TEST(StreamFunction, ProceduralRiverCarriesQEverywhere) {
  ProceduralRiverParams params;
  params.length = 120.0f;
  params.vertices_across = 17;
  RiverMesh mesh;
  ASSERT_TRUE(ProceduralRiver(params).generate_mesh(&mesh).ok());
  const StreamFunction flow = make_flow({mesh.positions, mesh.indices}, {20.0f, 1.5f, 0.0f});
  expect_conserves_discharge(flow);
}

TEST(StreamFunction, TooSmallSearchRadiusNamesSectionAndVertex) {
  const TestMesh m = test::straight_channel(10.0f, 10.0f, 3, 5);
  RiverSurface surface;
  ASSERT_TRUE(RiverSurface::build(m.positions, m.indices, {}, &surface).ok());
  StreamFunction flow;
  const Status status = StreamFunction::create(std::move(surface), {1.0f, 1.5f, 4.0f}, &flow);
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.message().find("vertex 1 (section 0)"), std::string::npos) << status.message();
  EXPECT_NE(status.message().find("search radius"), std::string::npos) << status.message();
}

TEST(StreamFunction, BadParameters) {
  const TestMesh m = test::straight_channel(10.0f, 10.0f, 3, 5);
  for (const FlowParams& params : {FlowParams{NAN, 1.5f, 0.0f}, FlowParams{1.0f, 0.0f, 0.0f},
                                  FlowParams{1.0f, -1.0f, 0.0f}, FlowParams{1.0f, 1.5f, -3.0f},
                                  FlowParams{1.0f, 1.5f, INFINITY}}) {
    RiverSurface surface;
    ASSERT_TRUE(RiverSurface::build(m.positions, m.indices, {}, &surface).ok());
    StreamFunction flow;
    EXPECT_FALSE(StreamFunction::create(std::move(surface), params, &flow).ok());
  }
}

// --- Obstacles ----------------------------------------------------------------------------------

struct CylinderCase {
  static constexpr float kWidth = 10.0f, kLength = 40.0f, kQ = 20.0f, kRadius = 1.5f;
  static constexpr uint32_t kSections = 81, kAcross = 21;
  static Obstacle cylinder(glm::vec3 centre) {
    Obstacle o;
    o.centre = centre;
    o.radius = kRadius;
    return o;
  }
};

TEST(StreamFunctionObstacle, CylinderInAStraightChannel) {
  using C = CylinderCase;
  StreamFunction flow = make_flow(test::symmetric_channel(C::kWidth, C::kLength, C::kSections, C::kAcross),
                                  {C::kQ, 1.5f, 0.0f});
  const std::vector<glm::vec3> free_velocity(flow.node_velocity().begin(), flow.node_velocity().end());
  const glm::vec3 centre(0.0f, 0.0f, 0.5f * C::kLength);
  ASSERT_TRUE(flow.set_obstacles({C::cylinder(centre)}).ok());
  ASSERT_TRUE(flow.obstacle_in_water(0));
  EXPECT_NEAR(flow.obstacle_psi(0), 0.5 * C::kQ, 1e-6 * C::kQ);  // the undisturbed centreline

  const RiverSurface& s = flow.surface();
  const auto pos = s.node_positions();
  auto node_at = [&](float x, float z) {
    const uint32_t j = uint32_t(std::lround((0.5f * C::kWidth - x) / C::kWidth * (C::kAcross - 1)));
    const uint32_t k = uint32_t(std::lround(z / C::kLength * (C::kSections - 1)));
    return s.node_of(k * C::kAcross + j);
  };
  // Dry inside, wet outside; dry vertices do not move.
  for (uint32_t n = 0; n < s.node_count(); ++n) {
    const float r = glm::length(glm::vec2(pos[n].x, pos[n].z - centre.z));
    EXPECT_EQ(flow.node_wet()[n] != 0, r >= C::kRadius) << "node " << n;
    if (!flow.node_wet()[n]) {
      EXPECT_EQ(flow.node_velocity()[n], glm::vec3(0.0f));
    }
  }
  // Mirror symmetry across the centreline and along the flow (the triangulation is symmetric).
  for (uint32_t n = 0; n < s.node_count(); ++n) {
    const uint32_t m = node_at(-pos[n].x, pos[n].z);
    const uint32_t u = node_at(pos[n].x, C::kLength - pos[n].z);
    EXPECT_NEAR(flow.node_psi(n) + flow.node_psi(m), C::kQ, 1e-5 * C::kQ);
    EXPECT_NEAR(flow.node_psi(n), flow.node_psi(u), 1e-5 * C::kQ);
    const glm::vec3 v = flow.node_velocity()[n], vm = flow.node_velocity()[m];
    const glm::vec3 vu = flow.node_velocity()[u];
    EXPECT_NEAR(v.z, vm.z, 1e-4f);
    EXPECT_NEAR(v.x, -vm.x, 1e-4f);
    EXPECT_NEAR(v.z, vu.z, 1e-4f);
    EXPECT_NEAR(v.x, -vu.x, 1e-4f);
  }
  // Stagnation up- and downstream: the vertices just off the cylinder on the centreline barely
  // move; the shoulders speed up against the obstacle-free flow there.
  const uint32_t up = node_at(0.0f, centre.z - C::kRadius - 0.5f);
  const uint32_t down = node_at(0.0f, centre.z + C::kRadius + 0.5f);
  EXPECT_LT(glm::length(flow.node_velocity()[up]), 0.3f * glm::length(free_velocity[up]));
  EXPECT_LT(glm::length(flow.node_velocity()[down]), 0.3f * glm::length(free_velocity[down]));
  // The gaps beside it run faster than the free channel anywhere (the flow is squeezed; with
  // p > 1 the speed still falls to zero on the obstacle, algorithms.md §6.3).
  float fastest_free = 0.0f, fastest_gap = 0.0f;
  for (uint32_t n = 0; n < s.node_count(); ++n) {
    fastest_free = std::max(fastest_free, glm::length(free_velocity[n]));
    if (std::abs(pos[n].z - centre.z) < 0.01f) {
      fastest_gap = std::max(fastest_gap, glm::length(flow.node_velocity()[n]));
    }
  }
  EXPECT_GT(fastest_gap, 1.2f * fastest_free);
  // Each gap carries half the discharge: across the section through the centre, from each shore
  // to the cylinder.
  const size_t k = C::kSections / 2;
  const auto nodes = s.section_nodes(k);
  size_t first_dry = 0, last_dry = 0;
  for (size_t i = 0; i < nodes.size(); ++i) {
    if (!flow.node_wet()[nodes[i]]) {
      if (first_dry == 0) first_dry = i;
      last_dry = i;
    }
  }
  ASSERT_GT(first_dry, 0u);
  EXPECT_NEAR(test::triangle_flux(flow, k, 0, first_dry), 0.5 * C::kQ, 1e-5 * C::kQ);
  EXPECT_NEAR(test::triangle_flux(flow, k, last_dry, nodes.size() - 1), 0.5 * C::kQ, 1e-5 * C::kQ);
  expect_conserves_discharge(flow, 0.03);
}

TEST(StreamFunctionObstacle, OffCentreObstacleSplitsTheFlowByItsPsi) {
  using C = CylinderCase;
  StreamFunction flow = make_flow(test::straight_channel(C::kWidth, C::kLength, C::kSections, C::kAcross),
                                  {C::kQ, 1.5f, 0.0f});
  ASSERT_TRUE(flow.set_obstacles({C::cylinder({2.0f, 0.0f, 20.0f})}).ok());
  const double psi_obs = flow.obstacle_psi(0);
  EXPECT_GT(psi_obs, 0.5 * C::kQ);  // nearer the left bank (+X), so less flow passes left of it
  const size_t k = C::kSections / 2;
  const auto nodes = flow.surface().section_nodes(k);
  size_t first_dry = 0;
  while (flow.node_wet()[nodes[first_dry]]) ++first_dry;
  EXPECT_NEAR(test::triangle_flux(flow, k, 0, first_dry), C::kQ - psi_obs, 1e-5 * C::kQ);
  expect_conserves_discharge(flow, 0.03);
}

TEST(StreamFunctionObstacle, PolygonFootprint) {
  using C = CylinderCase;
  StreamFunction flow = make_flow(test::straight_channel(C::kWidth, C::kLength, C::kSections, C::kAcross),
                                  {C::kQ, 1.5f, 0.0f});
  Obstacle box;  // a 2 x 4 m box, long side along the flow, rotated a little
  box.centre = {-1.0f, 0.5f, 15.0f};
  box.polygon = {{-1.2f, -1.8f}, {0.8f, -2.2f}, {1.2f, 1.8f}, {-0.8f, 2.2f}};
  ASSERT_TRUE(flow.set_obstacles({box}).ok());
  const auto pos = flow.surface().node_positions();
  size_t dry = 0;
  for (uint32_t n = 0; n < flow.surface().node_count(); ++n) {
    const double d = footprint_distance(box, {box.centre.x, box.centre.z}, {pos[n].x, pos[n].z});
    EXPECT_EQ(flow.node_wet()[n] == 0, d < 0.0) << "node " << n;
    dry += flow.node_wet()[n] == 0 ? 1 : 0;
  }
  EXPECT_GT(dry, 10u);
  expect_conserves_discharge(flow, 0.03);
}

TEST(StreamFunctionObstacle, OnLandOrOutsideHasNoEffect) {
  using C = CylinderCase;
  StreamFunction flow = make_flow(test::straight_channel(C::kWidth, C::kLength, 41, 11),
                                  {C::kQ, 1.5f, 0.0f});
  const std::vector<double> free = test::node_psis(flow);
  ASSERT_TRUE(flow.set_obstacles({C::cylinder({9.0f, 0.0f, 20.0f}), C::cylinder({0.0f, 0.0f, -8.0f})}).ok());
  EXPECT_FALSE(flow.obstacle_in_water(0));
  EXPECT_FALSE(flow.obstacle_in_water(1));
  for (uint32_t n = 0; n < flow.surface().node_count(); ++n) EXPECT_EQ(flow.node_psi(n), free[n]);
}

TEST(StreamFunctionObstacle, EnteringTheWaterDoesNotPop) {
  // An object centred on the land just past the left bank takes the bank's psi: the flow hardly
  // changes when it starts to touch the water.
  using C = CylinderCase;
  StreamFunction flow = make_flow(test::straight_channel(C::kWidth, C::kLength, 41, 11),
                                  {C::kQ, 1.5f, 0.0f});
  const std::vector<double> free = test::node_psis(flow);
  ASSERT_TRUE(flow.set_obstacles({C::cylinder({5.0f + C::kRadius - 0.05f, 0.0f, 20.0f})}).ok());
  ASSERT_TRUE(flow.obstacle_in_water(0));
  EXPECT_EQ(flow.obstacle_bank(0), Bank::kLeft);
  EXPECT_NEAR(flow.obstacle_psi(0), C::kQ, 1e-6 * C::kQ);
  double worst = 0.0;
  for (uint32_t n = 0; n < flow.surface().node_count(); ++n) {
    worst = std::max(worst, std::abs(flow.node_psi(n) - free[n]));
  }
  EXPECT_LT(worst, 0.01 * C::kQ);
  // Sliding in further, the field changes smoothly with the position (no jumps).
  std::vector<double> previous = test::node_psis(flow);
  for (float x = 6.4f; x > 4.6f; x -= 0.1f) {
    ASSERT_TRUE(flow.move_obstacle(0, {x, 0.0f, 20.0f}).ok());
    double step = 0.0;
    for (uint32_t n = 0; n < flow.surface().node_count(); ++n) {
      step = std::max(step, std::abs(flow.node_psi(n) - previous[n]));
      previous[n] = flow.node_psi(n);
    }
    EXPECT_LT(step, 0.05 * C::kQ) << "x = " << x;
  }
  expect_conserves_discharge(flow, 0.03);
}

TEST(StreamFunctionObstacle, CoveringTheWholeRiverStaysFinite) {
  using C = CylinderCase;
  StreamFunction flow = make_flow(test::straight_channel(C::kWidth, C::kLength, 41, 11),
                                  {C::kQ, 1.5f, 0.0f});
  ASSERT_TRUE(flow.set_obstacles({C::cylinder({0.0f, 0.0f, 20.0f})}).ok());
  Obstacle huge = C::cylinder({0.0f, 0.0f, 20.0f});
  huge.radius = 8.0f;  // spans both banks
  ASSERT_TRUE(flow.set_obstacles({huge}).ok());
  for (uint32_t n = 0; n < flow.surface().node_count(); ++n) {
    EXPECT_TRUE(std::isfinite(flow.node_psi(n)));
    const glm::vec3 v = flow.node_velocity()[n];
    EXPECT_TRUE(std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z));
  }
}

TEST(StreamFunctionObstacle, BadObstacles) {
  using C = CylinderCase;
  StreamFunction flow = make_flow(test::straight_channel(C::kWidth, C::kLength, 11, 5), {1.0f, 1.5f, 0.0f});
  Obstacle zero = C::cylinder({0, 0, 5});
  zero.radius = 0.0f;
  Obstacle nan_centre = C::cylinder({NAN, 0, 5});
  Obstacle two_points;
  two_points.polygon = {{0, 0}, {1, 1}};
  Obstacle bow_tie;
  bow_tie.polygon = {{0, 0}, {2, 2}, {2, 0}, {0, 1}};
  Obstacle keys = C::cylinder({0, 0, 5});
  keys.keys = {{1.0, {0, 0, 5}}, {1.0, {0, 0, 6}}};
  const std::pair<Obstacle, const char*> cases[] = {
      {zero, "radius"}, {nan_centre, "centre"}, {two_points, "3"}, {bow_tie, "crosses itself"},
      {keys, "key 1"}};
  for (const auto& [obstacle, part] : cases) {
    const Status status = flow.set_obstacles({C::cylinder({0, 0, 2}), obstacle});
    ASSERT_FALSE(status.ok()) << part;
    EXPECT_NE(status.message().find("obstacle 1"), std::string::npos) << status.message();
    EXPECT_NE(status.message().find(part), std::string::npos) << status.message();
  }
  EXPECT_FALSE(flow.move_obstacle(5, {0, 0, 0}).ok());
  EXPECT_FALSE(flow.set_time(NAN).ok());
}

// --- Memory -------------------------------------------------------------------------------------

// A long river's flow keeps only what a re-solve needs per node and triangle: psi, the
// triangles' areas and velocities, node areas and bank tangents are derived when asked (no
// vertex maps either: the procedural mesh welds nothing). About 63 bytes a node for the surface
// (its lists in 2 bytes an entry, no list of its sections' nodes: 81 before, 89 before that) and
// 13 for the flow on a 13-vertex-wide strip (21 with psi kept, 79 before).
TEST(StreamFunctionMemory, KeepsNoBuildOnlyArrays) {
  ProceduralRiverParams params;
  params.length = 2000.0f;
  RiverMesh mesh;
  ASSERT_TRUE(ProceduralRiver(params).generate_mesh(&mesh).ok());
  RiverSurface surface;
  ASSERT_TRUE(RiverSurface::build(mesh.positions, mesh.indices, {}, &surface).ok());
  const double nodes = static_cast<double>(surface.node_count());
  const double surface_bytes = static_cast<double>(surface.memory_bytes());
  EXPECT_LE(surface_bytes / nodes, 65.0);
  StreamFunction flow;
  ASSERT_TRUE(StreamFunction::create(std::move(surface), {20.0f}, &flow).ok());
  EXPECT_LE((static_cast<double>(flow.memory_bytes()) - surface_bytes) / nodes, 14.0);
  // Without obstacles, psi under the obstacles is the obstacle-free psi.
  for (uint32_t n = 0; n < flow.surface().node_count(); n += 97) {
    EXPECT_EQ(flow.node_psi_free(n), flow.node_psi(n));
  }
}

// --- Incremental re-solves -----------------------------------------------------------------------

// psi is evaluated from the obstacles where they are, so its comparison holds for any two fields
// under the same obstacles: the velocities', kept from each update, are what guard the updates.
void expect_same_field(const StreamFunction& a, const StreamFunction& b) {
  ASSERT_EQ(a.surface().node_count(), b.surface().node_count());
  size_t psi_diff = 0, vel_diff = 0, wet_diff = 0, tri_diff = 0;
  for (uint32_t n = 0; n < a.surface().node_count(); ++n) {
    psi_diff += a.node_psi(n) != b.node_psi(n);
    vel_diff += a.node_velocity()[n] != b.node_velocity()[n];
    wet_diff += a.node_wet()[n] != b.node_wet()[n];
  }
  for (uint32_t t = 0; t < a.surface().triangle_count(); ++t) {
    tri_diff += a.triangle_velocity(t) != b.triangle_velocity(t);
  }
  EXPECT_EQ(psi_diff, 0u);
  EXPECT_EQ(vel_diff, 0u);
  EXPECT_EQ(wet_diff, 0u);
  EXPECT_EQ(tri_diff, 0u);
}

TEST(StreamFunctionIncremental, MoveEqualsFullResolve) {
  using C = CylinderCase;
  const TestMesh mesh = test::straight_channel(C::kWidth, 80.0f, 161, 21);
  const FlowParams params{C::kQ, 1.5f, 12.0f};  // a small s keeps the update local
  StreamFunction moved = make_flow(mesh, params);
  Obstacle box;
  box.centre = {2.0f, 0.0f, 60.0f};
  box.polygon = {{-1, -1}, {1, -1}, {1, 1}, {-1, 1}};
  ASSERT_TRUE(moved.set_obstacles({C::cylinder({0.0f, 0.0f, 20.0f}), box}).ok());
  const glm::vec3 path[] = {{0.3f, 0.0f, 21.7f}, {-2.2f, 0.1f, 24.0f}, {7.0f, 0.0f, 30.0f},
                            {3.0f, 0.0f, 55.0f}, {-6.4f, 0.0f, 25.0f}};
  glm::vec3 previous(0.0f, 0.0f, 20.0f);
  const auto pos = moved.surface().node_positions();
  bool was_wet = true;
  for (const glm::vec3& centre : path) {
    ASSERT_TRUE(moved.move_obstacle(0, centre).ok());
    // Exactly the vertices within s of the old or the new footprint in the water were re-solved.
    const bool wet = moved.obstacle_in_water(0);
    size_t near = 0;
    for (const glm::vec3& p : pos) {
      const float d_old = glm::length(glm::vec2(p.x - previous.x, p.z - previous.z)) - C::kRadius;
      const float d_new = glm::length(glm::vec2(p.x - centre.x, p.z - centre.z)) - C::kRadius;
      near += ((was_wet && d_old < params.search_radius) || (wet && d_new < params.search_radius)) ? 1 : 0;
    }
    was_wet = wet;
    EXPECT_EQ(moved.last_update().nodes_resolved, near);
    previous = centre;
    StreamFunction full = make_flow(mesh, params);
    ASSERT_TRUE(full.set_obstacles({C::cylinder(centre), box}).ok());
    expect_same_field(moved, full);
  }
}

TEST(StreamFunctionIncremental, KeyframesEqualFullResolveAtAnyTime) {
  using C = CylinderCase;
  const TestMesh mesh = test::straight_channel(C::kWidth, 60.0f, 121, 21);
  const FlowParams params{C::kQ, 1.5f, 15.0f};
  Obstacle boat = C::cylinder({0, 0, 0});
  boat.keys = {{0.0, {7.0f, 0.0f, 10.0f}}, {2.0, {1.0f, 0.0f, 20.0f}}, {5.0, {-2.0f, 0.0f, 45.0f}}};
  StreamFunction animated = make_flow(mesh, params);
  ASSERT_TRUE(animated.set_obstacles({boat}, 0.0).ok());
  for (const double t : {0.25, 0.5, 1.9, 2.0, 3.3, 4.0, 6.0}) {
    ASSERT_TRUE(animated.set_time(t).ok());
    StreamFunction full = make_flow(mesh, params);
    ASSERT_TRUE(full.set_obstacles({boat}, t).ok());
    EXPECT_EQ(animated.obstacle_centre(0), full.obstacle_centre(0));
    expect_same_field(animated, full);
  }
}

TEST(StreamFunctionIncremental, AddTurnAndRemoveEqualFullResolve) {
  // A boat steered at runtime: added, turned (a new polygon), removed, with another obstacle
  // before and after it in the list; every step equals a fresh solve of the same list.
  using C = CylinderCase;
  const TestMesh mesh = test::straight_channel(C::kWidth, 80.0f, 161, 21);
  const FlowParams params{C::kQ, 1.5f, 12.0f};
  Obstacle boat;
  boat.centre = {1.0f, 0.0f, 40.0f};
  boat.polygon = {{-0.8f, -2.5f}, {0.8f, -2.5f}, {0.8f, 2.5f}, {-0.8f, 2.5f}};
  Obstacle turned = boat;
  turned.centre = {0.5f, 0.0f, 41.0f};
  for (glm::vec2& p : turned.polygon) p = {0.8f * p.x - 0.6f * p.y, 0.6f * p.x + 0.8f * p.y};
  const Obstacle rock = C::cylinder({-2.0f, 0.0f, 20.0f});
  const Obstacle stone = C::cylinder({2.0f, 0.0f, 60.0f});
  const auto full_solve = [&](std::vector<Obstacle> obstacles) {
    StreamFunction full = make_flow(mesh, params);
    EXPECT_TRUE(full.set_obstacles(std::move(obstacles)).ok());
    return full;
  };

  StreamFunction live = make_flow(mesh, params);
  ASSERT_TRUE(live.add_obstacle(rock).ok());
  const size_t touched_by_rock = live.last_update().nodes_resolved;
  EXPECT_GT(touched_by_rock, 0u);
  EXPECT_LT(touched_by_rock, live.surface().node_count() / 2);  // local, not a full solve
  expect_same_field(live, full_solve({rock}));
  ASSERT_TRUE(live.add_obstacle(boat).ok());
  ASSERT_TRUE(live.add_obstacle(stone).ok());
  expect_same_field(live, full_solve({rock, boat, stone}));
  ASSERT_TRUE(live.replace_obstacle(1, turned).ok());
  expect_same_field(live, full_solve({rock, turned, stone}));
  ASSERT_TRUE(live.remove_obstacle(1).ok());
  ASSERT_EQ(live.obstacles().size(), 2u);
  expect_same_field(live, full_solve({rock, stone}));
  ASSERT_TRUE(live.remove_obstacle(0).ok());
  ASSERT_TRUE(live.remove_obstacle(0).ok());
  expect_same_field(live, make_flow(mesh, params));  // back to the free flow, bit for bit

  Obstacle flat = boat;
  flat.polygon = {{0, 0}, {1, 0}, {2, 0}};  // degenerate: no area
  const Status bad = live.add_obstacle(flat);
  EXPECT_FALSE(bad.ok());
  EXPECT_TRUE(live.obstacles().empty());
  EXPECT_FALSE(live.remove_obstacle(0).ok());
  EXPECT_FALSE(live.replace_obstacle(0, boat).ok());
}

// No obstacles set on a field that has none leaves it as it is, the free flow a full solve would
// give, reported as a full solve; set after some, they are all taken away, bit for bit. (What the
// skip saves, a long river's second solve at load, shows in time only: this guards its result.)
TEST(StreamFunctionIncremental, NoObstaclesSetEqualTheFreeFlowReportedAsAFullSolve) {
  using C = CylinderCase;
  const TestMesh mesh = test::straight_channel(C::kWidth, 80.0f, 161, 21);
  const FlowParams params{C::kQ, 1.5f, 12.0f};
  const StreamFunction free_flow = make_flow(mesh, params);
  StreamFunction none = make_flow(mesh, params);
  ASSERT_TRUE(none.set_obstacles({}).ok());
  expect_same_field(none, free_flow);
  EXPECT_EQ(none.last_update().nodes_resolved, none.surface().node_count());
  EXPECT_EQ(none.last_update().triangles_updated, none.surface().triangle_count());
  StreamFunction cleared = make_flow(mesh, params);
  ASSERT_TRUE(cleared.set_obstacles({C::cylinder({-2.0f, 0.0f, 20.0f})}).ok());
  ASSERT_TRUE(cleared.set_obstacles({}).ok());
  EXPECT_TRUE(cleared.obstacles().empty());
  expect_same_field(cleared, free_flow);
  EXPECT_EQ(cleared.last_update().nodes_resolved, cleared.surface().node_count());
}

TEST(StreamFunction, Deterministic) {
  ProceduralRiverParams params;
  params.length = 80.0f;
  RiverMesh mesh;
  ASSERT_TRUE(ProceduralRiver(params).generate_mesh(&mesh).ok());
  const TestMesh m{mesh.positions, mesh.indices};
  StreamFunction a = make_flow(m, {20.0f, 1.5f, 0.0f});
  StreamFunction b = make_flow(m, {20.0f, 1.5f, 0.0f});
  Obstacle rock = CylinderCase::cylinder(mesh.positions[mesh.positions.size() / 2]);
  ASSERT_TRUE(a.set_obstacles({rock}).ok());
  ASSERT_TRUE(b.set_obstacles({rock}).ok());
  expect_same_field(a, b);
}

}  // namespace
}  // namespace siviflow
