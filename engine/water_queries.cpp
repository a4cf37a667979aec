// Renderer::query_water: the river's point queries (sim/water_query.h) in the host's world, with
// the host's obstacle ids and this renderer's foam amount.
#include <algorithm>
#include <cmath>
#include <span>

#include <glm/geometric.hpp>
#include <glm/matrix.hpp>

#include "renderer_impl.h"
#include "siviflow/text_format.h"

namespace siviflow {

Status Renderer::query_water(std::span<const glm::vec3> points, std::span<WaterSample> out) const {
  return guarded(impl_->info, [&] { return impl_->query_water(points, out); });
}

Status Renderer::Impl::query_water(std::span<const glm::vec3> points,
                                   std::span<WaterSample> out) const {
  if (out.size() < points.size()) {
    return argument_error(text_format("query_water: out holds %zu samples for %zu points",
                                      out.size(), points.size()));
  }
  for (size_t i = 0; i < points.size(); ++i) {
    const glm::vec3& p = points[i];
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) {
      return argument_error(text_format("query_water: points[%zu] (%g, %g, %g) is not finite", i,
                                        double(p.x), double(p.y), double(p.z)));
    }
  }
  const bool placed = info.world_from_river != glm::mat4(1.0f);
  const glm::mat3 rotate(info.world_from_river);
  const glm::mat3 rotate_normal = glm::transpose(glm::inverse(rotate));
  // In batches, so a host's million points need no second million-sample buffer.
  constexpr size_t kBatch = 256;
  glm::vec3 in_river[kBatch];
  const SharedRiver& shared = *river;
  for (size_t first = 0; first < points.size(); first += kBatch) {
    const size_t n = std::min(kBatch, points.size() - first);
    for (size_t i = 0; i < n; ++i) {
      in_river[i] = placed ? glm::vec3(river_from_world * glm::vec4(points[first + i], 1.0f))
                           : points[first + i];
    }
    const std::span<WaterSample> batch = out.subspan(first, n);
    shared.flow.query(std::span<const glm::vec3>(in_river, n), batch);
    for (WaterSample& s : batch) {
      if (s.obstacle != WaterSample::kNoObstacle) {
        const size_t index = s.obstacle - 1;  // the flow's obstacles: the river's, then the host's
        s.obstacle = index < shared.scene_obstacle_count
                         ? WaterSample::kRiverObstacle + static_cast<uint32_t>(index)
                         : shared.runtime_obstacles[index - shared.scene_obstacle_count].id;
      }
      s.foam = std::clamp(s.foam * look.foam_amount, 0.0f, 1.0f);
      if (placed) {
        if (s.on_surface) {
          s.surface = glm::vec3(info.world_from_river * glm::vec4(s.surface, 1.0f));
          s.normal = glm::normalize(rotate_normal * s.normal);
        }
        s.velocity = rotate * s.velocity;
      }
    }
  }
  return Status::success();
}

}  // namespace siviflow
