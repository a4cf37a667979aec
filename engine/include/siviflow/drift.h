// Floating bodies carried by the water: leaves, crates, logs, a player's raft. Written on the
// query API alone (Renderer::query_water, or any function that answers the same way), so an
// engine could write it itself; it is here so that it need not.
//
//   std::vector<siviflow::FloatingBody> crates = ...;
//   auto ask = [&](std::span<const glm::vec3> p, std::span<siviflow::WaterSample> s) {
//     return water->query_water(p, s);
//   };
//   siviflow::drift_bodies(crates, frame_seconds, ask);  // once a frame, on any thread the
//                                                         // queries may run on
//
// Each body's velocity is pulled towards the water's at its centre at the rate `drag` (1/s), and
// its centre moves with that velocity, integrated with Heun's method (second order) in
// sub-steps of its own, short enough that it crosses no more than half its radius, nor more than
// 1/drag seconds, in one: a body drifts the same alone or beside others. A body stays on wet water: a step that would take its centre onto a bank or
// into an obstacle's footprint keeps only its part along the flow (banks and footprints are
// streamlines, so it slides along them), and the body's velocity loses what pointed out of the
// water. Each step ends with the centre on the water surface. Deterministic: the same bodies,
// step and water give the same result.
#pragma once

#include <functional>
#include <span>

#include <glm/vec3.hpp>

#include "siviflow/sim/water_sample.h"
#include "siviflow/status.h"

namespace siviflow {

struct FloatingBody {
  glm::vec3 position{0.0f};  // its centre, host world, metres: on the water surface after a step
  glm::vec3 velocity{0.0f};  // host world, m/s
  float radius = 0.5f;       // metres, > 0: sets how short the sub-steps are
  float drag = 2.0f;         // 1/s, >= 0: how fast it takes the water's velocity (0: it coasts)
  // Set by a step: its centre was not on wet water (off the river, or an obstacle was placed on
  // it), so it did not move.
  bool stranded = false;
};

// Answers like Renderer::query_water: one sample per point.
using WaterQueryFunction =
    std::function<Status(std::span<const glm::vec3> points, std::span<WaterSample> out)>;

// Advances every body by `dt_seconds` (> 0, finite). A body with a radius that is not positive
// and finite, a negative or non-finite drag, or a non-finite position or velocity is an error
// naming it (bodies[3].radius -1), and no body changes; so is a failing query.
Status drift_bodies(std::span<FloatingBody> bodies, float dt_seconds,
                    const WaterQueryFunction& query);

}  // namespace siviflow
