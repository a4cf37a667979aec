#include "view/float_control.h"

#include <numeric>
#include <string>
#include <vector>

namespace siviflow::view {

Status FloatControl::init(const SceneFile* scene, std::span<Renderer* const> renderers, World* world) {
  world_ = world;
  std::vector<WaterQueryFunction> queries;
  for (Renderer* river : renderers) {
    queries.push_back([river](std::span<const glm::vec3> p, std::span<WaterSample> s) {
      return river->query_water(p, s);
    });
  }
  const SceneFile none;
  SIVIFLOW_TRY(SceneFloats::create(scene != nullptr ? *scene : none, std::move(queries), &floats_));
  scene_floats_ = static_cast<uint32_t>(floats_.poses().size());
  world_index_.resize(scene_floats_);
  std::iota(world_index_.begin(), world_index_.end(), 0u);
  return Status::success();
}

Status FloatControl::drop_at(const glm::vec3& point) {
  // A log, then a leaf, in turn.
  const bool log = logs_dropped_ <= leaves_dropped_;
  uint32_t& dropped = log ? logs_dropped_ : leaves_dropped_;
  const uint32_t spares = log ? kSpareLogs : kSpareLeaves;
  if (dropped == spares) {
    return Status::error("all " + std::to_string(spares) + (log ? " logs" : " leaves") +
                         " are afloat already");
  }
  SceneFloat f = scene_float_defaults(log ? FloatMesh::kLog : FloatMesh::kLeaf);
  f.release_point = {point.x, point.z};
  SIVIFLOW_TRY(floats_.drop(f));
  world_index_.push_back(scene_floats_ + (log ? 0 : kSpareLogs) + dropped);
  ++dropped;
  return Status::success();
}

Status FloatControl::step(double time_seconds) {
  if (time_seconds > floats_.time()) SIVIFLOW_TRY(floats_.advance(time_seconds));
  const std::span<const FloatPose> poses = floats_.poses();
  for (size_t i = 0; i < poses.size(); ++i) {
    if (poses[i].shown) {
      SIVIFLOW_TRY(world_->place_float(world_index_[i], poses[i].centre, poses[i].heading));
    } else {
      SIVIFLOW_TRY(world_->hide_float(world_index_[i]));
    }
  }
  return Status::success();
}

}  // namespace siviflow::view
