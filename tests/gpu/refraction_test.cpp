// What lies under the water shows through it: a bright box just under the surface changes
// hundreds of water pixels clearly, the same box deeper far less (absorbed with the depth of
// water the light crosses), and a box in front of the water never shows in what the water
// refracts.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "gltf_test_files.h"
#include "run_command.h"
#include "siviflow/image_files.h"
#include "straight_channel.h"

namespace siviflow::testing {
namespace {

namespace fs = std::filesystem;

constexpr uint32_t kFrame = 8;  // the particles have faded in
constexpr glm::vec3 kBoulder{-3.5f, 0.0f, 8.0f};  // out of the way

// Draws nothing: the water reflects only the sky, so what changes on it is what it refracts.
void reflect_nothing(VkCommandBuffer, const ReflectionView&, void*) {}

class RefractionTest : public StraightChannelTest {
 protected:
  void SetUp() override {
    StraightChannelTest::SetUp();
    dir_ = fresh_test_dir("refraction");
    write_box_gltf(dir_ / "slab.gltf", glm::vec3(0.6f, 0.1f, 0.6f));  // untextured: white
    std::vector<float> rgba;
    for (int i = 0; i < 64; ++i) rgba.insert(rgba.end(), {1.0f, 1.0f, 1.0f, 1.0f});
    ASSERT_TRUE(write_png((dir_ / "white.png").string(), 8, 8, rgba.data()).ok());
    write_textured_box_gltf(dir_ / "magenta.gltf", glm::vec3(0.4f), "white.png",
                            glm::vec4(1.0f, 0.0f, 1.0f, 1.0f));
    // Steeply down on the channel: the water reflects little and shows what lies under it.
    set_camera({1.0f, 7.0f, -3.0f}, {1.0f, 0.0f, 2.0f}, {kWidth, kHeight});
  }

  // Frame kFrame of the channel with `objects`; `occluded`: they hide water from the particles.
  Frame frame_with(const std::vector<SceneObject>& objects, bool occluded = true) {
    CreateInfo info = make_create_info(kWidth, kHeight);
    info.reflection = &reflect_nothing;
    Status status = create_channel(info, kBoulder, WaterLook{}, objects);
    if (status.ok() && !occluded) status = renderer_->set_occluders({});
    EXPECT_TRUE(status.ok()) << status.message();
    std::vector<Frame> frames = render_still(0, kFrame + 1);
    return frames.empty() ? Frame{} : frames.back();
  }

  SceneObject object(const char* gltf, glm::vec3 at) const {
    SceneObject o;
    o.gltf = (dir_ / gltf).string();
    o.translation = at;
    return o;
  }

  fs::path dir_;
};

// The largest channel change of each pixel that is water in both frames (-1 elsewhere).
std::vector<float> changes(const Frame& a, const Frame& b) {
  std::vector<float> out(a.water_mask.size(), -1.0f);
  for (size_t i = 0; i < a.water_mask.size(); ++i) {
    if (a.water_mask[i] != 1.0f || b.water_mask[i] != 1.0f) continue;
    out[i] = 0.0f;
    for (int c = 0; c < 3; ++c) out[i] = std::max(out[i], std::abs(a.rgba[i * 4 + c] - b.rgba[i * 4 + c]));
  }
  return out;
}

TEST_F(RefractionTest, ABoxUnderTheWaterShowsThroughLessTheDeeperItLies) {
  // The slab's top 0.2 m and 1.2 m under the surface, in mid-channel (1.6 m deep).
  const Frame plain = frame_with({});
  const std::vector<float> near = changes(plain, frame_with({object("slab.gltf", {1.0f, -0.3f, 2.0f})}));
  const std::vector<float> far = changes(plain, frame_with({object("slab.gltf", {1.0f, -1.3f, 2.0f})}));
  // Over the pixels the shallow box changes clearly, how much each box changes them.
  size_t water = 0, clear = 0;
  double near_sum = 0.0, far_sum = 0.0;
  for (size_t i = 0; i < near.size(); ++i) {
    water += near[i] >= 0.0f ? 1 : 0;
    if (!(near[i] > 0.05f) || far[i] < 0.0f) continue;
    ++clear;
    near_sum += near[i];
    far_sum += far[i];
  }
  std::printf("the box 0.2 m down changes %zu of %zu water pixels by > 0.05, by %.3f on average; "
              "1.2 m down it changes them by %.3f\n",
              clear, water, near_sum / std::max<size_t>(clear, 1), far_sum / std::max<size_t>(clear, 1));
  ASSERT_GT(water, size_t{kWidth * kHeight / 3}) << "the camera looks at the water";
  EXPECT_GE(clear, 300u) << "the shallow box shows through clearly";
  EXPECT_LE(2.0 * far_sum, near_sum) << "deeper, the water absorbs it";
}

TEST_F(RefractionTest, WhatIsInFrontOfTheWaterNeverShowsInItsRefraction) {
  // A magenta box floating above the water between the camera and the channel: the water round
  // its outline must not take its colour (nor reflect it: the reflection draws nothing). The
  // particles are kept the same in both frames (the box hides no water from them), so that
  // only what the water refracts can differ.
  const Frame plain = frame_with({}, false);
  const Frame boxed = frame_with({object("magenta.gltf", {1.0f, 1.5f, 1.0f})}, false);
  size_t covered = 0, water = 0, tinted = 0;
  for (size_t i = 0; i < plain.water_mask.size(); ++i) {
    if (plain.water_mask[i] == 1.0f && boxed.water_mask[i] != 1.0f) ++covered;
    if (plain.water_mask[i] != 1.0f || boxed.water_mask[i] != 1.0f) continue;
    ++water;
    const auto magenta = [i](const Frame& f) {
      return 0.5f * (f.rgba[i * 4] + f.rgba[i * 4 + 2]) - f.rgba[i * 4 + 1];
    };
    tinted += magenta(boxed) - magenta(plain) > 0.02f ? 1 : 0;
  }
  std::printf("the box hides %zu water pixels; %zu of the %zu around it turn magenta\n", covered,
              tinted, water);
  ASSERT_GT(covered, 500u) << "the box is in front of the water";
  EXPECT_EQ(tinted, 0u);
}

}  // namespace
}  // namespace siviflow::testing
