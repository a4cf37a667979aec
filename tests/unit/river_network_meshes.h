// River networks for the sim tests and benchmarks: arms joining into one channel (a Y of two, a
// fan of more; read the other way, a fork), built row by row so every row is a section, the
// main channel a grid strip that islands can be cut from.
#pragma once

#include <cstdint>
#include <functional>
#include <glm/vec3.hpp>
#include <vector>

#include "river_test_meshes.h"
#include "sim/grid_holes.h"

namespace siviflow::test {

struct FanMesh {
  TestMesh mesh;
  uint32_t main_end = 0;           // a vertex in the middle of the main channel's far end
  std::vector<uint32_t> arm_ends;  // ... and of each arm's, from the left (+X) arm on
};

// `arm_lengths.size()` arms, each `arm_width` wide, meet at the tips of the tongues between them
// (z = 0) and run on as one channel along +Z to z = main_length. Upstream (z < 0) the arms lie
// side by side, the left one on +X, each tongue widening by 2 `spread` metres per metre; arm i
// reaches back to z = -arm_lengths[i]. Rows every `dz` along, `across` cells across each arm.
// `cut`, when given, says which quads (k along from the tips' row, j across) of the main
// channel's grid to cut out as islands (cut_grid_quads). With `blunt` cells, each tongue ends
// square, that many cells wide, instead of in a point.
inline FanMesh fan_channel(float arm_width, float main_length,
                           const std::vector<float>& arm_lengths, float spread, float dz,
                           uint32_t across,
                           const std::function<bool(uint32_t, uint32_t)>& cut = nullptr,
                           uint32_t blunt = 0) {
  FanMesh fan;
  TestMesh& m = fan.mesh;
  const uint32_t arms = uint32_t(arm_lengths.size());
  const float cell = arm_width / float(across);
  const uint32_t main_cells = arms * across + (arms - 1) * blunt;
  const float half = 0.5f * float(main_cells) * cell;
  auto row = [&](float z, float x_left, float x_right, uint32_t cells) {
    std::vector<uint32_t> ids;
    for (uint32_t j = 0; j <= cells; ++j) {
      const float t = float(j) / float(cells);
      ids.push_back(uint32_t(m.positions.size()));
      m.positions.push_back({x_left + t * (x_right - x_left), 0.0f, z});
    }
    return ids;
  };
  auto zip = [&](const std::vector<uint32_t>& a, const std::vector<uint32_t>& b) {
    for (size_t j = 0; j + 1 < a.size(); ++j) {
      m.indices.insert(m.indices.end(), {a[j], b[j], a[j + 1], a[j + 1], b[j], b[j + 1]});
    }
  };
  // The main channel first, a grid strip from the tips' row on.
  const uint32_t main_rows = uint32_t(std::lround(main_length / dz));
  const uint32_t main_across = main_cells + 1;
  std::vector<uint32_t> prev = row(0.0f, half, -half, main_cells);
  for (uint32_t k = 1; k <= main_rows; ++k) {
    std::vector<uint32_t> next = row(float(k) * dz, half, -half, main_cells);
    zip(prev, next);
    prev = std::move(next);
  }
  const glm::vec3 main_end = m.positions[prev[main_across / 2]];
  if (cut) cut_grid_quads(main_across, cut, &m.positions, &m.indices);
  for (uint32_t v = 0; v < m.positions.size(); ++v) {
    if (m.positions[v] == main_end) fan.main_end = v;
  }
  // Then each arm, from the tips' row (the grid's first, which the cut leaves whole) upstream.
  for (uint32_t i = 0; i < arms; ++i) {
    prev.clear();
    for (uint32_t j = 0; j <= across; ++j) prev.push_back(i * (across + blunt) + j);
    const uint32_t rows = uint32_t(std::lround(arm_lengths[i] / dz));
    const float shift_rate = (0.5f * float(arms - 1) - float(i)) * 2.0f * spread;
    for (uint32_t k = 1; k <= rows; ++k) {
      const float z = -float(k) * dz, shift = float(k) * dz * shift_rate;
      const float left = half - float(i) * (arm_width + float(blunt) * cell) + shift;
      std::vector<uint32_t> next = row(z, left, left - arm_width, across);
      zip(next, prev);
      prev = std::move(next);
    }
    fan.arm_ends.push_back(prev[across / 2]);
  }
  return fan;
}

struct YMesh {
  TestMesh mesh;
  uint32_t main_end = 0;   // a vertex in the middle of the main channel's far end
  uint32_t left_end = 0;   // ... of the left tributary's (+X side)
  uint32_t right_end = 0;  // ... of the right one's
};

// A Y: two arms (fan_channel), the left reaching back to -left_length, the right to
// -right_length, the tongue between them widening by 2 `spread` metres per metre.
inline YMesh y_channel(float arm_width, float main_length, float left_length, float right_length,
                       float spread, float dz, uint32_t across) {
  FanMesh fan =
      fan_channel(arm_width, main_length, {left_length, right_length}, spread, dz, across);
  return {std::move(fan.mesh), fan.main_end, fan.arm_ends[0], fan.arm_ends[1]};
}

}  // namespace siviflow::test
