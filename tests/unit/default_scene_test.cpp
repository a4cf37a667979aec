// The built-in world's objects: each tree and boulder stands on dry land beside the river, and a
// spot the water covers gets none.
#include "scene/default_scene.h"

#include <gtest/gtest.h>

#include <vector>

#include "default_river.h"

namespace siviflow {
namespace {

// The objects of `geometry`: its pieces without skirts (a terrain chunk has them).
std::vector<LodPiece> objects_of(const SceneGeometry& geometry) {
  std::vector<LodPiece> objects;
  for (const LodPiece& piece : geometry.pieces) {
    if (piece.skirts.empty()) objects.push_back(piece);
  }
  return objects;
}

// Every object's footprint centre lies where the river leaves land.
void expect_all_on_dry_land(const ProceduralRiver& river, const SceneGeometry& geometry) {
  for (const LodPiece& object : objects_of(geometry)) {
    const float x = 0.5f * (object.lo.x + object.hi.x);
    const float z = 0.5f * (object.lo.z + object.hi.z);
    EXPECT_EQ(river.depth_at(x, z), 0.0f)
        << "an object stands in the water at x " << x << ", z " << z;
  }
}

TEST(DefaultScene, EveryTreeAndBoulderStandsOnDryLand) {
  const ProceduralRiver river(default_river_params());
  const SceneGeometry geometry = build_scene_geometry(river, {});
  // Two boulders and six trees, all beside the default river's water.
  EXPECT_EQ(objects_of(geometry).size(), 8u);
  expect_all_on_dry_land(river, geometry);
}

TEST(DefaultScene, ASpotTheWaterCoversGetsNoObject) {
  for (const float width : {30.0f, 40.0f}) {
    ProceduralRiverParams params = default_river_params();
    params.width = width;  // wide enough to cover some spots the default river leaves dry
    const ProceduralRiver river(params);
    const SceneGeometry geometry = build_scene_geometry(river, {});
    EXPECT_LT(objects_of(geometry).size(), 8u) << "width " << width;
    expect_all_on_dry_land(river, geometry);
  }
}

}  // namespace
}  // namespace siviflow
