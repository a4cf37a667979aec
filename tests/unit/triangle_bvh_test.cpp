// The ray-cast hierarchy at the extremes of its input: centroids spread by a denormal distance,
// and positions past the world limit (siviflow/sim/world_limits.h). Bugs found by fuzzing and by
// mutants of real glTF files (issue 28), each failing on the code before its fix. And what a long
// river's hierarchy holds.
#include <algorithm>
#include <cstdint>
#include <numeric>
#include <random>
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

// Leaves of up to 16 triangles and the order in 2 bytes a triangle: under 8.5 bytes a triangle
// (nodes and the order); a 4-byte order held 10.5, and leaves of 8 14.8. Every vertex is still
// found where it lies.
TEST(TriangleBvh, AStripRiversHierarchyHoldsUnderNineBytesATriangle) {
  const test::TestMesh mesh = test::straight_channel(12.0f, 2000.0f, 2001, 13);  // 2 km, as a strip's
  TriangleBvh bvh;
  ASSERT_TRUE(TriangleBvh::build(mesh.positions, mesh.indices, &bvh).ok());
  EXPECT_LE(static_cast<double>(bvh.memory_bytes()) / static_cast<double>(bvh.triangle_count()),
            8.5);
  for (uint32_t v = 0; v < mesh.positions.size(); v += 101) {
    const glm::vec3& p = mesh.positions[v];
    glm::dvec3 weights;
    EXPECT_NE(bvh.locate_xz(p.x, p.z, &weights), UINT32_MAX) << "vertex " << v;
  }
}

// Triangles numbered in no order of their place (96000 of them, more than 2 bytes count): a leaf's
// lie too far apart in number for 2 bytes from its base, so the order keeps 4 bytes a triangle,
// and every ray finds the triangle the strip's hierarchy finds (renumbered) at the same t.
TEST(TriangleBvh, TrianglesNumberedAtRandomKeepAFourByteOrderAndTheSameHits) {
  const test::TestMesh mesh = test::straight_channel(12.0f, 4000.0f, 4001, 13);
  const uint32_t triangles = static_cast<uint32_t>(mesh.indices.size() / 3);
  std::vector<uint32_t> new_of_old(triangles);
  std::iota(new_of_old.begin(), new_of_old.end(), 0u);
  std::shuffle(new_of_old.begin(), new_of_old.end(), std::mt19937(11));
  std::vector<uint32_t> shuffled(mesh.indices.size());
  for (uint32_t t = 0; t < triangles; ++t) {
    for (int k = 0; k < 3; ++k) shuffled[3 * new_of_old[t] + k] = mesh.indices[3 * t + k];
  }
  TriangleBvh strip, mixed;
  ASSERT_TRUE(TriangleBvh::build(mesh.positions, mesh.indices, &strip).ok());
  ASSERT_TRUE(TriangleBvh::build(mesh.positions, shuffled, &mixed).ok());
  EXPECT_GE(mixed.memory_bytes(), strip.memory_bytes() + 2 * size_t{triangles});
  std::mt19937 random(5);
  std::uniform_real_distribution<float> across(-5.5f, 5.5f), along(0.1f, 3999.0f);
  for (int n = 0; n < 2000; ++n) {
    const glm::vec3 origin(across(random), 3.0f, along(random));
    RayHit a, b;
    ASSERT_TRUE(strip.intersect(origin, {0.1f, -1.0f, 0.2f}, 10.0f, &a)) << n;
    ASSERT_TRUE(mixed.intersect(origin, {0.1f, -1.0f, 0.2f}, 10.0f, &b)) << n;
    EXPECT_EQ(new_of_old[a.triangle], b.triangle) << n;
    EXPECT_EQ(a.t, b.t) << n;
    glm::dvec3 wa, wb;
    EXPECT_EQ(new_of_old[strip.locate_xz(origin.x, origin.z, &wa)],
              mixed.locate_xz(origin.x, origin.z, &wb));
  }
}

}  // namespace
}  // namespace siviflow
