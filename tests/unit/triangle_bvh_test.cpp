// The ray-cast hierarchy at the extremes of its input: centroids spread by a denormal distance,
// and positions past the world limit (siviflow/sim/world_limits.h). Bugs found by fuzzing and by
// mutants of real glTF files (issue 28), each failing on the code before its fix. And what a long
// river's hierarchy holds.
#include "sim/triangle_bvh.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numeric>
#include <random>
#include <vector>

#include "brute_force_ray.h"
#include "river_test_meshes.h"

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

// Leaves of up to 16 triangles and the order in 1 byte a triangle: 6.5 bytes a triangle (nodes
// and the order); the 2-byte order held 7.5, a 4-byte one 9.5, and leaves of 8 more still. Every
// vertex is still found where it lies.
TEST(TriangleBvh, AStripRiversHierarchyHoldsUnderSevenBytesATriangle) {
  const test::TestMesh mesh = test::straight_channel(12.0f, 2000.0f, 2001, 13);  // 2 km, as a strip's
  TriangleBvh bvh;
  ASSERT_TRUE(TriangleBvh::build(mesh.positions, mesh.indices, &bvh).ok());
  EXPECT_EQ(bvh.order_bytes(), 1);
  EXPECT_LE(static_cast<double>(bvh.memory_bytes()) / static_cast<double>(bvh.triangle_count()),
            7.0);
  for (uint32_t v = 0; v < mesh.positions.size(); v += 101) {
    const glm::vec3& p = mesh.positions[v];
    glm::dvec3 weights;
    EXPECT_NE(bvh.locate_xz(p.x, p.z, &weights), UINT32_MAX) << "vertex " << v;
  }
}

// The mesh's indices with triangle t renumbered new_of_old[t].
std::vector<uint32_t> renumbered(const test::TestMesh& mesh,
                                 const std::vector<uint32_t>& new_of_old) {
  std::vector<uint32_t> indices(mesh.indices.size());
  for (uint32_t t = 0; t < new_of_old.size(); ++t) {
    for (int k = 0; k < 3; ++k) indices[3 * new_of_old[t] + k] = mesh.indices[3 * t + k];
  }
  return indices;
}

// The mesh's triangles renumbered at random: new_of_old[t] is triangle t's new number.
std::vector<uint32_t> shuffled_triangles(const test::TestMesh& mesh,
                                         std::vector<uint32_t>* new_of_old) {
  new_of_old->resize(mesh.indices.size() / 3);
  std::iota(new_of_old->begin(), new_of_old->end(), 0u);
  std::shuffle(new_of_old->begin(), new_of_old->end(), std::mt19937(11));
  return renumbered(mesh, *new_of_old);
}

// The hierarchy of a strip as numbered and of the same strip numbered at random, whose indices
// it keeps (a hierarchy reads them in place).
struct StripAndShuffled {
  std::vector<uint32_t> new_of_old, shuffled;
  TriangleBvh strip, mixed;
};
void build_strip_and_shuffled(const test::TestMesh& mesh, StripAndShuffled* out) {
  out->shuffled = shuffled_triangles(mesh, &out->new_of_old);
  ASSERT_TRUE(TriangleBvh::build(mesh.positions, mesh.indices, &out->strip).ok());
  ASSERT_TRUE(TriangleBvh::build(mesh.positions, out->shuffled, &out->mixed).ok());
}

// Random rays down onto a strip of the given half width and length find the same triangle
// (renumbered by new_of_old) at the same t in both hierarchies, and so does locate_xz.
void expect_the_same_hits(const TriangleBvh& a, const TriangleBvh& b,
                          const std::vector<uint32_t>& new_of_old, float half_width, float length) {
  std::mt19937 random(5);
  std::uniform_real_distribution<float> across(-half_width, half_width), along(0.1f, length);
  for (int n = 0; n < 2000; ++n) {
    const glm::vec3 origin(across(random), 3.0f, along(random));
    RayHit ha, hb;
    ASSERT_TRUE(a.intersect(origin, {0.1f, -1.0f, 0.2f}, 10.0f, &ha)) << n;
    ASSERT_TRUE(b.intersect(origin, {0.1f, -1.0f, 0.2f}, 10.0f, &hb)) << n;
    EXPECT_EQ(new_of_old[ha.triangle], hb.triangle) << n;
    EXPECT_EQ(ha.t, hb.t) << n;
    glm::dvec3 wa, wb;
    EXPECT_EQ(new_of_old[a.locate_xz(origin.x, origin.z, &wa)],
              b.locate_xz(origin.x, origin.z, &wb));
  }
}

