// A scene's floats through `siviflow capture`: drawn over the water, moving in the motion layer,
// replayed the same in every shard and resume, and refused by name where they would start off
// the water.
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>

#include "run_command.h"
#include "siviflow/frame_folder.h"
#include "siviflow/image_files.h"

namespace siviflow::testing {
namespace {

namespace fs = std::filesystem;

// A straight river past a boulder under a still camera; `floats` is the scene's "floats" value.
std::string scene_text(const std::string& floats) {
  return R"({"version": 1,
    "river": {"procedural": {"meander_amplitude": 0.0, "width_variation": 0.0}},
    "obstacles": [{"center": [0.5, 0.0, -20.0], "radius": 1.4}],
    "floats": )" + floats + R"(,
    "camera": {"keys": [{"t": 0, "position": [-4.0, 5.0, -38.0], "target": [0.0, 0.0, -25.0]}]}})";
}

const std::string kFloats = R"([
    {"mesh": "log", "release_point": [-1.0, -31.0], "radius": 1.2},
    {"mesh": "log", "release_point": [2.0, -29.0], "radius": 1.0, "release_time": 0.1},
    {"mesh": "leaf", "release_point": [0.0, -30.0], "radius": 0.4}])";

class CaptureFloatsTest : public ::testing::Test {
 protected:
  void SetUp() override { dir_ = fresh_test_dir("capture_floats"); }
  fs::path write_scene(const std::string& name, const std::string& floats) {
    const fs::path path = dir_ / (name + ".json");
    std::ofstream(path) << scene_text(floats);
    return path;
  }
  fs::path folder(const std::string& name) {
    const fs::path path = dir_ / name;
    fs::create_directories(path);
    return path;
  }
  fs::path dir_;
};

TEST_F(CaptureFloatsTest, FloatsAreDrawnOverTheWaterAndMoveInTheMotionLayer) {
  const fs::path with = folder("with");
  const fs::path without = folder("without");
  const std::string args = " --range 20:21 --size 320x180 --aov depth,flow,motion --validation --out ";
  RunResult r = run_siviflow("capture " + write_scene("floats", kFloats).string() + args + with.string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  r = run_siviflow("capture " + write_scene("none", "[]").string() + args + without.string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  ExrImage a;
  ExrImage b;
  ASSERT_TRUE(read_exr((with / frame_file_name(20)).string(), &a).ok());
  ASSERT_TRUE(read_exr((without / frame_file_name(20)).string(), &b).ok());
  ASSERT_NE(a.find("water.A"), nullptr);
  ASSERT_NE(a.find("motion.X"), nullptr);
  const std::vector<float>& mask_with = *a.find("water.A");
  const std::vector<float>& mask_without = *b.find("water.A");
  // The floats hide water: there, and only there, the pixels move under the still camera.
  size_t float_pixels = 0;
  size_t moving = 0;
  for (size_t i = 0; i < mask_with.size(); ++i) {
    const float x = (*a.find("motion.X"))[i];
    const float y = (*a.find("motion.Y"))[i];
    const bool on_float = mask_without[i] == 1.0f && mask_with[i] == 0.0f;
    if (!on_float) {
      if (mask_with[i] == 0.0f) {
        ASSERT_EQ(x, 0.0f) << "still ground at pixel " << i;
        ASSERT_EQ(y, 0.0f) << "still ground at pixel " << i;
      }
      continue;
    }
    ++float_pixels;
    // Downstream is away from the camera: up the image (motion.Y is then minus y up: < 0).
    if (std::hypot(x, y) > 0.02f && y < 0.0f) ++moving;
  }
  std::printf("%zu pixels of floats, %zu of them moving upstream-to-downstream\n", float_pixels, moving);
  EXPECT_GT(float_pixels, 40u) << "two logs and a leaf in view";
  EXPECT_GT(moving, float_pixels * 9 / 10);
}

TEST_F(CaptureFloatsTest, ShardsAndResumesReplayTheFloatsBitIdentically) {
  const std::string scene = write_scene("floats", kFloats).string();
  const fs::path full = folder("full");
  const fs::path shard = folder("shard");
  const std::string args = "capture " + scene + " --size 96x54 --aov motion --out ";
  ASSERT_EQ(run_siviflow(args + full.string() + " --range 0:8").exit_code, 0);
  // The second log is released at frame 3, within the frames the shard only simulates.
  ASSERT_EQ(run_siviflow(args + shard.string() + " --range 5:8").exit_code, 0);
  for (uint32_t frame = 5; frame < 8; ++frame) {
    const std::string name = frame_file_name(frame);
    ExrImage a;
    ExrImage b;
    ASSERT_TRUE(read_exr((full / name).string(), &a).ok());
    ASSERT_TRUE(read_exr((shard / name).string(), &b).ok());
    for (const char* channel : {"R", "G", "B", "A", "motion.X", "motion.Y", "motion.Z", "motion.W"}) {
      EXPECT_EQ(*a.find(channel), *b.find(channel)) << name << " " << channel;
    }
  }
  const fs::path resumed = dir_ / "resumed";
  fs::copy(full, resumed);
  fs::remove(resumed / frame_file_name(4));
  fs::remove(resumed / frame_file_name(6));
  const RunResult run = run_siviflow(args + resumed.string() + " --range 0:8 --resume");
  ASSERT_EQ(run.exit_code, 0) << run.output;
  EXPECT_NE(run.output.find("wrote 2 of frames 0..7"), std::string::npos) << run.output;
  for (uint32_t frame = 0; frame < 8; ++frame) {
    EXPECT_EQ(read_file(full / frame_file_name(frame)), read_file(resumed / frame_file_name(frame)))
        << frame_file_name(frame);
  }
}

TEST_F(CaptureFloatsTest, ReleasePointsOffTheWaterAreRefusedByName) {
  const fs::path out = folder("out");
  RunResult r = run_siviflow("capture " +
                             write_scene("off", R"([{"release_point": [0, -30]}, {"release_point": [40, -30]}])")
                                 .string() +
                             " --size 64x36 --out " + out.string());
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_NE(r.output.find("off.json: floats[1].release_point: (40, -30) is not on any river"),
            std::string::npos)
      << r.output;
  r = run_siviflow("capture " + write_scene("in", R"([{"release_point": [0.5, -20]}])").string() +
                   " --size 64x36 --out " + out.string());
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_NE(r.output.find("floats[0].release_point: (0.5, -20) is inside obstacles[0]'s footprint"),
            std::string::npos)
      << r.output;
  EXPECT_TRUE(fs::is_empty(out)) << "nothing written";
}

}  // namespace
}  // namespace siviflow::testing
