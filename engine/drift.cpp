// drift_bodies: floating bodies advanced through the water's flow by its point queries alone.
#include "siviflow/drift.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include <glm/geometric.hpp>

#include "siviflow/text_format.h"

namespace siviflow {
namespace {

constexpr int kMaxSubsteps = 256;      // a body crossing more in one call is slowed, not unstable
constexpr float kStepOfRadius = 0.5f;  // no sub-step takes a body further than this of its radius
constexpr float kStillSpeed = 1e-4f;   // m/s below which the water has no direction to slide along

bool finite(const glm::vec3& v) {
  return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

std::string vec_text(const glm::vec3& v) {
  return text_format("(%g, %g, %g)", double(v.x), double(v.y), double(v.z));
}

Status check_bodies(std::span<const FloatingBody> bodies, float dt_seconds) {
  if (!(std::isfinite(dt_seconds) && dt_seconds > 0.0f)) {
    return Status::error(text_format("drift_bodies: dt_seconds %g must be positive and finite",
                                     double(dt_seconds)));
  }
  for (size_t i = 0; i < bodies.size(); ++i) {
    const FloatingBody& b = bodies[i];
    if (!(std::isfinite(b.radius) && b.radius > 0.0f)) {
      return Status::error(text_format("drift_bodies: bodies[%zu].radius %g must be positive and finite",
                                       i, double(b.radius)));
    }
    if (!(std::isfinite(b.drag) && b.drag >= 0.0f)) {
      return Status::error(text_format("drift_bodies: bodies[%zu].drag %g must be finite and not negative",
                                       i, double(b.drag)));
    }
    if (!finite(b.position)) {
      return Status::error(text_format("drift_bodies: bodies[%zu].position %s is not finite", i,
                                       vec_text(b.position).c_str()));
    }
    if (!finite(b.velocity)) {
      return Status::error(text_format("drift_bodies: bodies[%zu].velocity %s is not finite", i,
                                       vec_text(b.velocity).c_str()));
    }
  }
  return Status::success();
}

Status ask(const WaterQueryFunction& query, const std::vector<glm::vec3>& points,
           std::vector<WaterSample>* samples) {
  samples->resize(points.size());
  const Status status = query(points, *samples);
  if (!status.ok()) return Status::error("drift_bodies: the water query failed: " + status.message());
  return Status::success();
}

}  // namespace

Status drift_bodies(std::span<FloatingBody> bodies, float dt_seconds,
                    const WaterQueryFunction& query) {
  SIVIFLOW_TRY(check_bodies(bodies, dt_seconds));
  // The bodies on wet water move; the rest are stranded where they are.
  std::vector<glm::vec3> x, v, points;
  std::vector<WaterSample> here;
  for (const FloatingBody& b : bodies) points.push_back(b.position);
  SIVIFLOW_TRY(ask(query, points, &here));
  std::vector<size_t> moving;
  for (size_t i = 0; i < bodies.size(); ++i) {
    if (here[i].wet) {
      moving.push_back(i);
      x.push_back(bodies[i].position);
      v.push_back(bodies[i].velocity);
    }
  }
  {
    std::vector<WaterSample> wet_here;
    for (size_t i : moving) wet_here.push_back(here[i]);
    here = std::move(wet_here);
  }
  // Each body's own sub-steps, short enough for its speed against its radius and for its drag,
  // so that no body's path depends on the others it is drifted with. Sub-step `step` advances
  // the bodies that take that many; their queries go together.
  std::vector<int> steps(moving.size(), 1);
  std::vector<float> h(moving.size());
  int most_steps = 1;
  for (size_t k = 0; k < moving.size(); ++k) {
    const FloatingBody& b = bodies[moving[k]];
    const float speed = std::max(glm::length(v[k]), glm::length(here[k].velocity));
    const float by_distance = std::ceil(speed * dt_seconds / (kStepOfRadius * b.radius));
    const float by_drag = std::ceil(b.drag * dt_seconds);
    steps[k] = static_cast<int>(std::min(std::max({by_distance, by_drag, 1.0f}), float(kMaxSubsteps)));
    h[k] = dt_seconds / static_cast<float>(steps[k]);
    most_steps = std::max(most_steps, steps[k]);
  }
  std::vector<size_t> active;  // indices into `moving` that take this sub-step
  std::vector<glm::vec3> dx1(moving.size()), dv1(moving.size());
  std::vector<WaterSample> there_active;
  for (int step = 0; step < most_steps; ++step) {
    active.clear();
    for (size_t k = 0; k < moving.size(); ++k) {
      if (step < steps[k]) active.push_back(k);
    }
    // Heun: the slope here, a full Euler step, the slope there, and the mean of the two.
    points.clear();
    for (size_t k : active) {
      const float drag = bodies[moving[k]].drag;
      dx1[k] = v[k];
      dv1[k] = drag * (here[k].velocity - v[k]);
      points.push_back(x[k] + h[k] * dx1[k]);
    }
    SIVIFLOW_TRY(ask(query, points, &there_active));
    for (size_t j = 0; j < active.size(); ++j) {
      const size_t k = active[j];
      const float drag = bodies[moving[k]].drag;
      const glm::vec3 vp = v[k] + h[k] * dv1[k];
      // Off the water the flow is unknown: the water of the step's start stands in.
      const glm::vec3 u = there_active[j].wet ? there_active[j].velocity : here[k].velocity;
      points[j] = x[k] + 0.5f * h[k] * (dx1[k] + vp);
      v[k] += 0.5f * h[k] * (dv1[k] + drag * (u - vp));
    }
    // Kept on wet water: a step onto a bank or into a footprint keeps only its part along the
    // flow where it started, and failing that the body waits where it is.
    SIVIFLOW_TRY(ask(query, points, &there_active));
    std::vector<size_t> blocked;  // indices into `active`
    for (size_t j = 0; j < active.size(); ++j) {
      if (!there_active[j].wet) blocked.push_back(j);
    }
    if (!blocked.empty()) {
      std::vector<glm::vec3> slid;
      std::vector<WaterSample> slid_samples;
      for (size_t j : blocked) {
        const size_t k = active[j];
        const glm::vec3 u = here[k].velocity;
        const float speed = glm::length(u);
        const glm::vec3 along = speed > kStillSpeed ? u / speed : glm::vec3(0.0f);
        slid.push_back(x[k] + glm::dot(points[j] - x[k], along) * along);
        v[k] = glm::dot(v[k], along) * along;
      }
      SIVIFLOW_TRY(ask(query, slid, &slid_samples));
      for (size_t i = 0; i < blocked.size(); ++i) {
        const size_t j = blocked[i];
        if (slid_samples[i].wet) {
          points[j] = slid[i];
          there_active[j] = slid_samples[i];
        } else {
          points[j] = x[active[j]];
          there_active[j] = here[active[j]];
        }
      }
    }
    for (size_t j = 0; j < active.size(); ++j) {  // settled on the surface
      const size_t k = active[j];
      x[k] = there_active[j].surface;
      here[k] = there_active[j];
    }
  }
  for (size_t i = 0; i < bodies.size(); ++i) bodies[i].stranded = true;
  for (size_t k = 0; k < moving.size(); ++k) {
    FloatingBody& b = bodies[moving[k]];
    b.position = x[k];
    b.velocity = v[k];
    b.stranded = false;
  }
  return Status::success();
}

}  // namespace siviflow
