#include "scene/default_scene.h"

#include "scene/river_ground.h"
#include "scene/terrain_chunks.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <glm/geometric.hpp>
#include <glm/gtc/constants.hpp>

namespace siviflow {
namespace {

constexpr int kTerrainColumns = 120;   // quads across the valley (1.5 m)
constexpr int kTerrainRows = 160;      // quads along the valley (1.5 m)
constexpr float kTerrainHalfWidth = 90.0f;
constexpr glm::vec3 kGranite(0.46f, 0.44f, 0.42f);
constexpr glm::vec3 kSandstone(0.55f, 0.45f, 0.35f);

glm::vec3 terrain_normal(const ProceduralRiver& river, float x, float z) {
  const float e = 0.5f;
  const float dx = river.terrain_height(x + e, z) - river.terrain_height(x - e, z);
  const float dz = river.terrain_height(x, z + e) - river.terrain_height(x, z - e);
  return glm::normalize(glm::vec3(-dx, 2.0f * e, -dz));
}

void add_terrain(const ProceduralRiver& river, SceneGeometry* geometry) {
  const float half_length = 0.5f * river.params().length;
  std::vector<SceneVertex> points;
  for (int row = 0; row <= kTerrainRows; ++row) {
    const float z = -half_length + river.params().length * static_cast<float>(row) / kTerrainRows;
    for (int col = 0; col <= kTerrainColumns; ++col) {
      const float x = -kTerrainHalfWidth + 2.0f * kTerrainHalfWidth * static_cast<float>(col) /
                                               kTerrainColumns;
      const float y = river.terrain_height(x, z);
      points.push_back(
          ground_vertex({x, y, z}, terrain_normal(river, x, z), y - river.water_level()));
    }
  }
  add_chunked_grid(points, kTerrainColumns, kTerrainRows, geometry);
}

// A latitude-longitude ellipsoid, squashed and bumped so it reads as a boulder.
void add_boulder(glm::vec3 centre, glm::vec3 radii, glm::vec3 albedo, float seed,
                 SceneGeometry* geometry) {
  constexpr int kRings = 10;
  constexpr int kSegments = 16;
  const uint32_t base = static_cast<uint32_t>(geometry->vertices.size());
  for (int ring = 0; ring <= kRings; ++ring) {
    const float theta = glm::pi<float>() * static_cast<float>(ring) / kRings;
    for (int seg = 0; seg <= kSegments; ++seg) {
      const float phi = glm::two_pi<float>() * static_cast<float>(seg) / kSegments;
      const glm::vec3 unit(std::sin(theta) * std::cos(phi), std::cos(theta),
                           std::sin(theta) * std::sin(phi));
      const float bump = 1.0f + 0.12f * std::sin(3.0f * phi + seed) * std::sin(2.0f * theta + seed);
      const glm::vec3 p = centre + unit * radii * bump;
      const glm::vec3 n = glm::normalize(unit / radii);
      const float occlusion = 0.55f + 0.45f * (unit.y * 0.5f + 0.5f);
      geometry->vertices.push_back({p, n, glm::vec4(albedo, occlusion)});
    }
  }
  for (uint32_t ring = 0; ring < kRings; ++ring) {
    for (uint32_t seg = 0; seg < kSegments; ++seg) {
      const uint32_t a = base + ring * (kSegments + 1) + seg;
      const uint32_t b = a + 1;
      const uint32_t c = a + kSegments + 1;
      const uint32_t d = c + 1;
      geometry->indices.insert(geometry->indices.end(), {a, b, c, b, d, c});
    }
  }
}

// The triangles from `first_index` on as one piece, drawn whole wherever it is seen.
void add_object_piece(uint32_t first_index, SceneGeometry* geometry) {
  geometry->pieces.push_back(object_piece(*geometry, first_index,
                                          static_cast<uint32_t>(geometry->indices.size()) - first_index, 0));
}

// A cone on a cylinder: a conifer, tall enough to show in the water's reflection later.
void add_tree(glm::vec3 foot, float height, SceneGeometry* geometry) {
  constexpr int kSegments = 12;
  const glm::vec3 trunk_colour(0.25f, 0.16f, 0.09f);
  const glm::vec3 crown_colour(0.07f, 0.20f, 0.08f);
  const float trunk_radius = 0.04f * height;
  const float trunk_height = 0.25f * height;
  const float crown_radius = 0.22f * height;
  const auto add_ring_pair = [&](float r0, float y0, float r1, float y1, glm::vec3 colour) {
    const uint32_t base = static_cast<uint32_t>(geometry->vertices.size());
    const float slope = (r0 - r1) / (y1 - y0);
    for (int seg = 0; seg <= kSegments; ++seg) {
      const float phi = glm::two_pi<float>() * static_cast<float>(seg) / kSegments;
      const glm::vec3 radial(std::cos(phi), 0.0f, std::sin(phi));
      const glm::vec3 n = glm::normalize(radial + glm::vec3(0.0f, slope, 0.0f));
      geometry->vertices.push_back({foot + radial * r0 + glm::vec3(0, y0, 0), n, glm::vec4(colour, 0.6f)});
      geometry->vertices.push_back({foot + radial * r1 + glm::vec3(0, y1, 0), n, glm::vec4(colour, 1.0f)});
    }
    for (uint32_t seg = 0; seg < kSegments; ++seg) {
      const uint32_t a = base + 2 * seg;
      geometry->indices.insert(geometry->indices.end(), {a, a + 1, a + 2, a + 2, a + 1, a + 3});
    }
  };
  add_ring_pair(trunk_radius, -0.5f, trunk_radius, trunk_height, trunk_colour);
  add_ring_pair(crown_radius, trunk_height, 0.0f, height, crown_colour);
}

// The obstacles: a boulder as wide as each footprint, slightly squat, modelled at the origin.
void add_obstacle_boulders(const std::vector<Obstacle>& obstacles, SceneGeometry* geometry) {
  for (size_t i = 0; i < obstacles.size(); ++i) {
    const uint32_t first = static_cast<uint32_t>(geometry->indices.size());
    add_boulder(glm::vec3(0.0f), boulder_radii(obstacles[i]), i % 2 == 0 ? kGranite : kSandstone, 3.0f + static_cast<float>(i), geometry);
    geometry->obstacle_boulders.push_back({first, static_cast<uint32_t>(geometry->indices.size()) - first});
  }
}

}  // namespace

SceneVertex ground_vertex(const glm::vec3& position, const glm::vec3& normal, float above_water) {
  // Bare rock where the ground is steep and high on the hills; the rest by height, per fragment.
  const float rock = std::max(glm::clamp((0.85f - normal.y) * 4.0f, 0.0f, 1.0f),
                              glm::clamp((above_water - 14.0f) / 6.0f, 0.0f, 1.0f));
  return {position, normal, glm::vec4(0.0f, 0.0f, 0.0f, SIVIFLOW_GROUND_VERTEX),
          glm::vec2(above_water, rock)};
}

SceneLook default_scene_look() { return SceneLook{}; }

LodPiece object_piece(const SceneGeometry& geometry, uint32_t first_index, uint32_t index_count,
                      uint32_t material) {
  LodPiece piece;
  piece.lo = glm::vec3(std::numeric_limits<float>::max());
  piece.hi = glm::vec3(std::numeric_limits<float>::lowest());
  for (uint32_t i = first_index; i < first_index + index_count; ++i) {
    piece.lo = glm::min(piece.lo, geometry.vertices[geometry.indices[i]].position);
    piece.hi = glm::max(piece.hi, geometry.vertices[geometry.indices[i]].position);
  }
  piece.levels = {{first_index, index_count}};
  piece.material = material;
  return piece;
}

void append_geometry(SceneGeometry&& other, SceneGeometry* into) {
  const auto first_vertex = static_cast<uint32_t>(into->vertices.size());
  const auto first_index = static_cast<uint32_t>(into->indices.size());
  into->vertices.insert(into->vertices.end(), other.vertices.begin(), other.vertices.end());
  for (uint32_t index : other.indices) into->indices.push_back(first_vertex + index);
  const auto shifted = [first_index](IndexRange range) {
    range.first_index += first_index;
    return range;
  };
  for (LodPiece& piece : other.pieces) {
    for (IndexRange& level : piece.levels) level = shifted(level);
    for (auto& edges : piece.skirts) {
      for (IndexRange& skirt : edges) skirt = shifted(skirt);
    }
    into->pieces.push_back(std::move(piece));
  }
  for (const IndexRange& boulder : other.obstacle_boulders) {
    into->obstacle_boulders.push_back(shifted(boulder));
  }
}

SceneGeometry build_scene_geometry(const ProceduralRiver& river, const std::vector<Obstacle>& obstacles) {
  SceneGeometry geometry;
  add_terrain(river, &geometry);
  // Boulders on both banks, and trees: a piece each.
  // Each where the river leaves land for it, a metre from the water (a wider river, a
  // confluence's, may cover the spot); `offset` across the valley from the centreline at z, the
  // spot on_ground stands it on.
  const auto dry = [&](float offset, float z) {
    const float x = river.centreline_x(z) + offset;
    for (const glm::vec2 d : {glm::vec2(0, 0), glm::vec2(1, 0), glm::vec2(-1, 0), glm::vec2(0, 1), glm::vec2(0, -1)}) {
      if (river.depth_at(x + d.x, z + d.y) > 0.0f) return false;
    }
    return true;
  };
  auto first = static_cast<uint32_t>(geometry.indices.size());
  if (dry(-10.0f, -20.0f)) {
    add_boulder(on_ground(river, -10.0f, -20.0f) + glm::vec3(0, 0.6f, 0), {2.2f, 1.6f, 1.9f}, kGranite, 1.0f, &geometry);
    add_object_piece(first, &geometry);
  }
  first = static_cast<uint32_t>(geometry.indices.size());
  if (dry(11.0f, 12.0f)) {
    add_boulder(on_ground(river, 11.0f, 12.0f) + glm::vec3(0, 0.5f, 0), {1.6f, 1.2f, 1.5f}, kSandstone, 2.0f, &geometry);
    add_object_piece(first, &geometry);
  }
  for (int i = 0; i < 6; ++i) {
    const float z = -60.0f + 22.0f * static_cast<float>(i);
    const float offset = ((i % 2 == 0) ? -1.0f : 1.0f) * (13.0f + 3.0f * static_cast<float>(i % 3));
    if (!dry(offset, z)) continue;
    first = static_cast<uint32_t>(geometry.indices.size());
    add_tree(on_ground(river, offset, z), 7.0f + static_cast<float>(i % 3), &geometry);
    add_object_piece(first, &geometry);
  }
  add_obstacle_boulders(obstacles, &geometry);
  return geometry;
}

Status build_riverbed_geometry(const RiverMesh& river, const std::vector<Obstacle>& obstacles,
                              std::span<const RiverMesh> ground_rivers, SceneGeometry* out) {
  SceneGeometry geometry;
  std::vector<glm::vec3> normals(river.positions.size(), glm::vec3(0.0f));
  std::vector<glm::vec3> bed(river.positions.size());
  for (size_t v = 0; v < bed.size(); ++v) bed[v] = river.positions[v] - glm::vec3(0.0f, river.depth[v], 0.0f);
  for (size_t t = 0; t + 2 < river.indices.size(); t += 3) {
    const glm::vec3& a = bed[river.indices[t]];
    const glm::vec3 n = glm::cross(bed[river.indices[t + 1]] - a, bed[river.indices[t + 2]] - a);
    for (int k = 0; k < 3; ++k) normals[river.indices[t + k]] += n;  // area-weighted
  }
  for (size_t v = 0; v < bed.size(); ++v) {
    glm::vec3 n = glm::length(normals[v]) > 0.0f ? glm::normalize(normals[v]) : glm::vec3(0, 1, 0);
    if (n.y < 0.0f) n = -n;  // the file's winding may face down; the bed is lit from above
    geometry.vertices.push_back(ground_vertex(bed[v], n, -river.depth[v]));
  }
  geometry.indices = river.indices;
  add_object_piece(0, &geometry);  // the bed
  SIVIFLOW_TRY(add_ground_around_rivers(ground_rivers, &geometry));
  add_obstacle_boulders(obstacles, &geometry);
  *out = std::move(geometry);
  return Status::success();
}

Camera river_overview_camera(std::span<const glm::vec3> positions) {
  glm::vec3 lo = positions.front();
  glm::vec3 hi = lo;
  for (const glm::vec3& p : positions) {
    lo = glm::min(lo, p);
    hi = glm::max(hi, p);
  }
  const glm::vec3 centre = 0.5f * (lo + hi);
  const float extent = std::max(glm::length(hi - lo), 1.0f);
  Camera camera;
  camera.position = centre + glm::vec3(0.0f, 0.35f, -0.55f) * extent;
  camera.target = centre;
  camera.fov_y_deg = 55.0f;
  camera.near_plane = 0.1f;
  camera.far_plane = std::max(600.0f, 4.0f * extent);
  return camera;
}

Camera default_camera(const ProceduralRiver& river, double time_seconds) {
  // Glide downstream (+Z) above the water, looking ahead along the river.
  const float z = -55.0f + 2.0f * static_cast<float>(time_seconds);
  const float look_ahead = 30.0f;
  Camera camera;
  camera.position = {river.centreline_x(z) - 4.0f, 6.5f, z};
  camera.target = {river.centreline_x(z + look_ahead), 0.5f, z + look_ahead};
  camera.fov_y_deg = 55.0f;
  camera.near_plane = 0.1f;
  camera.far_plane = 600.0f;
  return camera;
}

}  // namespace siviflow
