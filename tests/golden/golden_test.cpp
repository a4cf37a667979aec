// Golden frames: three views of the default scene at 320x180, rendered by `siviflow capture`
// on lavapipe with validation, compared with tests/golden/*.exr within a tolerance: the beauty
// with its alpha, the depth and the water mask.
// Regenerate them only on purpose: tools/scripts/update_goldens.sh.
#include <filesystem>
#include <string>

#include <gtest/gtest.h>

#include "golden/golden_compare.h"
#include "run_command.h"

namespace siviflow::testing {
namespace {

namespace fs = std::filesystem;

class GoldenTest : public ::testing::TestWithParam<int> {};

TEST_P(GoldenTest, DefaultSceneFrameMatchesGolden) {
  const int frame = GetParam();
  const fs::path out = fs::path(SIVIFLOW_BINARY_DIR) / "tests" / "golden_out" / std::to_string(frame);
  fs::remove_all(out);
  fs::create_directories(out);
  const RunResult r = run_siviflow("capture --range " + std::to_string(frame) + ":" +
                                   std::to_string(frame + 1) +
                                   " --size 320x180 --aov depth,flow --validation --out " +
                                   out.string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  char name[32];
  std::snprintf(name, sizeof(name), "frame_%05d.exr", frame);
  const fs::path golden = fs::path(SIVIFLOW_TEST_DATA_DIR).parent_path() / "golden" / name;
  ASSERT_TRUE(fs::exists(golden)) << golden;
  const GoldenResult result =
      compare_with_golden((out / name).string(), golden.string(), (out / "diff.png").string(), {});
  EXPECT_TRUE(result.pass) << result.message;
}

// The start of the glide (particles fading in), the boulder rolling in, and later downstream.
INSTANTIATE_TEST_SUITE_P(Views, GoldenTest, ::testing::Values(0, 75, 240));

}  // namespace
}  // namespace siviflow::testing
