// An axis-aligned box in the horizontal x/z plane (world metres, in doubles): where something
// changed on the river, which what depends on it re-derives.
#pragma once

#include <cmath>
#include <limits>

#include <glm/common.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

namespace siviflow {

struct XzBox {
  glm::dvec2 lo{std::numeric_limits<double>::infinity()};  // (x, z)
  glm::dvec2 hi{-std::numeric_limits<double>::infinity()};

  static XzBox everywhere() {
    constexpr double kInfinity = std::numeric_limits<double>::infinity();
    return {glm::dvec2(-kInfinity), glm::dvec2(kInfinity)};
  }
  bool empty() const { return lo.x > hi.x || lo.y > hi.y; }
  bool finite() const {
    return std::isfinite(lo.x) && std::isfinite(lo.y) && std::isfinite(hi.x) && std::isfinite(hi.y);
  }
  bool holds(const glm::vec3& p) const {
    return p.x >= lo.x && p.x <= hi.x && p.z >= lo.y && p.z <= hi.y;
  }
  void grow(const glm::vec3& p) {
    lo = glm::min(lo, glm::dvec2(p.x, p.z));
    hi = glm::max(hi, glm::dvec2(p.x, p.z));
  }
  XzBox widened(double by) const { return {lo - by, hi + by}; }
};

}  // namespace siviflow
