// What gameplay learns of the water at a point (Renderer::query_water, sim/water_query.h): from
// the solved flow and the river surface, on the CPU, the same answer the picture is drawn from.
#pragma once

#include <cstdint>

#include <glm/vec3.hpp>

namespace siviflow {

struct WaterSample {
  // The point lies over (or under) the river surface, measured along the river's up axis.
  bool on_surface = false;
  // On the surface and outside every obstacle's footprint: where something can float.
  bool wet = false;
  glm::vec3 surface{0.0f};   // the water surface point above or below the query point, metres
  glm::vec3 normal{0.0f};    // the surface's macro normal there (its triangle's), unit; 0 off it
  glm::vec3 velocity{0.0f};  // the flow at the surface, m/s (tangent to it); 0 where not wet
  float depth = 0.0f;        // from the surface down to the bed, metres
  float foam = 0.0f;         // the foam the material shows there, 0..1 (WaterLook::foam_amount in)
  // The obstacle whose footprint holds the point: Renderer::add_obstacle's id, or
  // kRiverObstacle + its index in WaterRiver::obstacles; kNoObstacle outside every footprint.
  uint32_t obstacle = 0;
  static constexpr uint32_t kNoObstacle = 0;
  static constexpr uint32_t kRiverObstacle = 0x80000000u;
};

}  // namespace siviflow
