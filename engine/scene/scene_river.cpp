#include "siviflow/scene_river.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <memory>
#include <utility>

#include <glm/common.hpp>
#include <glm/geometric.hpp>

#include "default_river.h"
#include "river_simulation.h"
#include "scene/gltf_import.h"
#include "siviflow/sim/procedural_river.h"
#include "siviflow/sim/river_surface.h"
#include "siviflow/sim/river_tuning.h"
#include "siviflow/sim/spatial_grid.h"
#include "siviflow/sim/world_limits.h"
#include "siviflow/text_format.h"

namespace siviflow {
namespace {

Status in_scene(const SceneFile& scene, const Status& status) {
  return Status::error(scene.path + ": " + status.message(), status.code());
}

// A river's error in its scene: one about its named ends ("ends[2]: ...") names the key.
Status in_scene(const SceneFile& scene, size_t river_index, const Status& status) {
  if (status.message().rfind("ends", 0) != 0) return in_scene(scene, status);
  return Status::error(scene.path + ": " + scene.rivers[river_index].key + "." + status.message(),
                       status.code());
}

double cross2(glm::dvec2 o, glm::dvec2 a, glm::dvec2 b) {
  return (a.x - o.x) * (b.y - o.y) - (a.y - o.y) * (b.x - o.x);
}

// Andrew's monotone chain: the convex hull, counter-clockwise in (x, z), collinear points dropped.
std::vector<glm::dvec2> convex_hull(std::vector<glm::dvec2> points) {
  std::sort(points.begin(), points.end(),
            [](glm::dvec2 a, glm::dvec2 b) { return a.x < b.x || (a.x == b.x && a.y < b.y); });
  points.erase(std::unique(points.begin(), points.end()), points.end());
  if (points.size() < 3) return points;
  std::vector<glm::dvec2> hull(2 * points.size());
  size_t k = 0;
  for (size_t i = 0; i < points.size(); ++i) {
    while (k >= 2 && cross2(hull[k - 2], hull[k - 1], points[i]) <= 0.0) --k;
    hull[k++] = points[i];
  }
  for (size_t i = points.size() - 1, lower = k + 1; i-- > 0;) {
    while (k >= lower && cross2(hull[k - 2], hull[k - 1], points[i]) <= 0.0) --k;
    hull[k++] = points[i];
  }
  hull.resize(k - 1);  // the last point repeats the first
  return hull;
}

// The river's vertices in an XZ grid, for the water level under an object without a full scan.
class WaterLevel {
 public:
  explicit WaterLevel(std::span<const glm::vec3> river) : river_(river) {
    glm::dvec2 lo(river[0].x, river[0].z), hi = lo;
    for (const glm::vec3& p : river) {
      lo = glm::min(lo, glm::dvec2(p.x, p.z));
      hi = glm::max(hi, glm::dvec2(p.x, p.z));
    }
    const double area = std::max((hi.x - lo.x) * (hi.y - lo.y), 1e-12);
    grid_.init(lo, hi, 2.0 * std::sqrt(area / static_cast<double>(river.size())), river.size());
    grid_.insert_points(river);
  }

  // The highest river vertex inside [lo, hi] (the most of the object counts as wet), else the
  // height of the river vertex nearest the box's centre (widening the search ring by ring).
  float under(glm::dvec2 lo, glm::dvec2 hi) const {
    bool found = false;
    float top = 0.0f;
    grid_.for_each_in(lo, hi, [&](uint32_t v) {
      const glm::vec3& p = river_[v];
      if (p.x >= lo.x && p.x <= hi.x && p.z >= lo.y && p.z <= hi.y) {
        top = found ? std::max(top, p.y) : p.y;
        found = true;
      }
    });
    if (found) return top;
    const glm::dvec2 centre = 0.5 * (lo + hi);
    double best = -1.0;
    for (double grow = grid_.cell_size(); best < 0.0; grow *= 2.0) {
      grid_.for_each_in(lo - grow, hi + grow, [&](uint32_t v) {
        const glm::vec3& p = river_[v];
        const double d = glm::length(glm::dvec2(p.x, p.z) - centre);
        if (best < 0.0 || d < best) {
          best = d;
          top = p.y;
        }
      });
    }
    return top;
  }

