#include "scene/lod_culling.h"

#include <cmath>

#include <glm/common.hpp>
#include <glm/geometric.hpp>

#include "view_culling.h"

namespace siviflow {

uint32_t choose_level(const LodPiece& piece, const CullView& view) {
  if (piece.levels.empty() ||
      box_outside_view(piece.lo, piece.hi, view.view_proj, view.clip_plane)) {
    return kCulled;
  }
  // The nearest point of the box sets the smallest error the chunk needs.
  const glm::vec3 nearest = glm::clamp(view.camera, piece.lo, piece.hi);
  const float distance = glm::length(nearest - view.camera);
  uint32_t level = 0;
  while (level + 1 < piece.level_error.size() &&
         piece.level_error[level + 1] * view.focal_pixels <= view.max_error_pixels * distance) {
    ++level;
  }
  return level;
}

void append_piece_ranges(std::span<const LodPiece> pieces, std::span<const uint32_t> levels,
                         size_t i, std::vector<IndexRange>* out) {
  const LodPiece& piece = pieces[i];
  const uint32_t level = levels[i];
  IndexRange joined = piece.levels[level];
  if (!piece.skirts.empty()) {
    for (size_t edge = 0; edge < kChunkEdges; ++edge) {
      const int32_t across = piece.across[edge];
      // A neighbour left out draws nothing to open a crack against.
      if (across != 0 && (levels[i + across] == level || levels[i + across] == kCulled)) continue;
      const IndexRange& skirt = piece.skirts[level][edge];
      if (skirt.first_index == joined.first_index + joined.index_count) {
        joined.index_count += skirt.index_count;
      } else {
        out->push_back(joined);
        joined = skirt;
      }
    }
  }
  out->push_back(joined);
}

float focal_pixels(const glm::mat4& projection, float viewport_height) {
  return std::abs(projection[1][1]) * 0.5f * viewport_height;
}

}  // namespace siviflow
