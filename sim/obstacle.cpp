#include "siviflow/sim/obstacle.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <glm/common.hpp>
#include <glm/geometric.hpp>

#include "siviflow/sim/river_tuning.h"
#include "siviflow/sim/world_limits.h"
#include "siviflow/text_format.h"

namespace siviflow {
namespace {

double cross2(glm::dvec2 a, glm::dvec2 b) { return a.x * b.y - a.y * b.x; }

double segment_distance(glm::dvec2 p, glm::dvec2 a, glm::dvec2 b) {
  const glm::dvec2 ab = b - a;
  const double len2 = glm::dot(ab, ab);
  const double u = len2 > 0.0 ? std::clamp(glm::dot(p - a, ab) / len2, 0.0, 1.0) : 0.0;
  return glm::length(p - (a + u * ab));
}

// Proper crossing of segments ab and cd (touching at an end does not count).
bool segments_cross(glm::dvec2 a, glm::dvec2 b, glm::dvec2 c, glm::dvec2 d) {
  const double d1 = cross2(b - a, c - a), d2 = cross2(b - a, d - a);
  const double d3 = cross2(d - c, a - c), d4 = cross2(d - c, b - c);
  return ((d1 > 0 && d2 < 0) || (d1 < 0 && d2 > 0)) && ((d3 > 0 && d4 < 0) || (d3 < 0 && d4 > 0));
}

// Strictly inside triangle (either winding).
bool inside_triangle(std::span<const glm::dvec2, 3> t, glm::dvec2 p) {
  const double a = cross2(t[1] - t[0], p - t[0]);
  const double b = cross2(t[2] - t[1], p - t[1]);
  const double c = cross2(t[0] - t[2], p - t[2]);
  return (a > 0 && b > 0 && c > 0) || (a < 0 && b < 0 && c < 0);
}

}  // namespace

Status validate_obstacle(const Obstacle& o, size_t index) {
  if (!within_world(o.centre)) {
    return Status::error(text_format("obstacle %zu: its centre ", index) + world_limit_problem(o.centre));
  }
  if (!std::isfinite(o.height) || !(o.height >= 0.0f)) {
    return Status::error(text_format("obstacle %zu has height %g: it must be finite and >= 0",
                                     index, double(o.height)));
  }
  if (o.polygon.empty()) {
    if (!(o.radius > 0.0f && o.radius <= kMaxWorldCoordinate)) {
      return Status::error(text_format(
          "obstacle %zu has radius %g: a circular obstacle needs a positive radius within the "
          "world limit (%g m)", index, o.radius, double(kMaxWorldCoordinate)));
    }
  } else {
    const size_t n = o.polygon.size();
    if (n < 3 || n > kMaxPolygonPoints) {
      return Status::error(text_format(
          "obstacle %zu has a footprint polygon of %zu points: it needs between 3 and %zu", index,
          n, kMaxPolygonPoints));
    }
    double area2 = 0.0, scale = 0.0;
    for (size_t i = 0; i < n; ++i) {
      const glm::vec2 p = o.polygon[i];
      if (!within_world(p)) {
        return Status::error(text_format("obstacle %zu: footprint point %zu ", index, i) +
                             world_limit_problem(p));
      }
      area2 += cross2(glm::dvec2(p), glm::dvec2(o.polygon[(i + 1) % n]));
      scale = std::max({scale, std::abs(double{p.x}), std::abs(double{p.y})});
    }
    if (!(std::abs(area2) > 1e-12 * scale * scale)) {
      return Status::error(text_format("obstacle %zu: its footprint polygon has zero area", index));
    }
    for (size_t i = 0; i < n; ++i) {
      for (size_t j = i + 1; j < n; ++j) {
        if (j == i + 1 || (i == 0 && j == n - 1)) continue;  // neighbouring edges share a point
        if (segments_cross(o.polygon[i], o.polygon[(i + 1) % n], o.polygon[j],
                           o.polygon[(j + 1) % n])) {
          return Status::error(text_format(
              "obstacle %zu: its footprint polygon crosses itself (edges %zu and %zu)", index, i,
              j));
        }
      }
    }
  }
  if (o.keys.size() > kMaxObstacleKeys) {
    return Status::error(text_format("obstacle %zu has %zu keys, more than the limit of %zu",
                                     index, o.keys.size(), kMaxObstacleKeys));
  }
  for (size_t k = 0; k < o.keys.size(); ++k) {
    if (!std::isfinite(o.keys[k].t)) {
      return Status::error(text_format("obstacle %zu: key %zu's time is not finite", index, k));
    }
    if (!within_world(o.keys[k].centre)) {
      return Status::error(text_format("obstacle %zu: key %zu's centre ", index, k) +
                           world_limit_problem(o.keys[k].centre));
    }
    if (k > 0 && !(o.keys[k].t > o.keys[k - 1].t)) {
      return Status::error(text_format(
          "obstacle %zu: key %zu (t = %g) does not come after key %zu (t = %g)", index, k,
          o.keys[k].t, k - 1, o.keys[k - 1].t));
    }
  }
  return Status::success();
}

glm::vec3 obstacle_centre_at(const Obstacle& o, double t) {
  if (o.keys.empty()) return o.centre;
  if (!(t > o.keys.front().t)) return o.keys.front().centre;  // also for a NaN time
  if (t >= o.keys.back().t) return o.keys.back().centre;
  const auto next = std::upper_bound(o.keys.begin(), o.keys.end(), t,
                                     [](double v, const ObstacleKey& k) { return v < k.t; });
  const ObstacleKey& b = *next;
  const ObstacleKey& a = *(next - 1);
  const double u = (t - a.t) / (b.t - a.t);
  return glm::vec3(glm::dvec3(a.centre) + u * (glm::dvec3(b.centre) - glm::dvec3(a.centre)));
}

double footprint_distance(const Obstacle& o, glm::dvec2 centre_xz, glm::dvec2 point) {
  const glm::dvec2 q = point - centre_xz;
  if (o.polygon.empty()) return glm::length(q) - double{o.radius};
  double best = std::numeric_limits<double>::max();
  bool inside = false;
  const size_t n = o.polygon.size();
  for (size_t i = 0, j = n - 1; i < n; j = i++) {
    const glm::dvec2 a(o.polygon[j]), b(o.polygon[i]);
    best = std::min(best, segment_distance(q, a, b));
    // Even-odd crossing test along +x.
    if ((b.y > q.y) != (a.y > q.y)) {
      const double x = a.x + (q.y - a.y) * (b.x - a.x) / (b.y - a.y);
      if (q.x < x) inside = !inside;
    }
  }
  return inside ? -best : best;
}

void footprint_bounds(const Obstacle& o, glm::dvec2 centre_xz, glm::dvec2* lo, glm::dvec2* hi) {
  if (o.polygon.empty()) {
    *lo = centre_xz - glm::dvec2(o.radius);
    *hi = centre_xz + glm::dvec2(o.radius);
    return;
  }
  glm::dvec2 a(std::numeric_limits<double>::max()), b(-std::numeric_limits<double>::max());
  for (const glm::vec2 p : o.polygon) {
    a = glm::min(a, glm::dvec2(p));
    b = glm::max(b, glm::dvec2(p));
  }
  *lo = centre_xz + a;
  *hi = centre_xz + b;
}

glm::dvec3 closest_barycentric(std::span<const glm::dvec2, 3> t, glm::dvec2 p) {
  const double det = cross2(t[1] - t[0], t[2] - t[0]);
  if (det != 0.0) {
    const double b1 = cross2(p - t[0], t[2] - t[0]) / det;
    const double b2 = cross2(t[1] - t[0], p - t[0]) / det;
    const double b0 = 1.0 - b1 - b2;
    if (b0 >= 0.0 && b1 >= 0.0 && b2 >= 0.0) return {b0, b1, b2};
  }
  glm::dvec3 best_bary(1.0, 0.0, 0.0);
  double best = std::numeric_limits<double>::max();
  for (int i = 0; i < 3; ++i) {
    const int j = (i + 1) % 3;
    const glm::dvec2 ab = t[j] - t[i];
    const double len2 = glm::dot(ab, ab);
    const double u = len2 > 0.0 ? std::clamp(glm::dot(p - t[i], ab) / len2, 0.0, 1.0) : 0.0;
    const double d = glm::length(p - (t[i] + u * ab));
    if (d < best) {
      best = d;
      best_bary = glm::dvec3(0.0);
      best_bary[i] = 1.0 - u;
      best_bary[j] = u;
    }
  }
  return best_bary;
}

bool footprint_overlaps_segment(const Obstacle& o, glm::dvec2 centre_xz, glm::dvec2 a,
                                glm::dvec2 b) {
  if (o.polygon.empty()) return segment_distance(centre_xz, a, b) < double{o.radius};
  if (footprint_distance(o, centre_xz, a) < 0.0 || footprint_distance(o, centre_xz, b) < 0.0) {
    return true;
  }
  const size_t n = o.polygon.size();
  for (size_t i = 0; i < n; ++i) {
    if (segments_cross(centre_xz + glm::dvec2(o.polygon[i]),
                       centre_xz + glm::dvec2(o.polygon[(i + 1) % n]), a, b)) {
      return true;
    }
  }
  return false;
}

bool footprint_overlaps_triangle(const Obstacle& o, glm::dvec2 centre_xz,
                                 std::span<const glm::dvec2, 3> tri) {
  if (o.polygon.empty()) {
    const glm::dvec3 b = closest_barycentric(tri, centre_xz);
    const glm::dvec2 closest = b.x * tri[0] + b.y * tri[1] + b.z * tri[2];
    return glm::length(closest - centre_xz) < double{o.radius};
  }
  for (const glm::dvec2& v : tri) {
    if (footprint_distance(o, centre_xz, v) < 0.0) return true;
  }
  const size_t n = o.polygon.size();
  for (size_t i = 0; i < n; ++i) {
    const glm::dvec2 a = centre_xz + glm::dvec2(o.polygon[i]);
    if (inside_triangle(tri, a)) return true;
    const glm::dvec2 b = centre_xz + glm::dvec2(o.polygon[(i + 1) % n]);
    for (int e = 0; e < 3; ++e) {
      if (segments_cross(a, b, tri[e], tri[(e + 1) % 3])) return true;
    }
  }
  return false;
}

}  // namespace siviflow
