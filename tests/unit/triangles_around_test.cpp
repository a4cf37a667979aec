// The triangles around each vertex, as a long river keeps them: the same lists as a plain count
// would give, in 1 byte a triangle for a mesh laid out section after section, in 2 for one whose
// sections are hundreds of vertices wide, and in 4 for one whose order is shuffled.
#include "siviflow/sim/triangles_around.h"

#include <cstdint>
#include <ranges>
#include <vector>

#include <gtest/gtest.h>

#include "river_test_meshes.h"
#include "siviflow/sim/river_surface.h"

namespace siviflow {
namespace {

static_assert(std::ranges::forward_range<TrianglesAround::Range>);

// Each vertex's triangles, ascending, counted the plain way.
std::vector<std::vector<uint32_t>> plain_lists(size_t vertex_count,
                                               const std::vector<uint32_t>& indices) {
  std::vector<std::vector<uint32_t>> lists(vertex_count);
  for (size_t i = 0; i < indices.size(); ++i)
    lists[indices[i]].push_back(static_cast<uint32_t>(i / 3));
  return lists;
}

void expect_lists(const TrianglesAround& around, const std::vector<std::vector<uint32_t>>& want) {
  ASSERT_EQ(around.vertex_count(), want.size());
  for (uint32_t v = 0; v < want.size(); ++v) {
    const TrianglesAround::Range range = around.of(v);
    const std::vector<uint32_t> got(range.begin(), range.end());
    ASSERT_EQ(range.size(), got.size());
    ASSERT_EQ(got, want[v]) << "vertex " << v;
  }
}

// 4 km of a 13-vertex strip: 104k triangles, far more than a 16-bit offset reaches from vertex 0.
TEST(TrianglesAround, AStripHoldsItsListsInOneByteATriangle) {
  const test::TestMesh mesh = test::straight_channel(12.0f, 4000.0f, 4001, 13);
  const TrianglesAround around = TrianglesAround::of_mesh(mesh.positions.size(), mesh.indices);
  EXPECT_TRUE(around.compact());
  EXPECT_EQ(around.offset_bytes(), 1);
  expect_lists(around, plain_lists(mesh.positions.size(), mesh.indices));
  // And each vertex's start in 2 bytes, from its block of 256 vertices' start.
  const size_t blocks = mesh.positions.size() / 256 + 1;
  EXPECT_LE(around.memory_bytes(),
            2 * (mesh.positions.size() + 1) + 4 * blocks + mesh.indices.size());
}

// Sections 200 vertices wide: a vertex's triangles lie about 400 from v * T / V, past what a byte
// reaches, so they keep 2 bytes a triangle, and the same lists.
TEST(TrianglesAround, AWideStripHoldsItsListsInTwoBytesATriangle) {
  const test::TestMesh mesh = test::straight_channel(400.0f, 100.0f, 51, 200);
  const TrianglesAround around = TrianglesAround::of_mesh(mesh.positions.size(), mesh.indices);
  EXPECT_EQ(around.offset_bytes(), 2);
  expect_lists(around, plain_lists(mesh.positions.size(), mesh.indices));
  EXPECT_LE(around.memory_bytes(), 2 * (mesh.positions.size() + 1) +
                                       4 * (mesh.positions.size() / 256 + 1) +
                                       2 * mesh.indices.size());
}

// A fan of 70000 triangles about vertex 0: vertex 1 starts 70000 entries past its block's start,
// more than 2 bytes count, so every start keeps 4 bytes, and the lists are the same.
TEST(TrianglesAround, AVertexOfTooManyTrianglesKeepsFourByteStarts) {
  constexpr uint32_t kFan = 70000;
  std::vector<uint32_t> indices;
  for (uint32_t i = 1; i <= kFan; ++i) indices.insert(indices.end(), {0, i, i + 1});
  const TrianglesAround around = TrianglesAround::of_mesh(kFan + 2, indices);
  expect_lists(around, plain_lists(kFan + 2, indices));
  EXPECT_GE(around.memory_bytes(), 4 * size_t{kFan + 3});
}

TEST(TrianglesAround, AShuffledMeshKeepsFourBytesATriangleAndTheSameLists) {
  std::vector<uint32_t> new_of_old;
  const test::TestMesh mesh =
      test::shuffled(test::straight_channel(12.0f, 4000.0f, 4001, 13), 7, &new_of_old);
  const TrianglesAround around = TrianglesAround::of_mesh(mesh.positions.size(), mesh.indices);
  EXPECT_FALSE(around.compact());
  EXPECT_EQ(around.offset_bytes(), 0);
  expect_lists(around, plain_lists(mesh.positions.size(), mesh.indices));
}

TEST(TrianglesAround, ANonIndexedMeshCountsEveryThreeVertices) {
  const std::vector<uint32_t> none;
  const TrianglesAround around = TrianglesAround::of_mesh(6, none);
  expect_lists(around, {{0}, {0}, {0}, {1}, {1}, {1}});
}

// The river surface keeps its nodes' triangles so: a procedural river's in 1 byte a triangle,
// and equal to a plain count over its triangles.
TEST(TrianglesAround, ARiverSurfacesNodesTrianglesAreCompact) {
  const test::TestMesh mesh = test::bend(40.0f, 52.0f, 3.0f, 600, 9);
  RiverSurface surface;
  ASSERT_TRUE(RiverSurface::build(mesh.positions, mesh.indices, {}, &surface).ok());
  EXPECT_EQ(surface.triangles_around().offset_bytes(), 1);
  const std::vector<uint32_t> triangles(surface.triangles().begin(), surface.triangles().end());
  expect_lists(surface.triangles_around(), plain_lists(surface.node_count(), triangles));
}

}  // namespace
}  // namespace siviflow
