#include "scene/terrain_chunks.h"

#include <algorithm>
#include <limits>
#include <map>

#include <glm/common.hpp>

namespace siviflow {
namespace {

// The grid lines a level of a chunk joins: every step-th from `begin`, and the chunk's end.
std::vector<uint32_t> level_lines(uint32_t begin, uint32_t end, uint32_t step) {
  std::vector<uint32_t> lines;
  for (uint32_t i = begin; i < end; i += step) lines.push_back(i);
  lines.push_back(end);
  return lines;
}

class ChunkBuilder {
 public:
  ChunkBuilder(const std::vector<SceneVertex>& points, uint32_t columns, uint32_t base,
               SceneGeometry* geometry)
      : points_(points), columns_(columns), base_(base), geometry_(geometry) {}

  // The chunk of grid quads [c0, c1) x [r0, r1).
  LodPiece build(uint32_t c0, uint32_t c1, uint32_t r0, uint32_t r1, float spacing) {
    LodPiece piece;
    piece.spacing = spacing;
    piece.lo = glm::vec3(std::numeric_limits<float>::max());
    piece.hi = glm::vec3(std::numeric_limits<float>::lowest());
    for (uint32_t r = r0; r <= r1; ++r) {
      for (uint32_t c = c0; c <= c1; ++c) {
        piece.lo = glm::min(piece.lo, points_[at(c, r)].position);
        piece.hi = glm::max(piece.hi, points_[at(c, r)].position);
      }
    }
    // A crack between levels is never deeper than the chunk's own rise.
    skirt_depth_ = std::max(1.0f, piece.hi.y - piece.lo.y);
    std::vector<uint32_t>& indices = geometry_->indices;
    for (uint32_t level = 0; level < kTerrainLevels; ++level) {
      const uint32_t step = 1u << level;
      if (step > std::max(c1 - c0, r1 - r0)) break;
      const std::vector<uint32_t> cols = level_lines(c0, c1, step);
      const std::vector<uint32_t> rows = level_lines(r0, r1, step);
      const auto first = static_cast<uint32_t>(indices.size());
      for (size_t j = 0; j + 1 < rows.size(); ++j) {
        for (size_t i = 0; i + 1 < cols.size(); ++i) {
          const uint32_t a = base_ + at(cols[i], rows[j]);
          const uint32_t b = base_ + at(cols[i + 1], rows[j]);
          const uint32_t c = base_ + at(cols[i], rows[j + 1]);
          const uint32_t d = base_ + at(cols[i + 1], rows[j + 1]);
          indices.insert(indices.end(), {a, c, b, b, c, d});
        }
      }
      const auto skirts_first = static_cast<uint32_t>(indices.size());
      for (size_t i = 0; i + 1 < cols.size(); ++i) {
        add_skirt(cols[i], r0, cols[i + 1], r0);
        add_skirt(cols[i], r1, cols[i + 1], r1);
      }
      for (size_t j = 0; j + 1 < rows.size(); ++j) {
        add_skirt(c0, rows[j], c0, rows[j + 1]);
        add_skirt(c1, rows[j], c1, rows[j + 1]);
      }
      const auto end = static_cast<uint32_t>(indices.size());
      piece.levels.push_back({first, end - first});
      if (level == 0) piece.level0_skirt_index_count = end - skirts_first;
    }
    piece.lo.y -= skirt_depth_;
    hung_.clear();  // skirts hang per chunk: their depth is the chunk's
    return piece;
  }

 private:
  uint32_t at(uint32_t column, uint32_t row) const { return row * (columns_ + 1) + column; }

  // The copy of grid point (column, row) hung skirt_depth_ below it.
  uint32_t hung(uint32_t column, uint32_t row) {
    const uint32_t point = at(column, row);
    const auto found = hung_.find(point);
    if (found != hung_.end()) return found->second;
    SceneVertex lowered = points_[point];
    lowered.position.y -= skirt_depth_;
    const auto index = static_cast<uint32_t>(geometry_->vertices.size());
    geometry_->vertices.push_back(lowered);
    hung_.emplace(point, index);
    return index;
  }

  // A wall from the edge (c0, r0)-(c1, r1) down to its hung copy (the scene draws both faces).
  void add_skirt(uint32_t c0, uint32_t r0, uint32_t c1, uint32_t r1) {
    const uint32_t a = base_ + at(c0, r0);
    const uint32_t b = base_ + at(c1, r1);
    const uint32_t a_low = hung(c0, r0);
    const uint32_t b_low = hung(c1, r1);
    geometry_->indices.insert(geometry_->indices.end(), {a, a_low, b, b, a_low, b_low});
  }

  const std::vector<SceneVertex>& points_;
  uint32_t columns_;
  uint32_t base_;
  SceneGeometry* geometry_;
  float skirt_depth_ = 1.0f;
  std::map<uint32_t, uint32_t> hung_;  // grid point -> its hung copy, in the current chunk
};

}  // namespace

void add_chunked_grid(const std::vector<SceneVertex>& points, uint32_t columns, uint32_t rows,
                      float spacing, SceneGeometry* geometry) {
  const auto base = static_cast<uint32_t>(geometry->vertices.size());
  geometry->vertices.insert(geometry->vertices.end(), points.begin(), points.end());
  ChunkBuilder builder(points, columns, base, geometry);
  for (uint32_t r0 = 0; r0 < rows; r0 += kChunkQuads) {
    for (uint32_t c0 = 0; c0 < columns; c0 += kChunkQuads) {
      geometry->pieces.push_back(builder.build(c0, std::min(c0 + kChunkQuads, columns), r0,
                                               std::min(r0 + kChunkQuads, rows), spacing));
    }
  }
}

}  // namespace siviflow
