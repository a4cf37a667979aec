// The tile table's lattice (shaders/shared.h): lattice point (i, j) is the world point
// (i, j) * tile / 2 in x, z. The table holds the points around the water, a power of two per
// axis (at most SIVIFLOW_TILE_TABLE_MAX, sized once), or a window of them around the camera when
// the river is larger. Pure: no Vulkan.
#pragma once

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include "siviflow/renderer.h"

namespace siviflow {

class TileLattice {
 public:
  // Sizes the table for water within the XZ bounds [lo, hi] at `tile_size_m`.
  void size(glm::vec2 water_lo, glm::vec2 water_hi, float tile_size_m);
  // The lattice at this frame's tile size (the table keeps its size), and the window's corner
  // for a camera at `camera` looking along `forward` (world, need not be unit).
  void place(glm::vec2 water_lo, glm::vec2 water_hi, float tile_size_m, glm::vec3 camera,
             glm::vec3 forward);
  const TileTableLayout& layout() const { return layout_; }

 private:
  void span(glm::vec2 water_lo, glm::vec2 water_hi, float tile_size_m);

  glm::ivec2 lo_{0};  // the lattice points within a tile of the water
  glm::ivec2 hi_{0};
  TileTableLayout layout_;
};

}  // namespace siviflow
