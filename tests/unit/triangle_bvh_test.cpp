// The ray-cast hierarchy at the extremes of its input: centroids spread by a denormal distance,
// and positions past the world limit (siviflow/sim/world_limits.h). Bugs found by fuzzing and by
// mutants of real glTF files (issue 28), each failing on the code before its fix. And what a long
// river's hierarchy holds.
#include <algorithm>
#include <cstdint>
#include <vector>

#include <gtest/gtest.h>

#include "river_test_meshes.h"
#include "sim/triangle_bvh.h"

namespace siviflow {
namespace {

// Found by a mutant of rivers.gltf (a node rotation of -3.4e38): the binning's kBins / extent was
// infinite for a denormal extent, a centroid at the low end fell in bin NaN, and the build wrote
// outside its bins.
TEST(TriangleBvh, CentroidsADenormalApartBuildAndAnswer) {
  std::vector<glm::vec3> positions;
  for (int i = 0; i < 40; ++i) {
    const float x = static_cast<float>(i) * 1.0e-44f;  // denormals
    positions.insert(positions.end(), {{x, 0.0f, 0.0f}, {x, 1.0f, 0.0f}, {x, 0.0f, 1.0f}});
  }
  TriangleBvh bvh;
  ASSERT_TRUE(TriangleBvh::build(positions, {}, &bvh).ok());
  EXPECT_EQ(bvh.triangle_count(), 40u);
  RayHit hit;
  EXPECT_TRUE(bvh.intersect({-1.0f, 0.25f, 0.25f}, {1.0f, 0.0f, 0.0f}, 10.0f, &hit));
}

TEST(TriangleBvh, PositionsPastTheWorldLimitAreRefusedByIndexAndValue) {
  const std::vector<glm::vec3> positions = {{0, 0, 0}, {1, 0, 0}, {0, 0, 1}, {0, 0, 0}, {-3.4e38f, 0, 0}, {0, 0, 1}};
  TriangleBvh bvh;
  const Status s = TriangleBvh::build(positions, {}, &bvh, "Mesh");
  EXPECT_EQ(s.message(), "Mesh::positions[4] (-3.4e+38, 0, 0) lies beyond the world limit of ±1e+06 m");
}

// Leaves of up to 16 triangles: under 10.5 bytes a triangle (nodes and the triangle order); 8 held
// 14.8. Every vertex is still found where it lies.
TEST(TriangleBvh, AStripRiversHierarchyHoldsUnderElevenBytesATriangle) {
  const test::TestMesh mesh = test::straight_channel(12.0f, 2000.0f, 2001, 13);  // 2 km, as a strip's
  TriangleBvh bvh;
  ASSERT_TRUE(TriangleBvh::build(mesh.positions, mesh.indices, &bvh).ok());
  EXPECT_LE(static_cast<double>(bvh.memory_bytes()) / static_cast<double>(bvh.triangle_count()),
            10.5);
  for (uint32_t v = 0; v < mesh.positions.size(); v += 101) {
    const glm::vec3& p = mesh.positions[v];
    glm::dvec3 weights;
    EXPECT_NE(bvh.locate_xz(p.x, p.z, &weights), UINT32_MAX) << "vertex " << v;
  }
}

// A river's hierarchy with leaves of its own runs of triangles holds no order (under 6 bytes a
// triangle, against 10.5) and answers every query as the spatial one does: the nearest hit of a
// ray and the triangle under a point for every triangle (so each is in a leaf), the nearest
// vertex and the vertices in a box; and a point on an edge goes to the same triangle.
TEST(TriangleBvh, LeavesOfTheMeshsRunsAnswerAsSpatialLeavesDo) {
  // Quads a metre square, rows of 24 triangles: runs of 16 and 8.
  const test::TestMesh mesh = test::straight_channel(12.0f, 2000.0f, 2001, 13);
  TriangleBvh spatial, runs;
  ASSERT_TRUE(TriangleBvh::build(mesh.positions, mesh.indices, &spatial).ok());
  ASSERT_TRUE(
      TriangleBvh::build(mesh.positions, mesh.indices, &runs, "River", BvhLeaves::kMeshRuns).ok());
  EXPECT_EQ(runs.triangle_count(), spatial.triangle_count());
  EXPECT_LE(static_cast<double>(runs.memory_bytes()) / static_cast<double>(runs.triangle_count()),
            6.0);
  const auto corner = [&](uint32_t t, int k) { return mesh.positions[mesh.indices[3 * t + k]]; };
  for (uint32_t t = 0; t < runs.triangle_count(); ++t) {
    // The centre of triangle t: on no edge, so no two triangles tie for it.
    const glm::vec3 p = (corner(t, 0) + corner(t, 1) + corner(t, 2)) / 3.0f;
    RayHit a, b;
    const glm::vec3 origin = p + glm::vec3(3.0f, 20.0f, -2.0f);
    const glm::vec3 direction = p - origin;
    ASSERT_TRUE(spatial.intersect(origin, direction, 2.0f, &a)) << "triangle " << t;
    ASSERT_TRUE(runs.intersect(origin, direction, 2.0f, &b)) << "triangle " << t;
    ASSERT_EQ(b.triangle, t);
    ASSERT_EQ(a.triangle, b.triangle);
    ASSERT_EQ(a.t, b.t) << "triangle " << t;
    glm::dvec3 wa, wb;
    ASSERT_EQ(runs.locate_xz(p.x, p.z, &wb), t);
    ASSERT_EQ(spatial.locate_xz(p.x, p.z, &wa), t);
    ASSERT_EQ(wa, wb) << "triangle " << t;
    // Halfway along its first edge, which it shares with a neighbour (but on the banks).
    const glm::vec3 edge = 0.5f * (corner(t, 0) + corner(t, 1));
    ASSERT_EQ(spatial.locate_xz(edge.x, edge.z, &wa), runs.locate_xz(edge.x, edge.z, &wb))
        << "triangle " << t;
    ASSERT_EQ(wa, wb) << "triangle " << t;
    if (t % 37 != 0) continue;
    EXPECT_EQ(spatial.nearest_vertex(p, 5.0f, t), runs.nearest_vertex(p, 5.0f, t))
        << "triangle " << t;
    EXPECT_TRUE(runs.any_hit(origin, direction, 0.0f, 2.0f)) << "triangle " << t;
    std::vector<uint32_t> in_a, in_b;
    const XzBox box{glm::dvec2(p.x, p.z) - 3.0, glm::dvec2(p.x, p.z) + 3.0};
    spatial.append_vertices_in(box, &in_a);
    runs.append_vertices_in(box, &in_b);
    std::sort(in_a.begin(), in_a.end());
    std::sort(in_b.begin(), in_b.end());
    EXPECT_EQ(in_a, in_b) << "triangle " << t;
    EXPECT_FALSE(in_a.empty());
  }
}

// A mesh whose order has no locality gets spatial leaves whatever was asked: runs of shuffled
// triangles would each span the river.
TEST(TriangleBvh, AShuffledMeshGetsSpatialLeaves) {
  std::vector<uint32_t> new_of_old;
  const test::TestMesh mesh =
      test::shuffled(test::straight_channel(12.0f, 2000.0f, 2001, 13), 3, &new_of_old);
  TriangleBvh spatial, runs;
  ASSERT_TRUE(TriangleBvh::build(mesh.positions, mesh.indices, &spatial).ok());
  ASSERT_TRUE(
      TriangleBvh::build(mesh.positions, mesh.indices, &runs, "River", BvhLeaves::kMeshRuns).ok());
  EXPECT_EQ(runs.memory_bytes(), spatial.memory_bytes());
}

}  // namespace
}  // namespace siviflow
