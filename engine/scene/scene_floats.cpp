#include "siviflow/scene_floats.h"

#include <cmath>
#include <string>
#include <utility>

#include "siviflow/text_format.h"

namespace siviflow {
namespace {

constexpr float kHeadingSpeed = 0.02f;  // m/s: slower, a float keeps the heading it had

}  // namespace

Status SceneFloats::create(const SceneFile& scene, std::vector<WaterQueryFunction> rivers,
                           SceneFloats* out) {
  if (out == nullptr) return Status::error("SceneFloats::create: out is null");
  SceneFloats made;
  made.rivers_ = std::move(rivers);
  for (size_t i = 0; i < scene.floats.size(); ++i) {
    Float f;
    f.spec = scene.floats[i];
    WaterSample sample;
    const Status found = made.river_of(f.spec.release_point, &f.river, &sample);
    if (!found.ok()) {
      return Status::error(text_format("%s: floats[%zu].release_point: ", scene.path.c_str(), i) +
                           found.message());
    }
    made.floats_.push_back(f);
  }
  made.poses_.resize(made.floats_.size());
  SIVIFLOW_TRY(made.advance(0.0));
  *out = std::move(made);
  return Status::success();
}

Status SceneFloats::river_of(glm::vec2 point, uint32_t* river, WaterSample* sample) const {
  const glm::vec3 at(point.x, 0.0f, point.y);
  for (uint32_t r = 0; r < rivers_.size(); ++r) {
    SIVIFLOW_TRY(rivers_[r](std::span(&at, 1), std::span(sample, 1)));
    if (!sample->on_surface) continue;
    if (!sample->wet) {
      const uint32_t id = sample->obstacle;
      const std::string which =
          id >= WaterSample::kRiverObstacle
              ? text_format("obstacles[%u]'s", id - WaterSample::kRiverObstacle)
              : text_format("obstacle %u's", id);
      return Status::error(text_format("(%g, %g) is inside ", double(point.x), double(point.y)) +
                           which + " footprint, not on the water");
    }
    *river = r;
    return Status::success();
  }
  return Status::error(text_format("(%g, %g) is not on any river", double(point.x), double(point.y)));
}

// At rest on the surface at its release point, along the flow there.
Status SceneFloats::release(Float* f) {
  WaterSample sample;
  const glm::vec3 at(f->spec.release_point.x, 0.0f, f->spec.release_point.y);
  SIVIFLOW_TRY(rivers_[f->river](std::span(&at, 1), std::span(&sample, 1)));
  f->body.position = sample.on_surface ? sample.surface : at;
  f->body.velocity = glm::vec3(0.0f);
  f->body.radius = f->spec.radius;
  f->body.drag = f->spec.drag;
  f->released = true;
  const size_t i = static_cast<size_t>(f - floats_.data());
  poses_[i].heading = std::atan2(sample.velocity.z, sample.velocity.x);
  return Status::success();
}

void SceneFloats::update_pose(size_t i) {
  const FloatingBody& body = floats_[i].body;
  FloatPose& pose = poses_[i];
  pose.shown = floats_[i].released;
  pose.centre = body.position;
  pose.velocity = body.velocity;
  if (glm::length(glm::vec2(body.velocity.x, body.velocity.z)) > kHeadingSpeed) {
    pose.heading = std::atan2(body.velocity.z, body.velocity.x);
  }
}

Status SceneFloats::advance(double time_seconds) {
  if (!(time_seconds >= time_)) {
    return Status::error(text_format("SceneFloats::advance: time %g is before the current %g",
                                     time_seconds, time_));
  }
  const double step = time_seconds - time_;
  // Those afloat already, one drift per river; then each one released within the step, for the
  // part of it after its release.
  for (uint32_t r = 0; r < rivers_.size(); ++r) {
    std::vector<FloatingBody> bodies;
    std::vector<size_t> which;
    for (size_t i = 0; i < floats_.size(); ++i) {
      if (floats_[i].released && floats_[i].river == r) {
        bodies.push_back(floats_[i].body);
        which.push_back(i);
      }
    }
    if (bodies.empty() || step <= 0.0) continue;
    SIVIFLOW_TRY(drift_bodies(bodies, static_cast<float>(step), rivers_[r]));
    for (size_t k = 0; k < which.size(); ++k) floats_[which[k]].body = bodies[k];
  }
  for (size_t i = 0; i < floats_.size(); ++i) {
    Float& f = floats_[i];
    if (f.released || f.spec.release_time > time_seconds) continue;
    SIVIFLOW_TRY(release(&f));
    const double afloat = time_seconds - std::max(f.spec.release_time, time_);
    if (afloat > 0.0) {
      SIVIFLOW_TRY(drift_bodies(std::span(&f.body, 1), static_cast<float>(afloat), rivers_[f.river]));
    }
  }
  for (size_t i = 0; i < floats_.size(); ++i) update_pose(i);
  time_ = time_seconds;
  return Status::success();
}

Status SceneFloats::drop(const SceneFloat& spec) {
  if (!(std::isfinite(spec.radius) && spec.radius > 0.0f) || !(std::isfinite(spec.drag) && spec.drag >= 0.0f)) {
    return Status::error(text_format("SceneFloats::drop: radius %g must be positive and drag %g "
                                     "not negative, both finite",
                                     double(spec.radius), double(spec.drag)));
  }
  Float f;
  f.spec = spec;
  f.spec.release_time = time_;
  WaterSample sample;
  SIVIFLOW_TRY(river_of(spec.release_point, &f.river, &sample));
  floats_.push_back(f);
  poses_.emplace_back();
  SIVIFLOW_TRY(release(&floats_.back()));
  update_pose(floats_.size() - 1);
  return Status::success();
}

}  // namespace siviflow
