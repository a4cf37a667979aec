#include "sim/triangle_bvh.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <type_traits>
#include <utility>

#include <glm/geometric.hpp>

#include "siviflow/sim/world_limits.h"

namespace siviflow {
namespace {

// Binned SAH, split down to leaves of 16 triangles: a 100 km river's hierarchy takes 18 MB with
// its order in 1 byte a triangle (21 in 2, 26 in 4, 40 with leaves of 8, 64 with 4); the particles'
// ray casts of a frame take 2-3 % longer than with 8 (0.50 against 0.49 ms at 1280x720).
constexpr uint32_t kLeafTriangles = 16;
// A node stays a leaf up to this size when splitting would not pay (SAH).
constexpr uint32_t kMaxLeafTriangles = 32;
static_assert(kMaxLeafTriangles <= 0xff);  // a leaf's count is the low byte of Node::leaf
constexpr int kBins = 16;
// Below this depth splits fall back to the object median, so the traversal stack is bounded.
constexpr int kMaxSahDepth = 40;
// Where few leaves' triangles lie too far apart in number for the 1-byte order, those are split
// (at most kMaxLeafTriangles - 1 levels more) rather than the whole order kept in 2 bytes.
constexpr uint32_t kSplitAtMostOneLeafIn = 64;
constexpr int kStackSize = 128;
static_assert(kStackSize > kMaxSahDepth + 32 + int{kMaxLeafTriangles});  // + 32 median levels

struct Aabb {
  glm::vec3 lo{std::numeric_limits<float>::infinity()};
  glm::vec3 hi{-std::numeric_limits<float>::infinity()};
  void grow(const glm::vec3& p) {
    lo = glm::min(lo, p);
    hi = glm::max(hi, p);
  }
  void grow(const Aabb& b) {
    lo = glm::min(lo, b.lo);
    hi = glm::max(hi, b.hi);
  }
  float half_area() const {
    const glm::vec3 e = hi - lo;
    return e.x < 0.0f ? 0.0f : e.x * e.y + e.y * e.z + e.z * e.x;
  }
};

// A triangle during the build: the centre of its bounds travels with it, so partitioning stays
// cache-local; the bounds themselves are read again from the mesh (16 bytes a triangle, not 28).
struct Ref {
  glm::vec3 centre;
  uint32_t triangle;
  float centroid(int axis) const { return centre[axis]; }
};

struct BuildTask {
  uint32_t node;
  uint32_t begin;
  uint32_t end;
  int depth;
};

// Whether the centroids spread along an axis by `extent` can be binned: a denormal extent makes
// kBins / extent infinite, and a centroid at the low end would then fall in bin NaN.
bool binnable(float extent) { return extent > 0.0f && std::isfinite(kBins / extent); }

// The bin of a centroid at `c` among centroids from `lo` spread over a binnable `extent`.
int bin_of(float c, float lo, float extent) {
  const float at = (c - lo) * (kBins / extent);
  return std::clamp(static_cast<int>(std::min(at, float(kBins - 1))), 0, kBins - 1);
}

// Squared distance from p to the box (0 inside).
float box_distance2(const glm::vec3& lo, const glm::vec3& hi, const glm::vec3& p) {
  const glm::vec3 d = glm::max(glm::max(lo - p, p - hi), glm::vec3(0.0f));
  return d.x * d.x + d.y * d.y + d.z * d.z;
}

}  // namespace

Status TriangleBvh::build(std::span<const glm::vec3> positions, std::span<const uint32_t> indices,
                          TriangleBvh* out, std::string_view mesh_name) {
  const std::string name(mesh_name);
  const size_t corner_count = indices.empty() ? positions.size() : indices.size();
  if (corner_count == 0) return Status::error(name + ": the mesh has no triangles");
  if (corner_count % 3 != 0) {
    return Status::error(name + (indices.empty() ? "::positions" : "::indices") + " has " +
                         std::to_string(corner_count) + " values, not 3 per triangle");
  }
  const size_t tri_count = corner_count / 3;
  if (tri_count > std::numeric_limits<uint32_t>::max() / 4 ||
      positions.size() > std::numeric_limits<uint32_t>::max()) {
    return Status::error(name + ": too many triangles (" + std::to_string(tri_count) + ")");
  }
  for (size_t i = 0; i < positions.size(); ++i) {
    const glm::vec3& p = positions[i];
    if (!within_world(p)) {
      return Status::error(name + "::positions[" + std::to_string(i) + "] " + world_limit_problem(p));
    }
  }
  for (size_t i = 0; i < indices.size(); ++i) {
    if (indices[i] >= positions.size()) {
      return Status::error(name + "::indices[" + std::to_string(i) + "] " +
                           std::to_string(indices[i]) + " is out of range (" +
                           std::to_string(positions.size()) + " positions)");
    }
  }

  TriangleBvh bvh;
  bvh.positions_ = positions;
  bvh.indices_ = indices;
  std::vector<Ref> refs(tri_count);
  const auto bounds = [&](uint32_t t) {
    Aabb b;
    for (int k = 0; k < 3; ++k) b.grow(positions[bvh.triangle_vertex(t, k)]);
    return b;
  };
  Aabb root_box;
  for (uint32_t t = 0; t < tri_count; ++t) {
    const Aabb b = bounds(t);
    refs[t] = {0.5f * (b.lo + b.hi), t};
    root_box.grow(b);
  }
  // A binary tree over n triangles has at most 2n - 1 nodes: reserved, it never reallocates (a
  // doubling held both copies at once); pages never written cost no memory.
  bvh.nodes_.reserve(2 * tri_count - 1);
  bvh.nodes_.push_back({root_box.lo, 0, root_box.hi, 0});

  std::vector<BuildTask> tasks{{0, 0, static_cast<uint32_t>(tri_count), 0}};
  struct Bin {
    Aabb box;
    uint32_t count = 0;
  };
  while (!tasks.empty()) {
    const BuildTask task = tasks.back();
    tasks.pop_back();
    const uint32_t count = task.end - task.begin;
    Node& node = bvh.nodes_[task.node];
    const Aabb node_box{node.lo, node.hi};
    if (count <= kLeafTriangles) {
      node.first = task.begin;
      node.leaf = count;
      continue;
    }
    Aabb centroids;
    for (uint32_t i = task.begin; i < task.end; ++i) centroids.grow(refs[i].centre);
    const glm::vec3 extent = centroids.hi - centroids.lo;

    int best_axis = -1;
    int best_split = 0;
    float best_cost = std::numeric_limits<float>::infinity();
    // One pass bins every axis, so each triangle's bounds are read once; the chosen split's
    // bins then give the children's bounds.
    Bin axis_bins[3][kBins];
    if (task.depth < kMaxSahDepth) {
      for (uint32_t i = task.begin; i < task.end; ++i) {
        const Aabb box = bounds(refs[i].triangle);
        for (int axis = 0; axis < 3; ++axis) {
          if (!binnable(extent[axis])) continue;
          const int b = bin_of(refs[i].centroid(axis), centroids.lo[axis], extent[axis]);
          axis_bins[axis][b].count++;
          axis_bins[axis][b].box.grow(box);
        }
      }
      for (int axis = 0; axis < 3; ++axis) {
        if (!binnable(extent[axis])) continue;
        const Bin* bins = axis_bins[axis];
        float right_area[kBins];
        uint32_t right_count[kBins];
        Aabb acc;
        uint32_t n = 0;
        for (int b = kBins - 1; b > 0; --b) {
          acc.grow(bins[b].box);
          n += bins[b].count;
          right_area[b] = acc.half_area();
          right_count[b] = n;
        }
        acc = Aabb{};
        n = 0;
        for (int b = 0; b < kBins - 1; ++b) {
          acc.grow(bins[b].box);
          n += bins[b].count;
          if (n == 0 || right_count[b + 1] == 0) continue;
          const float cost = acc.half_area() * static_cast<float>(n) +
                             right_area[b + 1] * static_cast<float>(right_count[b + 1]);
          if (cost < best_cost) {
            best_cost = cost;
            best_axis = axis;
            best_split = b + 1;
          }
        }
      }
      const float leaf_cost = node_box.half_area() * static_cast<float>(count);
      if (count <= kMaxLeafTriangles && !(best_cost < leaf_cost)) {
        node.first = task.begin;
        node.leaf = count;
        continue;
      }
    }

    uint32_t mid = 0;
    Aabb left_box, right_box;
    if (best_axis >= 0) {
      const float lo = centroids.lo[best_axis];
      const float axis_extent = extent[best_axis];
      const int axis = best_axis;
      const int split = best_split;
      Ref* m = std::partition(refs.data() + task.begin, refs.data() + task.end, [&](const Ref& r) {
        return bin_of(r.centroid(axis), lo, axis_extent) < split;
      });
      mid = static_cast<uint32_t>(m - refs.data());
      for (int b = 0; b < kBins; ++b) {
        (b < split ? left_box : right_box).grow(axis_bins[axis][b].box);
      }
    }
    if (best_axis < 0 || mid == task.begin || mid == task.end) {
      // Too deep for SAH, or centroids that coincide: the object median on the longest axis.
      const int axis = extent.x >= extent.y && extent.x >= extent.z ? 0 : (extent.y >= extent.z ? 1 : 2);
      mid = task.begin + count / 2;
      std::nth_element(refs.data() + task.begin, refs.data() + mid, refs.data() + task.end,
                       [axis](const Ref& a, const Ref& b) {
                         return a.centroid(axis) < b.centroid(axis) ||
                                (a.centroid(axis) == b.centroid(axis) && a.triangle < b.triangle);
                       });
      left_box = right_box = Aabb{};
      for (uint32_t i = task.begin; i < mid; ++i) left_box.grow(bounds(refs[i].triangle));
      for (uint32_t i = mid; i < task.end; ++i) right_box.grow(bounds(refs[i].triangle));
    }
    const uint32_t left = static_cast<uint32_t>(bvh.nodes_.size());
    bvh.nodes_[task.node].first = left;  // `node` may dangle once the vector grows
    bvh.nodes_[task.node].leaf = 0;
    bvh.nodes_.push_back({left_box.lo, 0, left_box.hi, 0});
    bvh.nodes_.push_back({right_box.lo, 0, right_box.hi, 0});
    tasks.push_back({left + 1, mid, task.end, task.depth + 1});
    tasks.push_back({left, task.begin, mid, task.depth + 1});
  }
  // Each leaf's triangles in ascending number: its range is its ends, a split of it parts the
  // numbers, and locate_xz's first match in it is its lowest.
  const auto by_number = [](const Ref& a, const Ref& b) { return a.triangle < b.triangle; };
  for (const Node& n : bvh.nodes_) {
    if (n.leaf != 0)
      std::sort(refs.begin() + n.first, refs.begin() + n.first + size_of(n), by_number);
  }
  const auto leaf_range = [&](const Node& n) {
    return std::pair{refs[n.first].triangle, refs[n.first + size_of(n) - 1].triangle};
  };
  // The order from each leaf's base: in 1 byte an entry where every leaf's triangles lie within
  // 255 of its lowest (its base, which the node's upper 24 bits must hold); else in 2 where they
  // lie within 65536 of the lowest rounded down to a multiple of 256; else in 4, no bases.
  constexpr uint32_t kMaxByteEntry = std::numeric_limits<uint8_t>::max();
  uint32_t leaves = 0, wide = 0, spread16 = 0;  // spread16: the largest 2-byte entry
  for (const Node& n : bvh.nodes_) {
    if (n.leaf == 0) continue;
    const auto [lo, hi] = leaf_range(n);
    ++leaves;
    wide += hi - lo > kMaxByteEntry ? 1 : 0;
    spread16 = std::max(spread16, hi - (lo & ~0xffu));
  }
  const bool bytes_address = tri_count <= (size_t{1} << 24);
  if (bytes_address && wide > 0 && wide <= leaves / kSplitAtMostOneLeafIn) {
    // Each wide leaf becomes two, parted at the widest gap between its triangles' numbers, until
    // every leaf's fit a byte (the children are appended, so this loop comes to them too).
    for (uint32_t k = 0; k < bvh.nodes_.size(); ++k) {
      const Node n = bvh.nodes_[k];
      if (n.leaf == 0) continue;
      if (const auto [lo, hi] = leaf_range(n); hi - lo <= kMaxByteEntry) continue;
      Ref* const begin = refs.data() + n.first;
      Ref* const end = begin + size_of(n);
      Ref* cut = begin + 1;
      for (Ref* r = begin + 2; r < end; ++r) {
        if (r->triangle - (r - 1)->triangle > cut->triangle - (cut - 1)->triangle) cut = r;
      }
      const auto child = [&](const Ref* from, const Ref* to) {
        Aabb box;
        for (const Ref* r = from; r < to; ++r) box.grow(bounds(r->triangle));
        const auto first = static_cast<uint32_t>(from - refs.data());
        return Node{box.lo, first, box.hi, static_cast<uint32_t>(to - from)};
      };
      bvh.nodes_[k].first = static_cast<uint32_t>(bvh.nodes_.size());
      bvh.nodes_[k].leaf = 0;
      bvh.nodes_.push_back(child(begin, cut));
      bvh.nodes_.push_back(child(cut, end));
    }
    wide = 0;
  }
  // Each leaf's base is its lowest triangle masked by `base_mask`, written into the leaf's upper
  // bits shifted up by `shift`; its entries are its triangles less the base.
  const auto fill_from_bases = [&](auto* order, uint32_t base_mask, int shift) {
    using Entry = typename std::remove_pointer_t<decltype(order)>::value_type;
    order->resize(tri_count);
    for (Node& n : bvh.nodes_) {
      if (n.leaf == 0) continue;
      const uint32_t base = leaf_range(n).first & base_mask;
      for (uint32_t i = n.first; i < n.first + size_of(n); ++i) {
        (*order)[i] = static_cast<Entry>(refs[i].triangle - base);
      }
      n.leaf = (base << shift) | size_of(n);
    }
  };
  if (bytes_address && wide == 0) {
    fill_from_bases(&bvh.order8_, ~0u, 8);
  } else if (spread16 <= std::numeric_limits<uint16_t>::max()) {
    fill_from_bases(&bvh.order16_, ~0xffu, 0);
  } else {
    bvh.order_.resize(tri_count);
    for (size_t i = 0; i < tri_count; ++i) bvh.order_[i] = refs[i].triangle;
  }
  refs = std::vector<Ref>();  // before the nodes' copy to their size
  bvh.nodes_.shrink_to_fit();
  *out = std::move(bvh);
  return Status::success();
}

size_t TriangleBvh::memory_bytes() const {
  return nodes_.capacity() * sizeof(Node) + order8_.capacity() +
         order16_.capacity() * sizeof(uint16_t) + order_.capacity() * sizeof(uint32_t);
}

uint32_t TriangleBvh::locate_xz(double x, double z, glm::dvec3* weights) const {
  if (nodes_.empty()) return UINT32_MAX;
  // A point this close outside a triangle (in barycentric weight) still lies on it: the edge
  // two triangles share must belong to one of them whatever the rounding.
  constexpr double kEdgeTolerance = 1e-9;
  const auto holds = [&](const Node& n) {
    return x >= n.lo.x && x <= n.hi.x && z >= n.lo.z && z <= n.hi.z;
  };
  uint32_t stack[kStackSize];
  int top = 0;
  if (!holds(nodes_[0])) return UINT32_MAX;
  stack[top++] = 0;
  while (top > 0) {
    const Node& n = nodes_[stack[--top]];
    if (n.leaf == 0) {  // the left child is searched first
      if (holds(nodes_[n.first + 1])) stack[top++] = n.first + 1;
      if (holds(nodes_[n.first])) stack[top++] = n.first;
      continue;
    }
    for (uint32_t i = n.first; i < n.first + size_of(n); ++i) {  // ascending: the lowest first
      const uint32_t tri = triangle_at(n, i);
      const glm::vec3& a = positions_[triangle_vertex(tri, 0)];
      const glm::vec3& b = positions_[triangle_vertex(tri, 1)];
      const glm::vec3& c = positions_[triangle_vertex(tri, 2)];
      const double e0x = double(b.x) - a.x, e0z = double(b.z) - a.z;
      const double e1x = double(c.x) - a.x, e1z = double(c.z) - a.z;
      const double px = x - a.x, pz = z - a.z;
      const double det = e0x * e1z - e1x * e0z;
      if (det == 0.0) continue;
      const double v = (px * e1z - e1x * pz) / det;
      const double w = (e0x * pz - px * e0z) / det;
      const double u = 1.0 - v - w;
      if (u >= -kEdgeTolerance && v >= -kEdgeTolerance && w >= -kEdgeTolerance) {
        *weights = glm::clamp(glm::dvec3(u, v, w), 0.0, 1.0);
        return tri;
      }
    }
  }
  return UINT32_MAX;
}

template <bool kAnyHit>
bool TriangleBvh::trace(const glm::vec3& origin, const glm::vec3& direction, float t_min,
                        float t_max, RayHit* hit) const {
  if (nodes_.empty()) return false;
  // A zero component would make 0 * inf = NaN in the slab test; a tiny one keeps it ordered.
  glm::vec3 inv;
  for (int a = 0; a < 3; ++a) {
    const float d = std::fabs(direction[a]) < 1e-30f ? std::copysign(1e-30f, direction[a])
                                                     : direction[a];
    inv[a] = 1.0f / d;
  }
  // Each slab distance rounds three times (the difference, 1/d, the product) and the growth once
  // more: grown by twice gamma(4), a ray that grazes a box enters it (Ize 2013, "Robust BVH Ray
  // Traversal"). The nearest hit so far is grown too, so a box that ties it within rounding is
  // still searched and the tie goes to the lower triangle.
  constexpr float kEps = std::numeric_limits<float>::epsilon() / 2.0f;
  constexpr float kFarGrowth = 1.0f + 2.0f * (4.0f * kEps / (1.0f - 4.0f * kEps));
  const auto enter = [&](const Node& n, float limit) {
    const glm::vec3 t0 = (n.lo - origin) * inv;
    const glm::vec3 t1 = (n.hi - origin) * inv;
    const glm::vec3 tn = glm::min(t0, t1), tf = glm::max(t0, t1);
    const float t_near = std::max(std::max(tn.x, tn.y), std::max(tn.z, 0.0f));
    const float t_far = std::min(std::min(std::min(tf.x, tf.y), tf.z), limit) * kFarGrowth;
    return t_near <= t_far ? t_near : std::numeric_limits<float>::infinity();
  };

  float best = t_max;
  bool found = false;
  uint32_t stack[kStackSize];
  int top = 0;
  if (enter(nodes_[0], best) == std::numeric_limits<float>::infinity()) return false;
  stack[top++] = 0;
  while (top > 0) {
    const Node& n = nodes_[stack[--top]];
    if (n.leaf != 0) {
      for (uint32_t i = n.first; i < n.first + size_of(n); ++i) {
        const uint32_t tri = triangle_at(n, i);
        const glm::vec3& v0 = positions_[triangle_vertex(tri, 0)];
        const glm::vec3 e1 = positions_[triangle_vertex(tri, 1)] - v0;
        const glm::vec3 e2 = positions_[triangle_vertex(tri, 2)] - v0;
        const glm::vec3 p = glm::cross(direction, e2);
        const float det = glm::dot(e1, p);
        if (det == 0.0f || !std::isfinite(det)) continue;
        const float inv_det = 1.0f / det;
        if (!std::isfinite(inv_det)) continue;  // a sliver: a subnormal det would make u, v NaN
        const glm::vec3 s = origin - v0;
        const float u = glm::dot(s, p) * inv_det;
        if (u < 0.0f || u > 1.0f) continue;
        const glm::vec3 q = glm::cross(s, e1);
        const float v = glm::dot(direction, q) * inv_det;
        if (v < 0.0f || u + v > 1.0f) continue;
        const float t = glm::dot(e2, q) * inv_det;
        if (t < t_min || t > best) continue;
        if constexpr (kAnyHit) return true;
        if (found && t == best && tri > hit->triangle) continue;  // ties: the lower triangle
        best = t;
        found = true;
        hit->t = t;
        hit->triangle = tri;
        // On the triangle's plane, not along a long ray: the particle lies on the surface.
        hit->position = v0 + u * e1 + v * e2;
      }
      continue;
    }
    const uint32_t l = n.first, r = n.first + 1;
    const float tl = enter(nodes_[l], best), tr = enter(nodes_[r], best);
    const float inf = std::numeric_limits<float>::infinity();
    // Push the far child first so the near one is popped first and shrinks `best` early.
    if (tl <= tr) {
      if (tr != inf) stack[top++] = r;
      if (tl != inf) stack[top++] = l;
    } else {
      if (tl != inf) stack[top++] = l;
      if (tr != inf) stack[top++] = r;
    }
  }
  return found;
}

bool TriangleBvh::intersect(const glm::vec3& origin, const glm::vec3& direction, float t_max,
                            RayHit* hit) const {
  return trace<false>(origin, direction, 0.0f, t_max, hit);
}

bool TriangleBvh::any_hit(const glm::vec3& origin, const glm::vec3& direction, float t_min,
                          float t_max) const {
  return trace<true>(origin, direction, t_min, t_max, nullptr);
}

void TriangleBvh::append_vertices_in(const XzBox& box, std::vector<uint32_t>* out) const {
  if (nodes_.empty() || box.empty()) return;
  const auto meets = [&](const Node& n) {
    return n.hi.x >= box.lo.x && n.lo.x <= box.hi.x && n.hi.z >= box.lo.y && n.lo.z <= box.hi.y;
  };
  uint32_t stack[kStackSize];
  int top = 0;
  if (meets(nodes_[0])) stack[top++] = 0;
  while (top > 0) {
    const Node& n = nodes_[stack[--top]];
    if (n.leaf == 0) {
      if (meets(nodes_[n.first + 1])) stack[top++] = n.first + 1;
      if (meets(nodes_[n.first])) stack[top++] = n.first;
      continue;
    }
    for (uint32_t i = n.first; i < n.first + size_of(n); ++i) {
      for (int k = 0; k < 3; ++k) {
        const uint32_t v = triangle_vertex(triangle_at(n, i), k);
        if (box.holds(positions_[v])) out->push_back(v);
      }
    }
  }
}

uint32_t TriangleBvh::nearest_vertex(const glm::vec3& p, float radius,
                                     uint32_t hint_triangle) const {
  uint32_t best_v = triangle_vertex(hint_triangle, 0);
  float best_d2 = distance2(p, positions_[best_v]);
  for (int k = 1; k < 3; ++k) {
    const uint32_t v = triangle_vertex(hint_triangle, k);
    const float d2 = distance2(p, positions_[v]);
    if (d2 < best_d2 || (d2 == best_d2 && v < best_v)) {
      best_d2 = d2;
      best_v = v;
    }
  }
  const float r2 = radius * radius;
  if (nodes_.empty() || !(r2 > 0.0f)) return best_v;
  uint32_t stack[kStackSize];
  int top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const Node& n = nodes_[stack[--top]];
    if (box_distance2(n.lo, n.hi, p) > std::min(best_d2, r2)) continue;
    if (n.leaf != 0) {
      for (uint32_t i = n.first; i < n.first + size_of(n); ++i) {
        for (int k = 0; k < 3; ++k) {
          const uint32_t v = triangle_vertex(triangle_at(n, i), k);
          const float d2 = distance2(p, positions_[v]);
          if (d2 <= r2 && (d2 < best_d2 || (d2 == best_d2 && v < best_v))) {
            best_d2 = d2;
            best_v = v;
          }
        }
      }
      continue;
    }
    const uint32_t l = n.first, r = n.first + 1;
    const float dl = box_distance2(nodes_[l].lo, nodes_[l].hi, p);
    const float dr = box_distance2(nodes_[r].lo, nodes_[r].hi, p);
    if (dl <= dr) {
      stack[top++] = r;
      stack[top++] = l;
    } else {
      stack[top++] = l;
      stack[top++] = r;
    }
  }
  return best_v;
}

}  // namespace siviflow
