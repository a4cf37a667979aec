#include "scene/terrain_chunks.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>

#include <glm/common.hpp>

namespace siviflow {
namespace {

constexpr float kSkirtMarginM = 0.1f;  // below the deepest crack

// The grid lines a level of a chunk joins: every step-th from `begin`, and the chunk's end.
std::vector<uint32_t> level_lines(uint32_t begin, uint32_t end, uint32_t step) {
  std::vector<uint32_t> lines;
  for (uint32_t i = begin; i < end; i += step) lines.push_back(i);
  lines.push_back(end);
  return lines;
}

// The most level `step`'s triangles over grid quads [c0, c1) x [r0, r1) stray in height from the
// grid's points (each coarse quad split as the fine ones are, from its top right to bottom left).
float level_error(const std::vector<SceneVertex>& points, uint32_t columns, uint32_t c0,
                  uint32_t c1, uint32_t r0, uint32_t r1, uint32_t step) {
  const auto y = [&](uint32_t c, uint32_t r) { return points[r * (columns + 1) + c].position.y; };
  const std::vector<uint32_t> cols = level_lines(c0, c1, step);
  const std::vector<uint32_t> rows = level_lines(r0, r1, step);
  float error = 0.0f;
  for (size_t j = 0; j + 1 < rows.size(); ++j) {
    for (size_t i = 0; i + 1 < cols.size(); ++i) {
      const float a = y(cols[i], rows[j]), b = y(cols[i + 1], rows[j]);
      const float c = y(cols[i], rows[j + 1]), d = y(cols[i + 1], rows[j + 1]);
      for (uint32_t r = rows[j]; r <= rows[j + 1]; ++r) {
        for (uint32_t col = cols[i]; col <= cols[i + 1]; ++col) {
          const float u = float(col - cols[i]) / float(cols[i + 1] - cols[i]);
          const float v = float(r - rows[j]) / float(rows[j + 1] - rows[j]);
          const float coarse = u + v <= 1.0f ? a + u * (b - a) + v * (c - a)
                                             : d + (1.0f - u) * (c - d) + (1.0f - v) * (b - d);
          error = std::max(error, std::abs(coarse - y(col, r)));
        }
      }
    }
  }
  return error;
}

class ChunkBuilder {
 public:
  // Skirts hang `skirt_depth` metres: deeper than any level's error, so no crack between two
  // chunks at any levels shows through.
  ChunkBuilder(const std::vector<SceneVertex>& points, uint32_t columns, uint32_t base,
               float skirt_depth, SceneGeometry* geometry)
      : points_(points), columns_(columns), base_(base), skirt_depth_(skirt_depth),
        geometry_(geometry) {}

