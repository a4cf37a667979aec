// Particles only on water a view sees: with the world's ground and objects as the renderer's
// occluders, no particle sits where the rendered frame shows something in front of the water
// (a pier standing in the channel, the default valley's banks); without them, many sit behind
// the pier. A bad occluder mesh is refused by name and changes nothing.
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "gltf_test_files.h"
#include "renderer_inspect.h"
#include "run_command.h"
#include "straight_channel.h"

namespace siviflow::testing {
namespace {

namespace fs = std::filesystem;

constexpr uint32_t kFrames = 4;
constexpr glm::vec3 kBoulder{-4.0f, 0.0f, 30.0f};  // out of the way
constexpr int kEdgePx = 2;  // a particle this close to visible water may sit on its edge

// Particles on screen whose pixel, and every pixel within kEdgePx of it, shows no water.
size_t particles_on_hidden_water(const Frame& frame, uint32_t height,
                                 std::span<const Particle> particles) {
  const int w = static_cast<int>(frame.width), h = static_cast<int>(height);
  size_t hidden = 0;
  for (const Particle& p : particles) {
    const int x = static_cast<int>(std::floor(p.screen.x)),
              y = static_cast<int>(std::floor(p.screen.y));
    if (p.slot == 0 || x < 0 || y < 0 || x >= w || y >= h) continue;
    bool water_near = false;
    for (int dy = -kEdgePx; dy <= kEdgePx && !water_near; ++dy) {
      for (int dx = -kEdgePx; dx <= kEdgePx && !water_near; ++dx) {
        const int qx = x + dx, qy = y + dy;
        water_near = qx >= 0 && qy >= 0 && qx < w && qy < h &&
                     frame.water_mask[static_cast<size_t>(qy) * w + qx] == 1.0f;
      }
    }
    hidden += water_near ? 0 : 1;
  }
  return hidden;
}

class HiddenWaterTest : public StraightChannelTest {
 protected:
  void SetUp() override {
    StraightChannelTest::SetUp();
    dir_ = fresh_test_dir("hidden_water");
    write_box_gltf(dir_ / "pier.gltf", glm::vec3(2.5f, 1.2f, 0.6f));
    // Low over the channel, looking downstream past a pier that stands in the water.
    set_camera({0.5f, 2.2f, -6.0f}, {0.0f, 0.0f, 14.0f}, {kWidth, kHeight});
  }

  // The last of kFrames frames of the channel with the pier, and how many particles of that
  // frame sit on water it hides; `occluded`: the renderer knows the world's geometry.
  size_t hidden_behind_pier(bool occluded, Frame* last) {
    CreateInfo info = make_create_info(kWidth, kHeight);
    SceneObject pier;
    pier.gltf = (dir_ / "pier.gltf").string();
    pier.translation = {0.0f, 0.7f, 4.0f};
    const Status status = create_channel(info, kBoulder, WaterLook{}, {pier});
    EXPECT_TRUE(status.ok()) << status.message();
    if (!occluded) {
      EXPECT_TRUE(renderer_->set_occluders({}).ok());
    }
    std::vector<Frame> frames = render_still(0, kFrames);
    if (frames.empty()) return 0;
    *last = frames.back();
    return particles_on_hidden_water(*last, kHeight, particle_field(*renderer_).particles());
  }

