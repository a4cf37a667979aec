// The water surface is drawn in chunks culled to the view, so a river's GPU cost follows the
// screen: a view of a long river's first reach draws a small part of its triangles, a view
// away from the water draws none, and the water a view sees is still all there.
#include <string>

#include "render_frames.h"
#include "renderer_inspect.h"

namespace siviflow::testing {
namespace {

class WaterChunksTest : public RenderTest {
 protected:
  // Renders one frame through `camera`; the water triangles it drew, and the frame.
  uint32_t draw(const Camera& camera, Frame* frame = nullptr) {
    std::vector<Frame> frames = render_views(
        0, 1, kWidth, kHeight, [&](double) { return camera_view(camera, {kWidth, kHeight}); });
    if (frame != nullptr && !frames.empty()) *frame = std::move(frames.front());
    return drawn_water_triangles(*renderer_);
  }
};

TEST_F(WaterChunksTest, ALongRiverDrawsTheReachInView) {
  SceneFile scene;
  const Status parsed = parse_scene_file(
      R"({"version":1,"river":{"procedural":{"length":2000}}})", "long.json", ".", &scene);
  ASSERT_TRUE(parsed.ok()) << parsed.message();
  ASSERT_TRUE(create_renderer(make_create_info(kWidth, kHeight), &scene).ok());
  SceneRiverData river;
  ASSERT_TRUE(scene_river_data(&scene, 0, &river).ok());
  const auto total = static_cast<uint32_t>(river.river().indices.size() / 3);

  // The scene's camera, near the upstream end looking downstream: the reach it sees.
  Frame frame;
  const uint32_t seen = draw(world_->scene_camera(0.0), &frame);
  EXPECT_GT(seen, 0u);
  EXPECT_LT(seen, total / 2) << "of " << total;
  size_t water_pixels = 0;
  for (float m : frame.water_mask) water_pixels += m > 0.5f ? 1 : 0;
  EXPECT_GT(water_pixels, size_t{kWidth} * kHeight / 20) << "the water in view is drawn";

  // Looking up into the sky: nothing; from high above the whole river: all of it.
  Camera up = world_->scene_camera(0.0);
  up.target = up.position + glm::vec3(0.0f, 10.0f, 0.1f);
  EXPECT_EQ(draw(up), 0u);
  Camera above;
  above.position = {0.0f, 4000.0f, -1.0f};
  above.target = {0.0f, 0.0f, 0.0f};
  above.far_plane = 10000.0f;
  EXPECT_EQ(draw(above), total);
}

}  // namespace
}  // namespace siviflow::testing
