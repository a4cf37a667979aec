// Ground around rivers given as meshes (a glTF river has no valley of its own): one height field
// that meets every river's banks at their water level and rises away from them into a valley
// floor and hills, so no river floats in a void; under the water it sinks beneath the riverbed
// that build_riverbed_geometry draws.
#pragma once

#include <span>

#include "scene/default_scene.h"
#include "siviflow/sim/procedural_river.h"
#include "siviflow/status.h"

namespace siviflow {

// Appends the ground's vertices (ground_vertex) and triangles to `geometry`. Fails only when a
// river's surface cannot be ray-cast (no triangles).
Status add_ground_around_rivers(std::span<const RiverMesh> rivers, SceneGeometry* geometry);

}  // namespace siviflow
