// The floats of a scene file (SceneFile::floats) replayed through the water's flow, the same way
// by every host that shows the scene: a capture, whatever frames it renders, and the viewer.
//
//   SceneFloats floats;
//   SceneFloats::create(scene, {one query per river, in the scene's order}, &floats);
//   per frame at time t, once the water is updated for t:
//     draw floats.poses();           // where they are at t
//     floats.advance(t_next);        // released and drifted through the water as it is at t
//
// Each float is released at its release time on the water surface at its release point, at
// rest, turned along the flow there, and from then on drifted (siviflow/drift.h) with its radius
// and drag through the river its release point lies on. Deterministic: the same scene, queries
// and times give the same poses, so a capture that starts at frame A replays frames 0..A-1 first.
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include <glm/vec3.hpp>

#include "siviflow/drift.h"
#include "siviflow/scene_file.h"
#include "siviflow/status.h"

namespace siviflow {

struct FloatPose {
  bool shown = false;        // released
  glm::vec3 centre{0.0f};    // on the water surface, metres
  float heading = 0.0f;      // radians: its length along (cos, 0, sin), where it drifts
  glm::vec3 velocity{0.0f};  // m/s
};

class SceneFloats {
 public:
  // Checks every float (radius, drag, release time) and its release point against the rivers (an
  // error names the scene file, the float and the point: "scene.json: floats[2].release_point:
  // (40, 3) is not on any river", or the footprint that holds it) and releases the floats due at
  // time 0.
  static Status create(const SceneFile& scene, std::vector<WaterQueryFunction> rivers,
                       SceneFloats* out);

  // Moves on to `time_seconds` (not before the current time): releases the floats due by then
  // and drifts the others from the current time, through the water as its queries answer now.
  Status advance(double time_seconds);

  // Releases one more float now, at `release_point` (a host dropping it; its release time is
  // ignored): an error, and nothing added, where the point is not on the water or the float's
  // numbers are out of range.
  Status drop(const SceneFloat& f);

  double time() const { return time_; }
  // One per float: the scene's, then the dropped ones.
  std::span<const FloatPose> poses() const { return poses_; }

 private:
  struct Float {
    SceneFloat spec;
    uint32_t river = 0;
    bool released = false;
    FloatingBody body;
  };
  // The river whose water (outside every footprint) holds `point`; an error naming why not.
  Status river_of(glm::vec2 point, uint32_t* river) const;
  Status release(Float* f, float* heading) const;
  Status drift(size_t i, double seconds);
  void update_pose(size_t i);

  std::vector<WaterQueryFunction> rivers_;
  std::vector<std::string> obstacle_names_;  // the rivers' own obstacles, as the scene names them
  std::vector<Float> floats_;
  std::vector<FloatPose> poses_;
  double time_ = 0.0;
};

}  // namespace siviflow
