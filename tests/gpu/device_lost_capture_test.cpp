// VK_ERROR_DEVICE_LOST during a capture, from a submit or from a fence wait, at each point of a
// short capture in turn (tests/gpu/lose_device_layer.cpp makes the device look lost): the tool
// exits 1 with a message naming the call and the result, and the frames it wrote before are
// complete (OpenEXR reads them whole and its deep check passes), consecutive from the first, and
// nothing partial or temporary is left in the folder.
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "run_command.h"
#include "siviflow/frame_folder.h"
#include "siviflow/image_files.h"

namespace siviflow::testing {
namespace {

namespace fs = std::filesystem;

constexpr int kFrames = 6;

// Captures frames 0..kFrames-1 with the device lost at the `at`-th call of `kind`; returns how
// many frames were written, after checking all of the above.
int capture_losing_device(const std::string& kind, int at) {
  const fs::path dir = fresh_test_dir("device_lost") / (kind + std::to_string(at));
  fs::create_directories(dir);
  // The validation layer (from the system's folder) sits below ours, between it and the driver:
  // it checks every call that reaches the real device, before and after the loss. (Above ours it
  // would take the device for lost while it is idle, and 1.3.239 then reports the host's
  // destruction of objects the lost device was using.)
  const std::string env = "VK_LAYER_PATH=/usr/share/vulkan/explicit_layer.d:"
                          SIVIFLOW_LOSE_DEVICE_LAYER_DIR
                          " VK_INSTANCE_LAYERS=VK_LAYER_SIVIFLOW_lose_device"
                          " SIVIFLOW_TEST_LOSE_DEVICE=" + kind + ":" + std::to_string(at);
  const RunResult run = run_siviflow(
      "capture --range 0:" + std::to_string(kFrames) +
          " --size 64x36 --aov depth --validation --out " + dir.string(),
      env);
  const std::string where = kind + ":" + std::to_string(at) + "\n" + run.output;
  EXPECT_EQ(run.exit_code, 1) << where;
  EXPECT_NE(run.output.find("VK_ERROR_DEVICE_LOST"), std::string::npos) << where;
  EXPECT_NE(run.output.find(kind == "submit" ? "vkQueueSubmit2" : "vkWaitForFences"),
            std::string::npos)
      << where;
  EXPECT_EQ(run.output.find("[vulkan error]"), std::string::npos) << where;

  std::vector<std::string> names;
  for (const auto& entry : fs::directory_iterator(dir)) {
    names.push_back(entry.path().filename().string());
  }
  std::sort(names.begin(), names.end());
  for (size_t i = 0; i < names.size(); ++i) {
    EXPECT_EQ(names[i], frame_file_name(static_cast<uint32_t>(i))) << "not consecutive, or not a frame; "
                                                         << where;
    const std::string file = (dir / names[i]).string();
    ExrImage image;
    const Status read = read_exr(file, &image);
    EXPECT_TRUE(read.ok()) << read.message();
    EXPECT_EQ(image.width, 64);
    EXPECT_NE(image.find("depth.Z"), nullptr) << file;
    const Status checked = check_exr_file(file);
    EXPECT_TRUE(checked.ok()) << checked.message();
  }
  return static_cast<int>(names.size());
}

// The frames written when the device is lost at each call of `kind` in turn, printed.
std::vector<int> sweep(const std::string& kind) {
  std::vector<int> written;
  for (int at = 1; at <= kFrames; ++at) written.push_back(capture_losing_device(kind, at));
  std::printf("frames written when the device is lost at %s 1..%d:", kind.c_str(), kFrames);
  for (int count : written) std::printf(" %d", count);
  std::printf("\n");
  return written;
}

TEST(DeviceLostCapture, LostAtEachSubmitLeavesOnlyCompleteFrames) {
  const std::vector<int> written = sweep("submit");
  // Frames submitted before the loss and waited for are written: more as the loss comes later.
  EXPECT_EQ(written.front(), 0);
  EXPECT_TRUE(std::is_sorted(written.begin(), written.end()));
  EXPECT_GT(written.back(), 0);
}

TEST(DeviceLostCapture, LostAtEachFenceWaitLeavesOnlyCompleteFrames) {
  const std::vector<int> written = sweep("wait");
  EXPECT_TRUE(std::is_sorted(written.begin(), written.end()));
  EXPECT_GT(written.back(), 0);
}

}  // namespace
}  // namespace siviflow::testing
