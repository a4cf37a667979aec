#include "scene/river_ground.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include <glm/common.hpp>
#include <glm/geometric.hpp>

#include "scene/terrain_chunks.h"
#include "sim/triangle_bvh.h"

namespace siviflow {
namespace {

constexpr float kMarginM = 60.0f;         // ground beyond the river's bounds on every side
constexpr float kMinSpacingM = 1.5f;      // grid spacing; coarser on very large rivers, so the
constexpr float kMaxQuads = 24000.0f;     // ground costs at most this many quads to draw
constexpr float kBankRiseM = 1.0f;        // the bank rises this much over its first few metres
constexpr float kBankRunM = 3.0f;
constexpr float kValleyRise = 0.003f;     // then the valley floor climbs as this times d^2 ...
constexpr float kHillHeightM = 6.0f;      // ... and breaks into hills this high far out
constexpr float kBelowBedM = 0.3f;        // under the water the ground hides below the bed
constexpr float kHashCellM = 8.0f;        // cell of the bank points' lookup grid

// The bank's points (where the water is 0 deep) in a uniform grid, for the nearest one.
class BankLookup {
 public:
  explicit BankLookup(std::vector<glm::vec3> points) : points_(std::move(points)) {
    lo_ = glm::vec2(std::numeric_limits<float>::max());
    glm::vec2 hi(std::numeric_limits<float>::lowest());
    for (const glm::vec3& p : points_) {
      lo_ = glm::min(lo_, glm::vec2(p.x, p.z));
      hi = glm::max(hi, glm::vec2(p.x, p.z));
    }
    size_ = glm::ivec2(glm::floor((hi - lo_) / kHashCellM)) + 1;
    start_.assign(size_t(size_.x) * size_.y + 1, 0);
    for (const glm::vec3& p : points_) ++start_[cell_index(cell_of(p))];
    for (size_t c = 1; c < start_.size(); ++c) start_[c] += start_[c - 1];
    order_.resize(points_.size());
    for (uint32_t i = 0; i < points_.size(); ++i) order_[--start_[cell_index(cell_of(points_[i]))]] = i;
  }

  // The bank point nearest to (x, z) in the horizontal plane, and its distance.
  const glm::vec3& nearest(glm::vec2 xz, float* distance) const {
    const glm::ivec2 centre = glm::clamp(glm::ivec2(glm::floor((xz - lo_) / kHashCellM)),
                                         glm::ivec2(0), size_ - 1);
    uint32_t best = 0;
    float best_sq = std::numeric_limits<float>::max();
    // Rings of cells outwards until the ring's nearest possible point lies beyond the best found
    // (ring r is at least r - 1 cells away, whether the point is inside the grid or beyond it).
    for (int ring = 0; ring <= std::max(size_.x, size_.y); ++ring) {
      const float reach = (ring - 1) * kHashCellM;
      if (ring > 1 && reach * reach > best_sq) break;
      for (int y = centre.y - ring; y <= centre.y + ring; ++y) {
        for (int x = centre.x - ring; x <= centre.x + ring; ++x) {
          if (std::max(std::abs(x - centre.x), std::abs(y - centre.y)) != ring) continue;
          if (x < 0 || y < 0 || x >= size_.x || y >= size_.y) continue;
          const size_t c = cell_index({x, y});
          for (uint32_t k = start_[c]; k < start_[c + 1]; ++k) {
            const glm::vec3& p = points_[order_[k]];
            const float sq = glm::dot(glm::vec2(p.x, p.z) - xz, glm::vec2(p.x, p.z) - xz);
            if (sq < best_sq) {
              best_sq = sq;
              best = order_[k];
            }
          }
        }
      }
    }
    *distance = std::sqrt(best_sq);
    return points_[best];
  }

 private:
  glm::ivec2 cell_of(const glm::vec3& p) const {
    return glm::clamp(glm::ivec2(glm::floor((glm::vec2(p.x, p.z) - lo_) / kHashCellM)),
                      glm::ivec2(0), size_ - 1);
  }
  size_t cell_index(glm::ivec2 c) const { return size_t(c.y) * size_.x + c.x; }

