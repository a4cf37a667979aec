// How far from the origin SiViFlow's geometry may lie: every position, centre, footprint point
// and key it is given, and every position its own arithmetic makes of them (glTF node and object
// transforms), stays within ±kMaxWorldCoordinate metres on each axis, or is refused by name.
// Why 10^6 m (1000 km): there, adjacent floats are 6.25 cm apart, as coarse as the centimetres
// the water's margins, footprints and particle mapping resolve; and the sums, differences and
// products of two coordinates that bounding boxes, centres and edge cross products form stay
// many orders below a float's overflow.
#pragma once

#include <cmath>
#include <string>

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include "siviflow/text_format.h"

namespace siviflow {

inline constexpr float kMaxWorldCoordinate = 1.0e6f;

inline bool within_world(float v) { return std::abs(v) <= kMaxWorldCoordinate; }  // NaN: false
inline bool within_world(const glm::vec3& p) {
  return within_world(p.x) && within_world(p.y) && within_world(p.z);
}
inline bool within_world(const glm::vec2& p) { return within_world(p.x) && within_world(p.y); }

// What is wrong with a position outside the world, for a message after its name: "is not finite"
// or "(3.4e+38, 0, 1) lies beyond the world limit of ±1e+06 m".
inline std::string world_limit_problem(const glm::vec3& p) {
  if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) return "is not finite";
  return text_format("(%g, %g, %g) lies beyond the world limit of ±%g m", double(p.x), double(p.y),
                     double(p.z), double(kMaxWorldCoordinate));
}

// The same for an [x, z] point: "(3.4e+38, 0) lies beyond ...".
inline std::string world_limit_problem(const glm::vec2& p) {
  if (!std::isfinite(p.x) || !std::isfinite(p.y)) return "is not finite";
  return text_format("(%g, %g) lies beyond the world limit of ±%g m", double(p.x), double(p.y),
                     double(kMaxWorldCoordinate));
}

}  // namespace siviflow
