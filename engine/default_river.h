// The built-in default river of the water renderer (CreateInfo::river null): the procedural
// river with its default parameters, and the two boulders in it (one in mid-river, one that
// rolls in from the bank). The built-in world draws the valley around it.
#pragma once

#include <vector>

#include <glm/vec3.hpp>

#include "siviflow/sim/obstacle.h"
#include "siviflow/sim/procedural_river.h"

namespace siviflow {

ProceduralRiverParams default_river_params();
// The obstacles in the water: the boulder in mid-river, and the one that rolls in from the
// right bank (the moving one, keyed, last in the list).
std::vector<Obstacle> default_scene_obstacles(const ProceduralRiver& river);
// The point on the valley's ground `lateral_offset` metres across from the centreline at `z`.
glm::vec3 on_ground(const ProceduralRiver& river, float lateral_offset, float z);

// The boulder the built-in world draws for an obstacle: as wide as its footprint reaches from
// its centre, this much of that as high above it.
inline constexpr float kBoulderHeightRatio = 0.95f;
float boulder_radius(const Obstacle& obstacle);
// The radii (x, y, z) of the ellipsoid the boulder is bumped from: slightly squat and narrow.
glm::vec3 boulder_radii(const Obstacle& obstacle);

}  // namespace siviflow
