// A river as the water renderer takes it (CreateInfo::river): its water surface, the water's
// depth and the bed's slope under each vertex, its flow and the obstacles in it. The renderer
// copies what it needs at create(); the host may free the arrays afterwards. A scene file's
// rivers come in this form from siviflow/scene_river.h.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

namespace siviflow {

struct WaterObstacleKey {
  double t = 0.0;            // seconds; keys strictly increasing in t
  glm::vec3 centre{0.0f};    // river-space position of the obstacle's centre at t
};

// An obstacle on the water (a boulder, a boat the player steers, a log): its footprint seen
// from above, which the flow goes round (its outline becomes a streamline).
struct WaterObstacle {
  // River-space position (the host's world under the default CreateInfo::world_from_river); the
  // footprint lies around it in x and z.
  glm::vec3 centre{0.0f};
  float radius = 0.0f;     // a circle of this radius (metres) when `polygon` is empty
  // How far it stands above its centre, metres: the water behind it, seen through it up to
  // there, gets no particles (0: flat, hides nothing). It counts as a solid over its whole
  // footprint: water seen under an overhang (a leaning log) counts as hidden.
  float height = 0.0f;
  // A polygon footprint: (x, z) offsets from the centre, 3 .. 4096 points, simple, either winding.
  std::vector<glm::vec2> polygon;
  float rotation_rad = 0.0f;  // turns the polygon about +Y as glm::rotate does (+X towards -Z)
  // The centre moves through these keys (linear between them, held before the first and after
  // the last) as update()'s time goes; empty: it stays at `centre`.
  std::vector<WaterObstacleKey> keys;
};

struct RiverFlowParams {
  float discharge = 20.0f;    // Q in m^2/s: psi from the right bank (0) to the left (Q)
  float shepard_power = 1.5f; // p of the interpolation weights; 1 gives plug flow
  float search_radius = 0.0f; // s in metres; 0: 3 x the widest section
};

// One open end of a river (where water enters or leaves), named by any vertex on it, or as the
// end nearest a point.
struct WaterRiverEnd {
  uint32_t vertex = 0;
  bool inflow = true;
  float discharge = 0.0f;  // m^2/s through it, >= 0; the ends balance (in = out)
  bool at_point = false;   // the end nearest `point` (river space), not the one holding `vertex`
  glm::vec3 point{0.0f};
};

struct WaterRiver {
  // The water surface: a strip of quads from bank to bank, one row of vertices per
  // cross-section (sections may differ in width and vertex count), triangles as index triples;
  // it may have holes (islands) and, as a network, more than two ends (a confluence, a fork).
  // The upstream end is the section holding vertex 0, unless `ends` names them; world metres,
  // +Y up.
  std::span<const glm::vec3> positions;
  std::span<const uint32_t> indices;
  // Per vertex, kept to 11 significant bits (binary16; the paper's auxiliary texture keeps 8):
  std::span<const float> depth;  // water depth under it, metres, 0 to 65504
  std::span<const float> slope;  // the bed's slope under it (rise over run), 0 to 65504
  RiverFlowParams flow;
  std::span<const WaterObstacle> obstacles;
  // Every end, each once, with its discharge (their inflows then make flow.discharge), or none:
  // then the end holding vertex 0 is the only inflow and the other ends (a strip has one) share
  // flow.discharge by their widths. A network takes a single inflow or a single outflow.
  std::span<const WaterRiverEnd> ends;
};

}  // namespace siviflow
