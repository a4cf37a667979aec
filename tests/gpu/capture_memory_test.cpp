// A capture's frames after the first reuse the memory the first ones faulted in: memory freed and
// faulted in again every frame (the process's allocator handing blocks back to the kernel) costs
// a 720p capture a tenth of its time, and shows here as page faults that grow with the frames.
#include <sys/resource.h>

#include <string>

#include <gtest/gtest.h>

#include "run_command.h"

namespace siviflow::testing {
namespace {

// Minor page faults of one capture of `frames` frames (through the shell, which waits for it).
long capture_page_faults(int frames, const std::string& out) {
  rusage before{};
  getrusage(RUSAGE_CHILDREN, &before);
  const RunResult r = run_siviflow("capture --frames " + std::to_string(frames) +
                                   " --size 320x180 --validation --force --out " + out);
  EXPECT_EQ(r.exit_code, 0) << r.output;
  rusage after{};
  getrusage(RUSAGE_CHILDREN, &after);
  return after.ru_minflt - before.ru_minflt;
}

TEST(CaptureMemory, LaterFramesFaultInNoFreshMemory) {
  const std::string out = fresh_test_dir("capture_memory").string();
  constexpr int kShortFrames = 3, kLongFrames = 11;
  const long short_run = capture_page_faults(kShortFrames, out);
  const long long_run = capture_page_faults(kLongFrames, out);
  // About 25 a frame; 3000 when OpenEXR's Huffman tables were mapped afresh for every block.
  const double per_frame = static_cast<double>(long_run - short_run) / (kLongFrames - kShortFrames);
  EXPECT_LT(per_frame, 500.0) << short_run << " faults for " << kShortFrames << " frames, "
                              << long_run << " for " << kLongFrames;
}

}  // namespace
}  // namespace siviflow::testing
