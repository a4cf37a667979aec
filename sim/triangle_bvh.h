// A bounding volume hierarchy over a triangle mesh (the river surface, the ground, a host's
// occluders): the closest hit of a ray (a pixel's ray into the water surface), whether a segment
// meets any triangle (a sight line), and the nearest vertex to a point, each in O(log n) of the
// mesh. Built once per mesh; the queries are const and allocate nothing.
#pragma once

#include <cstdint>
#include <span>
#include <string_view>
#include <vector>

#include <glm/vec3.hpp>

#include "siviflow/sim/xz_box.h"
#include "siviflow/status.h"

namespace siviflow {

struct RayHit {
  float t = 0.0f;         // origin + t * direction
  uint32_t triangle = 0;  // index of the triangle (3 consecutive indices, or 3 positions)
  glm::vec3 position{0.0f};
};

class TriangleBvh {
 public:
  // `indices` holds 3 vertex indices per triangle; when empty, every 3 positions are a triangle.
  // The spans are referenced, not copied: they must outlive the BVH and keep their contents.
  // Fails on no triangles, a count that is not a multiple of 3, an index out of range, a
  // position outside the world (siviflow/sim/world_limits.h), or more triangles than 32-bit
  // indices address.
  // Messages name the fields after `mesh_name` ("RiverFlowField::positions[3] is not finite").
  static Status build(std::span<const glm::vec3> positions, std::span<const uint32_t> indices,
                      TriangleBvh* out, std::string_view mesh_name = "RiverFlowField");

  size_t triangle_count() const { return order8_.size() + order16_.size() + order_.size(); }
  std::span<const glm::vec3> positions() const { return positions_; }
  std::span<const uint32_t> indices() const { return indices_; }
  uint32_t triangle_vertex(uint32_t triangle, int corner) const {
    return indices_.empty() ? triangle * 3 + static_cast<uint32_t>(corner)
                            : indices_[size_t{triangle} * 3 + static_cast<size_t>(corner)];
  }
  // Bytes held by the hierarchy itself (not the referenced mesh).
  size_t memory_bytes() const;
  // The bytes each triangle of the order takes: 1, 2 or 4.
  int order_bytes() const { return !order8_.empty() ? 1 : !order16_.empty() ? 2 : 4; }

  // Closest intersection of origin + t * direction, t in [0, t_max], with any triangle (both
  // sides). False when the ray misses.
  bool intersect(const glm::vec3& origin, const glm::vec3& direction, float t_max,
                 RayHit* hit) const;
  // Whether origin + t * direction meets any triangle for some t in [t_min, t_max] (stops at
  // the first one found).
  bool any_hit(const glm::vec3& origin, const glm::vec3& direction, float t_min,
               float t_max) const;

  // The triangle whose projection on the XZ plane holds (x, z) (where several do, the lowest
  // numbered of the first leaf the traversal meets that holds one: the same every time, a leaf
  // split by number or not), with its barycentric weights; UINT32_MAX when none does. In doubles:
  // far from the origin a float difference would lose the centimetres.
  uint32_t locate_xz(double x, double z, glm::dvec3* weights) const;

  // The vertex nearest to `p` (ties: the lower index) among the vertices within `radius` of it;
  // when none is, the nearest corner of `hint_triangle` (usually the triangle `p` lies on).
  uint32_t nearest_vertex(const glm::vec3& p, float radius, uint32_t hint_triangle) const;

  // Appends to `out` every vertex inside the x/z box (at any height), once per triangle it is a
  // corner of: a caller that wants each once sorts and removes the repeats.
  void append_vertices_in(const XzBox& box, std::vector<uint32_t>* out) const;

 private:
  struct Node {
    glm::vec3 lo;
    uint32_t first;  // leaf: first entry of the order; inner: index of the left child (right = +1)
    glm::vec3 hi;
    // Inner: 0. Leaf: its triangle count in the low byte (> 0); the rest is the base its
    // entries add to: with the 8-bit order its lowest triangle (shifted up by 8), with the
    // 16-bit order that triangle rounded down to a multiple of 256.
    uint32_t leaf;
  };
  static_assert(sizeof(Node) == 32);
  static uint32_t size_of(const Node& n) { return n.leaf & 0xffu; }
  // The triangle of entry i of leaf n's order.
  uint32_t triangle_at(const Node& n, uint32_t i) const {
    if (!order8_.empty()) return (n.leaf >> 8) + order8_[i];
    return order16_.empty() ? order_[i] : (n.leaf & ~0xffu) + order16_[i];
  }
  template <bool kAnyHit>
  bool trace(const glm::vec3& origin, const glm::vec3& direction, float t_min, float t_max,
             RayHit* hit) const;

  std::span<const glm::vec3> positions_;
  std::span<const uint32_t> indices_;
  std::vector<Node> nodes_;
  // Triangle indices, leaf by leaf, from their leaf's base: in 1 byte each where every leaf's
  // triangles lie within 255 of its lowest (a mesh whose triangles near in space are near in
  // number, as a river's), else in 2 where they fit, else the triangles themselves in 4. One
  // of the three is held.
  std::vector<uint8_t> order8_;
  std::vector<uint16_t> order16_;
  std::vector<uint32_t> order_;
};

// Squared distance, written once so every caller (and test) rounds the same way.
inline float distance2(const glm::vec3& a, const glm::vec3& b) {
  const glm::vec3 e = a - b;
  return e.x * e.x + e.y * e.y + e.z * e.z;
}

}  // namespace siviflow
