#include "sim/water_heights.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <glm/common.hpp>
#include <glm/geometric.hpp>

namespace siviflow {

WaterHeights water_heights(std::span<const glm::vec3> surface, float spacing, float margin,
                           uint32_t max_samples_per_axis) {
  glm::vec2 lo(std::numeric_limits<float>::max());
  glm::vec2 hi(std::numeric_limits<float>::lowest());
  for (const glm::vec3& p : surface) {
    lo = glm::min(lo, glm::vec2(p.x, p.z));
    hi = glm::max(hi, glm::vec2(p.x, p.z));
  }
  lo -= margin;
  hi += margin;
  const float widest = std::max(hi.x - lo.x, hi.y - lo.y);
  WaterHeights grid;
  grid.origin = lo;
  grid.spacing = std::max(spacing, widest / static_cast<float>(max_samples_per_axis - 1));
  const auto samples = [&](float extent) {
    return std::min(max_samples_per_axis,
                    static_cast<uint32_t>(std::ceil(extent / grid.spacing)) + 1);
  };
  grid.columns = samples(hi.x - lo.x);
  grid.rows = samples(hi.y - lo.y);
  const size_t count = size_t{grid.columns} * grid.rows;
  grid.heights.assign(count, 0.0f);

  // Seeds: each sample holding vertices takes the height of the one nearest to it.
  std::vector<float> seed_distance(count, std::numeric_limits<float>::max());
  for (const glm::vec3& p : surface) {
    const glm::vec2 at = (glm::vec2(p.x, p.z) - grid.origin) / grid.spacing;
    const auto column =
        static_cast<uint32_t>(std::clamp(std::lround(at.x), 0L, long{grid.columns} - 1));
    const auto row = static_cast<uint32_t>(std::clamp(std::lround(at.y), 0L, long{grid.rows} - 1));
    const size_t i = size_t{row} * grid.columns + column;
    const float d = glm::distance(at, glm::vec2(column, row));
    if (d < seed_distance[i]) {
      seed_distance[i] = d;
      grid.heights[i] = p.y;
    }
  }
  // Breadth-first from all seeds at once: every other sample takes the height of the seed whose
  // wave reaches it first (the nearest in steps), in a fixed order, so the grid is deterministic.
  constexpr uint32_t kUnreached = std::numeric_limits<uint32_t>::max();
  grid.steps.assign(count, kUnreached);
  std::vector<size_t> frontier;
  for (size_t i = 0; i < count; ++i) {
    if (seed_distance[i] != std::numeric_limits<float>::max()) {
      frontier.push_back(i);
      grid.steps[i] = 0;
    }
  }
  for (size_t next = 0; next < frontier.size(); ++next) {
    const size_t i = frontier[next];
    const uint32_t column = static_cast<uint32_t>(i % grid.columns);
    const uint32_t row = static_cast<uint32_t>(i / grid.columns);
    const auto visit = [&](size_t j) {
      if (grid.steps[j] != kUnreached) return;
      grid.steps[j] = grid.steps[i] + 1;
      grid.heights[j] = grid.heights[i];
      frontier.push_back(j);
    };
    if (column > 0) visit(i - 1);
    if (column + 1 < grid.columns) visit(i + 1);
    if (row > 0) visit(i - grid.columns);
    if (row + 1 < grid.rows) visit(i + grid.columns);
  }
  return grid;
}

}  // namespace siviflow
