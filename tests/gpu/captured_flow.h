// One frame of a scene captured by `siviflow capture` (its flow AOV, validated) and read back:
// what the end-to-end flow tests compare against their oracles.
#pragma once

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "run_command.h"
#include "siviflow/image_files.h"

namespace siviflow::testing {

struct CapturedFlow {
  ExrImage image;
  const std::vector<float>* water = nullptr;  // water.A
  const std::vector<float>* x = nullptr;      // flow.X
  const std::vector<float>* z = nullptr;      // flow.Z
};

// Writes `scene` into a fresh folder of `group`, captures frame 30 at `size` with the flow AOV
// under validation, and reads it; false (with the test failed) where any of it does not work.
inline bool capture_flow(const std::string& group, const std::string& scene,
                         const std::string& size, CapturedFlow* out) {
  const std::filesystem::path dir = fresh_test_dir(group);
  std::ofstream(dir / "scene.json") << scene;
  const RunResult run =
      run_siviflow("capture " + (dir / "scene.json").string() + " --range 30:31 --size " + size +
                   " --aov flow --validation --out " + dir.string());
  EXPECT_EQ(run.exit_code, 0) << run.output;
  if (run.exit_code != 0 || !read_exr((dir / "frame_00030.exr").string(), &out->image).ok())
    return false;
  out->water = out->image.find("water.A");
  out->x = out->image.find("flow.X");
  out->z = out->image.find("flow.Z");
  EXPECT_TRUE(out->water && out->x && out->z);
  return out->water && out->x && out->z;
}

}  // namespace siviflow::testing
