// The built-in meshes of floating bodies (SceneFloat::mesh): a log and a leaf, modelled around
// the origin along +x with the water surface at y = 0, drawn turned and moved to where each
// float drifts.
#pragma once

#include "index_range.h"
#include "scene/default_scene.h"
#include "siviflow/scene_file.h"

namespace siviflow {

// How far a float's mesh reaches from its centre along its length (x and z, any heading) and up:
// the upright cylinder a capture's motion vectors move with it.
glm::vec3 float_reach(FloatMesh mesh, float radius);

// Appends the mesh of a float `radius` metres long each way from its centre to `geometry`;
// `seed` varies its bark or colour. Returns its triangles.
IndexRange add_float_mesh(FloatMesh mesh, float radius, float seed, SceneGeometry* geometry);

}  // namespace siviflow
