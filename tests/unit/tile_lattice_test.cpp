// The tile table's lattice: sized once for the water at the starting tile size, placed every
// frame; a window that holds the camera's tiles and reaches ahead of it on a long river.
#include "tile_lattice.h"

#include <gtest/gtest.h>

#include "shaders/shared.h"

namespace siviflow {
namespace {

TEST(TileLattice, HoldsEveryPointOfASmallRiver) {
  TileLattice lattice;
  lattice.size({0.0f, 0.0f}, {10.0f, 10.0f}, 3.0f);
  // Points within a tile of the water: floor(-3 / 1.5) = -2 .. ceil(13 / 1.5) = 9, 12 of them.
  EXPECT_EQ(lattice.layout().width, 16u);
  EXPECT_EQ(lattice.layout().height, 16u);
  lattice.place({0.0f, 0.0f}, {10.0f, 10.0f}, 3.0f, {50.0f, 5.0f, 50.0f}, {1.0f, 0.0f, 1.0f});
  EXPECT_EQ(lattice.layout().corner_x, -2) << "wherever the camera, the window is the river";
  EXPECT_EQ(lattice.layout().corner_z, -2);
  // A smaller tile at runtime: more points, the same table, the window now slides.
  lattice.place({0.0f, 0.0f}, {10.0f, 10.0f}, 1.0f, {5.0f, 5.0f, -20.0f}, {0.0f, 0.0f, 1.0f});
  EXPECT_EQ(lattice.layout().width, 16u);
  EXPECT_EQ(lattice.layout().tile_size_m, 1.0f);
  EXPECT_EQ(lattice.layout().corner_z, -2) << "the window starts at the river's first point";
}

TEST(TileLattice, WindowOfALongRiverReachesAheadOfTheCamera) {
  TileLattice lattice;
  const glm::vec2 lo(-6.0f, 0.0f), hi(6.0f, 3000.0f);
  lattice.size(lo, hi, 3.0f);
  ASSERT_EQ(lattice.layout().height, SIVIFLOW_TILE_TABLE_MAX);
  const int table = static_cast<int>(SIVIFLOW_TILE_TABLE_MAX);
  // Looking down +Z from z = 1500 m (lattice z 1000): the camera's point is just inside the
  // window's near edge, the rest of the window ahead.
  lattice.place(lo, hi, 3.0f, {0.0f, 5.0f, 1500.0f}, {0.0f, -0.3f, 1.0f});
  const int camera = 1000;
  EXPECT_LE(lattice.layout().corner_z, camera - 1);
  EXPECT_GE(lattice.layout().corner_z, camera - 3);
  // Looking back up the river: the window lies behind in z.
  lattice.place(lo, hi, 3.0f, {0.0f, 5.0f, 1500.0f}, {0.0f, 0.0f, -1.0f});
  EXPECT_LE(lattice.layout().corner_z + table - 1, camera + 3);
  EXPECT_GE(lattice.layout().corner_z + table - 1, camera + 1);
  // Near the river's end, the window stays over the river.
  lattice.place(lo, hi, 3.0f, {0.0f, 5.0f, 2990.0f}, {0.0f, 0.0f, 1.0f});
  EXPECT_EQ(lattice.layout().corner_z + table - 1, 2002) << "ceil(3003 / 1.5)";
}

}  // namespace
}  // namespace siviflow