  std::vector<glm::vec3> points_;
  glm::vec2 lo_{0.0f};
  glm::ivec2 size_{1};
  std::vector<uint32_t> start_;  // per cell, its first entry of order_ (one past the last: +1)
  std::vector<uint32_t> order_;
};

}  // namespace

Status add_ground_around_rivers(std::span<const RiverMesh> rivers, SceneGeometry* geometry) {
  if (rivers.empty()) return Status::success();
  std::vector<TriangleBvh> bvhs(rivers.size());
  std::vector<glm::vec3> bank;
  glm::vec3 lo(std::numeric_limits<float>::max()), hi(std::numeric_limits<float>::lowest());
  for (size_t r = 0; r < rivers.size(); ++r) {
    const RiverMesh& river = rivers[r];
    SIVIFLOW_TRY(TriangleBvh::build(river.positions, river.indices, &bvhs[r]));
    const size_t before = bank.size();
    for (size_t v = 0; v < river.positions.size(); ++v) {
      if (river.depth[v] <= 1e-4f) bank.push_back(river.positions[v]);
      lo = glm::min(lo, river.positions[v]);
      hi = glm::max(hi, river.positions[v]);
    }
    // No dry edge found: every vertex bounds the water.
    if (bank.size() == before) bank.insert(bank.end(), river.positions.begin(), river.positions.end());
  }
  const BankLookup lookup(std::move(bank));

  const glm::vec2 origin = glm::vec2(lo.x, lo.z) - kMarginM;
  const glm::vec2 extent = glm::vec2(hi.x - lo.x, hi.z - lo.z) + 2.0f * kMarginM;
  const float spacing = std::max(kMinSpacingM, std::sqrt(extent.x * extent.y / kMaxQuads));
  const glm::ivec2 quads = glm::max(glm::ivec2(glm::ceil(extent / spacing)), glm::ivec2(1));
  const float ray_top = hi.y + 1.0f;  // down from above every river, to below every one
  const float ray_length = hi.y - lo.y + 2.0f;

  // Heights first (normals need the neighbours'), with each point's water level.
  const size_t columns = size_t(quads.x) + 1;
  std::vector<glm::vec3> points(columns * (quads.y + 1));
  std::vector<float> water(points.size());
  for (int row = 0; row <= quads.y; ++row) {
    for (int col = 0; col <= quads.x; ++col) {
      const glm::vec2 xz = origin + spacing * glm::vec2(col, row);
      float d = 0.0f;
      const glm::vec3& shore = lookup.nearest(xz, &d);
      float y = shore.y + kBankRiseM * glm::smoothstep(0.0f, kBankRunM, d) + kValleyRise * d * d;
      const float hills = glm::smoothstep(15.0f, 45.0f, d);
      y += hills * kHillHeightM *
           (0.5f + 0.5f * std::sin(0.045f * xz.x + 1.3f) * std::sin(0.037f * xz.y + 0.4f));
      for (size_t r = 0; r < rivers.size(); ++r) {
        RayHit hit;
        if (bvhs[r].intersect({xz.x, ray_top, xz.y}, {0.0f, -1.0f, 0.0f}, ray_length, &hit)) {
          // Under the water: below the bed there, out of sight.
          const uint32_t v = bvhs[r].nearest_vertex(hit.position, spacing, hit.triangle);
          y = std::min(y, hit.position.y - rivers[r].depth[v] - kBelowBedM);
        }
      }
      const size_t i = size_t(row) * columns + col;
      points[i] = {xz.x, y, xz.y};
      water[i] = shore.y;
    }
  }
  std::vector<SceneVertex> grid;
  grid.reserve(points.size());
  for (int row = 0; row <= quads.y; ++row) {
    for (int col = 0; col <= quads.x; ++col) {
      const auto at = [&](int c, int r) {
        return points[size_t(std::clamp(r, 0, quads.y)) * columns + std::clamp(c, 0, quads.x)];
      };
      const glm::vec3 n = glm::normalize(glm::cross(at(col, row + 1) - at(col, row - 1),
                                                    at(col + 1, row) - at(col - 1, row)));
      const size_t i = size_t(row) * columns + col;
      grid.push_back(ground_vertex(points[i], n.y < 0.0f ? -n : n, points[i].y - water[i]));
    }
  }
  add_chunked_grid(grid, uint32_t(quads.x), uint32_t(quads.y), geometry);
  return Status::success();
}

}  // namespace siviflow
