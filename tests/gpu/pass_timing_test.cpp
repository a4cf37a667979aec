// The timings bench reports come from Renderer::pass_times() and World::pass_times(): each pass
// named in the order it runs, starting no earlier than the one before, and all of them together
// inside the wall time the host waited for the frame (a timer reading 1000 times too long
// fails here). The world's draw statistics count what it drew.
#include <chrono>
#include <string>
#include <vector>

#include "gpu_test.h"

namespace siviflow::testing {
namespace {

constexpr uint32_t kWidth = 160;
constexpr uint32_t kHeight = 90;

class PassTimingTest : public GpuTest {};

TEST_F(PassTimingTest, PassesComeNamedInOrderInsideTheFrame) {
  CreateInfo info = make_create_info(kWidth, kHeight);
  info.readback_images = 0;
  info.enable_timing = true;
  info.measure_flow_floor = true;
  time_world_ = true;
  ASSERT_TRUE(create_renderer(info).ok());
  HostTargets targets;
  ASSERT_TRUE(create_sampled_targets({kWidth, kHeight}, &targets).ok());
  for (uint32_t frame = 0; frame < 3; ++frame) {
    const double time = frame / 30.0;
    const View view = camera_view(world_->scene_camera(time), {kWidth, kHeight});
    VkCommandBuffer cmd = VK_NULL_HANDLE;
    ASSERT_TRUE(context_->begin_slot(0, &cmd).ok());
    ASSERT_TRUE(renderer_->begin_frame(0).ok());
    ASSERT_TRUE(renderer_->update(view, time).ok());
    const Status recorded =
        record_world_and_water(cmd, 0, *world_, *renderer_, view, time, ReadbackTargets{}, &targets);
    ASSERT_TRUE(recorded.ok()) << recorded.message();
    const auto submitted = std::chrono::steady_clock::now();
    ASSERT_TRUE(context_->end_slot_and_submit(0).ok());
    ASSERT_TRUE(context_->wait_slot(0).ok());
    const double wall_ms = std::chrono::duration<double, std::milli>(
                               std::chrono::steady_clock::now() - submitted).count();

    std::vector<PassTime> water;
    ASSERT_TRUE(renderer_->pass_times(0, &water).ok());
    std::vector<std::string> names;
    for (const PassTime& pass : water) names.push_back(pass.name);
    EXPECT_EQ(names, (std::vector<std::string>{"upload", "reflection", "refraction copy",
                                               "flow tiles", "flow", "flow floor"}));
    ASSERT_FALSE(water.empty());
    EXPECT_EQ(water.front().begin_ms, 0.0);
    double sum = 0.0;
    for (size_t i = 0; i < water.size(); ++i) {
      EXPECT_GE(water[i].milliseconds, 0.0) << water[i].name;
      if (i > 0) {
        EXPECT_GE(water[i].begin_ms, water[i - 1].begin_ms) << water[i].name;
      }
      sum += water[i].milliseconds;
    }
    std::vector<PassTime> world;
    ASSERT_TRUE(world_->pass_times(0, &world).ok());
    ASSERT_EQ(world.size(), 1u);
    EXPECT_EQ(world[0].name, "world");
    EXPECT_GT(world[0].milliseconds, 0.0);
    // The world and the water ran one after the other inside the frame the host waited for.
    const double span = water.back().begin_ms + water.back().milliseconds;
    EXPECT_LE(sum, span + 1e-3);
    EXPECT_LE(span + world[0].milliseconds, wall_ms) << "timestamps longer than the frame";
    const WorldDrawStats drawn = world_->draw_stats();
    EXPECT_GT(drawn.main_triangles, 0u);
    EXPECT_GT(drawn.reflection_triangles, 0u);
  }
}

TEST_F(PassTimingTest, TimesNeedTimingAndAValidSlot) {
  CreateInfo info = make_create_info(kWidth, kHeight);
  ASSERT_TRUE(create_renderer(info).ok());
  std::vector<PassTime> times;
  const Status water = renderer_->pass_times(0, &times);
  EXPECT_FALSE(water.ok());
  EXPECT_NE(water.message().find("enable_timing"), std::string::npos) << water.message();
  const Status world = world_->pass_times(0, &times);
  EXPECT_FALSE(world.ok());
  EXPECT_NE(world.message().find("WorldCreateInfo::enable_timing"), std::string::npos)
      << world.message();
  time_world_ = true;
  info.enable_timing = true;
  ASSERT_TRUE(create_renderer(info).ok());
  const Status slot = world_->pass_times(7, &times);
  EXPECT_NE(slot.message().find("slot out of range"), std::string::npos) << slot.message();
  EXPECT_FALSE(renderer_->pass_times(7, &times).ok());
}

}  // namespace
}  // namespace siviflow::testing
