// River Surface Generator (Algorithm 1): sections and banks from the topology, per-vertex data,
// and every bad river mesh of reliability.md §5 that reaches the sim.
#include "siviflow/sim/river_surface.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <span>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "siviflow/sim/river_tuning.h"
#include "sim/grid_holes.h"
#include "unit/river_test_meshes.h"

namespace siviflow {
namespace {

using test::TestMesh;

Status build(const TestMesh& m, RiverSurface* s, RiverSurfaceOptions options = {}) {
  return RiverSurface::build(m.positions, m.indices, options, s);
}

// Fails the test unless building gives an error containing every one of `parts`.
void expect_error(const TestMesh& m, std::initializer_list<const char*> parts) {
  RiverSurface s;
  const Status status = build(m, &s);
  ASSERT_FALSE(status.ok()) << "expected an error containing " << *parts.begin();
  for (const char* part : parts) {
    EXPECT_NE(status.message().find(part), std::string::npos)
        << "message: \"" << status.message() << "\" lacks \"" << part << "\"";
  }
}

TEST(RiverSurface, StraightChannelSectionsBanksAndDistances) {
  const TestMesh m = test::straight_channel(10.0f, 40.0f, 21, 6);
  RiverSurface s;
  ASSERT_TRUE(build(m, &s).ok());
  ASSERT_EQ(s.sections().size(), 21u);
  EXPECT_EQ(s.vertex_count(), m.positions.size());
  EXPECT_FLOAT_EQ(s.widest_section(), 10.0f);
  for (size_t v = 0; v < m.positions.size(); ++v) {
    const RiverVertex rv = s.vertex(v);
    const uint32_t k = uint32_t(v / 6), j = uint32_t(v % 6);
    EXPECT_EQ(rv.section, k) << "vertex " << v;
    EXPECT_EQ(rv.bank, j == 0 ? Bank::kLeft : j == 5 ? Bank::kRight : Bank::kNone) << "vertex " << v;
    EXPECT_FLOAT_EQ(rv.width, 10.0f);
    EXPECT_NEAR(rv.d_left, 5.0f - m.positions[v].x, 1e-5f);
    EXPECT_NEAR(rv.d_right, 5.0f + m.positions[v].x, 1e-5f);
    EXPECT_NEAR(rv.flow_direction.z, 1.0f, 1e-6f);
    EXPECT_NEAR(std::abs(rv.flow_direction.x) + std::abs(rv.flow_direction.y), 0.0f, 1e-6f);
  }
  for (size_t k = 0; k < s.sections().size(); ++k) {
    EXPECT_NEAR(s.sections()[k].along, 2.0f * float(k), 1e-4f);
    const auto nodes = s.section_nodes(k);
    ASSERT_EQ(nodes.size(), 6u);
    EXPECT_GT(s.node_positions()[nodes.front()].x, s.node_positions()[nodes.back()].x);
  }
}

// A strip numbered section after section keeps no list of its sections' nodes (4 bytes a node):
// each section is a run of consecutive nodes. Shuffled, it keeps the list, and the sections hold
// the same nodes, left to right.
TEST(RiverSurface, ASectionAfterSectionStripKeepsNoListOfItsSectionsNodes) {
  for (const bool mirrored : {false, true}) {
    TestMesh m = test::straight_channel(10.0f, 40.0f, 21, 7);
    if (mirrored) {  // the nodes then run from the right shore to the left across each section
      for (glm::vec3& p : m.positions) p.x = -p.x;
    }
    std::vector<uint32_t> new_of_old;
    const TestMesh mixed = test::shuffled(m, 3, &new_of_old);
    RiverSurface runs, listed;
    ASSERT_TRUE(build(m, &runs).ok());
    ASSERT_TRUE(build(mixed, &listed).ok());
    EXPECT_GE(listed.memory_bytes(), runs.memory_bytes() + 4 * runs.node_count());
    ASSERT_EQ(runs.sections().size(), listed.sections().size());
    for (size_t k = 0; k < runs.sections().size(); ++k) {
      const SectionNodes a = runs.section_nodes(k), b = listed.section_nodes(k);
      ASSERT_EQ(a.size(), b.size());
      for (size_t i = 0; i < a.size(); ++i) {
        EXPECT_EQ(new_of_old[a[i]], b[i]) << "section " << k << ", node " << i;
        EXPECT_EQ(runs.node_section()[a[i]], k);
      }
      EXPECT_EQ(std::vector<uint32_t>(a.begin(), a.end()).size(), a.size());
      EXPECT_EQ(runs.node_bank()[a.front()], Bank::kLeft);
      EXPECT_EQ(runs.node_bank()[a.back()], Bank::kRight);
    }
  }
}

// Sections of 2 to 40 nodes, numbered section after section: the surface keeps no list of its
// nodes' sections either (4 bytes a node, for a quarter byte), and finds each node's from the
// sections' runs, across every block it searches from.
TEST(RiverSurface, ASectionAfterSectionStripFindsItsNodesSectionsWithoutAList) {
  std::vector<std::vector<glm::vec3>> rows;
  for (uint32_t k = 0; k < 90; ++k) {
    const float z = 2.0f * float(k);
    rows.push_back(test::section_line({5.0f, 0.0f, z}, {-5.0f, 0.0f, z}, 2 + (k * 7) % 39));
  }
  const TestMesh m = test::mesh_from_sections(rows);
  std::vector<uint32_t> new_of_old;
  const TestMesh mixed = test::shuffled(m, 5, &new_of_old);
  RiverSurface runs, listed;
  ASSERT_TRUE(build(m, &runs).ok());
  ASSERT_TRUE(build(mixed, &listed).ok());
  EXPECT_GE(listed.memory_bytes(), runs.memory_bytes() + 7 * runs.node_count());
  for (size_t k = 0; k < rows.size(); ++k) {
    for (const uint32_t n : runs.section_nodes(k)) {
      EXPECT_EQ(runs.node_section()[n], k) << "node " << n;
      EXPECT_EQ(runs.node(n).section, k) << "node " << n;
      EXPECT_EQ(listed.node_section()[new_of_old[n]], k) << "node " << n;
    }
  }
  EXPECT_EQ(runs.node_section().size(), runs.node_count());
}

TEST(RiverSurface, UpstreamEndFollowsVertexZero) {
  // Vertex 0 at the z = 40 end: the river now flows along -Z, and the left bank is at -X.
  TestMesh m = test::straight_channel(10.0f, 40.0f, 11, 4);
  for (glm::vec3& p : m.positions) p = glm::vec3(-p.x, p.y, 40.0f - p.z);
  RiverSurface s;
  ASSERT_TRUE(build(m, &s).ok());
  EXPECT_NEAR(s.vertex(0).flow_direction.z, -1.0f, 1e-6f);
  EXPECT_EQ(s.vertex(0).section, 0u);
  EXPECT_EQ(s.vertex(0).bank, Bank::kLeft);
  EXPECT_LT(s.node_positions()[s.section_nodes(0).front()].x, 0.0f);

  // The upstream marker may also be any vertex of an end section.
  RiverSurface t;
  const TestMesh straight = test::straight_channel(10.0f, 40.0f, 11, 4);
  RiverSurfaceOptions options;
  options.upstream_vertex = uint32_t(straight.positions.size() - 2);  // on the z = 40 end
  ASSERT_TRUE(build(straight, &t, options).ok());
  EXPECT_NEAR(t.vertex(0).flow_direction.z, -1.0f, 1e-6f);
  EXPECT_EQ(t.vertex(0).section, 10u);
}

TEST(RiverSurface, VertexOrderDoesNotMatter) {
  const TestMesh m = test::straight_channel(8.0f, 30.0f, 16, 5);
  std::vector<uint32_t> new_of_old;
  const TestMesh shuffled = test::shuffled(m, 1234, &new_of_old);
  RiverSurface a, b;
  ASSERT_TRUE(build(m, &a).ok());
  ASSERT_TRUE(build(shuffled, &b).ok());
  for (size_t v = 0; v < m.positions.size(); ++v) {
    const RiverVertex x = a.vertex(v), y = b.vertex(new_of_old[v]);
    EXPECT_EQ(x.section, y.section);
    EXPECT_EQ(x.bank, y.bank);
    EXPECT_EQ(x.d_left, y.d_left);
    EXPECT_EQ(x.d_right, y.d_right);
    EXPECT_EQ(x.flow_direction, y.flow_direction);
  }
}

TEST(RiverSurface, SectionsMayDifferInWidthAndVertexCount) {
  std::vector<std::vector<glm::vec3>> sections;
  const uint32_t counts[] = {3, 4, 6, 2, 5, 5, 3};
  for (uint32_t k = 0; k < 7; ++k) {
    const float half = 2.0f + float(k);
    const float z = 3.0f * float(k);
    sections.push_back(test::section_line({half, 0, z}, {-half, 0, z}, counts[k]));
  }
  const TestMesh m = test::mesh_from_sections(sections);
  RiverSurface s;
  const Status status = build(m, &s);
  ASSERT_TRUE(status.ok()) << status.message();
  ASSERT_EQ(s.sections().size(), 7u);
  for (uint32_t k = 0; k < 7; ++k) {
    EXPECT_EQ(s.sections()[k].node_count, counts[k]);
    EXPECT_FLOAT_EQ(s.sections()[k].width, 4.0f + 2.0f * float(k));
  }
}

TEST(RiverSurface, NonIndexedAndSplitVerticesAreWelded) {
  const TestMesh m = test::straight_channel(6.0f, 12.0f, 7, 4);
  TestMesh soup;
  for (const uint32_t i : m.indices) soup.positions.push_back(m.positions[i]);
  RiverSurface indexed, welded;
  ASSERT_TRUE(build(m, &indexed).ok());
  ASSERT_TRUE(build(soup, &welded).ok());
  EXPECT_EQ(welded.node_count(), m.positions.size());
  EXPECT_EQ(welded.vertex_count(), soup.positions.size());
  for (size_t v = 0; v < soup.positions.size(); ++v) {
    const RiverVertex x = welded.vertex(v);
    const RiverVertex y = indexed.vertex(m.indices[v]);
    EXPECT_EQ(x.section, y.section);
    EXPECT_EQ(x.bank, y.bank);
    EXPECT_EQ(x.d_left, y.d_left);
  }
  // Without welding both vertex-node maps are the identity: none is kept, and the per-vertex
  // accessors still answer.
  EXPECT_FALSE(indexed.welded());
  EXPECT_TRUE(welded.welded());
  EXPECT_EQ(indexed.vertex_count(), m.positions.size());
  for (uint32_t v = 0; v < m.positions.size(); ++v) {
    EXPECT_EQ(indexed.node_of(v), v);
    EXPECT_EQ(indexed.vertex_of_node(v), v);
    EXPECT_EQ(indexed.node_positions()[v], m.positions[v]);
  }
  // The soup's surface holds its two maps (4 bytes a vertex, 4 a node) beyond the indexed one's.
  EXPECT_GE(welded.memory_bytes(),
            indexed.memory_bytes() + 4 * (soup.positions.size() + welded.node_count()));
}

TEST(RiverSurface, BendFlowDirectionIsPerpendicularToRadialSections) {
  const TestMesh m = test::bend(20.0f, 30.0f, 1.5707963f, 31, 5);
  RiverSurface s;
  ASSERT_TRUE(build(m, &s).ok());
  for (const RiverSection& sec : s.sections()) {
    const glm::vec3 radial = glm::normalize(glm::vec3(sec.midpoint.x, 0.0f, sec.midpoint.z));
    EXPECT_NEAR(glm::dot(radial, sec.flow_direction), 0.0f, 1e-5f);
    // Counter-clockwise seen from +Y: from +X towards +Z means flowing along +theta.
    const glm::vec3 theta(-radial.z, 0.0f, radial.x);
    EXPECT_NEAR(glm::dot(theta, sec.flow_direction), 1.0f, 1e-5f);
    EXPECT_NEAR(sec.width, 10.0f, 1e-4f);
  }
  // Flowing along +theta with +Y up, the left bank is the outer one.
  EXPECT_EQ(s.vertex(0).bank, Bank::kRight);
}

TEST(RiverSurface, TrianglesAreWoundUpwards) {
  TestMesh m = test::straight_channel(6.0f, 12.0f, 7, 4);
  for (size_t t = 0; t < m.indices.size(); t += 6) std::swap(m.indices[t + 1], m.indices[t + 2]);
  RiverSurface s;
  ASSERT_TRUE(build(m, &s).ok());
  const auto pos = s.node_positions();
  const auto tri = s.triangles();
  for (size_t t = 0; t < s.triangle_count(); ++t) {
    const glm::vec3 n = glm::cross(pos[tri[3 * t + 1]] - pos[tri[3 * t]], pos[tri[3 * t + 2]] - pos[tri[3 * t]]);
    EXPECT_GT(n.y, 0.0f) << "triangle " << t;
  }
}

TEST(RiverSurface, Deterministic) {
  const TestMesh m = test::bend(5.0f, 9.0f, 2.0f, 40, 7);
  RiverSurface a, b;
  ASSERT_TRUE(build(m, &a).ok());
  ASSERT_TRUE(build(m, &b).ok());
  ASSERT_EQ(a.node_count(), b.node_count());
  for (uint32_t n = 0; n < a.node_count(); ++n) {
    EXPECT_EQ(a.node_d_left()[n], b.node_d_left()[n]);
    EXPECT_EQ(a.node_section()[n], b.node_section()[n]);
  }
  EXPECT_TRUE(std::equal(a.triangles().begin(), a.triangles().end(), b.triangles().begin()));
}

// The input is read no more once inputs_read is called: spoiled there (every position NaN, every
// index out of range), the build gives the same surface, and says whether it welded.
TEST(RiverSurface, InputsAreNotReadAfterInputsRead) {
  const TestMesh m = test::bend(5.0f, 9.0f, 2.0f, 40, 7);
  TestMesh soup;
  for (const uint32_t i : m.indices) soup.positions.push_back(m.positions[i]);
  for (const TestMesh* mesh : std::initializer_list<const TestMesh*>{&m, &soup}) {
    RiverSurface plain, spoiled;
    ASSERT_TRUE(build(*mesh, &plain).ok());
    TestMesh copy = *mesh;
    int calls = 0;
    bool welded = false;
    RiverSurfaceOptions options;
    options.inputs_read = [&](bool w) {
      ++calls;
      welded = w;
      std::fill(copy.positions.begin(), copy.positions.end(),
                glm::vec3(std::numeric_limits<float>::quiet_NaN()));
      std::fill(copy.indices.begin(), copy.indices.end(), 0xffffffffu);
    };
    ASSERT_TRUE(build(copy, &spoiled, options).ok());
    EXPECT_EQ(calls, 1);
    EXPECT_EQ(welded, mesh == &soup);
    ASSERT_EQ(spoiled.node_count(), plain.node_count());
    EXPECT_TRUE(std::ranges::equal(spoiled.node_positions(), plain.node_positions()));
    EXPECT_TRUE(std::ranges::equal(spoiled.triangles(), plain.triangles()));
    for (uint32_t n = 0; n < plain.node_count(); ++n) {
      EXPECT_EQ(spoiled.node_d_left()[n], plain.node_d_left()[n]);
      EXPECT_EQ(spoiled.node_section()[n], plain.node_section()[n]);
    }
  }
  // Not called when the build fails before.
  TestMesh bad = m;
  bad.indices.pop_back();
  int calls = 0;
  RiverSurfaceOptions options;
  options.inputs_read = [&](bool) { ++calls; };
  RiverSurface s;
  EXPECT_FALSE(build(bad, &s, options).ok());
  EXPECT_EQ(calls, 0);
}

// `rewound` flags the triangles whose winding the build reversed: a triangle given the other way
// round is flagged where it was not, and with their last two corners swapped back the
// triangles are the input's indices.
TEST(RiverSurface, RewoundFlagsTheTrianglesItWoundOtherwise) {
  const TestMesh wound = test::bend(5.0f, 9.0f, 2.0f, 40, 7);
  TestMesh mixed = wound;
  std::vector<bool> reversed(mixed.indices.size() / 3, false);
  for (size_t t = 0; t < reversed.size(); t += 3) {
    std::swap(mixed.indices[3 * t + 1], mixed.indices[3 * t + 2]);
    reversed[t] = true;
  }
  std::vector<bool> wound_flags;
  RiverSurface plain;
  RiverSurfaceOptions wound_options;
  wound_options.rewound = &wound_flags;
  ASSERT_TRUE(build(wound, &plain, wound_options).ok());
  ASSERT_EQ(wound_flags.size(), reversed.size());
  std::vector<bool> rewound;
  RiverSurfaceOptions options;
  options.rewound = &rewound;
  RiverSurface s;
  ASSERT_TRUE(build(mixed, &s, options).ok());
  EXPECT_TRUE(std::ranges::equal(s.triangles(), plain.triangles()));
  ASSERT_EQ(rewound.size(), reversed.size());
  std::vector<uint32_t> given_back(s.triangles().begin(), s.triangles().end());
  for (size_t t = 0; t < rewound.size(); ++t) {
    EXPECT_EQ(rewound[t], wound_flags[t] != reversed[t]) << t;
    if (rewound[t]) std::swap(given_back[3 * t + 1], given_back[3 * t + 2]);
  }
  EXPECT_EQ(given_back, mixed.indices);
}

TEST(RiverSurface, SharedMeshIsReadFromTheSharerAndFreesItsOwn) {
  const TestMesh m = test::bend(5.0f, 9.0f, 2.0f, 40, 7);
  RiverSurface s;
  ASSERT_TRUE(build(m, &s).ok());
  const size_t own_bytes = s.memory_bytes();
  // What a unified-memory device's vertex and index buffers would hold.
  const std::vector<glm::vec3> positions(s.node_positions().begin(), s.node_positions().end());
  const std::vector<uint32_t> triangles(s.triangles().begin(), s.triangles().end());
  const size_t nodes = s.node_count();
  const size_t vertices = s.vertex_count();
  ASSERT_TRUE(s.share_mesh(positions, triangles).ok());
  EXPECT_EQ(s.node_count(), nodes);
  EXPECT_EQ(s.vertex_count(), vertices);
  EXPECT_EQ(s.node_positions().data(), positions.data());
  EXPECT_EQ(s.triangles().data(), triangles.data());
  EXPECT_EQ(s.triangle_count(), triangles.size() / 3);
  EXPECT_EQ(s.memory_bytes(),
            own_bytes - positions.size() * sizeof(glm::vec3) - triangles.size() * sizeof(uint32_t));
  // A copy reads the same shared arrays.
  const RiverSurface copy = s;
  EXPECT_EQ(copy.node_positions().data(), positions.data());
}

TEST(RiverSurface, SharedMeshThatDiffersIsRefused) {
  const TestMesh m = test::straight_channel(6.0f, 12.0f, 7, 4);
  RiverSurface s;
  ASSERT_TRUE(build(m, &s).ok());
  std::vector<glm::vec3> positions(s.node_positions().begin(), s.node_positions().end());
  const std::vector<uint32_t> triangles(s.triangles().begin(), s.triangles().end());
  const glm::vec3* own = s.node_positions().data();
  const Status shorter = s.share_mesh(std::span(positions).first(positions.size() - 1), triangles);
  ASSERT_FALSE(shorter.ok());
  EXPECT_NE(shorter.message().find("positions"), std::string::npos) << shorter.message();
  positions[3].y += 0.5f;
  const Status moved = s.share_mesh(positions, triangles);
  ASSERT_FALSE(moved.ok());
  EXPECT_NE(moved.message().find("differ"), std::string::npos) << moved.message();
  EXPECT_EQ(s.node_positions().data(), own);  // its own, unchanged
}

// --- Bad meshes (reliability.md §5 rows 6-16) --------------------------------------------------

TEST(RiverSurfaceBad, Empty) { expect_error({}, {"no vertices"}); }

TEST(RiverSurfaceBad, HugeCountIsRefusedBeforeReading) {
  const glm::vec3 one(0.0f);
  // A span that claims far more vertices than exist: the size check must come before any read.
  const std::span<const glm::vec3> huge(&one, kMaxRiverVertices + 1);
  RiverSurface s;
  const Status status = RiverSurface::build(huge, {}, {}, &s);
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.message().find("limit"), std::string::npos) << status.message();
}

TEST(RiverSurfaceBad, IndicesNotAMultipleOfThree) {
  TestMesh m = test::straight_channel(4, 4, 3, 3);
  m.indices.pop_back();
  expect_error(m, {"not a multiple of 3"});
}

TEST(RiverSurfaceBad, IndexOutOfRange) {
  TestMesh m = test::straight_channel(4, 4, 3, 3);
  m.indices[7] = 99;
  expect_error(m, {"triangle 2", "vertex 99"});
}

TEST(RiverSurfaceBad, NonFinitePosition) {
  TestMesh m = test::straight_channel(4, 4, 3, 3);
  m.positions[4].y = std::numeric_limits<float>::quiet_NaN();
  expect_error(m, {"vertex 4", "non-finite"});
  m.positions[4].y = std::numeric_limits<float>::infinity();
  expect_error(m, {"vertex 4", "non-finite"});
}

TEST(RiverSurfaceBad, DegenerateTriangles) {
  TestMesh m = test::straight_channel(4, 4, 3, 3);
  m.indices[4] = m.indices[3];
  expect_error(m, {"triangle 1", "degenerate", "twice"});
  TestMesh line;  // a single "section" given as one triangle of collinear points
  line.positions = {{0, 0, 0}, {1, 0, 0}, {2, 0, 0}};
  expect_error(line, {"triangle 0", "zero area"});
}

TEST(RiverSurfaceBad, OneSection) {
  TestMesh tri;
  tri.positions = {{0, 0, 0}, {1, 0, 0}, {0, 0, 1}};
  tri.indices = {0, 1, 2};
  expect_error(tri, {"at least two sections"});
}

TEST(RiverSurfaceBad, ZeroWidth) {
  // Every section's shores coincide.
  TestMesh m = test::straight_channel(0.0f, 10.0f, 6, 2);
  expect_error(m, {"degenerate", "same position", "zero-width"});
  // One section pinched to a point in an otherwise fine river.
  TestMesh pinched = test::straight_channel(4.0f, 10.0f, 6, 3);
  for (int j = 0; j < 3; ++j) pinched.positions[3 * 3 + j].x = 0.0f;
  expect_error(pinched, {"same position"});
}

TEST(RiverSurfaceBad, TinyWidthSection) {
  TestMesh m = test::straight_channel(4.0f, 10.0f, 6, 2);
  m.positions[2 * 2 + 0].x = 1e-6f;  // section 2 squeezed to 2e-6 m
  m.positions[2 * 2 + 1].x = -1e-6f;
  expect_error(m, {"section 2", "zero width"});
}

TEST(RiverSurfaceBad, Disconnected) {
  TestMesh a = test::straight_channel(4, 8, 5, 3);
  const TestMesh b = test::straight_channel(4, 8, 5, 3);
  const uint32_t offset = uint32_t(a.positions.size());
  for (glm::vec3 p : b.positions) a.positions.push_back(p + glm::vec3(20, 0, 0));
  for (uint32_t i : b.indices) a.indices.push_back(i + offset);
  expect_error(a, {"disconnected"});
}

TEST(RiverSurfaceBad, UnusedVertex) {
  TestMesh m = test::straight_channel(4, 8, 5, 3);
  m.positions.push_back({50, 0, 50});
  expect_error(m, {"vertex 15", "not used"});
}

TEST(RiverSurfaceIsland, AHoleIsAnIslandBetweenTwoArms) {
  // A 5x5 grid of vertices 2 m apart (x = 4 .. -4, z = 0 .. 8) missing the quad at x in [0, 2],
  // z in [2, 4]: a left arm 2 m wide and a right arm 4 m wide.
  TestMesh m = test::straight_channel(8, 8, 5, 5);
  std::vector<uint32_t> kept;
  for (size_t t = 0; t < m.indices.size(); t += 3) {
    bool middle = true;
    for (int i = 0; i < 3; ++i) {
      const uint32_t v = m.indices[t + i];
      const uint32_t k = v / 5, j = v % 5;
      middle = middle && (k == 1 || k == 2) && (j == 1 || j == 2);
    }
    if (!middle) kept.insert(kept.end(), m.indices.begin() + long(t), m.indices.begin() + long(t) + 3);
  }
  m.indices = kept;
  RiverSurface s;
  const Status status = build(m, &s);
  ASSERT_TRUE(status.ok()) << status.message();
  ASSERT_EQ(s.islands().size(), 1u);
  EXPECT_EQ(s.island_nodes(0).size(), 4u);
  ASSERT_EQ(s.sections().size(), 5u);
  for (uint32_t n = 0; n < s.node_count(); ++n) {
    const RiverVertex v = s.node(n);
    const glm::vec3 p = s.node_positions()[n];
    EXPECT_EQ(v.section, uint32_t(std::lround(p.z / 2))) << "vertex " << n;
    const bool beside = v.section == 1 || v.section == 2;
    const bool shore = beside && p.x > -1.0f && p.x < 3.0f;
    EXPECT_EQ(s.on_island(n), shore) << "vertex " << n;
    if (shore || !beside) continue;
    const bool left = p.x > 0.0f;
    EXPECT_EQ(v.left_border, left ? kLeftBankBorder : island_border(0)) << "vertex " << n;
    EXPECT_EQ(v.right_border, left ? island_border(0) : kRightBankBorder) << "vertex " << n;
    EXPECT_NEAR(v.d_left + v.d_right, left ? 2.0f : 4.0f, 1e-5f) << "vertex " << n;
    EXPECT_NEAR(left ? v.d_left : v.d_right, 4.0f - std::abs(p.x), 1e-5f) << "vertex " << n;
    EXPECT_NEAR(v.width, 6.0f, 1e-5f) << "vertex " << n;
  }
}

TEST(RiverSurfaceIsland, AnEllipticIslandKeepsEverySectionFromBankToBank) {
  const TestMesh m = test::channel_with_island(10, 60, 61, 21, 1.0f, 30.0f, 2.0f, 12.0f);
  RiverSurface s;
  const Status status = build(m, &s);
  ASSERT_TRUE(status.ok()) << status.message();
  ASSERT_EQ(s.islands().size(), 1u);
  ASSERT_EQ(s.sections().size(), 61u);
  size_t parted = 0;
  for (size_t k = 0; k < s.sections().size(); ++k) {
    const auto nodes = s.section_nodes(k);
    EXPECT_EQ(s.node_bank()[nodes.front()], Bank::kLeft);
    EXPECT_EQ(s.node_bank()[nodes.back()], Bank::kRight);
    bool island = false;
    for (const uint32_t n : nodes) {
      island = island || s.on_island(n);
      EXPECT_NEAR(s.node_positions()[n].z, float(k), 1e-4f) << "section " << k;
    }
    parted += island ? 1 : 0;
  }
  // Quad centres at z = k + 0.5 inside |z - 30| < 12 cut 24 rows of quads: 25 sections meet it.
  EXPECT_EQ(parted, 25u);
}

TEST(RiverSurfaceBad, IslandTouchingABank) {
  // A 5x5 grid (vertex k * 5 + j) missing quad (1, 1) and the triangle of quad (1, 0) that
  // reaches the left bank's vertex 10: the island's shore passes through the bank there.
  TestMesh m = test::straight_channel(8, 8, 5, 5);
  std::vector<uint32_t> kept;
  for (size_t t = 0; t < m.indices.size(); t += 3) {
    const std::array<uint32_t, 3> tri{m.indices[t], m.indices[t + 1], m.indices[t + 2]};
    const bool island = std::find(tri.begin(), tri.end(), 7u) != tri.end() &&
                        std::find(tri.begin(), tri.end(), 11u) != tri.end();
    const bool pinch = tri == std::array<uint32_t, 3>{6, 11, 10};
    if (!island && !pinch) kept.insert(kept.end(), tri.begin(), tri.end());
  }
  m.indices = kept;
  expect_error(m, {"vertex 10", "an island and a bank"});
}

TEST(RiverSurfaceBad, ZeroWidthNeckBesideAnIsland) {
  // The 5x5 grid missing quad (1, 1) (x in [0, 2], z in [2, 4]), its left bank pulled in to
  // 5 micrometres from the island's shore beside it (vertices 5 and 10, at x = 4 before).
  TestMesh m = test::straight_channel(8, 8, 5, 5);
  std::vector<uint32_t> kept;
  for (size_t t = 0; t < m.indices.size(); t += 3) {
    const std::array<uint32_t, 3> tri{m.indices[t], m.indices[t + 1], m.indices[t + 2]};
    const auto has = [&](uint32_t v) { return std::find(tri.begin(), tri.end(), v) != tri.end(); };
    if (!(has(7) && has(11))) kept.insert(kept.end(), tri.begin(), tri.end());
  }
  m.indices = kept;
  m.positions[5].x = m.positions[10].x = 2.0f + 5e-6f;
  expect_error(m, {"zero-width neck", "vertices 5 and 6"});
}

TEST(RiverSurfaceBad, NonManifoldEdge) {
  TestMesh m = test::straight_channel(4, 8, 5, 3);
  m.positions.push_back({0.5f, 3.0f, 3.0f});
  // Triangle 0's second edge runs across the first band: two triangles share it already.
  m.indices.insert(m.indices.end(), {m.indices[1], m.indices[2], uint32_t(m.positions.size() - 1)});
  expect_error(m, {"non-manifold"});
}

// A triangle hanging off the strip by one corner (its other two vertices its own): two parts
// touching at a single vertex, refused naming it.
TEST(RiverSurfaceBad, DanglingTriangle) {
  TestMesh m = test::straight_channel(4, 8, 5, 3);
  const uint32_t corner = 0;  // the upstream end's left corner
  const glm::vec3 p = m.positions[corner];
  m.positions.push_back(p + glm::vec3(1.0f, 0.0f, -1.0f));
  m.positions.push_back(p + glm::vec3(-0.5f, 0.0f, -1.5f));
  m.indices.insert(m.indices.end(), {corner, uint32_t(m.positions.size() - 2), uint32_t(m.positions.size() - 1)});
  expect_error(m, {"non-manifold at vertex 0"});
}

// A strip bent round until its left bank meets itself at one vertex: refused naming it.
TEST(RiverSurfaceBad, BorderTouchingItself) {
  // A ring of quads, 12 sections about the origin, the inner bank's last vertex welded onto its
  // first: the ring is open (its ends apart) but its inner border passes twice through one point.
  std::vector<std::vector<glm::vec3>> sections;
  for (int k = 0; k <= 12; ++k) {
    const float a = 6.2831853f * float(k) / 12.0f * 0.95f;
    glm::vec3 in(2.0f * std::cos(a), 0.0f, 2.0f * std::sin(a));
    if (k == 12) in = glm::vec3(2.0f, 0.0f, 0.0f);  // back onto section 0's inner vertex
    sections.push_back(test::section_line(glm::vec3(4.0f * std::cos(a), 0.0f, 4.0f * std::sin(a)), in, 3));
  }
  const TestMesh m = test::mesh_from_sections(sections);
  expect_error(m, {"non-manifold at vertex"});
}

TEST(RiverSurfaceBad, ClosedMesh) {
  TestMesh tetra;
  tetra.positions = {{0, 0, 0}, {1, 0, 0}, {0, 0, 1}, {0, 1, 0}};
  tetra.indices = {0, 2, 1, 0, 1, 3, 1, 2, 3, 2, 0, 3};
  expect_error(tetra, {"closed"});
}

TEST(RiverSurfaceBad, FanIsNotAStrip) {
  TestMesh fan;
  fan.positions.push_back({0, 0, 0});
  for (int i = 0; i < 6; ++i) {
    const float a = float(i) * 1.0471976f;
    fan.positions.push_back({std::cos(a), 0, std::sin(a)});
  }
  for (uint32_t i = 0; i < 6; ++i) fan.indices.insert(fan.indices.end(), {0, 1 + i, 1 + (i + 1) % 6});
  // Vertex 0 is the hub, inside the mesh: it cannot mark an end.
  expect_error(fan, {"vertex 0", "not on the border"});
  RiverSurface s;
  RiverSurfaceOptions options;
  options.upstream_vertex = 1;
  const Status status = RiverSurface::build(fan.positions, fan.indices, options, &s);
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.message().find("not a strip"), std::string::npos) << status.message();
}

