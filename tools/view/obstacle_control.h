// The obstacles the viewer lets a user drag, add and remove: each scene obstacle of every river
// (handed to the renderers as runtime obstacles, so they can move) and boulders added under the
// cursor. A pixel becomes a ray cast onto the rivers' water surfaces; moving an obstacle moves
// it in every river's renderer (the flow re-routes from the next update) and its boulder in the
// world.
#pragma once

#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include <glm/vec3.hpp>

#include "siviflow/renderer.h"
#include "siviflow/scene_river.h"
#include "siviflow/world.h"
#include "view/fly_camera.h"

namespace siviflow::view {

// Boulders the user can add beyond the scene's (the world builds them up front).
inline constexpr uint32_t kSpareBoulders = 8;
inline constexpr float kSpareBoulderRadius = 1.5f;

class ObstacleControl {
 public:
  // `rivers`: the scene's rivers, whose first `scene_obstacles` obstacles are the scene's
  // (world boulders 0 .. scene_obstacles - 1): the caller removed those from the rivers it
  // created the renderers with; they are added here as runtime obstacles.
  Status init(std::span<const SceneRiverData> rivers, size_t scene_obstacles,
              std::span<Renderer* const> renderers, World* world);

  // Where `ray` meets the water surface of any river, or nothing.
  std::optional<glm::vec3> hit_water(const Ray& ray) const;

  // The obstacle under `ray` becomes the dragged one; false when there is none.
  bool begin_drag(const Ray& ray, double time_seconds);
  // Moves the dragged obstacle to where `ray` meets the water (nothing when it misses).
  Status drag_to(const Ray& ray);
  void end_drag() { dragged_.reset(); }
  bool dragging() const { return dragged_.has_value(); }
  // A boulder of kSpareBoulderRadius where `ray` meets the water; an error when it misses or
  // every spare is in use.
  Status add_at(const Ray& ray);
  // Removes the obstacle under `ray`; false when there is none.
  Status remove_at(const Ray& ray, double time_seconds, bool* removed);

  struct Placed {
    glm::vec3 centre;
    float radius;  // of the circle, or the polygon's farthest corner
  };
  // The obstacles now in the water, at `time_seconds` (keys still move the undragged ones).
  std::vector<Placed> placed(double time_seconds) const;

 private:
  struct Entry {
    WaterObstacle obstacle;
    std::vector<uint32_t> ids;  // per renderer
    uint32_t boulder = 0;       // the world's
    bool active = true;
  };
  glm::vec3 centre_at(const Entry& entry, double time_seconds) const;
  std::optional<size_t> entry_under(const Ray& ray, double time_seconds) const;
  Status add_to_renderers(Entry* entry);
  Status remove_from_renderers(Entry* entry);

  std::vector<const RiverMesh*> meshes_;
  std::vector<Renderer*> renderers_;
  World* world_ = nullptr;
  std::vector<Entry> entries_;
  std::optional<size_t> dragged_;
};

}  // namespace siviflow::view
