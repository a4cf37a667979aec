// Which pieces of the built-in world a view draws, and how finely: a piece outside the view's
// frustum or wholly below its clip plane is left out, a terrain chunk draws the coarsest level
// whose height error still looks at most a pixel or so where the chunk is nearest, and its skirts
// only along edges where a crack can open.
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include <glm/mat4x4.hpp>
#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

#include "index_range.h"

namespace siviflow {

// A terrain chunk's edges: the grid lines it begins and ends on, first its rows', then its
// columns'.
constexpr size_t kChunkEdges = 4;

// A static piece of the world: a terrain chunk with its levels of detail, or an object.
struct LodPiece {
  glm::vec3 lo{0.0f};  // bounds in the world
  glm::vec3 hi{0.0f};
  std::vector<IndexRange> levels;  // level 0 first; a chunk's ground only
  // Per level, the most its surface strays from level 0's in height (metres; non-decreasing).
  // Empty: one level, drawn at any distance.
  std::vector<float> level_error;
  // A chunk's skirts: per level, each edge's, laid right after the level's ground and in edge
  // order. Empty for an object.
  std::vector<std::array<IndexRange, kChunkEdges>> skirts;
  // The chunk across each edge, as its index in the pieces less this one's; 0 where none is.
  std::array<int32_t, kChunkEdges> across{};
  uint32_t material = 0;  // SceneDraw::material
  bool one_sided = false;  // SceneDraw::one_sided
};

struct CullView {
  glm::mat4 view_proj{1.0f};
  glm::vec3 camera{0.0f};
  glm::vec4 clip_plane{0.0f, 0.0f, 0.0f, 1.0f};  // kept where dot(plane, (p, 1)) >= 0
  float focal_pixels = 1.0f;  // pixels per unit of tangent: viewport height / (2 tan(fov_y / 2))
  float max_error_pixels = 1.0f;  // the most a level's height error may look
};

constexpr uint32_t kCulled = ~uint32_t{0};

// The level `piece` is drawn at in `view`, or kCulled.
uint32_t choose_level(const LodPiece& piece, const CullView& view);

// What piece `i` of `pieces` draws at `levels[i]` (each piece's choose_level; not kCulled): its
// level's ground, and the skirts of the edges across which a chunk is drawn at another level or
// none lies (a crack opens only between levels), ranges that touch joined; appended to `out`.
// `levels` holds a level for every piece, so the pieces across (by `across`) are found in it.
void append_piece_ranges(std::span<const LodPiece> pieces, std::span<const uint32_t> levels,
                         size_t i, std::vector<IndexRange>* out);

// The focal length in pixels of a perspective projection shown `viewport_height` pixels high.
float focal_pixels(const glm::mat4& projection, float viewport_height);

}  // namespace siviflow