TEST(RiverSurfaceBad, TShapeIsNotAStrip) {
  // A T of quads: a confluence (three ends), which no single strip of sections describes.
  std::vector<glm::vec3> pos;
  std::vector<uint32_t> idx;
  auto vertex = [&](float x, float z) {
    for (uint32_t i = 0; i < pos.size(); ++i) {
      if (pos[i] == glm::vec3(x, 0, z)) return i;
    }
    pos.push_back({x, 0, z});
    return uint32_t(pos.size() - 1);
  };
  for (int cz = 0; cz < 5; ++cz) {
    for (int cx = 0; cx < 6; ++cx) {
      if (cz >= 2 && (cx < 2 || cx >= 4)) continue;
      const uint32_t a = vertex(float(cx), float(cz)), b = vertex(float(cx + 1), float(cz));
      const uint32_t c = vertex(float(cx), float(cz + 1)), d = vertex(float(cx + 1), float(cz + 1));
      idx.insert(idx.end(), {a, c, b, b, c, d});
    }
  }
  TestMesh m{pos, idx};
  expect_error(m, {"not a strip"});
}

TEST(RiverSurfaceBad, UpstreamVertexOutOfRange) {
  const TestMesh m = test::straight_channel(4, 8, 5, 3);
  RiverSurface s;
  RiverSurfaceOptions options;
  options.upstream_vertex = 1000;
  const Status status = RiverSurface::build(m.positions, m.indices, options, &s);
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.message().find("1000"), std::string::npos);
}

}  // namespace
}  // namespace siviflow
