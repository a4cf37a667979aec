// The view the tests of the flow's marks on the water measure: a still camera looking down on a
// straight channel, flowing along +Z, with a boulder in mid-stream that the host can move (a
// runtime obstacle of the renderer, drawn by the world's boulder of the same place), and islands
// where a test asks for them.
#pragma once

#include <cmath>
#include <glm/mat4x4.hpp>
#include <glm/matrix.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>
#include <optional>
#include <vector>

#include "render_frames.h"
#include "siviflow/scene_file.h"
#include "siviflow/scene_river.h"

namespace siviflow::testing {

class StraightChannelTest : public RenderTest {
 protected:
  static constexpr float kBoulderRadius = 1.2f;
  static constexpr float kChannelWidth = 12.0f;

  static SceneFile channel_scene(const glm::vec3& boulder,
                                 const std::vector<ProceduralIsland>& islands = {},
                                 const std::optional<ProceduralConfluence>& confluence = {}) {
    SceneFile scene;
    scene.path = "straight-channel.json";
    ProceduralRiverParams& river = scene.rivers[0].procedural;
    river.length = 120.0f;
    river.meander_amplitude = 0.0f;
    river.width = kChannelWidth;
    river.width_variation = 0.0f;
    river.islands = islands;
    river.confluence = confluence;
    Obstacle obstacle;
    obstacle.centre = boulder;
    obstacle.radius = kBoulderRadius;
    scene.obstacles.push_back(obstacle);
    return scene;
  }

  // The world of the channel with its boulder at `boulder`, `objects`, `islands` and
  // `confluence`, and the
  // water of the channel with the boulder as a runtime obstacle (so that move_boulder can move
  // it), which reflects the world unless `info` names a reflection of its own; the world's
  // ground and objects are its occluders.
  Status create_channel(CreateInfo info, const glm::vec3& boulder, const WaterLook& look = {},
                        const std::vector<SceneObject>& objects = {},
                        const std::vector<ProceduralIsland>& islands = {},
                        const std::optional<ProceduralConfluence>& confluence = {}) {
    renderer_.reset();
    world_.reset();
    scene_ = channel_scene(boulder, islands, confluence);
    scene_.look = look;
    scene_.objects = objects;
    WorldCreateInfo world_info = context_->world_create_info(info.color_format, info.depth_format);
    world_info.frames_in_flight = info.frames_in_flight;
    world_info.scene = &scene_;
    SIVIFLOW_TRY(World::create(world_info, &world_));
    SceneRiverData river;
    SIVIFLOW_TRY(scene_river_data(&scene_, 0, &river));
    river.obstacles.clear();
    const WaterRiver water = river.river();
    info.river = &water;
    info.look = &scene_.look;
    if (info.reflection == nullptr) {
      info.reflection = &World::draw_reflection;
      info.reflection_user = world_.get();
    }
    SIVIFLOW_TRY(Renderer::create(info, &renderer_));
    SIVIFLOW_TRY(renderer_->set_occluders(world_->occluders()));
    WaterObstacle obstacle;
    obstacle.centre = boulder;
    obstacle.radius = kBoulderRadius;
    return renderer_->add_obstacle(obstacle, &obstacle_id_);
  }

  Status move_boulder(const glm::vec3& centre) {
    SIVIFLOW_TRY(renderer_->move_obstacle(obstacle_id_, centre));
    return world_->place_boulder(0, centre);
  }

  // Places the still camera (by default it looks down the channel at the boulder from behind
  // and above) and sizes the view.
  void set_camera(const glm::vec3& position, const glm::vec3& target, VkExtent2D extent) {
    camera_.position = position;
    camera_.target = target;
    extent_ = extent;
  }
  View view() const { return camera_view(camera_, extent_); }

  std::vector<Frame> render_still(uint32_t first, uint32_t end) {
    return render_views(first, end, extent_.width, extent_.height,
                        [this](double) { return view(); });
  }

  // Where the centre of pixel (x, y) sees the water's level plane (y = 0), in x and z.
  glm::vec2 water_point(double x, double y) const {
    const View v = view();
    const glm::mat4 to_world = glm::inverse(v.projection * v.view);
    const glm::vec2 ndc{(x + 0.5) / extent_.width * 2.0 - 1.0,
                        (y + 0.5) / extent_.height * 2.0 - 1.0};
    const glm::vec4 near = to_world * glm::vec4(ndc, 0.0f, 1.0f);
    const glm::vec4 far = to_world * glm::vec4(ndc, 1.0f, 1.0f);
    const glm::vec3 a = glm::vec3(near) / near.w, b = glm::vec3(far) / far.w;
    const float t = a.y / (a.y - b.y);
    const glm::vec3 p = a + t * (b - a);
    return {p.x, p.z};
  }

  // The pixel (x right, y down) where world point `p` is seen.
  glm::dvec2 pixel_of(const glm::vec3& p) const {
    const View v = view();
    const glm::vec4 clip = v.projection * v.view * glm::vec4(p, 1.0f);
    return {(clip.x / clip.w + 1.0) * 0.5 * extent_.width - 0.5,
            (clip.y / clip.w + 1.0) * 0.5 * extent_.height - 0.5};
  }

  SceneFile scene_;
  uint32_t obstacle_id_ = 0;
  Camera camera_{{0.0f, 15.0f, -7.0f}, {0.0f, 0.0f, 4.0f}};
  VkExtent2D extent_{kWidth, kHeight};
};

}  // namespace siviflow::testing