// Sections of 200 vertices: a leaf's triangles span more than a byte from its lowest, so the
// order keeps 2 bytes a triangle, and answers as the same strip numbered at random does (4).
TEST(TriangleBvh, AWideStripKeepsATwoByteOrderAndTheSameHits) {
  const test::TestMesh mesh = test::straight_channel(200.0f, 400.0f, 401, 200);
  StripAndShuffled trees;
  ASSERT_NO_FATAL_FAILURE(build_strip_and_shuffled(mesh, &trees));
  EXPECT_EQ(trees.strip.order_bytes(), 2);
  EXPECT_EQ(trees.mixed.order_bytes(), 4);
  expect_the_same_hits(trees.strip, trees.mixed, trees.new_of_old, 99.0f, 399.0f);
}

// Twenty triangles swap numbers with ones 2 km downstream: the few leaves they fall in would
// need 2 bytes, so they are split instead and the order keeps 1 byte a triangle, with the same
// hits as the strip numbered in order.
TEST(TriangleBvh, AFewTrianglesNumberedFarAwaySplitTheirLeavesAndKeepAOneByteOrder) {
  const test::TestMesh mesh = test::straight_channel(12.0f, 4000.0f, 4001, 13);
  std::vector<uint32_t> new_of_old(mesh.indices.size() / 3);
  std::iota(new_of_old.begin(), new_of_old.end(), 0u);
  for (uint32_t t = 1000; t < 1000 + 20 * 997; t += 997)
    std::swap(new_of_old[t], new_of_old[t + 48000]);
  const std::vector<uint32_t> swapped = renumbered(mesh, new_of_old);
  TriangleBvh strip, split;
  ASSERT_TRUE(TriangleBvh::build(mesh.positions, mesh.indices, &strip).ok());
  ASSERT_TRUE(TriangleBvh::build(mesh.positions, swapped, &split).ok());
  EXPECT_EQ(split.order_bytes(), 1);
  EXPECT_LE(split.memory_bytes(), strip.memory_bytes() + 40 * 2 * 32);  // two 32-byte nodes a split
  expect_the_same_hits(strip, split, new_of_old, 5.5f, 3999.0f);
}

// Triangles numbered in no order of their place (96000 of them, more than 2 bytes count): a leaf's
// lie too far apart in number for 2 bytes from its base, so the order keeps 4 bytes a triangle
// (the strip's 1), and every ray finds the triangle the strip's hierarchy finds (renumbered) at
// the same t.
TEST(TriangleBvh, TrianglesNumberedAtRandomKeepAFourByteOrderAndTheSameHits) {
  const test::TestMesh mesh = test::straight_channel(12.0f, 4000.0f, 4001, 13);
  StripAndShuffled trees;
  ASSERT_NO_FATAL_FAILURE(build_strip_and_shuffled(mesh, &trees));
  EXPECT_EQ(trees.strip.order_bytes(), 1);
  EXPECT_EQ(trees.mixed.order_bytes(), 4);
  EXPECT_GE(trees.mixed.memory_bytes(), trees.strip.memory_bytes() + 3 * trees.new_of_old.size());
  expect_the_same_hits(trees.strip, trees.mixed, trees.new_of_old, 5.5f, 3999.0f);
}

