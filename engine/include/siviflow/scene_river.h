// The rivers of a scene file: in the form the water renderer takes (scene_river_data), and
// solved on their own (build_scene_river_flow: a river surface and a stream-function flow with
// the scene's obstacles placed at a given time).
#pragma once

#include <cstddef>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include <glm/vec3.hpp>

#include "siviflow/scene_file.h"
#include "siviflow/sim/obstacle.h"
#include "siviflow/sim/procedural_river.h"
#include "siviflow/sim/stream_function.h"
#include "siviflow/status.h"
#include "siviflow/water_river.h"

namespace siviflow {

// A glTF river has no riverbed: its depth is this much in mid-river, falling as a parabola to
// nothing at the banks (4 d_left d_right / width^2 of it).
inline constexpr float kGltfRiverDepth = 1.5f;

// A river of a scene in the form the renderer takes: CreateInfo::river = &river() (spans into
// this object, which must outlive create()). Also what the built-in world draws around it.
struct SceneRiverData {
  RiverMesh mesh;                        // positions, indices, depth under each vertex
  std::vector<float> slope;              // the bed's slope under each vertex
  std::vector<WaterObstacle> obstacles;  // the scene's, then those of objects marked obstacle
  RiverFlowParams flow;
  std::vector<WaterRiverEnd> ends;            // the scene's (or the generator's), or none
  std::optional<ProceduralRiver> procedural;  // the generator it came from, if it did
  WaterRiver river() const;
  // For CreateInfo::river_copied, with river_copied_user this data: frees every array river()
  // points into (the generator and the flow parameters stay).
  static void release_arrays(void* river);
};

// River `river_index` of `scene` (null: the built-in default river, procedural, with its two
// boulders): a procedural river with its terrain's slope, a glTF river with the depth profile
// above. Errors name the scene file (and the glTF file), or the index the scene lacks.
Status scene_river_data(const SceneFile* scene, size_t river_index, SceneRiverData* out);
// River `river_index` as the scene gives it, nothing generated: a procedural river's generator
// (its mesh and slope left empty: a 100 km river has a million vertices) or a glTF river's mesh,
// depth and slope; no obstacles. What the built-in world draws the valley or bed from.
Status scene_river_shape(const SceneFile* scene, size_t river_index, SceneRiverData* out);

struct SceneRiverFlow {
  std::vector<glm::vec3> positions;  // the river primitive's vertices, in the file's accessor order
  StreamFunction flow;               // per input vertex: surface data, psi, velocity, wet
};

// An object's footprint keeps at most this many hull corners: the flow's distance queries cost
// one segment test per corner, and a few hundred outline any mesh's waterline closely enough.
inline constexpr size_t kMaxObjectFootprintPoints = 256;

// Loads the mesh of river `river_index` of `scene`, builds its surface and solves its flow with
// the scene's obstacles at `time_seconds`: first `scene.obstacles`, then one per object marked
// `obstacle` (scene_object_obstacles). Errors name the scene file (and the glTF file where it is
// the cause), or the river index the scene does not have.
Status build_scene_river_flow(const SceneFile& scene, size_t river_index, double time_seconds,
                              SceneRiverFlow* out);

// One static polygon obstacle per object marked `obstacle`, in the order of `scene.objects`.
// The object (load_gltf_object) is placed by its translation, rotation and scale; the water
// level under it is the highest river vertex inside its XZ bounds (else the nearest river
// vertex). Its footprint is the XZ convex hull of the mesh below that level (vertices and the
// points where edges pierce it), or of the whole mesh when it lies wholly above or below: an
// object marked obstacle cuts the river. The obstacle is centred at the hull's centroid, y at
// the water level. Errors name the scene file, the object and its glTF file.
Status scene_object_obstacles(const SceneFile& scene, std::span<const glm::vec3> river_positions,
                              std::vector<Obstacle>* out);

// The solved field as CSV: header `vertex,x,y,z,section,bank,width,d_left,d_right,psi,vx,vy,vz,wet`
// and one row per vertex in accessor order (bank -1 left, +1 right, 0 interior; wet 0 when dry).
std::string flow_field_csv(const SceneRiverFlow& river);

}  // namespace siviflow
