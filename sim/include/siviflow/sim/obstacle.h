// Obstacles: objects touching the river, seen from above as a footprint in the XZ plane (a circle
// or a polygon) that moves with a keyframed centre. The stream function treats the part of the
// river inside a footprint as dry and the footprint's outline as a boundary (a streamline).
#pragma once

#include <cstddef>
#include <span>
#include <vector>

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include "siviflow/status.h"

namespace siviflow {

struct ObstacleKey {
  double t = 0.0;          // seconds
  glm::vec3 centre{0.0f};  // world position of the obstacle's centre at t
};

struct Obstacle {
  glm::vec3 centre{0.0f};  // world position when there are no keys
  // Circle footprint of this radius (metres) when `polygon` is empty.
  float radius = 0.0f;
  // How far it stands above its centre (metres, >= 0): a solid from the water up to there that
  // hides the water behind it (0: flat, hides nothing).
  float height = 0.0f;
  // Polygon footprint: (x, z) offsets from the centre, either winding, simple, >= 3 points.
  std::vector<glm::vec2> polygon;
  // Keyframed centre: strictly increasing t; linear in between, held before the first key and
  // after the last. Empty: the obstacle stays at `centre`.
  std::vector<ObstacleKey> keys;
};

// Checks one obstacle; the message names it by `index`.
Status validate_obstacle(const Obstacle& obstacle, size_t index);

// Centre of a (valid) obstacle at time t.
glm::vec3 obstacle_centre_at(const Obstacle& obstacle, double t);

// Signed distance in the XZ plane from `point` to the footprint placed at `centre_xz`: negative
// inside, zero on the outline.
double footprint_distance(const Obstacle& obstacle, glm::dvec2 centre_xz, glm::dvec2 point);

// Bounds of the footprint placed at `centre_xz`.
void footprint_bounds(const Obstacle& obstacle, glm::dvec2 centre_xz, glm::dvec2* lo,
                      glm::dvec2* hi);

// Whether the footprint placed at `centre_xz` overlaps the interior of triangle `tri` (XZ).
bool footprint_overlaps_triangle(const Obstacle& obstacle, glm::dvec2 centre_xz,
                                 std::span<const glm::dvec2, 3> tri);

// Whether the footprint placed at `centre_xz` overlaps the segment ab (XZ).
bool footprint_overlaps_segment(const Obstacle& obstacle, glm::dvec2 centre_xz, glm::dvec2 a,
                                glm::dvec2 b);

// Closest point of triangle `tri` to `point`, as barycentric weights (all in the XZ plane).
glm::dvec3 closest_barycentric(std::span<const glm::dvec2, 3> tri, glm::dvec2 point);

}  // namespace siviflow
