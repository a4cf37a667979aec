// A height grid (the procedural valley, the ground around glTF rivers) cut into square chunks,
// each drawable at levels of detail that join every 2^l-th grid point, with skirts hanging from
// every level's edges so neighbours at different levels leave no cracks between them.
#pragma once

#include <cstdint>
#include <vector>

#include "scene/default_scene.h"

namespace siviflow {

constexpr uint32_t kChunkQuads = 16;    // grid quads along a chunk's side
constexpr uint32_t kTerrainLevels = 4;  // levels 0..3: every 1st, 2nd, 4th, 8th grid point

// Appends the grid's `points` ((columns + 1) x (rows + 1) vertices, row by row, counter-
// clockwise seen from above as the row grows towards the viewer) to `geometry` as chunk pieces,
// each level with its height error.
void add_chunked_grid(const std::vector<SceneVertex>& points, uint32_t columns, uint32_t rows,
                      SceneGeometry* geometry);

}  // namespace siviflow
