// The floats of the viewer: the scene file's, replayed by a capture's code, and the ones the
// user drops under the cursor (F key: a log, then a leaf, in turn, from the world's spares).
// Each frame, once the water is updated for its time, they drift on to it and the world draws
// them where they are.
#pragma once

#include <cstdint>
#include <span>

#include <glm/vec3.hpp>

#include "siviflow/renderer.h"
#include "siviflow/scene_floats.h"
#include "siviflow/world.h"

namespace siviflow::view {

// Floats the user can drop, of each mesh (the world builds them up front).
inline constexpr uint32_t kSpareLogs = 12;
inline constexpr uint32_t kSpareLeaves = 12;

class FloatControl {
 public:
  // `scene`: null for the built-in default scene (no floats of its own). `world` was created with
  // kSpareLogs and kSpareLeaves.
  Status init(const SceneFile* scene, std::span<Renderer* const> renderers, World* world);
  // Drops the next spare float at `point` on the water, now; an error when it is off the water
  // or every spare of its mesh is afloat.
  Status drop_at(const glm::vec3& point);
  // Drifts every float on to `time_seconds` (held when time stands still or goes back) and
  // stands them in the world.
  Status step(double time_seconds);
  std::span<const FloatPose> poses() const { return floats_.poses(); }

 private:
  SceneFloats floats_;
  World* world_ = nullptr;
  std::vector<uint32_t> world_index_;  // per pose: the world's float that draws it
  uint32_t scene_floats_ = 0;
  uint32_t logs_dropped_ = 0;
  uint32_t leaves_dropped_ = 0;
};

}  // namespace siviflow::view
