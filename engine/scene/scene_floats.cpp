#include "siviflow/scene_floats.h"

#include <cmath>
#include <string>
#include <utility>

#include "siviflow/text_format.h"

namespace siviflow {
namespace {

constexpr float kHeadingSpeed = 0.02f;  // m/s: slower, a float keeps the heading it had

// What is wrong with a float's own numbers ("radius -1 must be ..."), or "".
std::string float_problem(const SceneFloat& f) {
  if (!(std::isfinite(f.radius) && f.radius > 0.0f && f.radius <= kMaxFloatRadius)) {
    return text_format("radius %g must be in (0, %g] metres", double(f.radius), double(kMaxFloatRadius));
  }
  if (!(std::isfinite(f.drag) && f.drag >= 0.0f)) {
    return text_format("drag %g must be finite and not negative", double(f.drag));
  }
  if (!(std::isfinite(f.release_time) && f.release_time >= 0.0)) {
    return text_format("release_time %g must be finite and not negative", f.release_time);
  }
  return "";
}

}  // namespace

Status SceneFloats::create(const SceneFile& scene, std::vector<WaterQueryFunction> rivers,
                           SceneFloats* out) {
  if (out == nullptr) return Status::error("SceneFloats::create: out is null");
  SceneFloats made;
  made.rivers_ = std::move(rivers);
  // The rivers' own obstacles as the scene file names them: its obstacles, then its objects
  // marked obstacle (scene_river.h).
  for (size_t i = 0; i < scene.obstacles.size(); ++i) {
    made.obstacle_names_.push_back(text_format("obstacles[%zu]", i));
  }
  for (size_t i = 0; i < scene.objects.size(); ++i) {
    if (scene.objects[i].obstacle) made.obstacle_names_.push_back(text_format("objects[%zu]", i));
  }
  for (size_t i = 0; i < scene.floats.size(); ++i) {
    Float f;
    f.spec = scene.floats[i];
    const std::string problem = float_problem(f.spec);
    if (!problem.empty()) {
      return Status::error(text_format("%s: floats[%zu]: ", scene.path.c_str(), i) + problem);
    }
    const Status found = made.river_of(f.spec.release_point, &f.river);
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

Status SceneFloats::river_of(glm::vec2 point, uint32_t* river) const {
  const glm::vec3 at(point.x, 0.0f, point.y);
  for (uint32_t r = 0; r < rivers_.size(); ++r) {
    WaterSample sample;
    SIVIFLOW_TRY(rivers_[r](std::span(&at, 1), std::span(&sample, 1)));
    if (!sample.on_surface) continue;
    if (!sample.wet) {
      const uint32_t id = sample.obstacle;
      const size_t index = id - WaterSample::kRiverObstacle;
      const std::string which = id < WaterSample::kRiverObstacle ? text_format("obstacle %u", id)
                                : index < obstacle_names_.size() ? obstacle_names_[index]
                                                                 : text_format("obstacle %zu", index);
      return Status::error(text_format("(%g, %g) is inside ", double(point.x), double(point.y)) +
                           which + "'s footprint, not on the water");
    }
    *river = r;
    return Status::success();
  }
  return Status::error(text_format("(%g, %g) is not on any river", double(point.x), double(point.y)));
}

// At rest on the surface at its release point, turned along the flow there.
Status SceneFloats::release(Float* f, float* heading) const {
  WaterSample sample;
  const glm::vec3 at(f->spec.release_point.x, 0.0f, f->spec.release_point.y);
  SIVIFLOW_TRY(rivers_[f->river](std::span(&at, 1), std::span(&sample, 1)));
  f->body.position = sample.on_surface ? sample.surface : at;
  f->body.velocity = glm::vec3(0.0f);
  f->body.radius = f->spec.radius;
  f->body.drag = f->spec.drag;
  f->released = true;
  *heading = std::atan2(sample.velocity.z, sample.velocity.x);
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

Status SceneFloats::drift(size_t i, double seconds) {
  const Status drifted =
      drift_bodies(std::span(&floats_[i].body, 1), static_cast<float>(seconds), rivers_[floats_[i].river]);
  if (!drifted.ok()) return Status::error(text_format("floats[%zu]: ", i) + drifted.message());
  return Status::success();
}

Status SceneFloats::advance(double time_seconds) {
  if (!(time_seconds >= time_)) {
    return Status::error(text_format("SceneFloats::advance: time %g is before the current %g",
                                     time_seconds, time_));
  }
  // Those afloat already drift the whole step; each one released within it, the part after its
  // release. One at a time: drift_bodies is per body anyway, and an error names the float.
  const double step = time_seconds - time_;
  for (size_t i = 0; i < floats_.size(); ++i) {
    if (floats_[i].released && step > 0.0) SIVIFLOW_TRY(drift(i, step));
  }
  for (size_t i = 0; i < floats_.size(); ++i) {
    Float& f = floats_[i];
    if (f.released || f.spec.release_time > time_seconds) continue;
    SIVIFLOW_TRY(release(&f, &poses_[i].heading));
    const double afloat = time_seconds - std::max(f.spec.release_time, time_);
    if (afloat > 0.0) SIVIFLOW_TRY(drift(i, afloat));
  }
  for (size_t i = 0; i < floats_.size(); ++i) update_pose(i);
  time_ = time_seconds;
  return Status::success();
}

Status SceneFloats::drop(const SceneFloat& spec) {
  Float f;
  f.spec = spec;
  f.spec.release_time = time_;
  const std::string problem = float_problem(f.spec);
  if (!problem.empty()) return Status::error("SceneFloats::drop: " + problem);
  SIVIFLOW_TRY(river_of(spec.release_point, &f.river));
  FloatPose pose;
  SIVIFLOW_TRY(release(&f, &pose.heading));  // nothing added until it is afloat
  floats_.push_back(f);
  poses_.push_back(pose);
  update_pose(floats_.size() - 1);
  return Status::success();
}

}  // namespace siviflow
