#include "siviflow/scene_river.h"

#include <cstdio>

#include "scene/gltf_import.h"
#include "sim/procedural_river.h"
#include "sim/river_surface.h"

namespace siviflow {
namespace {

Status in_scene(const SceneFile& scene, const Status& status) {
  return Status::error(scene.path + ": " + status.message(), status.code());
}

}  // namespace

Status build_scene_river_flow(const SceneFile& scene, double time_seconds, SceneRiverFlow* out) {
  std::vector<uint32_t> indices;
  if (scene.river.source == SceneRiver::Source::kGltf) {
    TriangleMesh mesh;
    SIVIFLOW_TRY(load_river_mesh(scene.river.gltf, scene.river.mesh, &mesh));
    out->positions = std::move(mesh.positions);
    indices = std::move(mesh.indices);
  } else {
    Status status = ProceduralRiver::validate(scene.river.procedural);
    if (!status.ok()) return in_scene(scene, status);
    RiverMesh mesh;
    status = ProceduralRiver(scene.river.procedural).generate_mesh(&mesh);
    if (!status.ok()) return in_scene(scene, status);
    out->positions = std::move(mesh.positions);
    indices = std::move(mesh.indices);
  }
  RiverSurface surface;
  Status status = RiverSurface::build(out->positions, indices, RiverSurfaceOptions{}, &surface);
  if (!status.ok()) return in_scene(scene, status);
  status = StreamFunction::create(std::move(surface), scene.flow, &out->flow);
  if (!status.ok()) return in_scene(scene, status);
  status = out->flow.set_obstacles(scene.obstacles, time_seconds);
  if (!status.ok()) return in_scene(scene, status);
  return Status::success();
}

std::string flow_field_csv(const SceneRiverFlow& river) {
  std::string csv = "vertex,x,y,z,section,bank,width,d_left,d_right,psi,vx,vy,vz,wet\n";
  const RiverSurface& surface = river.flow.surface();
  char row[512];
  for (size_t v = 0; v < river.positions.size(); ++v) {
    const RiverVertex vertex = surface.vertex(v);
    const glm::vec3& p = river.positions[v];
    const glm::vec3 velocity = river.flow.velocity(v);
    // %.9g round-trips a float exactly; psi is a double and gets %.17g.
    std::snprintf(row, sizeof(row), "%zu,%.9g,%.9g,%.9g,%u,%d,%.9g,%.9g,%.9g,%.17g,%.9g,%.9g,%.9g,%d\n",
                  v, p.x, p.y, p.z, vertex.section, static_cast<int>(vertex.bank), vertex.width,
                  vertex.d_left, vertex.d_right, river.flow.psi(v), velocity.x, velocity.y,
                  velocity.z, river.flow.wet(v) ? 1 : 0);
    csv += row;
  }
  return csv;
}

}  // namespace siviflow
