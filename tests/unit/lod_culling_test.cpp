// The built-in world's culling and levels of detail: a chunk further away never draws more
// triangles, a chunk behind the camera, beside the frustum, beyond its far plane or below the
// reflection's clip plane is not drawn, and a chunked grid's levels join ever fewer points with skirts at their edges.
#include <algorithm>
#include <array>
#include <cmath>

#include <glm/geometric.hpp>
#include <glm/gtc/matrix_transform.hpp>
#include <gtest/gtest.h>

#include "scene/lod_culling.h"
#include "scene/terrain_chunks.h"
#include "view_culling.h"

namespace siviflow {
namespace {

constexpr float kHeight = 720.0f;
constexpr float kFar = 10000.0f;

glm::mat4 projection() {
  glm::mat4 p = glm::perspectiveRH_ZO(glm::radians(55.0f), 16.0f / 9.0f, 0.1f, kFar);
  p[1][1] *= -1.0f;  // Vulkan's +Y down
  return p;
}

// A camera at `eye` looking along +Z.
CullView view_from(glm::vec3 eye) {
  CullView view;
  view.camera = eye;
  view.view_proj = projection() * glm::lookAtRH(eye, eye + glm::vec3(0, 0, 1), glm::vec3(0, 1, 0));
  view.focal_pixels = focal_pixels(projection(), kHeight);
  return view;
}

// A grid of quads 1.5 m apart, its corner at the origin, rolling up to `amplitude` metres above
// and below y = 0.
SceneGeometry rolling_grid(uint32_t columns, uint32_t rows, float amplitude) {
  std::vector<SceneVertex> points;
  for (uint32_t r = 0; r <= rows; ++r) {
    for (uint32_t c = 0; c <= columns; ++c) {
      const float y = amplitude * std::sin(0.5f * c) * std::sin(0.3f * r);
      points.push_back(ground_vertex({c * 1.5f, y, r * 1.5f}, {0, 1, 0}, 1.0f));
    }
  }
  SceneGeometry geometry;
  add_chunked_grid(points, columns, rows, &geometry);
  return geometry;
}

LodPiece chunk_at(float z) {
  SceneGeometry geometry = rolling_grid(16, 16, 1.0f);
  LodPiece piece = geometry.pieces.at(0);
  piece.lo.z += z;
  piece.hi.z += z;
  return piece;
}

TEST(LodCulling, FocalPixelsOfTheProjection) {
  EXPECT_NEAR(focal_pixels(projection(), kHeight), kHeight / (2.0f * std::tan(glm::radians(27.5f))), 0.01f);
}

TEST(LodCulling, AChunkTwiceAsFarDrawsAtMostTheSameTriangles) {
  const CullView view = view_from({12.0f, 5.0f, 0.0f});
  const LodPiece chunk = chunk_at(0.0f);
  ASSERT_EQ(chunk.level_error.size(), kTerrainLevels);
  EXPECT_EQ(chunk.level_error[0], 0.0f);
  for (uint32_t level = 1; level < kTerrainLevels; ++level) {
    EXPECT_GE(chunk.level_error[level], chunk.level_error[level - 1]) << level;
    EXPECT_LT(chunk.levels[level].index_count, chunk.levels[level - 1].index_count) << level;
  }
  EXPECT_GT(chunk.level_error[1], 0.0f);
  uint32_t levels_seen = 0;
  for (float z = 2.0f; z < 5000.0f; z *= 2.0f) {
    const LodPiece near = chunk_at(z);
    const LodPiece far = chunk_at(2.0f * z);
    const uint32_t near_level = choose_level(near, view);
    const uint32_t far_level = choose_level(far, view);
    ASSERT_NE(near_level, kCulled) << z;
    ASSERT_NE(far_level, kCulled) << z;
    EXPECT_GE(far_level, near_level) << z;
    EXPECT_LE(far.levels[far_level].index_count, near.levels[near_level].index_count) << z;
    levels_seen |= 1u << far_level;
  }
  // Near, the finest; far, the coarsest; and the levels between on the way.
  EXPECT_EQ(choose_level(chunk_at(2.0f), view), 0u);
  EXPECT_EQ(levels_seen & (1u << (kTerrainLevels - 1)), 1u << (kTerrainLevels - 1)) << levels_seen;
  EXPECT_GE(__builtin_popcount(levels_seen), 3) << levels_seen;
  // A flat chunk is as good coarse as fine: its coarsest level, however near.
  SceneGeometry flat = rolling_grid(16, 16, 0.0f);
  EXPECT_EQ(choose_level(flat.pieces.at(0), view), kTerrainLevels - 1);
}

TEST(LodCulling, AChunkBehindTheCameraOrBesideTheViewIsNotDrawn) {
  const CullView view = view_from({12.0f, 5.0f, 0.0f});
  EXPECT_NE(choose_level(chunk_at(10.0f), view), kCulled);
  EXPECT_EQ(choose_level(chunk_at(-40.0f), view), kCulled) << "behind";
  LodPiece beside = chunk_at(10.0f);
  beside.lo.x += 300.0f;
  beside.hi.x += 300.0f;
  EXPECT_EQ(choose_level(beside, view), kCulled) << "far to the side";
  EXPECT_EQ(choose_level(chunk_at(kFar + 10.0f), view), kCulled) << "beyond the far plane";
  // One the camera stands in is seen whatever it looks at.
  EXPECT_NE(choose_level(chunk_at(-12.0f), view_from({12.0f, 0.0f, 0.0f})), kCulled);
}

TEST(LodCulling, AnInfiniteReverseDepthViewCullsOnlyWhatIsOutside) {
  const float f = 1.0f / std::tan(glm::radians(27.5f));
  glm::mat4 reverse(0.0f);  // near maps to 1, infinity to 0
  reverse[0][0] = f / (16.0f / 9.0f);
  reverse[1][1] = -f;
  reverse[2][3] = -1.0f;
  reverse[3][2] = 0.1f;
  const glm::vec3 eye(12.0f, 5.0f, 0.0f);
  CullView view = view_from(eye);
  view.view_proj = reverse * glm::lookAtRH(eye, eye + glm::vec3(0, 0, 1), glm::vec3(0, 1, 0));
  EXPECT_NE(choose_level(chunk_at(10.0f), view), kCulled);
  EXPECT_NE(choose_level(chunk_at(50000.0f), view), kCulled) << "no far plane";
  EXPECT_EQ(choose_level(chunk_at(-40.0f), view), kCulled) << "behind";
}

TEST(LodCulling, AChunkBelowTheReflectionsClipPlaneIsNotDrawn) {
  CullView view = view_from({12.0f, 5.0f, 0.0f});
  view.clip_plane = glm::vec4(0.0f, 1.0f, 0.0f, 0.0f);  // keeps y >= 0
  LodPiece under = chunk_at(10.0f);
  under.lo.y = -3.0f;
  under.hi.y = -0.5f;
  EXPECT_EQ(choose_level(under, view), kCulled);
  under.hi.y = 0.5f;  // one corner out of the water: drawn, clipped by the pass
  EXPECT_NE(choose_level(under, view), kCulled);
}

TEST(LodCulling, ObjectsHaveOneLevelAtAnyDistance) {
  LodPiece object;
  object.lo = {10.0f, 0.0f, 200.0f};
  object.hi = {12.0f, 3.0f, 202.0f};
  object.levels = {{0, 300}};  // no level errors: one level
  EXPECT_EQ(choose_level(object, view_from({12.0f, 5.0f, 0.0f})), 0u);
}

TEST(ViewCulling, ScreenBoundsHoldTheBoxAndCutItAtTheEye) {
  const CullView view = view_from({0.0f, 5.0f, 0.0f});  // looking along +Z, 5 m up
  const auto inside = [&](const glm::vec4& b, const glm::vec3& lo, const glm::vec3& hi) {
    // Every point of the box in front of the eye lands within the bounds.
    for (int i = 0; i <= 8; ++i) {
      for (int j = 0; j <= 8; ++j) {
        for (int k = 0; k <= 8; ++k) {
          const glm::vec3 p = lo + (hi - lo) * glm::vec3(i, j, k) / 8.0f;
          const glm::vec4 clip = view.view_proj * glm::vec4(p, 1.0f);
          if (clip.w < 0.01f) continue;
          const glm::vec2 uv = glm::clamp(0.5f * glm::vec2(clip) / clip.w + 0.5f, 0.0f, 1.0f);
          if (uv.x < b.x - 1e-5f || uv.x > b.z + 1e-5f || uv.y < b.y - 1e-5f || uv.y > b.w + 1e-5f) {
            return false;
          }
        }
      }
    }
    return true;
  };
  // A box ahead, below the horizon: a small part of the view, in its lower half.
  const glm::vec3 ahead_lo(-1.0f, 0.0f, 20.0f), ahead_hi(1.0f, 1.0f, 24.0f);
  const glm::vec4 ahead = box_screen_bounds(ahead_lo, ahead_hi, view.view_proj);
  EXPECT_TRUE(inside(ahead, ahead_lo, ahead_hi));
  EXPECT_LT(ahead.z - ahead.x, 0.2f);
  EXPECT_GT(ahead.y, 0.5f);
  // The water under the eye, reaching behind it: cut at the eye, it still leaves out the sky.
  const glm::vec3 under_lo(-20.0f, -1.0f, -30.0f), under_hi(20.0f, 0.0f, 200.0f);
  const glm::vec4 under = box_screen_bounds(under_lo, under_hi, view.view_proj);
  EXPECT_TRUE(inside(under, under_lo, under_hi));
  EXPECT_GT(under.y, 0.5f);
  EXPECT_EQ(under.w, 1.0f);
  EXPECT_EQ(under.x, 0.0f);
  EXPECT_EQ(under.z, 1.0f);
  // Wholly behind: nothing.
  const glm::vec4 behind = box_screen_bounds({-1.0f, 0.0f, -10.0f}, {1.0f, 1.0f, -5.0f}, view.view_proj);
  EXPECT_GT(behind.x, behind.z);
}

TEST(ViewCulling, ANarrowedViewCullsWhatLiesOutsideItsPart) {
  const CullView view = view_from({0.0f, 5.0f, 0.0f});  // looking along +Z: -X to the right
  // The lower half of the view, left third.
  const glm::vec4 part(0.0f, 0.5f, 1.0f / 3.0f, 1.0f);
  const glm::mat4 narrowed = narrowed_view(view.view_proj, part);
  // That part now spans the whole of clip space: its corners land on clip space's.
  const glm::vec4 lower_left = box_screen_bounds({12.0f, -2.0f, 20.0f}, {13.0f, -1.0f, 21.0f},
                                                 view.view_proj);
  ASSERT_GT(lower_left.x, part.x);  // on screen, inside the part
  ASSERT_LT(lower_left.z, part.z);
  ASSERT_GT(lower_left.y, part.y);
  ASSERT_LT(lower_left.w, part.w);
  const glm::vec4 same = box_screen_bounds({12.0f, -2.0f, 20.0f}, {13.0f, -1.0f, 21.0f}, narrowed);
  EXPECT_NEAR(same.x, (lower_left.x - part.x) / (part.z - part.x), 1e-4f);
  EXPECT_NEAR(same.y, (lower_left.y - part.y) / (part.w - part.y), 1e-4f);
  EXPECT_FALSE(box_outside_view({12.0f, -2.0f, 20.0f}, {13.0f, -1.0f, 21.0f}, narrowed));
  // A box in the view's upper half, or on its right, is outside the part.
  EXPECT_FALSE(box_outside_view({-1.0f, 20.0f, 40.0f}, {1.0f, 21.0f, 41.0f}, view.view_proj));
  EXPECT_TRUE(box_outside_view({-1.0f, 20.0f, 40.0f}, {1.0f, 21.0f, 41.0f}, narrowed));
  EXPECT_FALSE(box_outside_view({-21.0f, -2.0f, 40.0f}, {-20.0f, -1.0f, 41.0f}, view.view_proj));
  EXPECT_TRUE(box_outside_view({-21.0f, -2.0f, 40.0f}, {-20.0f, -1.0f, 41.0f}, narrowed));
}

// Every run of a piece's index buffer: its levels' ground, then their skirts.
std::vector<IndexRange> runs_of(const LodPiece& piece) {
  std::vector<IndexRange> runs = piece.levels;
  for (const auto& edges : piece.skirts) runs.insert(runs.end(), edges.begin(), edges.end());
  return runs;
}

TEST(TerrainChunks, LevelsJoinFewerPointsAndHangSkirts) {
  const SceneGeometry geometry = rolling_grid(40, 20, 1.0f);
  // 40 x 20 quads in 16-quad chunks: 3 x 2, the last row and column narrower.
  ASSERT_EQ(geometry.pieces.size(), 6u);
  const LodPiece& full = geometry.pieces[0];
  ASSERT_EQ(full.levels.size(), kTerrainLevels);
  ASSERT_EQ(full.skirts.size(), kTerrainLevels);
  for (uint32_t level = 0; level < kTerrainLevels; ++level) {
    const uint32_t per_side = 16u >> level;
    // Two triangles a quad; two a skirt segment, each edge's skirt right after the one before.
    EXPECT_EQ(full.levels[level].index_count, 6u * per_side * per_side) << level;
    uint32_t next = full.levels[level].first_index + full.levels[level].index_count;
    for (size_t edge = 0; edge < kChunkEdges; ++edge) {
      EXPECT_EQ(full.skirts[level][edge].first_index, next) << level << " " << edge;
      EXPECT_EQ(full.skirts[level][edge].index_count, 6u * per_side) << level << " " << edge;
      next += full.skirts[level][edge].index_count;
    }
  }
  // Row by row, three chunks a row: the chunks across each edge.
  using Across = std::array<int32_t, kChunkEdges>;
  EXPECT_EQ(geometry.pieces[0].across, (Across{0, 3, 0, 1}));
  EXPECT_EQ(geometry.pieces[4].across, (Across{-3, 0, -1, 1}));
  EXPECT_EQ(geometry.pieces[5].across, (Across{-3, 0, -1, 0}));
  // Skirts hang below the ground, deeper than any level's error: the bounds reach down.
  float deepest = 0.0f;
  for (const LodPiece& piece : geometry.pieces) deepest = std::max(deepest, piece.level_error.back());
  EXPECT_LT(full.lo.y, -deepest);
  EXPECT_LE(full.hi.y, 1.0f);
  // Every level's triangles use grid points (or their hung copies) of its own chunk only.
  for (const LodPiece& piece : geometry.pieces) {
    for (const IndexRange& level : runs_of(piece)) {
      for (uint32_t i = level.first_index; i < level.first_index + level.index_count; ++i) {
        const glm::vec3& p = geometry.vertices.at(geometry.indices.at(i)).position;
        EXPECT_GE(p.x, piece.lo.x - 1e-4f);
        EXPECT_LE(p.x, piece.hi.x + 1e-4f);
        EXPECT_GE(p.z, piece.lo.z - 1e-4f);
        EXPECT_LE(p.z, piece.hi.z + 1e-4f);
      }
    }
  }
  // One-sided: every level's ground faces up and every skirt out of its chunk (a crack is seen
  // from the neighbour's side), so culling back faces hides none of what the view sees.
  for (const LodPiece& piece : geometry.pieces) {
    EXPECT_TRUE(piece.one_sided);
    const glm::vec3 centre = 0.5f * (piece.lo + piece.hi);
    for (const IndexRange& level : runs_of(piece)) {
      for (uint32_t i = level.first_index; i < level.first_index + level.index_count; i += 3) {
        const glm::vec3& a = geometry.vertices[geometry.indices[i]].position;
        const glm::vec3& b = geometry.vertices[geometry.indices[i + 1]].position;
        const glm::vec3& c = geometry.vertices[geometry.indices[i + 2]].position;
        const glm::vec3 normal = glm::cross(b - a, c - a);
        const glm::vec2 out(a.x + b.x + c.x - 3.0f * centre.x, a.z + b.z + c.z - 3.0f * centre.z);
        if (std::abs(normal.y) > 1e-6f) {
          EXPECT_GT(normal.y, 0.0f) << "ground triangle " << i / 3;
        } else {
          EXPECT_GT(normal.x * out.x + normal.z * out.y, 0.0f) << "skirt triangle " << i / 3;
        }
      }
    }
  }
  // The chunk of 8 x 4 quads (the corner) coarsens as far as its longer side allows.
  EXPECT_EQ(geometry.pieces[5].levels.size(), 4u);
  EXPECT_EQ(geometry.pieces[5].level_error.size(), 4u);
}

// The ranges a chunk draws, at the levels chosen for all.
std::vector<IndexRange> ranges_of(const SceneGeometry& geometry,
                                  const std::vector<uint32_t>& levels, size_t i) {
  std::vector<IndexRange> ranges;
  append_piece_ranges(geometry.pieces, levels, i, &ranges);
  return ranges;
}

IndexRange joined(IndexRange a, const IndexRange& b) {
  EXPECT_EQ(a.first_index + a.index_count, b.first_index);
  a.index_count += b.index_count;
  return a;
}

// A chunk's level with all four skirts.
IndexRange whole(const LodPiece& piece, uint32_t level) {
  IndexRange range = piece.levels[level];
  for (const IndexRange& skirt : piece.skirts[level]) range = joined(range, skirt);
  return range;
}

TEST(TerrainChunks, SkirtsOnlyWhereACrackCanOpen) {
  // 3 x 3 chunks: the middle one (4) has a neighbour across every edge.
  const SceneGeometry geometry = rolling_grid(48, 48, 1.0f);
  ASSERT_EQ(geometry.pieces.size(), 9u);
  const LodPiece& middle = geometry.pieces[4];
  std::vector<uint32_t> levels(9, 1);
  // All at one level: they share every edge's points, and the middle one draws its ground only.
  EXPECT_EQ(ranges_of(geometry, levels, 4), std::vector<IndexRange>{middle.levels[1]});
  // A corner chunk hangs skirts along the grid's border, where no chunk lies across: its first
  // row's joined to its ground, its first column's apart.
  const LodPiece& corner = geometry.pieces[0];
  EXPECT_EQ(ranges_of(geometry, levels, 0),
            (std::vector<IndexRange>{joined(corner.levels[1], corner.skirts[1][0]),
                                     corner.skirts[1][2]}));
  // The chunk across the last row finer, the one across the first column coarser: a skirt on
  // each of those edges (the two joined), on both sides of each.
  levels[7] = 0;
  levels[3] = 2;
  EXPECT_EQ(ranges_of(geometry, levels, 4),
            (std::vector<IndexRange>{middle.levels[1],
                                     joined(middle.skirts[1][1], middle.skirts[1][2])}));
  // Those two differ from every neighbour (or lie on the border) across every edge: ground and
  // all skirts, one range.
  EXPECT_EQ(ranges_of(geometry, levels, 7), std::vector<IndexRange>{whole(geometry.pieces[7], 0)});
  EXPECT_EQ(ranges_of(geometry, levels, 3), std::vector<IndexRange>{whole(geometry.pieces[3], 2)});
  // A neighbour not drawn opens no crack.
  levels[7] = kCulled;
  levels[3] = kCulled;
  EXPECT_EQ(ranges_of(geometry, levels, 4), std::vector<IndexRange>{middle.levels[1]});
}

// The grid points a skirt hangs from (each segment's two upper corners; the rest are hung copies).
std::vector<uint32_t> hung_from(const SceneGeometry& geometry, const IndexRange& skirt) {
  std::vector<uint32_t> points;
  for (uint32_t i = skirt.first_index; i < skirt.first_index + skirt.index_count; i += 6) {
    points.push_back(geometry.indices[i]);
    points.push_back(geometry.indices[i + 2]);
  }
  std::sort(points.begin(), points.end());
  points.erase(std::unique(points.begin(), points.end()), points.end());
  return points;
}

TEST(TerrainChunks, ASkirtHangsFromTheEdgeItSharesWithTheChunkAcross) {
  // Two grids, the second appended after the first: its ranges and offsets move with it.
  SceneGeometry geometry = rolling_grid(3 * kChunkQuads, 2 * kChunkQuads, 1.0f);
  const size_t first_grid = geometry.pieces.size();
  append_geometry(rolling_grid(2 * kChunkQuads, 3 * kChunkQuads, 2.0f), &geometry);
  ASSERT_EQ(geometry.pieces.size(), first_grid + 6);
  size_t shared_edges = 0;
  for (size_t i = 0; i < geometry.pieces.size(); ++i) {
    const LodPiece& piece = geometry.pieces[i];
    const size_t grid_begin = i < first_grid ? 0 : first_grid;
    const size_t grid_end = i < first_grid ? first_grid : geometry.pieces.size();
    for (size_t level = 0; level < piece.skirts.size(); ++level) {
      // The skirts lie right after the level's ground, in the appended index buffer.
      EXPECT_EQ(piece.skirts[level][0].first_index,
                piece.levels[level].first_index + piece.levels[level].index_count);
      for (size_t edge = 0; edge < kChunkEdges; ++edge) {
        const int32_t across = piece.across[edge];
        if (across == 0) continue;
        const size_t other = i + across;
        ASSERT_GE(other, grid_begin) << i << " " << edge;
        ASSERT_LT(other, grid_end) << i << " " << edge;
        // Its first row's line is the last row's of the chunk before it, and so on: at one level
        // both hang from the same grid points.
        const size_t facing = edge ^ 1u;
        EXPECT_EQ(geometry.pieces[other].across[facing], -across);
        EXPECT_EQ(hung_from(geometry, piece.skirts[level][edge]),
                  hung_from(geometry, geometry.pieces[other].skirts[level][facing]))
            << i << " " << edge << " " << level;
        ++shared_edges;
      }
    }
  }
  // 3 x 2 chunks share 7 edges and 2 x 3 share 7, counted from both sides at 4 levels.
  EXPECT_EQ(shared_edges, 2u * 14u * kTerrainLevels);
}

}  // namespace
}  // namespace siviflow
