#include "view/obstacle_control.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <glm/geometric.hpp>

#include "default_river.h"

namespace siviflow::view {
namespace {

// A click this much beyond an obstacle's outline still picks it: boulders stand above the water.
constexpr float kPickSlack = 1.25f;
constexpr float kProbeHeight = 1000.0f;  // a vertical ray from this high finds the water below

// Distance along `ray` to triangle (a, b, c) (Moller-Trumbore), or a negative number.
float ray_triangle(const Ray& ray, glm::vec3 a, glm::vec3 b, glm::vec3 c) {
  const glm::vec3 e1 = b - a;
  const glm::vec3 e2 = c - a;
  const glm::vec3 p = glm::cross(ray.direction, e2);
  const float det = glm::dot(e1, p);
  if (std::abs(det) < 1e-12f) return -1.0f;
  const float inv = 1.0f / det;
  const glm::vec3 s = ray.origin - a;
  const float u = glm::dot(s, p) * inv;
  if (u < 0.0f || u > 1.0f) return -1.0f;
  const glm::vec3 q = glm::cross(s, e1);
  const float v = glm::dot(ray.direction, q) * inv;
  if (v < 0.0f || u + v > 1.0f) return -1.0f;
  return glm::dot(e2, q) * inv;
}

float outline_radius(const WaterObstacle& obstacle) {
  float radius = obstacle.radius;
  for (const glm::vec2& corner : obstacle.polygon) radius = std::max(radius, glm::length(corner));
  return radius;
}

}  // namespace

Status ObstacleControl::init(std::span<const SceneRiverData> rivers, size_t scene_obstacles,
                             std::span<Renderer* const> renderers, World* world) {
  world_ = world;
  renderers_.assign(renderers.begin(), renderers.end());
  for (const SceneRiverData& river : rivers) meshes_.push_back(&river.mesh);
  for (size_t i = 0; i < scene_obstacles; ++i) {
    Entry entry;
    entry.obstacle = rivers.front().obstacles[i];
    entry.boulder = static_cast<uint32_t>(i);
    SIVIFLOW_TRY(add_to_renderers(&entry));
    entries_.push_back(std::move(entry));
  }
  for (uint32_t i = 0; i < kSpareBoulders; ++i) {
    Entry spare;
    spare.obstacle.radius = kSpareBoulderRadius;
    spare.obstacle.height = kBoulderHeightRatio * kSpareBoulderRadius;  // as the world draws it
    spare.boulder = static_cast<uint32_t>(scene_obstacles) + i;
    spare.active = false;
    entries_.push_back(std::move(spare));
  }
  return Status::success();
}

Status ObstacleControl::add_to_renderers(Entry* entry) {
  entry->ids.clear();
  for (Renderer* renderer : renderers_) {
    uint32_t id = 0;
    SIVIFLOW_TRY(renderer->add_obstacle(entry->obstacle, &id));
    entry->ids.push_back(id);
  }
  entry->active = true;
  return Status::success();
}

Status ObstacleControl::remove_from_renderers(Entry* entry) {
  for (size_t r = 0; r < renderers_.size() && r < entry->ids.size(); ++r) {
    SIVIFLOW_TRY(renderers_[r]->remove_obstacle(entry->ids[r]));
  }
  entry->ids.clear();
  entry->active = false;
  return Status::success();
}

std::optional<glm::vec3> ObstacleControl::hit_water(const Ray& ray) const {
  float nearest = std::numeric_limits<float>::infinity();
  for (const RiverMesh* mesh : meshes_) {
    const std::vector<glm::vec3>& p = mesh->positions;
    for (size_t t = 0; t + 2 < mesh->indices.size(); t += 3) {
      const float d = ray_triangle(ray, p[mesh->indices[t]], p[mesh->indices[t + 1]],
                                   p[mesh->indices[t + 2]]);
      if (d > 0.0f && d < nearest) nearest = d;
    }
  }
  if (!std::isfinite(nearest)) return std::nullopt;
  return ray.origin + nearest * ray.direction;
}

glm::vec3 ObstacleControl::centre_at(const Entry& entry, double time_seconds) const {
  const std::vector<WaterObstacleKey>& keys = entry.obstacle.keys;
  if (keys.empty()) return entry.obstacle.centre;
  // Linear between keys, held before the first and after the last, as the renderer moves it.
  if (time_seconds <= keys.front().t) return keys.front().centre;
  if (time_seconds >= keys.back().t) return keys.back().centre;
  const auto after = std::upper_bound(
      keys.begin(), keys.end(), time_seconds,
      [](double t, const WaterObstacleKey& key) { return t < key.t; });
  const WaterObstacleKey& a = *(after - 1);
  const float u = static_cast<float>((time_seconds - a.t) / (after->t - a.t));
  return glm::mix(a.centre, after->centre, u);
}

std::optional<size_t> ObstacleControl::entry_under(const Ray& ray, double time_seconds) const {
  // The boulder stands on the water: the ray passes near its centre at the water's height.
  std::optional<size_t> best;
  float best_distance = std::numeric_limits<float>::infinity();
  for (size_t i = 0; i < entries_.size(); ++i) {
    if (!entries_[i].active) continue;
    glm::vec3 c = centre_at(entries_[i], time_seconds);
    const std::optional<glm::vec3> below =
        hit_water({c + glm::vec3(0.0f, kProbeHeight, 0.0f), glm::vec3(0.0f, -1.0f, 0.0f)});
    if (below) c.y = below->y;
    const float along = glm::dot(c - ray.origin, ray.direction);
    if (along <= 0.0f) continue;
    const float d = glm::length(ray.origin + along * ray.direction - c);
    if (d <= kPickSlack * outline_radius(entries_[i].obstacle) && d < best_distance) {
      best = i;
      best_distance = d;
    }
  }
  return best;
}

bool ObstacleControl::begin_drag(const Ray& ray, double time_seconds) {
  dragged_ = entry_under(ray, time_seconds);
  if (!dragged_) return false;
  Entry& entry = entries_[*dragged_];
  if (!entry.obstacle.keys.empty()) {
    // Dragged, it stays where the user puts it: the renderers take it again without its keys.
    entry.obstacle.centre = centre_at(entry, time_seconds);
    entry.obstacle.keys.clear();
    if (!remove_from_renderers(&entry).ok() || !add_to_renderers(&entry).ok() ||
        !world_->place_boulder(entry.boulder, entry.obstacle.centre).ok()) {
      dragged_.reset();
      return false;
    }
  }
  return true;
}

Status ObstacleControl::drag_to(const Ray& ray) {
  if (!dragged_) return Status::success();
  const std::optional<glm::vec3> hit = hit_water(ray);
  if (!hit) return Status::success();  // off the water: it stays where it was
  Entry& entry = entries_[*dragged_];
  // Across the water only: its boulder keeps the height it was modelled at.
  const glm::vec3 centre(hit->x, entry.obstacle.centre.y, hit->z);
  for (size_t r = 0; r < renderers_.size(); ++r) {
    SIVIFLOW_TRY(renderers_[r]->move_obstacle(entry.ids[r], centre, entry.obstacle.rotation_rad));
  }
  entry.obstacle.centre = centre;
  return world_->place_boulder(entry.boulder, centre);
}

Status ObstacleControl::add_at(const Ray& ray) {
  const std::optional<glm::vec3> hit = hit_water(ray);
  if (!hit) return Status::error("add a boulder: the cursor is not over the water");
  const auto spare = std::find_if(entries_.begin(), entries_.end(),
                                  [](const Entry& e) { return !e.active; });
  if (spare == entries_.end()) return Status::error("add a boulder: every boulder is in use");
  spare->obstacle.centre = *hit;
  SIVIFLOW_TRY(add_to_renderers(&*spare));
  return world_->place_boulder(spare->boulder, *hit);
}

Status ObstacleControl::remove_at(const Ray& ray, double time_seconds, bool* removed) {
  *removed = false;
  const std::optional<size_t> under = entry_under(ray, time_seconds);
  if (!under) return Status::success();
  Entry& entry = entries_[*under];
  SIVIFLOW_TRY(remove_from_renderers(&entry));
  if (dragged_ == under) dragged_.reset();
  *removed = true;
  return world_->hide_boulder(entry.boulder);
}

std::vector<ObstacleControl::Placed> ObstacleControl::placed(double time_seconds) const {
  std::vector<Placed> out;
  for (const Entry& entry : entries_) {
    if (entry.active) out.push_back({centre_at(entry, time_seconds), outline_radius(entry.obstacle)});
  }
  return out;
}

}  // namespace siviflow::view