  fs::path dir_;
};

TEST_F(HiddenWaterTest, NoParticleBehindAPierTheRendererKnows) {
  Frame with, without;
  const size_t hidden_with = hidden_behind_pier(true, &with);
  const size_t hidden_without = hidden_behind_pier(false, &without);
  size_t pier_pixels = 0;
  for (size_t i = 0; i < with.water_mask.size(); ++i) {
    pier_pixels += with.water_mask[i] == 0.0f && without.water_mask[i] == 0.0f ? 1 : 0;
  }
  const size_t particles = particle_field(*renderer_).particles().size();
  std::printf("particles on hidden water: %zu with the occluders, %zu without (of %zu)\n",
              hidden_with, hidden_without, particles);
  EXPECT_GT(hidden_without, 20u) << "the pier hides water the particles would be made on";
  EXPECT_EQ(hidden_with, 0u);
  EXPECT_GT(pier_pixels, 2000u) << "the pier and the banks are in view";
}

TEST_F(HiddenWaterTest, NoParticleOnWaterTheDefaultValleyHides) {
  // Along the default scene's camera path, low over the meanders, with the valley's ground as
  // the occluders (as our tools give it) and without: with them none sits on hidden water, and
  // the visible water keeps its particles (the ground meeting the water hides none of it).
  constexpr uint32_t kSeconds[] = {0, 8, 16, 24};
  size_t on_water[2][4] = {};  // particles on visible water, without and with
  for (const bool occluded : {true, false}) {
    ASSERT_TRUE(create_renderer(make_create_info(kWidth, kHeight)).ok());
    if (!occluded) {
      ASSERT_TRUE(renderer_->set_occluders({}).ok());
    }
    for (size_t i = 0; i < 4; ++i) {
      const std::vector<Frame> frames = render(kSeconds[i] * 30, kSeconds[i] * 30 + kFrames);
      ASSERT_EQ(frames.size(), kFrames);
      const std::span<const Particle> particles = particle_field(*renderer_).particles();
      const size_t hidden = particles_on_hidden_water(frames.back(), kHeight, particles);
      for (const Particle& p : particles) {
        const bool in = p.slot != 0 && p.screen.x >= 0.0f && p.screen.y >= 0.0f &&
                        p.screen.x < kWidth && p.screen.y < kHeight;
        const size_t pixel = size_t(p.screen.y) * kWidth + size_t(p.screen.x);
        on_water[occluded][i] += in && frames.back().water_mask[pixel] == 1.0f ? 1 : 0;
      }
      std::printf("default scene at %2u s, %s occluders: %zu particles on visible water, %zu on "
                  "hidden water\n", kSeconds[i], occluded ? "with" : "without",
                  on_water[occluded][i], hidden);
      if (occluded) {
        EXPECT_EQ(hidden, 0u) << "at " << kSeconds[i] << " s";
      }
    }
  }
  for (size_t i = 0; i < 4; ++i) {
    EXPECT_GE(on_water[1][i] * 100, on_water[0][i] * 95) << "at " << kSeconds[i] << " s";
  }
}

TEST_F(HiddenWaterTest, ABadOccluderMeshIsRefusedByName) {
  ASSERT_TRUE(create_channel(make_create_info(kWidth, kHeight), kBoulder).ok());
  ASSERT_EQ(render_still(0, 1).size(), 1u);
  const auto world = particle_field(*renderer_).occluders();
  ASSERT_NE(world, nullptr);
  const std::vector<glm::vec3> positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  const std::vector<uint32_t> out_of_range = {0, 1, 3};
  Status s = renderer_->set_occluders({positions, out_of_range});
  EXPECT_FALSE(s.ok());
  EXPECT_NE(
      s.message().find("set_occluders: OccluderMesh::indices[2] 3 is out of range (3 positions)"),
      std::string::npos)
      << s.message();
  const std::vector<glm::vec3> nan = {
      {0, 0, 0}, {1, std::numeric_limits<float>::quiet_NaN(), 0}, {0, 1, 0}};
  s = renderer_->set_occluders({nan, {}});
  EXPECT_FALSE(s.ok());
  EXPECT_NE(s.message().find("OccluderMesh::positions[1] is not finite"), std::string::npos)
      << s.message();
  // Finite, but past the world limit: a bounding box of it would overflow (issue 28's crash).
  const std::vector<glm::vec3> huge = {{0, 0, 0}, {3.4e38f, 0, 0}, {0, 1, 0}};
  s = renderer_->set_occluders({huge, {}});
  EXPECT_NE(s.message().find("OccluderMesh::positions[1] (3.4e+38, 0, 0) lies beyond the world "
                             "limit of ±1e+06 m"),
            std::string::npos)
      << s.message();
  const std::vector<glm::vec3> two = {{0, 0, 0}, {1, 0, 0}};
  s = renderer_->set_occluders({two, {}});
  EXPECT_NE(s.message().find("OccluderMesh::positions has 2 values, not 3 per triangle"),
            std::string::npos)
      << s.message();
  // Nothing changed: the renderer renders on with the world's occluders.
  EXPECT_EQ(render_still(1, 3).size(), 2u);
  EXPECT_EQ(particle_field(*renderer_).occluders(), world);
}

}  // namespace
}  // namespace siviflow::testing
