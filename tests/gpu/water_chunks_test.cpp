// The water surface is drawn in chunks culled to the view, so a river's GPU cost follows the
// screen: a view of a long river's first reach draws a small part of its triangles, a view
// away from the water draws none, and the water a view sees is still all there. The reflection
// is drawn, and the refraction copied, only where the water on screen samples them.
#include <algorithm>
#include <string>

#include "render_frames.h"
#include "renderer_inspect.h"
#include "siviflow/water_look.h"

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

TEST_F(WaterChunksTest, TheReflectionAndRefractionAreMadeWhereTheWaterSamplesThem) {
  ASSERT_TRUE(create_renderer(make_create_info(kWidth, kHeight)).ok());
  Frame frame;
  ASSERT_GT(draw(world_->scene_camera(0.0), &frame), 0u);
  // Every water pixel's reflection sample, bent by the ripples up to the look's distortion, lies
  // in the area the reflection is drawn in.
  // The same holds for the refraction copy, bent by the refraction's distortion, in view pixels.
  const VkRect2D reflected = RendererInspector::reflection_area(*renderer_);
  const VkRect2D refracted = RendererInspector::refraction_area(*renderer_);
  const VkExtent2D mirror_size = RendererInspector::reflection_extent(*renderer_);
  const VkExtent2D view_size{kWidth, kHeight};
  const WaterLook look;
  const auto holds = [&](const VkRect2D& area, VkExtent2D size, float reach, uint32_t x,
                         uint32_t y) {
    for (const float dx : {-reach, reach}) {
      for (const float dy : {-reach, reach}) {
        const float u = std::clamp((x + 0.5f) / kWidth + dx, 0.0f, 1.0f) * size.width;
        const float v = std::clamp((y + 0.5f) / kHeight + dy, 0.0f, 1.0f) * size.height;
        if (u < float(area.offset.x) || u > float(area.offset.x + area.extent.width) ||
            v < float(area.offset.y) || v > float(area.offset.y + area.extent.height)) {
          return false;
        }
      }
    }
    return true;
  };
  size_t water_pixels = 0;
  for (uint32_t y = 0; y < kHeight; ++y) {
    for (uint32_t x = 0; x < kWidth; ++x) {
      if (frame.water_mask[size_t{y} * kWidth + x] < 0.5f) continue;
      ++water_pixels;
      ASSERT_TRUE(holds(reflected, mirror_size, look.reflection_distortion, x, y)) << x << "," << y;
      ASSERT_TRUE(holds(refracted, view_size, look.refraction_distortion, x, y)) << x << "," << y;
    }
  }
  ASSERT_GT(water_pixels, 0u);
  // And the sky above the far bank is left out: the water is low on the screen.
  EXPECT_GT(reflected.offset.y, 0);
  EXPECT_LT(reflected.extent.height, mirror_size.height * 3 / 4);
  EXPECT_LT(refracted.extent.height, kHeight * 3 / 4);

  // Looking up into the sky, no water: nothing is drawn into the reflection, nothing copied.
  Camera up = world_->scene_camera(0.0);
  up.target = up.position + glm::vec3(0.0f, 10.0f, 0.1f);
  EXPECT_EQ(draw(up), 0u);
  EXPECT_EQ(RendererInspector::reflection_area(*renderer_).extent.width, 0u);
  EXPECT_EQ(RendererInspector::refraction_area(*renderer_).extent.width, 0u);
}

}  // namespace
}  // namespace siviflow::testing
