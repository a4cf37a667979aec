#include "tile_lattice.h"

#include <algorithm>
#include <bit>
#include <cstdint>

#include <glm/common.hpp>
#include <glm/geometric.hpp>

#include "shared.h"

namespace siviflow {

void TileLattice::span(glm::vec2 water_lo, glm::vec2 water_hi, float tile_size_m) {
  const float half_tile = 0.5f * tile_size_m;
  lo_ = glm::ivec2(glm::floor((water_lo - tile_size_m) / half_tile));
  hi_ = glm::ivec2(glm::ceil((water_hi + tile_size_m) / half_tile));
  layout_.tile_size_m = tile_size_m;
}

void TileLattice::size(glm::vec2 water_lo, glm::vec2 water_hi, float tile_size_m) {
  span(water_lo, water_hi, tile_size_m);
  const auto table_side = [](int points) {
    return std::min(std::bit_ceil(static_cast<uint32_t>(points)), SIVIFLOW_TILE_TABLE_MAX);
  };
  layout_.width = table_side(hi_.x - lo_.x + 1);
  layout_.height = table_side(hi_.y - lo_.y + 1);
  layout_.corner_x = lo_.x;
  layout_.corner_z = lo_.y;
}

// The window's corner: the river's first point when the table holds them all, else a window
// reaching as far ahead of the camera as it can (what lies behind is not seen), kept over the
// river. Water beyond the window, farther than the table's reach (768 m at
// SIVIFLOW_TILE_TABLE_MAX), takes the tiles of points a table size away.
void TileLattice::place(glm::vec2 water_lo, glm::vec2 water_hi, float tile_size_m,
                        glm::vec3 camera, glm::vec3 forward) {
  span(water_lo, water_hi, tile_size_m);
  const glm::ivec2 size(layout_.width, layout_.height);
  const glm::vec2 position = glm::vec2(camera.x, camera.z) / (0.5f * tile_size_m);
  glm::vec2 ahead(forward.x, forward.z);
  ahead = glm::length(ahead) > 0.0f ? glm::normalize(ahead) : glm::vec2(0.0f);
  // The window's centre half a window ahead, less a tile, so the camera's own tiles stay in it.
  const glm::ivec2 centre(glm::round(position + ahead * (0.5f * glm::vec2(size) - 2.0f)));
  const glm::ivec2 corner = glm::clamp(centre - size / 2, lo_, glm::max(lo_, hi_ - size + 1));
  layout_.corner_x = corner.x;
  layout_.corner_z = corner.y;
}

}  // namespace siviflow
