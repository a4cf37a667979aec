// The river of a scene file, solved: its mesh (glTF or procedural) turned into a river surface
// and a stream-function flow with the scene's obstacles placed at a given time.
#pragma once

#include <string>
#include <vector>

#include <glm/vec3.hpp>

#include "siviflow/scene_file.h"
#include "sim/status.h"
#include "sim/stream_function.h"

namespace siviflow {

struct SceneRiverFlow {
  std::vector<glm::vec3> positions;  // the river primitive's vertices, in the file's accessor order
  StreamFunction flow;               // per input vertex: surface data, psi, velocity, wet
};

// Loads the river mesh of `scene`, builds its surface and solves the flow with the scene's
// obstacles at `time_seconds`. Errors name the scene file (and the glTF file where it is the cause).
Status build_scene_river_flow(const SceneFile& scene, double time_seconds, SceneRiverFlow* out);

// The solved field as CSV: header `vertex,x,y,z,section,bank,width,d_left,d_right,psi,vx,vy,vz,wet`
// and one row per vertex in accessor order (bank -1 left, +1 right, 0 interior; wet 0 when dry).
std::string flow_field_csv(const SceneRiverFlow& river);

}  // namespace siviflow
