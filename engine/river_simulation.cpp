#include "river_simulation.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include <glm/geometric.hpp>

#include "sim/half_float.h"
#include "siviflow/sim/river_surface.h"
#include "siviflow/sim/world_limits.h"
#include "siviflow/text_format.h"

namespace siviflow {

std::vector<WaterRiverEnd> procedural_river_ends(const RiverMesh& mesh, float discharge) {
  std::vector<WaterRiverEnd> ends;
  float inflow_width = 0.0f;
  for (const RiverMeshEnd& end : mesh.ends) inflow_width += end.inflow ? end.width : 0.0f;
  for (const RiverMeshEnd& end : mesh.ends) {
    ends.push_back({end.vertex, end.inflow, end.inflow ? discharge * end.width / inflow_width : discharge});
  }
  return ends;
}

Status procedural_river_input(const ProceduralRiver& river, RiverInput* out) {
  RiverInput input;
  SIVIFLOW_TRY(river.generate_mesh(&input.mesh));
  input.depth = halves_of(input.mesh.depth);
  input.slope = halves_of(input.mesh.slope);
  input.mesh.depth = std::vector<float>();  // freed: `= {}` would keep the capacity
  input.mesh.slope = std::vector<float>();
  RiverSurfaceOptions options;
  for (const RiverMeshEnd& end : input.mesh.ends) options.ends.push_back({end.vertex, end.inflow});
  SIVIFLOW_TRY(RiverSurface::build(input.mesh.positions, input.mesh.indices, options, &input.surface));
  if (!input.surface.welded() &&
      std::ranges::equal(input.surface.triangles(), input.mesh.indices)) {
    input.mesh.positions = std::vector<glm::vec3>();  // freed: `= {}` would keep the capacity
    input.mesh.indices = std::vector<uint32_t>();
  }
  *out = std::move(input);
  return Status::success();
}

FlowParams river_flow_params(const RiverFlowParams& flow, const RiverInput& input) {
  FlowParams params{flow.discharge, flow.shepard_power, flow.search_radius};
  params.end_discharges = input.end_discharges;
  if (!params.end_discharges.empty()) {
    params.discharge = 0.0f;
    for (size_t e = 0; e < params.end_discharges.size(); ++e) {
      if (input.surface.ends()[e].inflow) params.discharge += params.end_discharges[e];
    }
  }
  return params;
}

RiverSurfaceOptions river_surface_options(std::span<const WaterRiverEnd> ends) {
  RiverSurfaceOptions options;
  for (const WaterRiverEnd& end : ends) options.ends.push_back({end.vertex, end.inflow, end.at_point, end.point});
  return options;
}

std::vector<float> surface_end_discharges(const RiverSurface& surface,
                                          std::span<const WaterRiverEnd> ends) {
  std::vector<float> q;
  if (ends.empty()) return q;
  for (const RiverEnd& end : surface.ends()) q.push_back(ends[end.mark].discharge);
  return q;
}

Status river_input_from(const WaterRiver& river, const std::function<void()>& copied,
                        RiverInput* out) {
  const size_t count = river.positions.size();
  const auto per_vertex = [count](size_t size, const char* field) {
    if (size == count) return Status::success();
    return Status::error(text_format("CreateInfo::river->%s has %zu values for %zu positions", field,
                                     size, count));
  };
  SIVIFLOW_TRY(per_vertex(river.depth.size(), "depth"));
  SIVIFLOW_TRY(per_vertex(river.slope.size(), "slope"));
  for (size_t v = 0; v < count; ++v) {
    const glm::vec3& p = river.positions[v];
    if (!within_world(p)) {
      return Status::error(text_format("CreateInfo::river->positions[%zu] ", v) + world_limit_problem(p));
    }
    if (!(river.depth[v] >= 0.0f && river.depth[v] <= kLargestHalf)) {
      return Status::error(
          text_format("CreateInfo::river->depth[%zu] %g is not a depth from 0 to 65504 m", v,
                      double(river.depth[v])));
    }
    if (!(river.slope[v] >= 0.0f && river.slope[v] <= kLargestHalf)) {
      return Status::error(
          text_format("CreateInfo::river->slope[%zu] %g is not a slope from 0 to 65504", v,
                      double(river.slope[v])));
    }
  }
  for (size_t e = 0; e < river.ends.size(); ++e) {
    const float q = river.ends[e].discharge;
    if (!(q >= 0.0f) || !std::isfinite(q)) {
      return Status::error(text_format("CreateInfo::river->ends[%zu].discharge %g is not a finite "
                                       "discharge >= 0", e, double(q)));
    }
  }
  RiverInput input;
  input.depth = halves_of(river.depth);
  input.slope = halves_of(river.slope);
  RiverSurfaceOptions options = river_surface_options(river.ends);
  // Past this the host's arrays are not read, and the host frees them: the mesh is copied where
  // vertices were welded. Unwelded, its positions are the surface's nodes and its indices the
  // surface's triangles but where it rewound them, given back below (no copy held through the
  // build, which peaks there: 32 MB for a 100 km river).
  options.inputs_read = [&](bool welded) {
    if (welded) {
      input.mesh.positions.assign(river.positions.begin(), river.positions.end());
      input.mesh.indices.assign(river.indices.begin(), river.indices.end());
    }
    if (copied) copied();
  };
  std::vector<bool> rewound;
  options.rewound = &rewound;
  const std::vector<WaterRiverEnd> ends(river.ends.begin(), river.ends.end());
  const Status built = RiverSurface::build(river.positions, river.indices, options, &input.surface);
  if (!built.ok()) return Status::error("CreateInfo::river: " + built.message(), built.code());
  input.end_discharges = surface_end_discharges(input.surface, ends);
  if (!input.surface.welded() && std::ranges::find(rewound, true) != rewound.end()) {
    // The host's winding is kept, as the foam and queries add its corners.
    const auto nodes = input.surface.node_positions();
    const auto tris = input.surface.triangles();
    input.mesh.positions.assign(nodes.begin(), nodes.end());
    input.mesh.indices.assign(tris.begin(), tris.end());
    for (size_t t = 0; t < rewound.size(); ++t) {
      if (rewound[t]) std::swap(input.mesh.indices[3 * t + 1], input.mesh.indices[3 * t + 2]);
    }
  }
  *out = std::move(input);
  return Status::success();
}

Obstacle flow_obstacle(const WaterObstacle& placed) {
  Obstacle obstacle;
  obstacle.centre = placed.centre;
  obstacle.radius = placed.radius;
  obstacle.height = placed.height;
  const float c = std::cos(placed.rotation_rad);
  const float s = std::sin(placed.rotation_rad);
  obstacle.polygon.reserve(placed.polygon.size());
  for (const glm::vec2& p : placed.polygon) {
    obstacle.polygon.push_back({c * p.x + s * p.y, -s * p.x + c * p.y});
  }
  for (const WaterObstacleKey& key : placed.keys) obstacle.keys.push_back({key.t, key.centre});
  return obstacle;
}

Status check_obstacle(const WaterObstacle& placed, size_t index) {
  if (!std::isfinite(placed.rotation_rad)) {
    return Status::error(text_format("obstacle %zu: WaterObstacle::rotation_rad %g is not finite",
                                     index, double(placed.rotation_rad)));
  }
  return validate_obstacle(flow_obstacle(placed), index);
}

Status RiverFlow::create(RiverInput river, const FlowParams& flow, std::vector<Obstacle> obstacles,
                         const MeshHome& home) {
  const size_t vertices = river.surface.vertex_count();
  if (!river.mesh.depth.empty() || !river.mesh.slope.empty() ||
      (!river.depth.empty() && river.depth.size() != vertices) ||
      (!river.slope.empty() && river.slope.size() != vertices)) {
    return Status::error(text_format(
        "RiverFlow::create: %zu depths and %zu slopes for %zu vertices (give RiverInput's "
        "halves, one a vertex or none, and leave the mesh's empty)",
        river.depth.size(), river.slope.size(), vertices));
  }
  mesh_ = std::move(river.mesh);
  depth_ = std::move(river.depth);
  slope_ = std::move(river.slope);
  per_node_ = mesh_.positions.empty();
  SIVIFLOW_TRY(StreamFunction::validate_params(flow));  // before the costly work below
  // The mesh's home and the ray-cast hierarchy come before the flow's arrays: a long river's
  // copy into its home and the hierarchy's build scratch then meet 28 MB less of them.
  if (home) {
    PlacedMesh placed;
    if (per_node_) {
      SIVIFLOW_TRY(home(river.surface.node_positions(), river.surface.triangles(), &placed));
      if (placed.positions.data() != nullptr) {
        SIVIFLOW_TRY(river.surface.share_mesh(placed.positions, placed.indices));
      }
    } else {
      SIVIFLOW_TRY(home(mesh_.positions, mesh_.indices, &placed));
    }
  }
  // On the surface's arrays before they move into the flow: a moved vector's elements stay put.
  auto bvh = std::make_shared<TriangleBvh>();
  SIVIFLOW_TRY(TriangleBvh::build(per_node_ ? river.surface.node_positions() : mesh_.positions,
                                  per_node_ ? river.surface.triangles() : mesh_.indices,
                                  bvh.get()));
  SIVIFLOW_TRY(StreamFunction::create(std::move(river.surface), flow, &flow_));
  for (const Obstacle& obstacle : obstacles) has_keys_ = has_keys_ || !obstacle.keys.empty();
  SIVIFLOW_TRY(flow_.set_obstacles(std::move(obstacles), 0.0));
  bvh_ = std::move(bvh);  // only now: on a failure above its arrays are gone with the surface
  full_solves_ = 1;
  const RiverSurface& surface = flow_.surface();
  const size_t count = surface.vertex_count();
  NodeSections section = surface.node_section();
  if (per_node_) {
    field_.positions = surface.node_positions();
    field_.indices = surface.triangles();
    field_.flow = flow_.node_velocity();
  } else {
    section_copy_.resize(count);
    for (size_t v = 0; v < count; ++v) section_copy_[v] = section[surface.node_of(v)];
    section = NodeSections(section_copy_);
    velocity_copy_.resize(count);
    field_.positions = mesh_.positions;
    field_.indices = mesh_.indices;
    field_.flow = velocity_copy_;
  }
  foam_.resize(count);
  // The surface's, when its nodes are the vertices.
  const TrianglesAround* around = per_node_ ? &surface.triangles_around() : nullptr;
  SIVIFLOW_TRY(FoamField::create(field_.positions, field_.indices, section, bvh_.get(),
                                 FoamParams{}, &foam_field_, around));
  refresh_velocity();
  // No speed: the particles take |flow|, as it would have held.
  field_.depth = depth_;
  field_.slope = slope_;
  field_.foam = foam_;
  water_query_ = WaterQuery(field_, bvh_.get());
  return Status::success();
}

void RiverFlow::query(std::span<const glm::vec3> points, std::span<WaterSample> out) const {
  std::vector<DryFootprint> footprints;
  dry_footprints(&footprints);
  for (size_t i = 0; i < points.size(); ++i) out[i] = water_query_.sample(points[i], footprints);
}

void RiverFlow::refresh_velocity() {
  // Only where the flow changed (everywhere after a full solve): a long river's velocities and
  // foam are not derived again for a boulder moved at one place. (A welded vertex stands exactly
  // on its node, so the nodes' boxes hold it.)
  const std::vector<XzBox>& changed = flow_.last_update().velocity_changed;
  if (!velocity_copy_.empty()) {
    const bool everywhere =
        std::any_of(changed.begin(), changed.end(), [](const XzBox& box) { return !box.finite(); });
    if (everywhere) {
      for (size_t v = 0; v < velocity_copy_.size(); ++v) velocity_copy_[v] = flow_.velocity(v);
    } else {
      std::vector<uint32_t> moved;
      for (const XzBox& box : changed) bvh_->append_vertices_in(box, &moved);
      for (const uint32_t v : moved) velocity_copy_[v] = flow_.velocity(v);
    }
  }
  foam_field_.update(field_.flow, margin_distances(flow_.surface()), changed, foam_);
}

Status RiverFlow::set_time(double time_seconds) {
  time_ = time_seconds;  // where an obstacle keyed later starts
  if (!has_keys_) return Status::success();
  SIVIFLOW_TRY(flow_.set_time(time_seconds));
  if (flow_.last_update().nodes_resolved == 0) return Status::success();  // nothing moved
  refresh_velocity();
  return Status::success();
}

Status RiverFlow::add_obstacle(Obstacle obstacle) {
  const bool keyed = !obstacle.keys.empty();
  SIVIFLOW_TRY(flow_.add_obstacle(std::move(obstacle), time_));
  has_keys_ = has_keys_ || keyed;
  refresh_velocity();
  return Status::success();
}

Status RiverFlow::replace_obstacle(size_t index, Obstacle obstacle) {
  const bool keyed = !obstacle.keys.empty();
  SIVIFLOW_TRY(flow_.replace_obstacle(index, std::move(obstacle), time_));
  has_keys_ = has_keys_ || keyed;
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
  river_ = &river;
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

void RiverFlow::dry_footprints(std::vector<DryFootprint>* out) const {
  out->clear();
  const std::span<const Obstacle> obstacles = flow_.obstacles();
  for (size_t i = 0; i < obstacles.size(); ++i) {
    const glm::vec3 centre = flow_.obstacle_centre(i);
    // Flat (no height): it hides nothing, wherever its centre stands.
    const double top = obstacles[i].height > 0.0f ? double(centre.y) + obstacles[i].height
                                                  : -std::numeric_limits<double>::infinity();
    out->push_back({&obstacles[i], glm::dvec2(centre.x, centre.z), top});
  }
}

Status RiverFlow::set_occluders(std::span<const glm::vec3> positions,
                                std::span<const uint32_t> indices) {
  if (positions.empty() && indices.empty()) {
    occluders_.reset();
    return Status::success();
  }
  // The mesh and its hierarchy in one block; the hierarchy's pointer shares the block's life.
  struct Mesh {
    std::vector<glm::vec3> positions;
    std::vector<uint32_t> indices;
    TriangleBvh bvh;
  };
  auto mesh = std::make_shared<Mesh>();
  mesh->positions.assign(positions.begin(), positions.end());
  mesh->indices.assign(indices.begin(), indices.end());
  SIVIFLOW_TRY(TriangleBvh::build(mesh->positions, mesh->indices, &mesh->bvh, "OccluderMesh"));
  occluders_ = std::shared_ptr<const TriangleBvh>(mesh, &mesh->bvh);
  return Status::success();
}

Status RiverView::simulate(const glm::mat4& view_proj, float dt_seconds) {
  if (river_ == nullptr)
    return Status::error("particles: simulate on a view create() did not make");
  river_->dry_footprints(&dry_);
  std::shared_ptr<const TriangleBvh> occluders = river_->occluders();
  if (particles_.occluders() != occluders) particles_.set_occluders(std::move(occluders));
  return particles_.update(ScreenCamera{view_proj, viewport_}, particles_.next_frame(), dt_seconds,
                           dry_);
}

Status RiverView::pack(std::span<std::byte> staging) {
  return flow_textures_.pack(particles_, staging);
}

}  // namespace siviflow