  // The chunk of grid quads [c0, c1) x [r0, r1), its levels' errors given.
  LodPiece build(uint32_t c0, uint32_t c1, uint32_t r0, uint32_t r1, std::vector<float> errors) {
    LodPiece piece;
    piece.level_error = std::move(errors);
    piece.lo = glm::vec3(std::numeric_limits<float>::max());
    piece.hi = glm::vec3(std::numeric_limits<float>::lowest());
    for (uint32_t r = r0; r <= r1; ++r) {
      for (uint32_t c = c0; c <= c1; ++c) {
        piece.lo = glm::min(piece.lo, points_[at(c, r)].position);
        piece.hi = glm::max(piece.hi, points_[at(c, r)].position);
      }
    }
    std::vector<uint32_t>& indices = geometry_->indices;
    for (uint32_t level = 0; level < piece.level_error.size(); ++level) {
      const uint32_t step = 1u << level;
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
      piece.levels.push_back({first, static_cast<uint32_t>(indices.size()) - first});
      // Each skirt faces out of the chunk: a crack is seen from the neighbour's side. One run
      // an edge, in kChunkEdges' order, right after the ground.
      std::array<IndexRange, kChunkEdges>& skirts = piece.skirts.emplace_back();
      const auto add_edge = [&](size_t edge, const auto& add_segments) {
        const auto edge_first = static_cast<uint32_t>(indices.size());
        add_segments();
        skirts[edge] = {edge_first, static_cast<uint32_t>(indices.size()) - edge_first};
      };
      add_edge(0, [&] {
        for (size_t i = 0; i + 1 < cols.size(); ++i) add_skirt(cols[i + 1], r0, cols[i], r0);
      });
      add_edge(1, [&] {
        for (size_t i = 0; i + 1 < cols.size(); ++i) add_skirt(cols[i], r1, cols[i + 1], r1);
      });
      add_edge(2, [&] {
        for (size_t j = 0; j + 1 < rows.size(); ++j) add_skirt(c0, rows[j], c0, rows[j + 1]);
      });
      add_edge(3, [&] {
        for (size_t j = 0; j + 1 < rows.size(); ++j) add_skirt(c1, rows[j + 1], c1, rows[j]);
      });
    }
    piece.lo.y -= skirt_depth_;
    piece.one_sided = true;  // ground seen from above, its skirts from outside
    hung_.clear();  // each chunk its own copies: a neighbour may draw at another level
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

  // A wall from the edge (c0, r0)-(c1, r1) down to its hung copy, facing the side to the right of
  // that edge seen from above (+Y).
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
  float skirt_depth_;
  SceneGeometry* geometry_;
  std::map<uint32_t, uint32_t> hung_;  // grid point -> its hung copy, in the current chunk
};

}  // namespace

void add_chunked_grid(const std::vector<SceneVertex>& points, uint32_t columns, uint32_t rows,
                      SceneGeometry* geometry) {
  struct Chunk {
    uint32_t c0, c1, r0, r1;
    std::vector<float> errors;
  };
  std::vector<Chunk> chunks;
  float deepest = 0.0f;
  for (uint32_t r0 = 0; r0 < rows; r0 += kChunkQuads) {
    for (uint32_t c0 = 0; c0 < columns; c0 += kChunkQuads) {
      Chunk chunk{c0, std::min(c0 + kChunkQuads, columns), r0, std::min(r0 + kChunkQuads, rows), {}};
      for (uint32_t level = 0; level < kTerrainLevels; ++level) {
        const uint32_t step = 1u << level;
        if (step > std::max(chunk.c1 - chunk.c0, chunk.r1 - chunk.r0)) break;
        const float error =
            level == 0 ? 0.0f : level_error(points, columns, chunk.c0, chunk.c1, chunk.r0, chunk.r1, step);
        // Non-decreasing, so a level further on is never finer.
        chunk.errors.push_back(chunk.errors.empty() ? error : std::max(error, chunk.errors.back()));
      }
      deepest = std::max(deepest, chunk.errors.back());
      chunks.push_back(std::move(chunk));
    }
  }
  const auto base = static_cast<uint32_t>(geometry->vertices.size());
  geometry->vertices.insert(geometry->vertices.end(), points.begin(), points.end());
  ChunkBuilder builder(points, columns, base, deepest + kSkirtMarginM, geometry);
  // Chunks row by row, each row `per_row` of them: the pieces across the edges by offset.
  const auto per_row = static_cast<int32_t>((columns + kChunkQuads - 1) / kChunkQuads);
  const auto count = static_cast<int32_t>(chunks.size());
  for (int32_t i = 0; i < count; ++i) {
    Chunk& chunk = chunks[i];
    LodPiece piece = builder.build(chunk.c0, chunk.c1, chunk.r0, chunk.r1, std::move(chunk.errors));
    const int32_t column = i % per_row;
    piece.across = {i >= per_row ? -per_row : 0, i + per_row < count ? per_row : 0,
                    column > 0 ? -1 : 0, column + 1 < per_row ? 1 : 0};
    geometry->pieces.push_back(std::move(piece));
  }
}

}  // namespace siviflow
