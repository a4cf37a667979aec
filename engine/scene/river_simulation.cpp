#include "scene/river_simulation.h"

#include <cmath>
#include <string>

#include <glm/geometric.hpp>

#include "scene/default_scene.h"
#include "siviflow/scene_river.h"
#include "sim/river_surface.h"

namespace siviflow {
namespace {

constexpr float kSlopeStep = 0.5f;         // metres: finite-difference step of the riverbed slope

}  // namespace

Status procedural_river_input(const ProceduralRiver& river, RiverInput* out) {
  RiverInput input;
  SIVIFLOW_TRY(river.generate_mesh(&input.mesh));
  const RiverMesh& mesh = input.mesh;
  SIVIFLOW_TRY(RiverSurface::build(mesh.positions, mesh.indices, RiverSurfaceOptions{}, &input.surface));
  input.slope.resize(mesh.positions.size());
  for (size_t v = 0; v < mesh.positions.size(); ++v) {
    const glm::vec3& p = mesh.positions[v];
    const float dx = river.terrain_height(p.x + kSlopeStep, p.z) - river.terrain_height(p.x - kSlopeStep, p.z);
    const float dz = river.terrain_height(p.x, p.z + kSlopeStep) - river.terrain_height(p.x, p.z - kSlopeStep);
    input.slope[v] = std::sqrt(dx * dx + dz * dz) / (2.0f * kSlopeStep);
  }
  *out = std::move(input);
  return Status::success();
}

Status gltf_river_input(TriangleMesh gltf, RiverInput* out) {
  RiverInput input;
  SIVIFLOW_TRY(RiverSurface::build(gltf.positions, gltf.indices, RiverSurfaceOptions{}, &input.surface));
  input.mesh.positions = std::move(gltf.positions);
  input.mesh.indices = std::move(gltf.indices);
  const size_t count = input.mesh.positions.size();
  input.mesh.depth.resize(count);
  input.slope.resize(count);
  for (size_t v = 0; v < count; ++v) {
    const RiverVertex vertex = input.surface.vertex(v);
    const float w2 = vertex.width * vertex.width;
    input.mesh.depth[v] = kGltfRiverDepth * 4.0f * vertex.d_left * vertex.d_right / w2;
    input.slope[v] = std::abs(kGltfRiverDepth * 4.0f * (vertex.d_right - vertex.d_left) / w2);
  }
  *out = std::move(input);
  return Status::success();
}

Status scene_river_input(const SceneFile* scene, size_t river_index, RiverInput* out,
                         std::optional<ProceduralRiver>* procedural) {
  const size_t rivers = scene == nullptr ? 1 : scene->rivers.size();
  if (river_index >= rivers) {
    return Status::error((scene == nullptr ? std::string("the default scene") : scene->path) +
                         ": no river " + std::to_string(river_index) + " (it has " +
                         std::to_string(rivers) + ")");
  }
  if (scene == nullptr) {
    procedural->emplace(default_river_params());
    return procedural_river_input(**procedural, out);
  }
  const auto in_scene = [scene](const Status& status) {
    return status.ok() ? status : Status::error(scene->path + ": " + status.message(), status.code());
  };
  const SceneRiver& river = scene->rivers[river_index];
  if (river.source == SceneRiver::Source::kGltf) {
    TriangleMesh gltf;
    SIVIFLOW_TRY(in_scene(load_river_mesh(river.gltf, river.mesh, &gltf)));
    procedural->reset();
    return in_scene(gltf_river_input(std::move(gltf), out));
  }
  SIVIFLOW_TRY(in_scene(ProceduralRiver::validate(river.procedural)));
  procedural->emplace(river.procedural);
  return in_scene(procedural_river_input(**procedural, out));
}

Status RiverFlow::create(RiverInput river, const FlowParams& flow, std::vector<Obstacle> obstacles) {
  mesh_ = std::move(river.mesh);
  slope_ = std::move(river.slope);
  SIVIFLOW_TRY(StreamFunction::create(std::move(river.surface), flow, &flow_));
  for (const Obstacle& obstacle : obstacles) has_keys_ = has_keys_ || !obstacle.keys.empty();
  SIVIFLOW_TRY(flow_.set_obstacles(std::move(obstacles), 0.0));
  full_solves_ = 1;
  const size_t count = mesh_.positions.size();
  velocity_.resize(count);
  speed_.resize(count);
  refresh_velocity();
  field_.positions = mesh_.positions;
  field_.indices = mesh_.indices;
  field_.flow = velocity_;
  field_.speed = speed_;
  field_.depth = mesh_.depth;
  field_.slope = slope_;
  auto bvh = std::make_shared<RiverBvh>();
  SIVIFLOW_TRY(RiverBvh::build(field_.positions, field_.indices, bvh.get()));
  bvh_ = std::move(bvh);
  return Status::success();
}

void RiverFlow::refresh_velocity() {
  for (size_t v = 0; v < velocity_.size(); ++v) {
    velocity_[v] = flow_.velocity(v);
    speed_[v] = glm::length(velocity_[v]);
  }
}

Status RiverFlow::set_time(double time_seconds) {
  if (!has_keys_) return Status::success();
  SIVIFLOW_TRY(flow_.set_time(time_seconds));
  if (flow_.last_update().nodes_resolved == 0) return Status::success();  // nothing moved
  // A few thousand vertices: re-reading them all costs less than tracking which changed.
  refresh_velocity();
  return Status::success();
}

Status RiverFlow::add_obstacle(Obstacle obstacle) {
  SIVIFLOW_TRY(flow_.add_obstacle(std::move(obstacle)));
  refresh_velocity();
  return Status::success();
}

Status RiverFlow::replace_obstacle(size_t index, Obstacle obstacle) {
  SIVIFLOW_TRY(flow_.replace_obstacle(index, std::move(obstacle)));
  refresh_velocity();
  return Status::success();
}

Status RiverFlow::move_obstacle(size_t index, const glm::vec3& centre) {
  SIVIFLOW_TRY(flow_.move_obstacle(index, centre));
  refresh_velocity();
  return Status::success();
}

Status RiverFlow::remove_obstacle(size_t index) {
  SIVIFLOW_TRY(flow_.remove_obstacle(index));
  refresh_velocity();
  return Status::success();
}

Status RiverView::create(const RiverFlow& river, uint64_t seed, glm::uvec2 viewport) {
  ParticleParams params;
  params.seed = seed;
  params.viewport = viewport;
  SIVIFLOW_TRY(ParticleField::create(river.field(), river.bvh(), params, &particles_));
  SIVIFLOW_TRY(FlowTextures::create(particles_, kDefaultFlowTexelPx, &flow_textures_));
  viewport_ = viewport;
  return Status::success();
}

Status RiverView::resize(glm::uvec2 viewport) {
  ParticleParams params = particles_.params();
  params.viewport = viewport;
  ParticleField particles;
  SIVIFLOW_TRY(ParticleField::create(particles_.river(), particles_.shared_bvh(), params, &particles));
  FlowTextures textures;
  SIVIFLOW_TRY(FlowTextures::create(particles, kDefaultFlowTexelPx, &textures));
  particles_ = std::move(particles);
  flow_textures_ = std::move(textures);
  viewport_ = viewport;
  return Status::success();
}

Status RiverView::simulate(const glm::mat4& view_proj, float dt_seconds) {
  return particles_.update(ScreenCamera{view_proj, viewport_}, particles_.next_frame(), dt_seconds);
}

Status RiverView::pack(std::span<std::byte> staging) {
  return flow_textures_.pack(particles_, staging);
}

}  // namespace siviflow
