// The built-in default scene: the procedural river's valley (terrain and riverbed), a few
// objects on the banks and in the water, the sun, and a camera that moves along the river.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

#include "default_river.h"
#include "scene/lod_culling.h"
#include "shaders/shared.h"
#include "siviflow/renderer.h"
#include "siviflow/sim/obstacle.h"
#include "siviflow/sim/procedural_river.h"

namespace siviflow {

using gpu::SceneVertex;

struct SceneGeometry {
  std::vector<SceneVertex> vertices;
  std::vector<uint32_t> indices;  // triangle list, counter-clockwise seen from outside
  // What never moves, each piece culled and (terrain chunks) given a level of detail per view.
  std::vector<LodPiece> pieces;
  // One boulder per obstacle, modelled around the origin and drawn translated to where its
  // obstacle is each frame.
  std::vector<IndexRange> obstacle_boulders;
};

// The triangles [first_index, first_index + index_count) of `geometry` as one piece, drawn whole
// wherever it is seen.
LodPiece object_piece(const SceneGeometry& geometry, uint32_t first_index, uint32_t index_count,
                      uint32_t material);

// Moves `other` into `into` after what it holds (its indices and pieces shifted to match).
void append_geometry(SceneGeometry&& other, SceneGeometry* into);

// Tunables of the look of the default scene, in one place.
struct SceneLook {
  glm::vec3 sun_direction{0.45f, 0.62f, 0.35f};  // towards the sun; normalised on use
  float sun_disc_intensity = 20.0f;
  float fog_density = 0.0022f;  // per metre at the water level
  float fog_height_falloff = 0.05f;  // per metre of height
};

SceneLook default_scene_look();

// A vertex of the ground (SIVIFLOW_GROUND_VERTEX) `above_water` metres above the water near it
// (negative: under it), coloured by the scene shader from that height and its steepness.
SceneVertex ground_vertex(const glm::vec3& position, const glm::vec3& normal, float above_water);
// Terrain of the river's valley, trees and boulders on its banks, and a boulder for each obstacle.
SceneGeometry build_scene_geometry(const ProceduralRiver& river, const std::vector<Obstacle>& obstacles);
// For a river from a file, which brings no terrain: its bed (the surface lowered by the depth
// of each vertex), the ground around `ground_rivers` (river_ground.h: all the scene's glTF
// rivers, in one, with the first river's bed when that one is from a file; a procedural first
// river brings its own valley, and glTF rivers beside it get no ground), and a boulder for
// each obstacle.
Status build_riverbed_geometry(const RiverMesh& river, const std::vector<Obstacle>& obstacles,
                               std::span<const RiverMesh> ground_rivers, SceneGeometry* out);
// The camera of the default scene at time t (seconds): it glides down the valley.
Camera default_camera(const ProceduralRiver& river, double time_seconds);
// A still camera for a river from a file without camera keys: above and in front of its bounds,
// looking at their centre.
Camera river_overview_camera(std::span<const glm::vec3> positions);

}  // namespace siviflow
