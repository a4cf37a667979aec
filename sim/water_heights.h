// The height of the water surface on a regular XZ grid around the river, for the flow pass's
// tile table: each tile centre is placed on the water at its own height before it is projected
// into the screen-space flow texture (a descending river is not one plane).
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

namespace siviflow {

struct WaterHeights {
  glm::vec2 origin{0.0f};       // world x, z of sample (0, 0)
  float spacing = 1.0f;         // metres between samples along x and z
  uint32_t columns = 0;         // samples along x
  uint32_t rows = 0;            // samples along z
  std::vector<float> heights;   // rows * columns, row-major (z major), metres
  std::vector<uint32_t> steps;  // per sample: grid steps (4-neighbour) to a sample with a vertex

  float at(uint32_t column, uint32_t row) const { return heights[size_t{row} * columns + column]; }
};

// Samples every `spacing` metres (more if needed to stay within `max_samples_per_axis`) over the
// XZ bounds of `surface` widened by `margin` metres. A sample holding vertices takes the height
// of the one nearest to it; every other sample that of the first such sample reached in
// 4-neighbour steps growing outwards from all of them (the nearest in steps), so
// samples beyond the banks carry the height of the water next to them; `steps` says how far
// that water is. `surface` not empty,
// finite; spacing > 0; max_samples_per_axis >= 2.
WaterHeights water_heights(std::span<const glm::vec3> surface, float spacing, float margin,
                           uint32_t max_samples_per_axis);

}  // namespace siviflow