// Each quad's two triangles (2q and 2q + 1) share an edge; at its midpoint both hold the point.
// Numbered in order, with each pair's numbers swapped, or with a few far apart (their leaves
// split by number), a hierarchy answers with the pair's lower number wherever the two share a
// leaf, whatever order its build met them in: nearly every pair, and those in split leaves.
TEST(TriangleBvh, APointOnAnEdgeTwoTrianglesShareBelongsToTheLowerNumber) {
  const test::TestMesh mesh = test::straight_channel(12.0f, 4000.0f, 4001, 13);
  const uint32_t triangles = static_cast<uint32_t>(mesh.indices.size() / 3);
  std::vector<uint32_t> in_order(triangles), pairs_swapped(triangles);
  std::iota(in_order.begin(), in_order.end(), 0u);
  for (uint32_t t = 0; t < triangles; ++t) pairs_swapped[t] = t ^ 1u;
  std::vector<uint32_t> far_apart = in_order;
  std::vector<bool> moved(triangles, false);
  for (uint32_t t = 1000; t < 1000 + 20 * 997; t += 997) {
    std::swap(far_apart[t], far_apart[t + 48000]);
    moved[t] = moved[t + 48000] = true;
  }
  for (const std::vector<uint32_t>* new_of_old : {&in_order, &pairs_swapped, &far_apart}) {
    const std::vector<uint32_t> indices = renumbered(mesh, *new_of_old);
    TriangleBvh bvh;
    ASSERT_TRUE(TriangleBvh::build(mesh.positions, indices, &bvh).ok());
    ASSERT_EQ(bvh.order_bytes(), 1);
    uint32_t pairs = 0, lower = 0, moved_pairs = 0, moved_lower = 0;
    for (uint32_t t = 0; t + 1 < triangles; t += 2, ++pairs) {
      // Triangle 2q is (a, a + 1, b) and 2q + 1 is (a + 1, b + 1, b): they share a + 1 and b.
      const glm::dvec3 p = 0.5 * (glm::dvec3(mesh.positions[mesh.indices[3 * t + 1]]) +
                                  glm::dvec3(mesh.positions[mesh.indices[3 * t + 2]]));
      const uint32_t a = (*new_of_old)[t], b = (*new_of_old)[t + 1];
      glm::dvec3 weights;
      const uint32_t found = bvh.locate_xz(p.x, p.z, &weights);
      ASSERT_TRUE(found == a || found == b) << "pair " << t << " found " << found;
      lower += found == std::min(a, b) ? 1 : 0;
      if (moved[t] || moved[t + 1]) {
        ++moved_pairs;
        moved_lower += found == std::min(a, b) ? 1 : 0;
      }
    }
    const char* numbering = new_of_old == &in_order        ? "in order"
                            : new_of_old == &pairs_swapped ? "pairs swapped"
                                                           : "far apart";
    EXPECT_GE(lower, pairs * 9 / 10) << numbering;
    EXPECT_GE(moved_lower, moved_pairs * 9 / 10) << numbering;
  }
}

// Rays from an eye a few metres above a rippled strip, aimed at its vertices (where its leaves'
// boxes end) at grazing angles, hit where a search of every triangle hits. The slab test's
// rounding rejected a box such a ray only just enters (53 of these 8190 rays missed the
// water). Where two triangles both hold the vertex, their t differ by the triangle test's own
// rounding (up to a thousandth at the most grazing angles), and either is the nearest.
TEST(TriangleBvh, ARayGrazingABoxHitsWhereEveryTriangleSearchedHits) {
  test::TestMesh mesh = test::straight_channel(20.0f, 200.0f, 101, 11);
  std::mt19937 random(3);
  std::uniform_real_distribution<float> ripple(-0.05f, 0.05f);
  for (glm::vec3& p : mesh.positions) p.y += ripple(random);
  TriangleBvh bvh;
  ASSERT_TRUE(TriangleBvh::build(mesh.positions, mesh.indices, &bvh).ok());
  std::uniform_real_distribution<float> eye_x(-30.0f, 30.0f), eye_y(0.3f, 4.0f),
      eye_z(-40.0f, 0.0f);
  int missed = 0, hits = 0;
  for (uint32_t v = 0; v < mesh.positions.size(); ++v) {
    for (int n = 0; n < 8; ++n) {
      const glm::vec3 origin(eye_x(random), eye_y(random), eye_z(random));
      const glm::vec3 direction = mesh.positions[v] - origin;
      RayHit expected, got;
      const bool want =
          test::brute_force_hit(mesh.positions, mesh.indices, origin, direction, 2.0f, &expected);
      const bool have = bvh.intersect(origin, direction, 2.0f, &got);
      hits += want ? 1 : 0;
      if (want && !have) ++missed;
      EXPECT_TRUE(want || !have) << v;  // nothing found where no triangle is met
      const auto holds_v = [&](uint32_t t) {
        return mesh.indices[3 * t] == v || mesh.indices[3 * t + 1] == v ||
               mesh.indices[3 * t + 2] == v;
      };
      if (want && have && !(holds_v(got.triangle) && holds_v(expected.triangle))) {
        EXPECT_NEAR(got.t, expected.t, 1e-5f * expected.t) << v;
      }
    }
  }
  EXPECT_GT(hits, 8000);
  EXPECT_EQ(missed, 0) << "of " << hits << " rays that meet a triangle";
}

}  // namespace
}  // namespace siviflow
