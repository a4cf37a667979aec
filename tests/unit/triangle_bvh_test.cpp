// The ray-cast hierarchy at the extremes of its input: centroids spread by a denormal distance,
// and positions past the world limit (siviflow/sim/world_limits.h). Bugs found by fuzzing and by
// mutants of real glTF files (issue 28), each failing on the code before its fix. And what a long
// river's hierarchy holds.
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

}  // namespace
}  // namespace siviflow
