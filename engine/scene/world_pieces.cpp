// The world's pieces that move: the boulders standing for obstacles and the floats a host
// drifts, placed and hidden by the host, and the draws each view makes of them and of the static
// pieces it sees.
#include <algorithm>
#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include <glm/geometric.hpp>
#include <glm/mat3x3.hpp>
#include <glm/matrix.hpp>

#include "scene/float_meshes.h"
#include "scene/world_impl.h"

namespace siviflow {
namespace {

// The constants that draw a model turned by `heading` about +y and placed at `offset` with the
// scene shaders, which work in the model's coordinates: light, clip and fog see the same
// directions and distances as for the placed model.
gpu::SceneConstants posed(const gpu::SceneConstants& constants, glm::vec3 offset,
                          float heading = 0.0f) {
  const float c = std::cos(heading);
  const float s = std::sin(heading);
  glm::mat4 model(1.0f);
  model[0] = glm::vec4(c, 0.0f, s, 0.0f);  // +x turned towards +z
  model[2] = glm::vec4(-s, 0.0f, c, 0.0f);
  model[3] = glm::vec4(offset, 1.0f);
  const glm::mat3 to_model = glm::transpose(glm::mat3(model));
  gpu::SceneConstants moved = constants;
  moved.view_proj = constants.view_proj * model;
  moved.camera_position =
      glm::vec4(to_model * (glm::vec3(constants.camera_position) - offset), constants.camera_position.w);
  moved.sun_direction = glm::vec4(to_model * glm::vec3(constants.sun_direction), constants.sun_direction.w);
  moved.clip_plane = glm::vec4(to_model * glm::vec3(constants.clip_plane),
                               constants.clip_plane.w + glm::dot(glm::vec3(constants.clip_plane), offset));
  moved.fog.z += offset.y;  // height fog needs the world height, not the model's
  return moved;
}

}  // namespace

// The pieces `view` sees, nearest first, then the boulders where their obstacles are at the
// frame's time, then the floats where their host placed them; `which` 0 main view, 1 mirrored.
void World::Impl::select_draws(const CullView& view, const gpu::SceneConstants& constants,
                               size_t which, std::vector<SceneDraw>* draws, uint32_t* triangles) {
  piece_levels.resize(pieces.size());
  for (size_t i = 0; i < pieces.size(); ++i) piece_levels[i] = choose_level(pieces[i], view);
  std::vector<std::pair<float, SceneDraw>>& seen = sorted_pieces;
  seen.clear();
  for (size_t i = 0; i < pieces.size(); ++i) {
    if (piece_levels[i] == kCulled) continue;
    const LodPiece& piece = pieces[i];
    const glm::vec3 nearest = glm::clamp(view.camera, piece.lo, piece.hi);
    const float distance = glm::length(nearest - view.camera);
    piece_ranges.clear();
    append_piece_ranges(pieces, piece_levels, i, &piece_ranges);
    for (const IndexRange& range : piece_ranges) {
      seen.push_back({distance, {range.first_index, range.index_count, &constants, piece.material,
                                 piece.one_sided}});
    }
  }
  std::stable_sort(seen.begin(), seen.end(),
                   [](const auto& a, const auto& b) { return a.first < b.first; });
  draws->clear();
  for (const auto& entry : seen) draws->push_back(entry.second);
  for (size_t i = 0; i < obstacles.size(); ++i) {
    if (!shown[i]) continue;
    obstacle_constants[2 * i + which] = posed(constants, boulder_centre(i, time));
    draws->push_back({boulders[i].first_index, boulders[i].index_count,
                      &obstacle_constants[2 * i + which]});
  }
  for (size_t i = 0; i < floats.size(); ++i) {
    const WorldFloat& f = floats[i];
    if (!f.shown) continue;
    float_constants[2 * i + which] = posed(constants, f.centre, f.heading);
    draws->push_back({f.triangles.first_index, f.triangles.index_count, &float_constants[2 * i + which]});
  }
  *triangles = 0;
  for (const SceneDraw& draw : *draws) *triangles += draw.index_count / 3;
}

uint32_t World::boulder_count() const { return static_cast<uint32_t>(impl_->obstacles.size()); }

Status World::place_boulder(uint32_t index, const glm::vec3& centre) {
  if (index >= boulder_count()) {
    return world_error("place_boulder: no boulder " + std::to_string(index) + " (there are " +
                       std::to_string(boulder_count()) + ")");
  }
  if (!std::isfinite(centre.x) || !std::isfinite(centre.y) || !std::isfinite(centre.z)) {
    return world_error("place_boulder: centre is not finite");
  }
  impl_->placed[index] = centre;
  impl_->shown[index] = true;
  return Status::success();
}

Status World::hide_boulder(uint32_t index) {
  if (index >= boulder_count()) {
    return world_error("hide_boulder: no boulder " + std::to_string(index) + " (there are " +
                       std::to_string(boulder_count()) + ")");
  }
  impl_->shown[index] = false;
  return Status::success();
}

Status World::boulder_at(uint32_t index, double time_seconds, BoulderPose* out) const {
  if (index >= boulder_count()) {
    return world_error("boulder_at: no boulder " + std::to_string(index) + " (there are " +
                       std::to_string(boulder_count()) + ")");
  }
  if (out == nullptr) return world_error("boulder_at: out is null");
  out->shown = impl_->shown[index];
  out->centre = impl_->boulder_centre(index, time_seconds);
  out->radii = boulder_radii(impl_->obstacles[index]);
  return Status::success();
}

uint32_t World::float_count() const { return static_cast<uint32_t>(impl_->floats.size()); }

Status World::place_float(uint32_t index, const glm::vec3& centre, float heading) {
  if (index >= float_count()) {
    return world_error("place_float: no float " + std::to_string(index) + " (there are " +
                       std::to_string(float_count()) + ")");
  }
  if (!std::isfinite(centre.x) || !std::isfinite(centre.y) || !std::isfinite(centre.z) ||
      !std::isfinite(heading)) {
    return world_error("place_float: centre or heading is not finite");
  }
  WorldFloat& f = impl_->floats[index];
  f.centre = centre;
  f.heading = heading;
  f.shown = true;
  return Status::success();
}

Status World::hide_float(uint32_t index) {
  if (index >= float_count()) {
    return world_error("hide_float: no float " + std::to_string(index) + " (there are " +
                       std::to_string(float_count()) + ")");
  }
  impl_->floats[index].shown = false;
  return Status::success();
}

Status World::float_reach(uint32_t index, glm::vec3* out) const {
  if (index >= float_count()) {
    return world_error("float_reach: no float " + std::to_string(index) + " (there are " +
                       std::to_string(float_count()) + ")");
  }
  if (out == nullptr) return world_error("float_reach: out is null");
  *out = siviflow::float_reach(impl_->floats[index].mesh, impl_->floats[index].radius);
  return Status::success();
}

}  // namespace siviflow
