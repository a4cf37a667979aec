#include "default_river.h"

#include <algorithm>

#include <glm/geometric.hpp>

namespace siviflow {
namespace {

constexpr float kInRiverRadius = 1.3f;  // the boulder in mid-river
constexpr float kMovingRadius = 1.1f;   // the boulder that rolls into the river

}  // namespace

ProceduralRiverParams default_river_params() { return ProceduralRiverParams{}; }

float boulder_radius(const Obstacle& obstacle) {
  float radius = obstacle.radius;
  for (const glm::vec2& corner : obstacle.polygon) radius = std::max(radius, glm::length(corner));
  return radius;
}

glm::vec3 boulder_radii(const Obstacle& obstacle) {
  const float radius = boulder_radius(obstacle);
  return {radius, kBoulderHeightRatio * radius, 0.92f * radius};
}

glm::vec3 on_ground(const ProceduralRiver& river, float lateral_offset, float z) {
  const float x = river.centreline_x(z) + lateral_offset;
  return {x, river.terrain_height(x, z), z};
}

std::vector<Obstacle> default_scene_obstacles(const ProceduralRiver& river) {
  Obstacle in_river;
  in_river.centre = on_ground(river, 1.5f, 2.0f) + glm::vec3(0.0f, 0.3f, 0.0f);
  in_river.radius = kInRiverRadius;
  in_river.height = kBoulderHeightRatio * kInRiverRadius;
  // Rolls from the right bank (x < centreline looking downstream +Z) into the river, 0 .. 4 s.
  Obstacle moving;
  const float z = -12.0f;
  const glm::vec3 bank = on_ground(river, -11.0f, z) + glm::vec3(0.0f, kMovingRadius * 0.6f, 0.0f);
  const glm::vec3 water = on_ground(river, -2.0f, z) + glm::vec3(0.0f, kMovingRadius * 0.4f, 0.0f);
  moving.centre = bank;
  moving.radius = kMovingRadius;
  moving.height = kBoulderHeightRatio * kMovingRadius;
  moving.keys = {{0.0, bank}, {1.0, bank}, {4.0, water}};
  return {in_river, moving};
}

}  // namespace siviflow