 private:
  std::span<const glm::vec3> river_;
  XzGrid grid_;
};

// The footprint obstacle of one object (positions and bounds in world space): the XZ hull of the
// mesh where it is below `water` (vertices and edge crossings), or all of it when not crossing.
Status footprint_obstacle(const GltfObject& object, float water, Obstacle* out) {
  const bool crosses = object.bounds_min.y <= water && object.bounds_max.y > water;
  std::vector<glm::dvec2> points;
  for (const GltfPrimitive& primitive : object.primitives) {
    for (const glm::vec3& p : primitive.positions) {
      if (!crosses || p.y <= water) points.emplace_back(p.x, p.z);
    }
    if (!crosses) continue;
    // Where an edge pierces the water plane, so a sparse mesh still gets its waterline outline.
    for (size_t t = 0; t + 2 < primitive.indices.size(); t += 3) {
      for (int e = 0; e < 3; ++e) {
        const glm::dvec3 a(primitive.positions[primitive.indices[t + e]]);
        const glm::dvec3 b(primitive.positions[primitive.indices[t + (e + 1) % 3]]);
        if ((a.y <= water) == (b.y <= water)) continue;
        const double u = (double{water} - a.y) / (b.y - a.y);
        points.emplace_back(a.x + u * (b.x - a.x), a.z + u * (b.z - a.z));
      }
    }
  }
  std::vector<glm::dvec2> hull = convex_hull(std::move(points));
  if (hull.size() > kMaxObjectFootprintPoints) {
    // A subset of a convex polygon's corners is convex: keep evenly spaced ones.
    std::vector<glm::dvec2> fewer(kMaxObjectFootprintPoints);
    for (size_t i = 0; i < fewer.size(); ++i) fewer[i] = hull[i * hull.size() / fewer.size()];
    hull = std::move(fewer);
  }
  double area2 = 0.0;
  glm::dvec2 centroid(0.0);
  for (size_t i = 0; i < hull.size(); ++i) {
    const glm::dvec2 a = hull[i], b = hull[(i + 1) % hull.size()];
    const double c = a.x * b.y - a.y * b.x;
    area2 += c;
    centroid += (a + b) * c;
  }
  if (hull.size() < 3 || !(area2 > 0.0) || !std::isfinite(area2)) {
    return Status::error(
        "its footprint on the water plane has no area (the mesh is flat seen from above)");
  }
  centroid /= 3.0 * area2;
  Obstacle obstacle;
  obstacle.centre =
      glm::vec3(static_cast<float>(centroid.x), water, static_cast<float>(centroid.y));
  const glm::dvec2 centre(obstacle.centre.x, obstacle.centre.z);  // offsets from the stored centre
  for (const glm::dvec2& p : hull) obstacle.polygon.emplace_back(p - centre);
  const Status valid = validate_obstacle(obstacle, 0);
  if (!valid.ok()) return Status::error("its footprint is not usable: " + valid.message());
  *out = std::move(obstacle);
  return Status::success();
}

}  // namespace

Status scene_object_obstacles(const SceneFile& scene, std::span<const glm::vec3> river_positions,
                              std::vector<Obstacle>* out) {
  std::vector<Obstacle> obstacles;
  if (river_positions.empty()) {
    *out = std::move(obstacles);
    return Status::success();
  }
  std::unique_ptr<WaterLevel> water;  // built on the first obstacle object only
  for (size_t i = 0; i < scene.objects.size(); ++i) {
    const SceneObject& so = scene.objects[i];
    if (!so.obstacle) continue;
    const std::string what = text_format("objects[%zu] (%s): ", i, so.gltf.c_str());
    GltfObject object;
    const Status loaded = load_gltf_object(so.gltf, &object);  // its message starts with the file
    if (!loaded.ok()) {
      return Status::error(scene.path + text_format(": objects[%zu]: ", i) + loaded.message());
    }
    glm::vec3 lo(0.0f), hi(0.0f);
    bool first = true;
    for (GltfPrimitive& primitive : object.primitives) {
      for (size_t v = 0; v < primitive.positions.size(); ++v) {
        glm::vec3& p = primitive.positions[v];
        p = so.translation + so.rotation * (so.scale * p);  // glTF order: scale, rotate, translate
        if (!within_world(p)) {
          return Status::error(scene.path + ": " + what +
                               text_format("vertex %zu placed by the object's translation, "
                                           "rotation and scale ", v) +
                               world_limit_problem(p));
        }
        lo = first ? p : glm::min(lo, p);
        hi = first ? p : glm::max(hi, p);
        first = false;
      }
    }
    object.bounds_min = lo;
    object.bounds_max = hi;
    if (!water) water = std::make_unique<WaterLevel>(river_positions);
    const float level = water->under(glm::dvec2(lo.x, lo.z), glm::dvec2(hi.x, hi.z));
    Obstacle obstacle;
    const Status footprint = footprint_obstacle(object, level, &obstacle);
    if (!footprint.ok()) return Status::error(scene.path + ": " + what + footprint.message());
    obstacle.height = std::max(0.0f, hi.y - obstacle.centre.y);  // it hides the water up to its top
    obstacles.push_back(std::move(obstacle));
  }
  *out = std::move(obstacles);
  return Status::success();
}

WaterRiver SceneRiverData::river() const {
  WaterRiver river;
  river.positions = mesh.positions;
  river.indices = mesh.indices;
  river.depth = mesh.depth;
  river.slope = slope;
  river.flow = flow;
  river.obstacles = obstacles;
  river.ends = ends;
  return river;
}

void SceneRiverData::release_arrays(void* river) {
  SceneRiverData& data = *static_cast<SceneRiverData*>(river);
  data.mesh = RiverMesh();
  data.slope = std::vector<float>();
  data.obstacles = std::vector<WaterObstacle>();
  data.ends = std::vector<WaterRiverEnd>();
}

namespace {

// The host form of a flow obstacle of the scene (keys and all).
WaterObstacle water_obstacle(const Obstacle& obstacle) {
  WaterObstacle out;
  out.centre = obstacle.centre;
  out.radius = obstacle.radius;
  out.height = obstacle.height;
  out.polygon = obstacle.polygon;
  for (const ObstacleKey& key : obstacle.keys) out.keys.push_back({key.t, key.centre});
  return out;
}

// The scene's ends of a river on its mesh (a point names the end nearest it). Errors name the key.
Status resolve_ends(const SceneRiver& river, std::span<const glm::vec3> positions,
                    std::vector<WaterRiverEnd>* out) {
  out->clear();
  for (size_t i = 0; i < river.ends.size(); ++i) {
    const SceneRiverEnd& end = river.ends[i];
    if (end.by_vertex && end.vertex >= positions.size()) {
      return Status::error(text_format("%s.ends[%zu].vertex: %u is not in the river mesh (%zu vertices)",
                                       river.key.c_str(), i, end.vertex, positions.size()));
    }
    out->push_back({end.vertex, end.inflow, end.discharge, !end.by_vertex, end.near});
  }
  return Status::success();
}

// A glTF river's depth (the profile of kGltfRiverDepth) and the slope of that bed across.
Status gltf_river_data(TriangleMesh gltf, SceneRiverData* out) {
  RiverSurface surface;
  SIVIFLOW_TRY(RiverSurface::build(gltf.positions, gltf.indices, river_surface_options(out->ends), &surface));
  out->mesh.positions = std::move(gltf.positions);
  out->mesh.indices = std::move(gltf.indices);
  const size_t count = out->mesh.positions.size();
  out->mesh.depth.resize(count);
  out->slope.resize(count);
  for (size_t v = 0; v < count; ++v) {
    const RiverVertex vertex = surface.vertex(v);
    // Across the vertex's arm: from bank to bank, or to an island's shore (where it is 0 deep).
    const float arm = vertex.d_left + vertex.d_right;
    const float w2 = arm > 0.0f ? arm * arm : 1.0f;
    out->mesh.depth[v] = kGltfRiverDepth * 4.0f * vertex.d_left * vertex.d_right / w2;
    out->slope[v] = std::abs(kGltfRiverDepth * 4.0f * (vertex.d_right - vertex.d_left) / w2);
  }
  return Status::success();
}

}  // namespace

Status scene_river_shape(const SceneFile* scene, size_t river_index, SceneRiverData* out) {
  const size_t rivers = scene == nullptr ? 1 : scene->rivers.size();
  if (river_index >= rivers) {
    return Status::error((scene == nullptr ? std::string("the default scene") : scene->path) +
                         ": no river " + std::to_string(river_index) + " (it has " +
                         std::to_string(rivers) + ")");
  }
  SceneRiverData data;
  if (scene == nullptr) {
    data.procedural.emplace(default_river_params());
  } else {
    const SceneRiver& river = scene->rivers[river_index];
    data.flow = {river.flow.discharge, river.flow.p, river.flow.search_radius};
    if (river.source == SceneRiver::Source::kGltf) {
      TriangleMesh gltf;
      Status status = load_river_mesh(river.gltf, river.mesh, &gltf);
      if (status.ok()) status = resolve_ends(river, gltf.positions, &data.ends);
      if (status.ok()) status = gltf_river_data(std::move(gltf), &data);
      if (!status.ok()) return in_scene(*scene, river_index, status);
    } else {
      const Status status = ProceduralRiver::validate(river.procedural);
      if (!status.ok()) return in_scene(*scene, status);
      data.procedural.emplace(river.procedural);
    }
  }
  *out = std::move(data);
  return Status::success();
}

Status scene_river_data(const SceneFile* scene, size_t river_index, SceneRiverData* out) {
  SceneRiverData data;
  SIVIFLOW_TRY(scene_river_shape(scene, river_index, &data));
  if (data.procedural) {
    Status status = data.procedural->generate_mesh(&data.mesh);
    data.slope = std::move(data.mesh.slope);
    if (status.ok() && scene != nullptr) {
      status = resolve_ends(scene->rivers[river_index], data.mesh.positions, &data.ends);
    }
    if (status.ok() && data.ends.empty()) {
      data.ends = procedural_river_ends(data.mesh, data.flow.discharge);
    }
    if (!status.ok()) return scene == nullptr ? status : in_scene(*scene, status);
  }
  std::vector<Obstacle> obstacles;
  if (scene == nullptr) {
    obstacles = default_scene_obstacles(*data.procedural);
  } else {
    obstacles = scene->obstacles;
    std::vector<Obstacle> from_objects;
    SIVIFLOW_TRY(scene_object_obstacles(*scene, data.mesh.positions, &from_objects));
    obstacles.insert(obstacles.end(), from_objects.begin(), from_objects.end());
  }
  for (const Obstacle& obstacle : obstacles) data.obstacles.push_back(water_obstacle(obstacle));
  *out = std::move(data);
  return Status::success();
}

Status build_scene_river_flow(const SceneFile& scene, size_t river_index, double time_seconds,
                              SceneRiverFlow* out) {
  SceneRiverData data;
  SIVIFLOW_TRY(scene_river_data(&scene, river_index, &data));
  out->positions = std::move(data.mesh.positions);
  RiverSurface surface;
  Status status = RiverSurface::build(out->positions, data.mesh.indices,
                                      river_surface_options(data.ends), &surface);
  if (!status.ok()) return in_scene(scene, river_index, status);
  FlowParams flow{data.flow.discharge, data.flow.shepard_power, data.flow.search_radius};
  flow.end_discharges = surface_end_discharges(surface, data.ends);
  status = StreamFunction::create(std::move(surface), flow, &out->flow);
  if (!status.ok()) return in_scene(scene, status);
  std::vector<Obstacle> obstacles;
  for (const WaterObstacle& obstacle : data.obstacles) obstacles.push_back(flow_obstacle(obstacle));
  status = out->flow.set_obstacles(std::move(obstacles), time_seconds);
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
