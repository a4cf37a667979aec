// What a host changes on a running renderer: obstacles placed at runtime, the geometry that
// hides the water, the water's look and its debug view.
#include <cmath>
#include <span>
#include <string>
#include <vector>

#include "renderer_impl.h"
#include "siviflow/text_format.h"

namespace siviflow {
namespace {

// The host's obstacle checked as the flow would check it, named by `id`.
Status check_obstacle(const char* call, const WaterObstacle& placed, uint32_t id) {
  const Status valid = check_obstacle(placed, id);
  if (!valid.ok()) return argument_error(std::string(call) + ": " + valid.message());
  return Status::success();
}

}  // namespace

size_t Renderer::Impl::runtime_obstacle_index(uint32_t id) const {
  const auto& placed = river->runtime_obstacles;
  for (size_t i = 0; i < placed.size(); ++i) {
    if (placed[i].id == id) return i;
  }
  return placed.size();
}

Status Renderer::add_obstacle(const WaterObstacle& obstacle, uint32_t* id) {
  return guarded(impl_->info, [&] { return impl_->add_obstacle(obstacle, id); });
}

Status Renderer::move_obstacle(uint32_t id, const glm::vec3& centre, float rotation_rad) {
  return guarded(impl_->info, [&] { return impl_->move_obstacle(id, centre, rotation_rad); });
}

Status Renderer::remove_obstacle(uint32_t id) {
  return guarded(impl_->info, [&] { return impl_->remove_obstacle(id); });
}

Status Renderer::set_occluders(const OccluderMesh& mesh) {
  return guarded(impl_->info, [&] { return impl_->set_occluders(mesh); });
}

Status Renderer::set_look(const WaterLook& look) {
  return guarded(impl_->info, [&] { return impl_->set_look(look); });
}

Status Renderer::Impl::set_occluders(const OccluderMesh& mesh) {
  if (frame_begun) return argument_error("set_occluders called between begin_frame and record");
  // The host's world into river space, where the flow and the particles live.
  std::vector<glm::vec3> in_river;
  std::span<const glm::vec3> positions = mesh.positions;
  if (info.world_from_river != glm::mat4(1.0f)) {
    in_river.reserve(positions.size());
    for (const glm::vec3& p : positions) {
      in_river.push_back(glm::vec3(river_from_world * glm::vec4(p, 1.0f)));
    }
    positions = in_river;
  }
  const Status built = river->flow.set_occluders(positions, mesh.indices);
  if (!built.ok()) return argument_error("set_occluders: " + built.message());
  return Status::success();
}

Status Renderer::Impl::add_obstacle(const WaterObstacle& obstacle, uint32_t* id) {
  if (frame_begun) return argument_error("add_obstacle called between begin_frame and record");
  if (id == nullptr) return argument_error("add_obstacle: id must not be null");
  const uint32_t new_id = river->next_obstacle_id;
  SIVIFLOW_TRY(check_obstacle("add_obstacle", obstacle, new_id));
  SIVIFLOW_TRY(river->flow.add_obstacle(flow_obstacle(obstacle)));
  river->runtime_obstacles.push_back({new_id, obstacle});
  ++river->next_obstacle_id;
  *id = new_id;
  return Status::success();
}

Status Renderer::Impl::move_obstacle(uint32_t id, const glm::vec3& centre, float rotation_rad) {
  if (frame_begun) return argument_error("move_obstacle called between begin_frame and record");
  auto& placed = river->runtime_obstacles;
  const size_t i = runtime_obstacle_index(id);
  if (i == placed.size()) {
    return argument_error(text_format("move_obstacle: no obstacle with id %u", id));
  }
  WaterObstacle moved = placed[i].placed;
  moved.centre = centre;
  moved.rotation_rad = rotation_rad;
  SIVIFLOW_TRY(check_obstacle("move_obstacle", moved, id));
  const size_t index = river->scene_obstacle_count + i;
  // A circle, or a polygon that did not turn, only moves: one incremental re-solve.
  const bool turned = !moved.polygon.empty() && rotation_rad != placed[i].placed.rotation_rad;
  SIVIFLOW_TRY(turned ? river->flow.replace_obstacle(index, flow_obstacle(moved))
                      : river->flow.move_obstacle(index, centre));
  placed[i].placed = std::move(moved);
  return Status::success();
}

Status Renderer::Impl::remove_obstacle(uint32_t id) {
  if (frame_begun) return argument_error("remove_obstacle called between begin_frame and record");
  auto& placed = river->runtime_obstacles;
  const size_t i = runtime_obstacle_index(id);
  if (i == placed.size()) {
    return argument_error(text_format("remove_obstacle: no obstacle with id %u", id));
  }
  SIVIFLOW_TRY(river->flow.remove_obstacle(river->scene_obstacle_count + i));
  placed.erase(placed.begin() + static_cast<std::ptrdiff_t>(i));
  return Status::success();
}

Status Renderer::Impl::set_look(const WaterLook& new_look) {
  std::string problem;
  const std::string field = water_look_error(new_look, &problem);
  if (!field.empty()) return argument_error("set_look: WaterLook::" + field + " " + problem);
  look = new_look;
  return Status::success();
}

const WaterLook& Renderer::look() const { return impl_->look; }

const char* debug_view_name(DebugView view) {
  static constexpr const char* kNames[kDebugViewCount] = {"none", "flow", "particles", "tiles"};
  const auto index = static_cast<uint32_t>(view);
  return index < kDebugViewCount ? kNames[index] : "";
}

Status Renderer::set_debug_view(DebugView view) {
  return guarded(impl_->info, [&] {
    if (static_cast<uint32_t>(view) >= kDebugViewCount) {
      return argument_error(text_format("set_debug_view: %u is not a DebugView",
                                        static_cast<uint32_t>(view)));
    }
    impl_->debug_view = view;
    return Status::success();
  });
}

DebugView Renderer::debug_view() const { return impl_->debug_view; }

}  // namespace siviflow
