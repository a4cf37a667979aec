// River networks for the sim tests: a Y of two tributaries joining into one channel (or, read
// the other way, a fork), built row by row so every row is a section.
#pragma once

#include <cstdint>
#include <vector>

#include <glm/vec3.hpp>

#include "river_test_meshes.h"

namespace siviflow::test {

struct YMesh {
  TestMesh mesh;
  // A vertex in the middle of each end.
  uint32_t main_end = 0;   // the main channel's far end (z = main_length)
  uint32_t left_end = 0;   // the left tributary's (+X side) far end
  uint32_t right_end = 0;  // the right tributary's
};

// Two arms, each `arm_width` wide, meet at the tip of the tongue between them (x = 0, z = 0)
// and run on as one channel twice as wide along +Z to z = main_length. Upstream (z < 0) the left
// arm lies on +X, the right on -X, the tongue between them widening by `spread` metres per metre;
// the left arm reaches back to z = -left_length, the right to -right_length. Rows every `dz`
// along, `across` cells across each arm.
inline YMesh y_channel(float arm_width, float main_length, float left_length, float right_length,
                       float spread, float dz, uint32_t across) {
  YMesh y;
  TestMesh& m = y.mesh;
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
  const float w = arm_width;
  const uint32_t main_rows = uint32_t(std::lround(main_length / dz));
  std::vector<uint32_t> tip_row = row(0.0f, w, -w, 2 * across);
  std::vector<uint32_t> prev = tip_row;
  for (uint32_t k = 1; k <= main_rows; ++k) {
    std::vector<uint32_t> next = row(float(k) * dz, w, -w, 2 * across);
    zip(prev, next);
    prev = std::move(next);
  }
  y.main_end = prev[across];
  for (const int side : {+1, -1}) {
    const float length = side > 0 ? left_length : right_length;
    const uint32_t rows = uint32_t(std::lround(length / dz));
    // The tip row's half on this side, from the left shore to the right.
    prev = side > 0 ? std::vector<uint32_t>(tip_row.begin(), tip_row.begin() + across + 1)
                    : std::vector<uint32_t>(tip_row.begin() + across, tip_row.end());
    for (uint32_t k = 1; k <= rows; ++k) {
      const float z = -float(k) * dz, off = float(k) * dz * spread;
      std::vector<uint32_t> next =
          side > 0 ? row(z, w + off, off, across) : row(z, -off, -w - off, across);
      zip(next, prev);
      prev = std::move(next);
    }
    (side > 0 ? y.left_end : y.right_end) = prev[across / 2];
  }
  return y;
}

}  // namespace siviflow::test
